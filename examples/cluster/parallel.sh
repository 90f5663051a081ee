#!/usr/bin/env bash
# Runs a thesis's tables as frame shards with GNU parallel, then merges them
# into exactly what one unsplit run prints (`warplight tables merge`).
#
#   TABLES=fabianowski:all PROTOCOL=thesis SHARDS=10 OUT=shards examples/cluster/parallel.sh
#
# Environment (defaults in brackets): WARPLIGHT, TABLES, PROTOCOL, FRAMES, OUT
# and EXTRA as in settings.sh, and
#   SHARDS     number of frame ranges [4]
#   JOBS       shards run at once on this machine [1: each shard uses every core]
#   SSH        a GNU parallel --sshlogin list to spread shards over machines
#              (each needs warplight and the scenes at the same paths) []
set -euo pipefail
# shellcheck source=settings.sh
source "$(dirname "$0")/settings.sh"
SHARDS=${SHARDS:-4}
JOBS=${JOBS:-1}
command -v parallel >/dev/null || { echo "GNU parallel is not installed (apt-get install parallel)" >&2; exit 1; }
mkdir -p "$OUT"
rm -f "$OUT"/shard-*.json
ranges=()
for ((i = 0; i < SHARDS; i++)); do
  r=$(shard_range "$i" "$SHARDS")
  if [ -n "$r" ]; then ranges+=("$r"); fi
done
ssh=()
if [ -n "${SSH:-}" ]; then ssh=(--sshlogin "$SSH"); fi
# shellcheck disable=SC2086 # TABLES and EXTRA are word lists
parallel "${ssh[@]}" --jobs "$JOBS" --halt now,fail=1 \
  "$WARPLIGHT" tables $TABLES --protocol "$PROTOCOL" $EXTRA --frames {} \
  --out "$OUT/shard-{#}.json" ">" /dev/null "2>" "$OUT/shard-{#}.log" ::: "${ranges[@]}"
"$WARPLIGHT" tables merge "$OUT"/shard-*.json > "$OUT/tables.md"
echo "merged ${#ranges[@]} shards into $OUT/tables.md"
