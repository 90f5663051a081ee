#!/usr/bin/env bash
# Thesis 003's image figures rendered for docs/reproduction-lin2017.md, 128 x 128:
#
# - Fig. 6 (003:L286-288): MIS (balance heuristic) at the thesis' 10 frames
#   of one path a pixel (our 12 paths) and BSDF sampling alone at its 100
#   (our 120), scenes/cornell-glossy-floor.toml, seed 0:
#   docs/images/lin-fig6-{mis,bsdf}.png;
# - Fig. 8 (003:L305-308): bdpt, nee and pt at the thesis' 100 frames of one
#   path a pixel (our 100), scenes/cornell-inverted.toml, exposure +2, seed
#   800 (the seed of the first run of `warplight tables lin:fig8`, which
#   renders 32 x 32):
#   docs/images/lin-fig8-{bdpt,nee,pt}.png;
# - Fig. 9 (003:L332-336): Monte Carlo (bdpt) and MLT over bdpt at its frames
#   1, 30 and 100 (our 4, 32 and 100 paths a pixel), on Fig. 8's box with the
#   light facing the ceiling (exposure +2: the room is lit only through the
#   light's 1 cm gap) and on the original box, seed 900 (the first run of
#   `warplight tables lin:fig9`): docs/images/lin-fig9-SCENE-{mc,mlt}-{1,30,100}.png.
#
# Usage: tools/lin-figures.sh    (WARPLIGHT: the binary [target/release/warplight])
set -euo pipefail
cd "$(dirname "$0")/.."
WARPLIGHT=${WARPLIGHT:-target/release/warplight}
[ -x "$WARPLIGHT" ] || cargo build --release
render() { "$WARPLIGHT" render --method path --resolution 128x128 "$@"; }
render --scene cornell-glossy-floor --integrator mis --spp 12 --seed 0 -o docs/images/lin-fig6-mis.png
render --scene cornell-glossy-floor --integrator pt --spp 120 --seed 0 -o docs/images/lin-fig6-bsdf.png
for integrator in bdpt nee pt; do
  render --scene cornell-inverted --integrator "$integrator" --spp 100 --seed 800 --exposure 2 \
    -o "docs/images/lin-fig8-$integrator.png"
done
for scene in cornell-inverted cornell-lambert; do
  exposure=0
  [ "$scene" = cornell-inverted ] && exposure=2
  for pair in 1:4 30:32 100:100; do
    frame=${pair%%:*} spp=${pair##*:}
    for m in mc:bdpt mlt:mlt; do
      name=${m%%:*} integrator=${m##*:}
      render --scene "$scene" --integrator "$integrator" --spp "$spp" --seed 900 --exposure "$exposure" \
        -o "docs/images/lin-fig9-$scene-$name-$frame.png"
    done
  done
done
