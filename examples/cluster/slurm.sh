#!/usr/bin/env bash
# A Slurm job array that runs a thesis's tables as frame shards, one shard per
# array task; a dependent job merges them (`warplight tables merge`).
#
#   jobid=$(sbatch --parsable --array=0-9 examples/cluster/slurm.sh)
#   sbatch --dependency=afterok:$jobid --wrap "warplight tables merge shards/shard-*.json > shards/tables.md"
#
# Submit from the repository root (settings.sh is read from there: Slurm runs a
# copy of this script). Outside Slurm, SLURM_ARRAY_TASK_ID and
# SLURM_ARRAY_TASK_COUNT pick the shard by hand (what the tests do).
# Environment: WARPLIGHT, TABLES, PROTOCOL, FRAMES, OUT, EXTRA (settings.sh).
#SBATCH --job-name=warplight-tables
#SBATCH --cpus-per-task=8
#SBATCH --time=04:00:00
#SBATCH --output=shards/slurm-%A_%a.log
set -euo pipefail
# shellcheck source=settings.sh
source "${SLURM_SUBMIT_DIR:-.}/examples/cluster/settings.sh"
i=${SLURM_ARRAY_TASK_ID:?set SLURM_ARRAY_TASK_ID (Slurm does)}
n=${SLURM_ARRAY_TASK_COUNT:?set SLURM_ARRAY_TASK_COUNT (Slurm does)}
range=$(shard_range "$i" "$n")
mkdir -p "$OUT"
if [ -z "$range" ]; then echo "shard $i of $n has no frames"; exit 0; fi
export RAYON_NUM_THREADS=${SLURM_CPUS_PER_TASK:-0}
[ "$RAYON_NUM_THREADS" = 0 ] && unset RAYON_NUM_THREADS
# shellcheck disable=SC2086 # TABLES and EXTRA are word lists
"$WARPLIGHT" tables $TABLES --protocol "$PROTOCOL" $EXTRA --frames "$range" --out "$OUT/shard-$i.json" > /dev/null
