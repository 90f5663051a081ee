#!/usr/bin/env bash
# On a machine with the CUDA toolkit (sm_90): ptxas -arch=sm_90 of the
# validation suite's clang and nvcc PTX (the flags of validation_run.sh), then
# the SASS of the needleman_wunsch kernels into $OUT:
#   suite.{clang,nvcc}.sass   cuobjdump -sass of the whole cubin
#   nw.{clang,nvcc}.nvdisasm  nvdisasm -c -g (control flow, line info) of the cubin
# Fixture: tests/fixtures/validation/needleman_wunsch_clang.sass (docs/validation.md).
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/nw_sass}
mkdir -p "$OUT"
ptxas --version | tail -2 > "$OUT/env.txt" 2>&1
sed 's/^\.version 9\.5$/.version 9.0/' kernels/validation/suite.nvcc.ptx > /tmp/suite.nvcc.ptx
for d in "clang:kernels/validation/suite.ptx" "nvcc:/tmp/suite.nvcc.ptx"; do
  n=${d%%:*}
  ptxas -arch=sm_90 -v -o "/tmp/suite_$n.cubin" "${d#*:}" 2>> "$OUT/ptxas_$n.log"
  cuobjdump -sass "/tmp/suite_$n.cubin" > "$OUT/suite.$n.sass"
  nvdisasm -c "/tmp/suite_$n.cubin" > "$OUT/nw.$n.nvdisasm" 2>> "$OUT/env.txt"
done 2>> "$OUT/env.txt"
ls -l "$OUT"
