#!/usr/bin/env bash
# Third batch on the GPU machine: checks the table model of rcp/rsqrt/sqrt and
# the divisions (tools/device/mufu_model.cu) against the GPU on all 2^32 inputs.
# Writes $OUT/run.log and $OUT/mufu_model.json.
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/gpu_out}
mkdir -p "$OUT" /tmp/tab
log="$OUT/run.log"
{ date -u; nvidia-smi --query-gpu=name,driver_version,vbios_version,compute_cap --format=csv; } >> "$log" 2>&1
for n in rcp_1_2 rsqrt_1_4 sqrt_1_4; do
  python3 -c "import zlib,sys; open(sys.argv[2],'wb').write(zlib.decompress(open(sys.argv[1],'rb').read()))" \
    tests/fixtures/mufu/$n.i8.zlib /tmp/tab/$n.i8
done
nvcc -O3 -arch=sm_90 -o /tmp/mufu_model tools/device/mufu_model.cu >> "$log" 2>&1
timeout 400 /tmp/mufu_model /tmp/tab/rcp_1_2.i8 /tmp/tab/rsqrt_1_4.i8 /tmp/tab/sqrt_1_4.i8 > "$OUT/mufu_model.json" 2>> "$log"
echo "model rc=$?" >> "$log"
date -u >> "$log"
