#!/usr/bin/env bash
# Regenerates the generated parts of the docs: every block
#
#   <!-- generated: warplight ARGS -->
#   ...
#   <!-- end generated -->
#
# in docs/*.md and README.md is replaced by the output of `warplight ARGS`
# (run from the repository root), and the charts are redrawn (tools/charts.sh).
# The tables come from committed raw measurements (docs/results/*.json), so
# regenerating needs no emulation; rerun those to refresh the measurements:
#
#   warplight tables fabianowski:all --protocol quick --out docs/results/fabianowski-quick.json
#
# Usage: tools/regen-docs.sh [FILE.md ...]    (WARPLIGHT: the binary [target/release/warplight])
set -euo pipefail
cd "$(dirname "$0")/.."
WARPLIGHT=${WARPLIGHT:-target/release/warplight}
[ -x "$WARPLIGHT" ] || cargo build --release
files=("$@")
[ ${#files[@]} -gt 0 ] || mapfile -t files < <(grep -l -- '<!-- generated: warplight ' docs/*.md README.md)
for f in "${files[@]}"; do
  tmp=$(mktemp)
  skip=0
  while IFS= read -r line || [ -n "$line" ]; do
    if [[ $line =~ ^'<!-- generated: warplight '(.*)' -->'$ ]]; then
      printf '%s\n' "$line" >> "$tmp"
      # shellcheck disable=SC2086 # the block's arguments are a word list
      "$WARPLIGHT" ${BASH_REMATCH[1]} 2>/dev/null >> "$tmp"
      skip=1
    elif [[ $line == '<!-- end generated -->' ]]; then
      printf '%s\n' "$line" >> "$tmp"
      skip=0
    elif [ $skip = 0 ]; then
      printf '%s\n' "$line" >> "$tmp"
    fi
  done < "$f"
  mv "$tmp" "$f"
  echo "regenerated $f"
done
if [ -x tools/charts.sh ]; then tools/charts.sh; fi
