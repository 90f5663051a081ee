#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90), the CUDA toolkit, Nsight Compute
# and CuPy, from the repository root: what issue 20 left open about texture
# filtering and bfs. Writes into $OUT
#   env.txt       GPU, driver, toolkit versions; the log of each step
#   tex2.tgz      the second set of linear-filtering cases
#                 (tools/device/tex_filter_host.cu OUT 2: tex.json, NAME.{tex,crd,out})
#   bfs_ncu.csv, bfs_launches.txt, bfs_outputs.json
#                 the validation suite's bfs case run 5 times per dialect
#                 under Nsight Compute (tools/device/bfs_repeat.py)
# Then: tools/device/tex_filter_fixture.py DIR ENV 2 and
# tools/device/bfs_repeat.py fixture OUT tests/fixtures/validation/h200_bfs_repeat.json
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/issue20}
mkdir -p "$OUT"
X=$(mktemp -d)
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv
  nvcc --version | tail -2
  ncu --version | tail -1
} > "$OUT/env.txt" 2>&1
mkdir -p "$X/tex2"
if nvcc -O2 -arch=sm_90 -I. -o "$X/probe" tools/device/tex_filter_host.cu >> "$OUT/env.txt" 2>&1; then
  timeout 60 "$X/probe" "$X/tex2" 2 >> "$OUT/env.txt" 2>&1 || echo "probe failed: $?" >> "$OUT/env.txt"
  (cd "$X" && tar czf "$OUT/tex2.tgz" tex2)
else
  echo "probe build failed" >> "$OUT/env.txt"
fi
date -u >> "$OUT/env.txt"
# nvcc 13.5's PTX (.version 9.5) for a CUDA 13.0 toolkit: only the version line changed
sed 's/^\.version 9\.5$/.version 9.0/' kernels/validation/suite.nvcc.ptx > "$X/suite.nvcc.ptx"
export VALIDATION_NVCC_PTX=$X/suite.nvcc.ptx VALIDATION_SUITE=suite
m=l1tex__t_sectors_pipe_lsu_mem_global_op_ld_lookup_hit.sum,l1tex__t_sectors_pipe_lsu_mem_global_op_ld.sum
m+=,l1tex__t_requests_pipe_lsu_mem_global_op_ld.sum,smsp__sass_inst_executed_op_global_ld.sum
timeout 170 ncu --metrics "$m" --csv --print-units base -k 'regex:^bfs_' \
  python3 tools/device/bfs_repeat.py run "$OUT" 5 > "$OUT/bfs_ncu.csv" 2> "$OUT/bfs_ncu.err"
echo "ncu rc=$?" >> "$OUT/env.txt"
tail -5 "$OUT/bfs_ncu.err" >> "$OUT/env.txt"
date -u >> "$OUT/env.txt"
ls -la "$OUT" >> "$OUT/env.txt"
