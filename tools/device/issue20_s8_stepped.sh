#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90) and the CUDA toolkit, from the
# repository root: the last two checks issue 20 asked for. Writes into $OUT
#   env.txt        GPU, driver, toolkit versions; the log of each step
#   tex3.tgz       the third set of linear-filtering cases, signed 8-bit
#                  texels (tools/device/tex_filter_host.cu OUT 3)
#   loop_stepped.{clang,nvcc}.sass   cuobjdump -sass of ptxas -arch=sm_90 of
#                  kernels/validation/loop_stepped{,.nvcc}.ptx: does ptxas
#                  merge shared loads at a base stepped round a loop?
# Then: tools/device/tex_filter_fixture.py DIR ENV 3 (tests/tex_filter.rs);
# the SASS into tests/fixtures/validation/loop_stepped.sass
# (tests/validation_vectorize.rs).
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/issue20_s8}
mkdir -p "$OUT"
X=$(mktemp -d)
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv
  nvcc --version | tail -2
} > "$OUT/env.txt" 2>&1
for d in "clang:kernels/validation/loop_stepped.ptx" "nvcc:kernels/validation/loop_stepped.nvcc.ptx"; do
  n=${d%%:*}
  sed 's/^\.version 9\.[5-9]$/.version 9.0/' "${d#*:}" > "$X/ls_$n.ptx"
  ptxas -arch=sm_90 -v -o "$X/ls_$n.cubin" "$X/ls_$n.ptx" >> "$OUT/env.txt" 2>&1
  cuobjdump -sass "$X/ls_$n.cubin" > "$OUT/loop_stepped.$n.sass" 2>> "$OUT/env.txt"
  echo "$n: $(grep -c 'LDS' "$OUT/loop_stepped.$n.sass") LDS lines" >> "$OUT/env.txt"
done
mkdir -p "$X/tex3"
if nvcc -O2 -arch=sm_90 -I. -o "$X/probe" tools/device/tex_filter_host.cu >> "$OUT/env.txt" 2>&1; then
  timeout 60 "$X/probe" "$X/tex3" 3 >> "$OUT/env.txt" 2>&1 || echo "probe failed: $?" >> "$OUT/env.txt"
  (cd "$X" && tar czf "$OUT/tex3.tgz" tex3)
else
  echo "probe build failed" >> "$OUT/env.txt"
fi
date -u >> "$OUT/env.txt"
ls -la "$OUT" >> "$OUT/env.txt"
