#!/usr/bin/env bash
# On a machine with an sm_90 GPU, the CUDA toolkit and Nsight Compute: the
# f32 operations per test of kernels/lin2017/intersect.cu's tri_standard and
# tri_affine as the hardware executes them (table lin:s6.4,
# docs/reproduction-lin2017.md; fixture tests/fixtures/lin2017/h200_intersection_ops.json).
#   1. builds tools/device/intersect_ops_host.cu (which includes intersect.cu)
#      with nvcc -arch=sm_90 -O3 -lineinfo and runs it on 4096 pairs that all
#      hit, once with the nvcc-compiled kernels and once with the committed
#      clang PTX kernels/lin2017/intersect.ptx (the driver's JIT)
#   2. ncu on both runs: per-thread FADD, FMUL, FFMA and all instructions
#      executed (divide by 4096 for one test)
#   3. static SASS: ptxas -arch=sm_90 -lineinfo of the committed clang and
#      nvcc PTX, and the binary's own cubin; nvdisasm -g -c of each, and the
#      FADD/FMUL/FFMA/MUFU.RCP of each kernel counted per source line, the
#      division's slow-path subroutine apart
# Into $OUT: summary.txt (versions, hits, ncu metrics, static counts),
# log.txt, ncu.csv, hits.txt, sass.{clang,nvcc,bin}.txt.
# Environment: OUT (default /tmp/intersect_ops), N_PAIRS is fixed at 4096 in the host.
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
if ! command -v ncu >/dev/null; then
  for d in /usr/local/cuda/nsight-compute* /opt/nvidia/nsight-compute/*; do [ -x "$d/ncu" ] && PATH=$PATH:$d; done
fi
OUT=${OUT:-/tmp/intersect_ops}
W=$(mktemp -d)
mkdir -p "$OUT"
S=$OUT/summary.txt
LOG=$OUT/log.txt
: > "$S"
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,compute_cap --format=csv,noheader
  nvcc --version | tail -2
  ptxas --version | tail -1
  ncu --version | tail -1
} >> "$S" 2>&1

METRICS=smsp__sass_thread_inst_executed_op_fadd_pred_on.sum,smsp__sass_thread_inst_executed_op_fmul_pred_on.sum,smsp__sass_thread_inst_executed_op_ffma_pred_on.sum,smsp__sass_thread_inst_executed.sum
BUILD="nvcc -arch=sm_90 -O3 -lineinfo -Ikernels -o $W/host tools/device/intersect_ops_host.cu -lcuda"
echo "build: $BUILD" >> "$S"
if $BUILD >> "$LOG" 2>&1; then
  # the runs: outputs checked (every pair a hit), then the counts
  "$W/host" "$W/hits_nvcc.txt" >> "$S" 2>&1 || echo "FAILED: nvcc kernels" >> "$S"
  "$W/host" "$W/hits_clang.txt" kernels/lin2017/intersect.ptx >> "$S" 2>&1 || echo "FAILED: clang PTX kernels" >> "$S"
  { echo "# nvcc-compiled kernels"; cat "$W/hits_nvcc.txt"; echo "# clang PTX (driver JIT)"; cat "$W/hits_clang.txt"; } > "$OUT/hits.txt"
  for v in nvcc clang; do
    args=("$W/hits_ncu_$v.txt"); [ $v = clang ] && args+=(kernels/lin2017/intersect.ptx)
    echo "ncu ($v): ncu --metrics $METRICS --csv --print-units base $W/host ${args[*]}" >> "$S"
    ncu --metrics "$METRICS" --csv --print-units base --log-file "$W/ncu_$v.csv" "$W/host" "${args[@]}" >> "$LOG" 2>&1 \
      || echo "FAILED: ncu ($v)" >> "$S"
    { echo "# $v"; cat "$W/ncu_$v.csv"; } >> "$OUT/ncu.csv" 2>&1
    # "Kernel Name",...,"Metric Name","Metric Unit","Metric Value": value / 4096 per test
    awk -v v=$v -F'","' '/smsp__sass/ { k = $5; sub(/\(.*/, "", k); m = $(NF-2); x = $NF; gsub(/[",]/, "", x);
      printf "ncu %s %s %s %s per-test %.4f\n", v, k, m, x, x / 4096 }' "$W/ncu_$v.csv" >> "$S"
  done
  (cd "$W" && cuobjdump -xelf all host >> "$LOG" 2>&1)
  cp "$(ls "$W"/*sm_90*.cubin | head -1)" "$W/bin.cubin" 2>> "$LOG"
else
  echo "FAILED: build (log.txt)" >> "$S"
fi

# static: ptxas of the committed PTX; the nvcc PTX's .version lowered if this ptxas is older
ptxas -arch=sm_90 -lineinfo -o "$W/clang.cubin" kernels/lin2017/intersect.ptx >> "$LOG" 2>&1 || echo "FAILED: ptxas clang" >> "$S"
if ! ptxas -arch=sm_90 -lineinfo -o "$W/nvcc.cubin" kernels/lin2017/intersect.nvcc.ptx >> "$LOG" 2>&1; then
  sed -E 's/^\.version 9\.[5-9]$/.version 9.0/' kernels/lin2017/intersect.nvcc.ptx > "$W/nvcc.ptx"
  echo "nvcc PTX: .version lowered to 9.0 for this ptxas" >> "$S"
  ptxas -arch=sm_90 -lineinfo -o "$W/nvcc.cubin" "$W/nvcc.ptx" >> "$LOG" 2>&1 || echo "FAILED: ptxas nvcc" >> "$S"
fi
for c in clang nvcc bin; do
  [ -f "$W/$c.cubin" ] || continue
  nvdisasm -g -c "$W/$c.cubin" > "$OUT/sass.$c.txt" 2>> "$LOG"
  # per kernel, group (main / slowpath) and source line: FADD FMUL FFMA MUFU.RCP
  awk -v c=$c '
    /^\/\/-+ \.text\./ { f = $2; sub(/^\.text\./, "", f); g = "main"; loc = "?" }
    /^\$__internal/ { g = "slowpath" }
    /\/\/## File/ { n = $0; sub(/.*File "/, "", n); file = n; sub(/".*/, "", file); sub(/.*\//, "", file);
                    ln = n; sub(/.*line /, "", ln); sub(/[^0-9].*/, "", ln); loc = file ":" ln }
    /\/\*[0-9a-f]+\*\// { s = $0; sub(/.*\*\/ */, "", s); sub(/^@!?U?P[0-9T] */, "", s); split(s, t, /[ ;]/); op = t[1];
      b = op; if (b !~ /^MUFU/) sub(/\..*/, "", b); else { split(op, mm, "."); b = mm[1] "." mm[2] }
      if (b == "FADD" || b == "FMUL" || b == "FFMA" || b == "MUFU.RCP") {
        key = f " " g " " (g == "main" ? loc : "-"); cnt[key " " b]++; tot[f " " g " " b]++ } }
    END { for (k in tot) print "static " c " " k " " tot[k] | "sort";
          close("sort"); for (k in cnt) print "line " c " " k " " cnt[k] | "sort" }' "$OUT/sass.$c.txt" >> "$S"
done
rm -rf "$W"
ls -l "$OUT"
