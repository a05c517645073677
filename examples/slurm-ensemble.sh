#!/usr/bin/env bash
# One shard of an accelcal ensemble per task of a Slurm job array (see docs/CLUSTER.md).
#
#   array=$(sbatch --parsable --array=1-16 --cpus-per-task=8 \
#     examples/slurm-ensemble.sh study.toml /shared/run-42)
#   sbatch --dependency=afterok:$array --kill-on-invalid-dep=yes --wrap \
#     'accelcal merge /shared/run-42/part-*.bin --json /shared/run-42/ensemble.json'
#
# The array must be exactly 1-M: task K runs shard K/M and writes OUT_DIR/part-K.bin. To rerun
# shards of an earlier array alone, give M as the third argument:
#
#   sbatch --array=2 examples/slurm-ensemble.sh study.toml /shared/run-42 16
#
# Each task uses the CPUs Slurm gives it (--cpus-per-task; every CPU of the node when it is not
# set); nothing here asks for CPUs, memory or time, so the array fits any node and partition
# (give --cpus-per-task, --mem and --time to sbatch as the cluster needs). accelcal must be on
# the job's PATH (sbatch passes the submitting shell's), or named by ACCELCAL=/path/to/accelcal.
#SBATCH --job-name=accelcal-shard
set -euo pipefail

usage="usage: sbatch --array=1-M slurm-ensemble.sh CONFIG OUT_DIR [M]"
config="${1:?$usage}"
out="${2:?$usage}"
shard="${SLURM_ARRAY_TASK_ID:?run as a Slurm job array: $usage}"
if [ -n "${3:-}" ]; then
  shards="$3"
else
  count="${SLURM_ARRAY_TASK_COUNT:?run as a Slurm job array: $usage}"
  first="${SLURM_ARRAY_TASK_MIN:-1}"
  last="${SLURM_ARRAY_TASK_MAX:-$count}"
  if [ "$first" != 1 ] || [ "$last" != "$count" ]; then
    echo "error: the array is tasks $first-$last ($count of them), but it must be exactly 1-M" \
      "(task K runs shard K/M); to rerun some shards of M, give M as the third argument" >&2
    exit 2
  fi
  shards="$count"
fi
accelcal="${ACCELCAL:-accelcal}"
if ! command -v "$accelcal" >/dev/null; then
  echo "error: $accelcal is not on the PATH of the job on $(hostname) (PATH=$PATH):" \
    "install it on every node or set ACCELCAL=/path/to/accelcal" >&2
  exit 2
fi
mkdir -p "$out"
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-$(nproc)}"
exec "$accelcal" ensemble --config "$config" --shard "$shard/$shards" \
  --partial "$out/part-$shard.bin" --quiet
