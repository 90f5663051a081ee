#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, the CUDA toolkit and Nsight Compute:
# builds tools/gpu/micro_fixture.cu, profiles every launch, and writes
# $OUT/launches.txt and $OUT/ncu.csv (turned into tests/fixtures/h100_micro.json
# by tools/gpu/micro_to_json.py).
set -euo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/micro}
mkdir -p "$OUT"
nvcc -O3 -arch=sm_90 -Ikernels -o /tmp/micro_fixture tools/gpu/micro_fixture.cu
metrics=smsp__inst_executed.sum,smsp__thread_inst_executed.sum
for m in global_op_ld global_op_st local_op_ld local_op_st global_op_atom global_op_red; do
  metrics+=",l1tex__t_requests_pipe_lsu_mem_$m.sum,l1tex__t_sectors_pipe_lsu_mem_$m.sum"
done
for m in shared_op_ld shared_op_st; do
  metrics+=",l1tex__data_pipe_lsu_wavefronts_mem_$m.sum,l1tex__data_bank_conflicts_pipe_lsu_mem_$m.sum"
done
metrics+=",lts__t_sectors_op_atom.sum,lts__t_sectors_op_red.sum"
metrics+=",l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum,smsp__sass_branch_targets_threads_divergent.sum"
ncu --metrics "$metrics" --csv --print-units base /tmp/micro_fixture "$OUT/launches.txt" > "$OUT/ncu.csv"
nvidia-smi -L > "$OUT/gpu.txt"
ncu --version >> "$OUT/gpu.txt"
