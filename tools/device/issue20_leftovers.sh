#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90), the CUDA toolkit, Nsight Compute
# and CuPy, from the repository root: measures what issue 20 left open and
# writes into $OUT
#   env.txt    GPU, driver, toolkit versions; the log of each step
#   tex.tgz    linear texture filtering and sured.b (tools/device/tex_filter_host.cu:
#              tex.json, NAME.{tex,crd,out}, sured.json) and the probe's SASS
#   ua64.tgz   the 64-bit uniform-atomics suite (SUITE=uniform_atomics64
#              tools/device/validation_run.sh: env.txt, launches.txt,
#              outputs.json, ncu.csv, the SASS of both dialects)
# Then: tools/device/tex_filter_fixture.py (tests/fixtures/validation/h200_tex_filter.bin.z,
# h200_sured.json) and VALIDATION_SUITE=uniform_atomics64 python3
# tools/device/validation.py fixture UA64 tests/fixtures/validation/h200_uniform_atomics64.json
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/issue20}
mkdir -p "$OUT"
X=$(mktemp -d)
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv
  nvcc --version | tail -2
} > "$OUT/env.txt" 2>&1
mkdir -p "$X/tex"
if nvcc -O2 -arch=sm_90 -I. -o "$X/probe" tools/device/tex_filter_host.cu >> "$OUT/env.txt" 2>&1; then
  timeout 120 "$X/probe" "$X/tex" >> "$OUT/env.txt" 2>&1 || echo "probe failed: $?" >> "$OUT/env.txt"
  cuobjdump -sass "$X/probe" | awk '/Function : /{p = ($0 ~ /tf_|sr_/)} p' > "$X/tex/sass.txt" 2>&1
  (cd "$X/tex" && tar czf "$OUT/tex.tgz" .)
else
  echo "probe build failed" >> "$OUT/env.txt"
fi
date -u >> "$OUT/env.txt"
SUITE=uniform_atomics64 OUT="$X/ua64" timeout 400 tools/device/validation_run.sh >> "$OUT/env.txt" 2>&1
echo "validation_run rc=$?" >> "$OUT/env.txt"
(cd "$X/ua64" && tar czf "$OUT/ua64.tgz" .)
date -u >> "$OUT/env.txt"
ls -la "$OUT" "$X/tex" | head -60
