#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, the CUDA toolkit and Nsight Compute: profiles
# every launch of tools/gpu/bank_conflict_variation.cu (each kernel launched
# several times on the same data) and writes $OUT/variation.csv and $OUT/gpu.txt.
# docs/validation.md cites the result (which metrics vary between identical launches).
set -euo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/variation}
mkdir -p "$OUT"
nvcc -O3 -arch=sm_90 -o /tmp/bank_conflict_variation tools/gpu/bank_conflict_variation.cu
metrics=smsp__inst_executed.sum,smsp__sass_inst_executed_op_shared_ld.sum,smsp__sass_inst_executed_op_shared_st.sum
for m in shared_op_ld shared_op_st shared_op_atom; do
  metrics+=",l1tex__data_pipe_lsu_wavefronts_mem_$m.sum,l1tex__data_bank_conflicts_pipe_lsu_mem_$m.sum"
done
metrics+=",l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum"
metrics+=",l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum"
ncu --metrics "$metrics" --csv --print-units base /tmp/bank_conflict_variation > "$OUT/variation.csv"
nvidia-smi -L > "$OUT/gpu.txt"
ncu --version >> "$OUT/gpu.txt"
