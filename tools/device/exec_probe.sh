#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and the CUDA toolkit, writes into $OUT:
#   sanitizer/         tools/device/sanitizer.sh for the warp-synchronisation
#                      kernels (kernels/tests/planted_warp_race.cu) only
#   txq.txt            tools/device/txq_probe.cu: every query on every object
#                      ("OBJECT QUERY STATUS VALUE"), one process per query
#   txq_sass.txt       the TXQ instructions ptxas made of the queries
set -uo pipefail
export PATH=/usr/local/cuda/bin:$PATH
OUT=${OUT:-/tmp/exec_probe_out}
mkdir -p "$OUT/sanitizer"
KERNELS="planted_warp_race_synced planted_warp_race_nosync" OUT="$OUT/sanitizer" \
  bash tools/device/sanitizer.sh
bin=/tmp/txq_probe
if nvcc -arch=sm_90 -O3 -o "$bin" tools/device/txq_probe.cu > "$OUT/txq_build.txt" 2>&1; then
  : > "$OUT/txq.txt"
  for q in 0 1 2 3 4 5 6 7 8 9 10; do
    timeout 30 "$bin" "$q" >> "$OUT/txq.txt" 2>&1
    echo "# query $q exit: $?" >> "$OUT/txq.txt"
  done
  cuobjdump -sass "$bin" 2>&1 | grep -E "Function|TXQ" > "$OUT/txq_sass.txt"
fi
