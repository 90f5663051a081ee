#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and the CUDA toolkit: runs every planted
# kernel (kernels/tests/planted_*.cu, through tools/device/sanitizer_host.cu)
# plainly and under each compute-sanitizer tool. Writes into $OUT:
#   env.txt                 GPU, driver, toolkit and compute-sanitizer versions
#   plain.txt               each kernel's results without a tool
#   <tool>.txt              memcheck, racecheck, initcheck, synccheck: one
#                           "=== KERNEL" section per kernel, the tool's output
# The outputs become tests/fixtures/sanitizer/<tool>.txt (paths made relative
# to the repository by the sed below).
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/sanitizer_out}
mkdir -p "$OUT"
# KERNELS (environment): run only these
KERNELS=${KERNELS:-"planted_race_raw planted_race_waw planted_race_global planted_uninit_global planted_uninit_shared
  planted_oob planted_barrier_divergent planted_barrier_mismatch planted_warp_race_synced planted_warp_race_nosync"}
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv
  nvcc --version
  compute-sanitizer --version
} > "$OUT/env.txt" 2>&1
bin=/tmp/planted_host
if ! nvcc -arch=sm_90 -O3 -lineinfo -o "$bin" tools/device/sanitizer_host.cu >> "$OUT/env.txt" 2>&1; then
  echo "build failed" >> "$OUT/env.txt"
  exit 1
fi
root=$(pwd)
tidy() { sed -e "s#$root/##g" -e "s#tools/device/../../##g"; }
: > "$OUT/plain.txt"
for k in $KERNELS; do
  echo "=== $k" >> "$OUT/plain.txt"
  timeout 30 "$bin" "$k" >> "$OUT/plain.txt" 2>&1
  echo "exit: $?" >> "$OUT/plain.txt"
done
for tool in memcheck racecheck initcheck synccheck; do
  : > "$OUT/$tool.txt"
  for k in $KERNELS; do
    echo "=== $k" >> "$OUT/$tool.txt"
    timeout 30 compute-sanitizer --tool "$tool" --show-backtrace no "$bin" "$k" 2>&1 | tidy >> "$OUT/$tool.txt"
    echo "exit: ${PIPESTATUS[0]}" >> "$OUT/$tool.txt"
  done
done
date -u >> "$OUT/env.txt"
