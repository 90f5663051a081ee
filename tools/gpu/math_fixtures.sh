#!/usr/bin/env bash
# One device run for the math library fixtures (docs/prelude.md): libdevice's
# double sin/cos/tan (tools/device/trig64.sh) and the single/double-precision
# table again with the PTX `warplight compile` makes now
# (tools/device/mathlib.sh: carry chains as clang wrote them, `.file` without
# a temporary folder). Everything lands in $OUT.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-/tmp/math_fixtures_out}
mkdir -p "$OUT"
bash tools/device/trig64.sh
OUT="$OUT/mathlib" bash tools/device/mathlib.sh
# the table's bits against the committed fixture (the PTX the H200 ran before)
for k in f32 f64; do
  cmp "$OUT/mathlib/clang.$k.bin" tests/fixtures/mathlib/h200_clang.$k.bin && echo "mathlib $k: same bits as h200_clang.$k.bin"
done
cmp "$OUT/trig64_nvcc.f64.bin" "$OUT/trig64_clang.f64.bin" && echo "trig64: nvcc and clang + libdevice give the same bits" || true
