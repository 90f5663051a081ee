#!/usr/bin/env bash
# Redraws the charts in docs/images/ with `warplight chart` (charts in the docs
# are never drawn by hand):
#
#   docs/images/chart-4.5.svg                 Table 4.5, ours beside the thesis with the
#                                             tolerance bands, from docs/results/fabianowski-quick.json
#   docs/images/speed-accuracy-example.svg    the generic speed-against-accuracy plot,
#                                             from tests/fixtures/scatter.json
#   docs/images/lin-convergence-*-{spp,seconds,instructions,mean}.svg, lin-roulette-*-{...}.svg,
#   lin-pixels-*-{spp,seconds}.svg, lin-compaction-{lanes,paths}.svg
#                                             thesis 003's charts, from their *-data.json beside them
#
# Drawing needs no emulation: the table comes from the committed raw measurements.
# When those are missing they are measured first (minutes):
#
#   warplight tables fabianowski:all --protocol quick --out docs/results/fabianowski-quick.json
#
# Usage: tools/charts.sh    (WARPLIGHT: the binary [target/release/warplight];
#                            RESULTS: the raw measurements [docs/results/fabianowski-quick.json])
set -euo pipefail
cd "$(dirname "$0")/.."
WARPLIGHT=${WARPLIGHT:-target/release/warplight}
RESULTS=${RESULTS:-docs/results/fabianowski-quick.json}
[ -x "$WARPLIGHT" ] || cargo build --release
mkdir -p docs/images
if [ ! -f "$RESULTS" ]; then
  echo "charts.sh: $RESULTS is missing: measuring it (warplight tables fabianowski:all --protocol quick)" >&2
  mkdir -p "$(dirname "$RESULTS")"
  "$WARPLIGHT" tables fabianowski:all --protocol quick --out "$RESULTS" > /dev/null
fi
"$WARPLIGHT" chart table fabianowski:4.5 --from "$RESULTS" -o docs/images/chart-4.5.svg
"$WARPLIGHT" chart scatter tests/fixtures/scatter.json -o docs/images/speed-accuracy-example.svg
# Thesis 003's charts, redrawn from their committed data (no rendering; the
# commands that measured the data are in docs/reproduction-lin2017.md, "Charts"):
for s in cornell-lambert cornell-rough cornell-inverted cornell-caustic; do
  "$WARPLIGHT" chart lin-convergence --from "docs/images/lin-convergence-$s-data.json" \
    -o "docs/images/lin-convergence-$s-{}.svg" > /dev/null
done
for s in cornell-lambert cornell-rough; do
  "$WARPLIGHT" chart lin-convergence --from "docs/images/lin-roulette-$s-data.json" \
    -o "docs/images/lin-roulette-$s-{}.svg" > /dev/null
done
for s in env-spheres cornell-lambert; do
  "$WARPLIGHT" chart lin-pixel-sampling --from "docs/images/lin-pixels-$s-data.json" \
    -o "docs/images/lin-pixels-$s-{}.svg" > /dev/null
done
"$WARPLIGHT" chart lin-compaction --from docs/images/lin-compaction-data.json -o "docs/images/lin-compaction-{}.svg" > /dev/null
