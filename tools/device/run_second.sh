#!/usr/bin/env bash
# Second batch on the GPU machine: the contraction cases again (with the added
# ones) and tools/device/sfu_extra.cu (ex2 structure, rcp/rsqrt/sqrt/lg2 tables).
# CONTRACTION_ONLY=1: the contraction cases alone.
# Writes into $OUT: run.log, gpu_fma_contraction.json, contraction_sass_default.txt,
# sfu_extra.json and the four tables as .i8.xz.
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/gpu_out}
mkdir -p "$OUT"
log="$OUT/run.log"
{ date -u; nvidia-smi --query-gpu=name,driver_version,vbios_version,compute_cap --format=csv; ptxas --version | tail -2; } >> "$log" 2>&1
python3 tools/device/contraction.py gen /tmp/ctr >> "$log" 2>&1
python3 tools/device/contraction.py run /tmp/ctr /tmp/ctr >> "$log" 2>&1
cp /tmp/ctr/gpu_fma_contraction.json /tmp/ctr/contraction_sass_default.txt "$OUT/"
if [ -n "${CONTRACTION_ONLY:-}" ]; then date -u >> "$log"; exit 0; fi
nvcc -O3 -arch=sm_90 -o /tmp/sfu_extra tools/device/sfu_extra.cu >> "$log" 2>&1
mkdir -p /tmp/tab
timeout 300 /tmp/sfu_extra /tmp/tab > "$OUT/sfu_extra.json" 2>> "$log"
echo "extra rc=$?" >> "$log"
for f in /tmp/tab/*.i8; do python3 -c "import lzma,sys; open(sys.argv[2],'wb').write(lzma.compress(open(sys.argv[1],'rb').read(), preset=9|lzma.PRESET_EXTREME))" "$f" "$OUT/$(basename $f).xz"; done
ls -la "$OUT" >> "$log"
date -u >> "$log"
