#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90) and the CUDA toolkit: builds
# tools/gpu/semantics_fixture.cu and writes into $OUT
#   gpu_semantics.json   every sem_* kernel's inputs and outputs (-> tests/fixtures/)
#   env.txt              GPU, driver and toolkit versions
#   sass_ext.txt         SASS of the semantics_ext.cu kernels
# Run from the repository root: OUT=/tmp/o tools/gpu/measure_semantics.sh
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/gpu_out}
mkdir -p "$OUT"
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,vbios_version,compute_cap --format=csv
  nvcc --version
} > "$OUT/env.txt" 2>&1
nvcc -O2 -arch=sm_90 -Ikernels -o /tmp/semfix tools/gpu/semantics_fixture.cu > "$OUT/build.log" 2>&1 || { cat "$OUT/build.log"; exit 1; }
/tmp/semfix > "$OUT/gpu_semantics.json" 2> "$OUT/run.log" || { cat "$OUT/run.log"; exit 1; }
cuobjdump -sass /tmp/semfix | awk '/Function : /{p = ($0 ~ /sem_(redux|match|bar_red|prmt_modes|bits|dp|carry|half)/)} p' > "$OUT/sass_ext.txt" 2>&1
python3 -c "import json; d = json.load(open('$OUT/gpu_semantics.json')); print(d['device'], len(d['kernels']), 'kernels')"
