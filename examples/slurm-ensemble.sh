#!/usr/bin/env bash
# One shard of an accelcal ensemble per Slurm array task.
#   sbatch --array=1-16 examples/slurm-ensemble.sh study.toml /shared/run-42
# Then merge once every task has finished:
#   sbatch --dependency=afterok:<array job id> --wrap \
#     'accelcal merge /shared/run-42/part-*.bin --json /shared/run-42/ensemble.json'
#SBATCH --job-name=accelcal-shard
#SBATCH --cpus-per-task=4
#SBATCH --mem=2G
#SBATCH --time=02:00:00
set -euo pipefail

config="$1"
out="$2"
shards="${SLURM_ARRAY_TASK_COUNT:?run as a job array}"
shard="${SLURM_ARRAY_TASK_ID:?run as a job array}"
mkdir -p "$out"
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
accelcal ensemble --config "$config" --shard "$shard/$shards" \
  --partial "$out/part-$shard.bin" --quiet
