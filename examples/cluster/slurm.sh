#!/usr/bin/env bash
# A Slurm job array that runs a thesis's tables as frame shards, one shard per
# array task; a dependent job merges them (`warplight tables merge`).
#
#   jobid=$(sbatch --parsable --array=0-9 examples/cluster/slurm.sh)
#   sbatch --dependency=afterok:$jobid --wrap "warplight tables merge shards/shard-*.json > shards/tables.md"
#
# Outside Slurm, SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT pick the shard
# by hand (what the tests do). Environment as in parallel.sh: WARPLIGHT,
# TABLES, PROTOCOL, FRAMES, OUT, EXTRA.
#SBATCH --job-name=warplight-tables
#SBATCH --cpus-per-task=8
#SBATCH --time=04:00:00
#SBATCH --output=shards/slurm-%A_%a.log
set -euo pipefail
WARPLIGHT=${WARPLIGHT:-warplight}
TABLES=${TABLES:-fabianowski:all}
PROTOCOL=${PROTOCOL:-thesis}
case $PROTOCOL in thesis) default_frames=50 ;; *) default_frames=3 ;; esac
FRAMES=${FRAMES:-$default_frames}
OUT=${OUT:-shards}
EXTRA=${EXTRA:-}
i=${SLURM_ARRAY_TASK_ID:?set SLURM_ARRAY_TASK_ID (Slurm does)}
n=${SLURM_ARRAY_TASK_COUNT:?set SLURM_ARRAY_TASK_COUNT (Slurm does)}
a=$((i * FRAMES / n))
b=$(((i + 1) * FRAMES / n))
mkdir -p "$OUT"
if [ "$a" -ge "$b" ]; then echo "shard $i of $n has no frames"; exit 0; fi
export RAYON_NUM_THREADS=${SLURM_CPUS_PER_TASK:-0}
[ "$RAYON_NUM_THREADS" = 0 ] && unset RAYON_NUM_THREADS
# shellcheck disable=SC2086 # TABLES and EXTRA are word lists
"$WARPLIGHT" tables $TABLES --protocol "$PROTOCOL" $EXTRA --frames "$a..$b" --out "$OUT/shard-$i.json" > /dev/null
