#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, the CUDA toolkit and Nsight Compute: profiles
# every launch of tools/gpu/bank_conflict_variation.cu (each kernel launched
# five times on the same data) and writes $OUT/variation.csv and $OUT/gpu.txt.
# docs/validation.md cites the result (which metrics vary between identical launches).
set -euo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/variation}
mkdir -p "$OUT"
nvcc -O3 -arch=sm_90 -o /tmp/bank_conflict_variation tools/gpu/bank_conflict_variation.cu
metrics=smsp__sass_inst_executed_op_shared_ld.sum
metrics+=",l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum"
for m in ld st atom; do
  metrics+=",l1tex__data_pipe_lsu_wavefronts_mem_shared_op_$m.sum,l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_$m.sum"
done
# the CSV without Nsight Compute's own progress lines, as tests/fixtures/h200_shared_variation.csv
ncu --metrics "$metrics" --csv --print-units base /tmp/bank_conflict_variation | grep -v '^==' | grep -v '^no error$' > "$OUT/variation.csv"
nvidia-smi -L > "$OUT/gpu.txt"
ncu --version >> "$OUT/gpu.txt"
