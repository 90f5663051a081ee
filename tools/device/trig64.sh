#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and the CUDA toolkit: runs
# tools/device/trig64.cu (double sin, cos, tan) over
# tests/fixtures/mathlib/trig64_inputs.bin, built by nvcc and, through the
# driver, the clang-16 + libdevice PTX that `warplight compile` makes
# (tests/fixtures/mathlib/trig64.ptx). Writes $OUT/{trig64_env.txt,
# trig64_nvcc.f64.bin, trig64_clang.f64.bin}; the outputs become
# tests/fixtures/mathlib/h200_trig64_*.
set -euo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/trig64_out}
mkdir -p "$OUT"
work=$(mktemp -d)
{ date -u; nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv; nvcc --version; } > "$OUT/trig64_env.txt" 2>&1
nvcc -arch=sm_90 -O3 -I tools/device -o "$work/trig64_host" tools/device/trig64_host.cu -lcuda >> "$OUT/trig64_env.txt" 2>&1
"$work/trig64_host" tests/fixtures/mathlib/trig64_inputs.bin "$work" clang=tests/fixtures/mathlib/trig64.ptx >> "$OUT/trig64_env.txt" 2>&1
cp "$work/nvcc.f64.bin" "$OUT/trig64_nvcc.f64.bin"
cp "$work/clang.f64.bin" "$OUT/trig64_clang.f64.bin"
cat "$OUT/trig64_env.txt"
