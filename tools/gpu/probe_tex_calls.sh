#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (sm_90), the CUDA toolkit and Nsight Compute:
# builds tools/gpu/probe_tex_calls.cu and writes into $OUT
#   probe.json   textures, surfaces, indirect calls, setp on packed halves, txq
#   extra.tgz    half_*.bin (every 16-bit input's result), sass.txt (the kernels'
#                SASS), metrics.txt (Nsight Compute's texture/surface metric names)
#   ncu.csv      those metrics for every texture and surface launch
#   env.txt      GPU, driver and toolkit versions
# Run from the repository root: OUT=/tmp/o tools/gpu/probe_tex_calls.sh
# (tools/gpu/probe_to_fixture.py OUT makes tests/fixtures/gpu_textures.json)
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/gpu_out}
mkdir -p "$OUT"
X=$(mktemp -d)
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv
  nvcc --version
  ncu --version
} > "$OUT/env.txt" 2>&1
nvcc -O2 -arch=sm_90 -Ikernels -o "$X/probe" tools/gpu/probe_tex_calls.cu > "$X/build.log" 2>&1 || { cat "$X/build.log"; exit 1; }
"$X/probe" "$X" || exit 1
mv "$X/probe.json" "$OUT/probe.json"
cuobjdump -sass "$X/probe" | awk '/Function : /{p = ($0 ~ /tex|tld4|surf|call_|op_|describe|Square|Disc|ex2|tanh|setp/)} p' > "$X/sass.txt" 2>&1
ncu --query-metrics > "$X/all_metrics.txt" 2>&1
grep -iE "tex|surf" "$X/all_metrics.txt" > "$X/metrics.txt"
# the texture and surface metrics warplight reports (tests/textures.rs compares them)
metrics=smsp__inst_executed.sum,smsp__inst_executed_op_texture.sum,smsp__inst_executed_op_surface_ld.sum,smsp__inst_executed_op_surface_st.sum,l1tex__t_requests_pipe_tex_mem_texture.sum,l1tex__texin_requests_mem_texture.sum,l1tex__t_sectors_pipe_tex_mem_texture.sum,l1tex__t_requests_pipe_tex_mem_surface_op_ld.sum,l1tex__t_requests_pipe_tex_mem_surface_op_st.sum
mkdir -p "$X/n"
timeout 300 ncu --metrics "$metrics" -k 'regex:tex|tld4|surf' --csv --page raw "$X/probe" "$X/n" > "$OUT/ncu.csv" 2> "$X/ncu.err" || { echo "ncu failed"; tail -20 "$X/ncu.err"; }
tail -5 "$X/ncu.err" >> "$OUT/env.txt"
(cd "$X" && tar czf "$OUT/extra.tgz" half_*.bin sass.txt metrics.txt)
python3 -c "import json; d = json.load(open('$OUT/probe.json')); print(d['device'], len(d['cases']), 'cases')"
ls -la "$OUT"
