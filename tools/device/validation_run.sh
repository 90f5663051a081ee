#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90), the CUDA toolkit, Nsight Compute
# and CuPy: runs the validation suite (kernels/validation/suite{,.nvcc}.ptx,
# cases in tools/device/validation.py) under Nsight Compute. Writes into $OUT:
#   env.txt            GPU, driver, toolkit, profiler versions
#   launches.txt       one line per launch: id dialect case kernel
#   outputs.json       the output buffers after each case (base64, little-endian words)
#   ncu.csv            every metric of every launch
#   suite.{clang,nvcc}.sass   ptxas -arch=sm_90 of each PTX (what the JIT makes of it)
# Then: python3 tools/device/validation.py fixture $OUT tests/fixtures/validation/h200.json
# SUITE=uniform_atomics measures kernels/validation/uniform_atomics.cu instead
# (fixture tests/fixtures/validation/h200_uniform_atomics.json, made with
# VALIDATION_SUITE=uniform_atomics).
set -uo pipefail
SUITE=${SUITE:-suite}
export VALIDATION_SUITE=$SUITE
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/validation}
mkdir -p "$OUT"
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,vbios_version,compute_cap --format=csv
  ptxas --version | tail -2
  ncu --version
  python3 -c 'import cupy; print("cupy", cupy.__version__)'
} > "$OUT/env.txt" 2>&1
# nvcc 13.5's PTX (.version 9.5) for a CUDA 13.0 toolkit: only the version line changed
sed 's/^\.version 9\.5$/.version 9.0/' "kernels/validation/$SUITE.nvcc.ptx" > "/tmp/$SUITE.nvcc.ptx"
export VALIDATION_NVCC_PTX=/tmp/$SUITE.nvcc.ptx
for d in "clang:kernels/validation/$SUITE.ptx" "nvcc:/tmp/$SUITE.nvcc.ptx"; do
  ptxas -arch=sm_90 -o "/tmp/${SUITE}_${d%%:*}.cubin" "${d#*:}" && cuobjdump -sass "/tmp/${SUITE}_${d%%:*}.cubin" > "$OUT/$SUITE.${d%%:*}.sass"
done 2>> "$OUT/env.txt"
want="smsp__inst_executed.sum smsp__thread_inst_executed.sum smsp__sass_branch_targets_threads_divergent.sum"
for m in shared_ld shared_st shared_atom global_ld global_st global_atom global_red local_ld local_st; do
  want+=" smsp__sass_inst_executed_op_$m.sum"
done
for m in global_op_ld global_op_st global_op_atom global_op_red local_op_ld local_op_st; do
  want+=" l1tex__t_requests_pipe_lsu_mem_$m.sum l1tex__t_sectors_pipe_lsu_mem_$m.sum"
done
want+=" l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum"
for m in ld st atom; do
  want+=" l1tex__data_pipe_lsu_wavefronts_mem_shared_op_$m.sum l1tex__data_bank_conflicts_pipe_lsu_mem_shared_op_$m.sum"
done
want+=" lts__t_sectors_op_atom.sum lts__t_sectors_op_red.sum"
# keep only the metrics this Nsight Compute knows, so that one unknown name cannot fail the run
ncu --query-metrics > "$OUT/query.txt" 2>&1
metrics=""
for m in $want; do
  if grep -Eq "^${m%.sum}[[:space:]]" "$OUT/query.txt"; then metrics+="${metrics:+,}$m"; else echo "not offered: $m" >> "$OUT/env.txt"; fi
done
# an unexpected listing format: ask for all of them
[ "$(echo "$metrics" | tr ',' '\n' | grep -c .)" -lt 12 ] && metrics=$(echo $want | tr ' ' ',')
kernels=$(grep -oE '^(K |SETX2\()[a-z0-9_]+' "kernels/validation/$SUITE.cu" | sed -E 's/^(K |SETX2\()//' | paste -sd'|')
ncu --metrics "$metrics" --csv --print-units base -k "regex:^($kernels)\$" \
  python3 tools/device/validation.py run "$OUT" > "$OUT/ncu.csv" 2> "$OUT/ncu.err"
echo "ncu rc=$?" >> "$OUT/env.txt"
rm -f "$OUT/query.txt"
date -u >> "$OUT/env.txt"
