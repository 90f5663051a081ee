#!/usr/bin/env bash
# Thesis 003's Fig. 9 (003:L332-336) as images: Monte Carlo (bdpt) and MLT
# over bdpt at the thesis' frames 1, 30 and 100 (one path a pixel each: our
# 4, 32 and 100 paths a pixel), on Fig. 8's box with the light facing the
# ceiling (exposure +2: the room is lit only through the light's 1 cm gap)
# and on the original box, 128 x 128, seed 900 (the first run of
# `warplight tables lin:fig9`). Writes docs/images/lin-fig9-SCENE-{mc,mlt}-{1,30,100}.png.
#
# Usage: tools/fig9-images.sh    (WARPLIGHT: the binary [target/release/warplight])
set -euo pipefail
cd "$(dirname "$0")/.."
WARPLIGHT=${WARPLIGHT:-target/release/warplight}
[ -x "$WARPLIGHT" ] || cargo build --release
for scene in cornell-inverted cornell-lambert; do
  exposure=0
  [ "$scene" = cornell-inverted ] && exposure=2
  for pair in 1:4 30:32 100:100; do
    frame=${pair%%:*} spp=${pair##*:}
    for m in mc:bdpt mlt:mlt; do
      name=${m%%:*} integrator=${m##*:}
      "$WARPLIGHT" render --method path --scene "$scene" --integrator "$integrator" --spp "$spp" \
        --resolution 128x128 --seed 900 --exposure "$exposure" -o "docs/images/lin-fig9-$scene-$name-$frame.png"
    done
  done
done
