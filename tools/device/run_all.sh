#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90), the CUDA toolkit and CuPy: measures
# FFMA contraction by ptxas (tools/device/contraction.py) and the SFU
# approximations over all inputs (tools/device/sfu_sweep.cu). Writes into $OUT:
#   env.txt                         GPU, driver, toolkit versions
#   run.log                         progress and per-case summaries
#   gpu_fma_contraction.json        contraction results (-> tests/fixtures/)
#   contraction_sass_{default,fmad_false}.txt
#   sfu_raw.json                    SFU sweep (-> tools/device/sfu_to_fixture.py)
#   sfu_sass.txt                    SASS of one wrapper kernel per instruction
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/gpu_out}
mkdir -p "$OUT"
{
  date -u
  nvidia-smi
  nvidia-smi --query-gpu=name,driver_version,vbios_version,clocks.max.sm,compute_cap --format=csv
  nvcc --version; ptxas --version; cuobjdump --version
  python3 -c 'import cupy; print("cupy", cupy.__version__)'
  uname -a
} > "$OUT/env.txt" 2>&1
log="$OUT/run.log"
echo "== contraction" >> "$log"
python3 tools/device/contraction.py gen /tmp/ctr >> "$log" 2>&1
python3 tools/device/contraction.py run /tmp/ctr "$OUT" >> "$log" 2>&1
echo "== sfu build" >> "$log"
nvcc -O3 -arch=sm_90 -o /tmp/sfu_sweep tools/device/sfu_sweep.cu >> "$log" 2>&1
cuobjdump -sass /tmp/sfu_sweep | awk '/Function : /{p = ($0 ~ /apply/)} p' > "$OUT/sfu_sass.txt"
echo "== sfu sweep" >> "$log"
timeout "${SFU_TIMEOUT:-400}" /tmp/sfu_sweep ${SFU_ONLY:-} > "$OUT/sfu_raw.json" 2>> "$log"
echo "sweep rc=$?" >> "$log"
date -u >> "$log"
