#!/usr/bin/env bash
# Byte-for-byte comparison of two accelcal binaries' three-axis outputs.
#
# Usage: tools/compare-imu-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]
#   env REALIZATIONS=N   (the ensembles' size, default 64)
#
# Runs, with each binary:
#   - `calibrate --imu` on examples/comma2k19_3d with 15 and 21 states, with and without
#     --estimate-noise: summary.json (timing fields removed) and estimates.csv;
#   - `simulate --model ins --logs` of the default 600 s drive, and `calibrate --imu` on it;
#   - `ensemble --model ins` with 15 and 21 states (scale factors of 1000 ppm), and the 15-state
#     one as 2 shards merged: the JSON, timing fields removed.
# Prints one line per compared file (same / DIFFERENT) and exits 1 when any file differs.
set -u
OLD=$(readlink -f "$1")
NEW=$(readlink -f "$2")
WORK=${3:-$(mktemp -d /tmp/compare_imu.XXXXXX)}
N=${REALIZATIONS:-64}
ROOT=$(readlink -f "$(dirname "$0")/..")
COMMA="$ROOT/examples/comma2k19_3d"
mkdir -p "$WORK"
cd "$WORK" || exit 2

printf '[filter]\nerror_states = 21\n' > cal21.toml
cat > ins21.toml <<'T'
model = "ins"
[imu]
gyro_scale_factor_sigma_ppm = 1000.0
accel_scale_factor_sigma_ppm = 1000.0
[filter]
error_states = 21
T
printf 'model = "ins"\n' > ins15.toml

strip_timing() {
    python3 - "$1" <<'P'
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if k not in ("elapsed_s", "realizations_per_s", "seconds", "wall_s")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
p = sys.argv[1]
json.dump(strip(json.load(open(p))), open(p, "w"), indent=1, sort_keys=True)
P
}

run() {
    # Each binary runs in a directory of its own with the same relative names, so that the file
    # names the summaries quote are the same.
    local bin=$1 o=.
    mkdir -p "$WORK/$2"
    cd "$WORK/$2" || exit 2
    "$bin" calibrate --imu "$COMMA/imu.csv" --gnss "$COMMA/gnss.csv" --out "$o/c15" --quiet
    "$bin" calibrate --imu "$COMMA/imu.csv" --gnss "$COMMA/gnss.csv" --config ../cal21.toml \
        --out "$o/c21" --quiet
    "$bin" calibrate --imu "$COMMA/imu.csv" --gnss "$COMMA/gnss.csv" --estimate-noise \
        --out "$o/c15n" --quiet
    "$bin" calibrate --imu "$COMMA/imu.csv" --gnss "$COMMA/gnss.csv" --config ../cal21.toml \
        --estimate-noise --out "$o/c21n" --quiet
    "$bin" simulate --model ins --logs "$o/sim" --quiet
    "$bin" calibrate --imu "$o/sim/imu.csv" --gnss "$o/sim/gnss.csv" --out "$o/csim" --quiet
    "$bin" ensemble --model ins --config ../ins15.toml --realizations "$N" --json "$o/e15.json" --quiet
    "$bin" ensemble --model ins --config ../ins21.toml --realizations "$N" --json "$o/e21.json" --quiet
    "$bin" ensemble --model ins --config ../ins15.toml --realizations "$N" --shard 1/2 \
        --partial "$o/p1" --quiet
    "$bin" ensemble --model ins --config ../ins15.toml --realizations "$N" --shard 2/2 \
        --partial "$o/p2" --quiet
    "$bin" merge "$o/p1" "$o/p2" --json "$o/merged.json" --quiet
    for f in "$o"/c*/summary.json "$o"/e*.json "$o/merged.json"; do strip_timing "$f"; done
    cd "$WORK" || exit 2
}

run "$OLD" old
run "$NEW" new
status=0
for f in c15/summary.json c15/estimates.csv c21/summary.json c21/estimates.csv \
         c15n/summary.json c15n/estimates.csv c21n/summary.json c21n/estimates.csv \
         sim/imu.csv sim/gnss.csv sim/truth.csv csim/summary.json csim/estimates.csv \
         e15.json e21.json merged.json; do
    if cmp -s "old/$f" "new/$f"; then echo "same       $f"; else echo "DIFFERENT  $f"; status=1; fi
done
echo "outputs in $WORK"
exit $status
