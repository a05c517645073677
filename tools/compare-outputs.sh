#!/usr/bin/env bash
# Byte-for-byte comparison of two accelcal binaries' outputs.
#
# Usage: tools/compare-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]
#   env COMMA=/path/to/examples/comma2k19   (default: examples/comma2k19 of this checkout)
#   env REALIZATIONS=N                      (ensemble size, default: the configuration's 10000)
#   env QUICK=1                             (skip --estimate-noise on the simulated 1-minute drive)
#
# Runs, with each binary, on the default configuration and on two drifting-bias configurations
# (bias_model = "random_walk" and "gauss_markov", truth and filter):
#   - `ensemble` (both engines, both truths) -> JSON, timing fields (elapsed_s,
#     realizations_per_s) removed before comparing;
#   - `simulate --logs` and `simulate --csv`;
#   - `calibrate` on the simulated logs (fix by fix, --every-sample, --estimate-noise) and on the
#     comma2k19 drive (raw and gravity-compensated axis; fix by fix, --every-sample,
#     --estimate-noise): summary.json and estimates.csv (summary.json without timing fields).
# Prints one line per compared file (same / DIFFERENT) and exits 1 when any file differs.
set -u
OLD=$(readlink -f "$1")
NEW=$(readlink -f "$2")
WORK=${3:-$(mktemp -d /tmp/compare_outputs.XXXXXX)}
COMMA=$(readlink -f "${COMMA:-$(dirname "$0")/../examples/comma2k19}")
mkdir -p "$WORK"
cd "$WORK" || exit 2

# The configured sample rate makes calibrate run its nominal-Δt mode on the simulated logs.
cat > default.toml <<'EOF'
[accelerometer]
sample_rate_hz = 200.0
EOF
cat > random_walk.toml <<'EOF'
[accelerometer]
sample_rate_hz = 200.0
bias_model = "random_walk"
bias_random_walk_m_s2_per_sqrt_s = 0.02
[filter]
bias_model = "random_walk"
bias_random_walk_m_s2_per_sqrt_s = 0.02
EOF
cat > gauss_markov.toml <<'EOF'
[accelerometer]
sample_rate_hz = 200.0
bias_model = "gauss_markov"
bias_correlation_time_s = 20.0
[filter]
bias_model = "gauss_markov"
bias_correlation_time_s = 20.0
EOF
# A drive of one minute at the default rates (for calibrate's noise estimation).
cat > minute.toml <<'EOF'
[accelerometer]
sample_rate_hz = 200.0
[profile]
duration_s = 60.0
EOF

# Removes the fields that measure time (and so differ run to run) from a JSON file, in place.
strip_timing() {
    python3 - "$1" <<'EOF'
import json, sys
path = sys.argv[1]
TIMING = {"elapsed_s", "realizations_per_s", "wall_s", "seconds", "elapsed"}
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in TIMING}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
with open(path) as f:
    data = json.load(f)
with open(path, "w") as f:
    json.dump(strip(data), f, indent=1, sort_keys=False)
    f.write("\n")
EOF
}

# run TAG BIN: every output of BIN into TAG/out/ (run from TAG/, so that the paths written
# into the outputs are the same for both binaries).
run() {
    local tag=$1 bin=$2 o=out
    rm -rf "${WORK:?}/$tag" && mkdir -p "$WORK/$tag/$o"
    cp "$WORK"/*.toml "$WORK/$tag/"
    cd "$WORK/$tag" || exit 2
    for cfg in default random_walk gauss_markov; do
        for engine in sample epoch; do
            for truth in analytic euler; do
                local r=()
                [ -n "${REALIZATIONS:-}" ] && r=(--realizations "$REALIZATIONS")
                "$bin" ensemble -q --config $cfg.toml --engine $engine --truth $truth "${r[@]}" \
                    --json "$o/ensemble.$cfg.$engine.$truth.json" > /dev/null 2>&1 ||
                    echo "ensemble $cfg $engine $truth failed (rc $?)" > "$o/ensemble.$cfg.$engine.$truth.err"
                [ -f "$o/ensemble.$cfg.$engine.$truth.json" ] && strip_timing "$o/ensemble.$cfg.$engine.$truth.json"
            done
        done
        "$bin" simulate -q --config $cfg.toml --logs "$o/logs.$cfg" --csv "$o/simulate.$cfg.csv" > /dev/null 2>&1 ||
            echo "simulate $cfg failed" > "$o/simulate.$cfg.err"
        "$bin" simulate -q --config $cfg.toml --truth euler --realization 3 --logs "$o/logs.$cfg.euler" > /dev/null 2>&1
    done
    "$bin" simulate -q --config minute.toml --seed 11 --logs "$o/logs.minute" > /dev/null 2>&1
    # calibrate NAME ACCEL GPS [CONFIG] [FLAGS...]
    cal() {
        local name=$1 accel=$2 gps=$3 cfg=$4
        shift 4
        local c=()
        [ -n "$cfg" ] && c=(--config "$cfg")
        "$bin" calibrate -q --accel "$accel" --gps "$gps" "${c[@]}" "$@" --out "$o/cal.$name" > "$o/cal.$name.stdout" 2>&1 ||
            echo "rc $?" >> "$o/cal.$name.stdout"
        for f in summary.json estimates.csv; do
            [ -f "$o/cal.$name/$f" ] && cp "$o/cal.$name/$f" "$o/cal.$name.$f"
        done
        [ -f "$o/cal.$name.summary.json" ] && strip_timing "$o/cal.$name.summary.json"
        rm -rf "$o/cal.$name"
    }
    for cfg in default random_walk gauss_markov; do
        local l="$o/logs.$cfg"
        cal sim.$cfg "$l/accelerometer.csv" "$l/gps.csv" $cfg.toml
        cal sim.$cfg.every "$l/accelerometer.csv" "$l/gps.csv" $cfg.toml --every-sample
        cal sim.$cfg.euler "$o/logs.$cfg.euler/accelerometer.csv" "$o/logs.$cfg.euler/gps.csv" $cfg.toml --every-sample
        # Without a configured rate: the per-step mode.
        cal sim.$cfg.perstep "$l/accelerometer.csv" "$l/gps.csv" "" --every-sample
    done
    if [ -z "${QUICK:-}" ]; then
        cal sim.minute.noise "$o/logs.minute/accelerometer.csv" "$o/logs.minute/gps.csv" minute.toml --estimate-noise
        cal sim.rw.noise "$o/logs.random_walk/accelerometer.csv" "$o/logs.random_walk/gps.csv" random_walk.toml --estimate-noise
    fi
    for axis in raw gravcomp; do
        local a="$COMMA/accel_$axis.csv" g="$COMMA/gps.csv"
        cal comma.$axis "$a" "$g" ""
        cal comma.$axis.every "$a" "$g" "" --every-sample
        cal comma.$axis.noise "$a" "$g" "" --estimate-noise
        cal comma.$axis.noise.every "$a" "$g" "" --estimate-noise --every-sample
        cal comma.$axis.rw "$a" "$g" random_walk.toml --every-sample
        cal comma.$axis.gm "$a" "$g" gauss_markov.toml --every-sample
    done
    # The realization CSV and the logs are compared as files.
    for d in "$o"/logs.*; do
        for f in "$d"/*; do cp "$f" "$o/$(basename "$d").$(basename "$f")"; done
        rm -rf "$d"
    done
    cd "$WORK" || exit 2
}

run old "$OLD"
run new "$NEW"

status=0
count=0
A=old/out
B=new/out
for f in $(cd $A && ls | sort); do
    count=$((count + 1))
    if [ ! -f "$B/$f" ]; then
        echo "MISSING in new: $f"
        status=1
    elif cmp -s "$A/$f" "$B/$f"; then
        echo "same       $f ($(wc -c < "$A/$f") bytes)"
    else
        echo "DIFFERENT  $f"
        diff "$A/$f" "$B/$f" | head -6 | sed 's/^/    /'
        status=1
    fi
done
for f in $(cd $B && ls | sort); do
    [ -f "$A/$f" ] || { echo "EXTRA in new: $f"; status=1; }
done
if [ $status -eq 0 ]; then
    echo "all $count files identical (work dir $WORK)"
else
    echo "differences found (work dir $WORK)"
fi
exit $status
