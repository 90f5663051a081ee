#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and the CUDA toolkit: runs
# tools/device/mathlib.cu over tests/fixtures/mathlib/inputs.bin built by nvcc
# and, through the driver, the clang-16 + libdevice PTX that `warplight
# compile` makes (tests/fixtures/mathlib/mathlib.ptx, as warplight runs it, and
# mathlib.orig.ptx, clang's own output before warplight's rewrites).
# Writes $OUT/{env.txt, nvcc.*.bin, clang.*.bin, clang_orig.*.bin}; the
# outputs become tests/fixtures/mathlib/h200_*.bin.
set -euo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/mathlib_out}
mkdir -p "$OUT"
{ date -u; nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv; nvcc --version; } > "$OUT/env.txt" 2>&1
nvcc -arch=sm_90 -O3 -o /tmp/mathlib_host tools/device/mathlib_host.cu -lcuda >> "$OUT/env.txt" 2>&1
/tmp/mathlib_host tests/fixtures/mathlib/inputs.bin "$OUT" \
  clang=tests/fixtures/mathlib/mathlib.ptx clang_orig=tests/fixtures/mathlib/mathlib.orig.ptx >> "$OUT/env.txt" 2>&1
cat "$OUT/env.txt"
