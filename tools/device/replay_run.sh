#!/usr/bin/env bash
# On a machine with an NVIDIA GPU, CuPy and Nsight Compute: replays every
# recording under $REC (made by tools/device/replay_cases.sh; a .tar.gz of
# them is unpacked first) with tools/device/replay.py, then profiles the
# timing cases and a few small ones under ncu. Into $OUT:
#   summary.txt          one line per case (reads equal, launches, times)
#   results.tar.gz       env.txt, <case>.json (replay.py's result, with
#                        --time 20 for the time-* and fig3-* cases, --passes 5
#                        for the compaction and regroup cases, --time 3 for the others),
#                        <case>.ncu.csv (ncu's metrics of each launch), logs
# Then, here: python3 tools/device/replay_fixture.py results.tar.gz REC FILE.
# Environment: REC (a folder or a .tar.gz: `tar -czf recordings.tar.gz -C
# /tmp/replay-cases .` here), OUT (default /tmp/replay-out).
set -uo pipefail
cd "$(dirname "$0")/../.."
export PATH=/usr/local/cuda/bin:$PATH
if ! command -v ncu >/dev/null; then
  for d in /usr/local/cuda/nsight-compute* /opt/nvidia/nsight-compute/*; do [ -x "$d/ncu" ] && PATH=$PATH:$d; done
fi
OUT=${OUT:-/tmp/replay-out}
REC=${REC:?the recordings: a folder or a .tar.gz}
W=$(mktemp -d)
mkdir -p "$OUT" "$W/results"
if [ -f "$REC" ]; then
  mkdir -p "$W/rec" && tar -xzf "$REC" -C "$W/rec" && REC=$W/rec
fi
R=$W/results
{
  date -u
  nvidia-smi --query-gpu=name,driver_version,vbios_version,compute_cap,clocks.max.sm --format=csv
  ncu --version | tail -1
  python3 -c 'import cupy; print("cupy", cupy.__version__)'
} > "$R/env.txt" 2>&1
METRICS=smsp__inst_executed.sum,smsp__thread_inst_executed.sum,gpu__time_duration.sum,launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active,dram__bytes.sum,l1tex__t_sector_hit_rate.pct,lts__t_sector_hit_rate.pct,smsp__sass_inst_executed_op_local_ld.sum,smsp__sass_inst_executed_op_local_st.sum
S=$OUT/summary.txt
: > "$S"
for d in "$REC"/*/; do
  name=$(basename "$d")
  # independent launches (frames) are timed by repeating each; a sequence of
  # launches that consume each other's state (the wavefront) by whole passes
  opts="--time 3"
  case $name in time-*|fig3-*|fig9-bdpt-*) opts="--time 20" ;; compaction*|regroup-*|fig9-mlt-*) opts="--passes 5" ;; esac
  timeout 300 python3 tools/device/replay.py "$d" --out "$R/$name.json" $opts > "$R/$name.log" 2>&1
  echo "$name rc=$? $(tail -1 "$R/$name.log")" >> "$S"
  # what is done so far comes back even if a later step runs past the call's limit
  tar -czf "$OUT/results.tar.gz" -C "$R" .
done
# ncu: the timing cases, and the small ones of each kernel family
for d in "$REC"/time-* "$REC"/lambert-nee "$REC"/lambert-bdpt "$REC"/lambert-mlt "$REC"/compaction* "$REC"/fig3* "$REC"/regroup-* "$REC"/fig9-*; do
  [ -d "$d" ] || continue
  name=$(basename "$d")
  timeout 400 ncu --csv --metrics "$METRICS" --log-file "$R/$name.ncu.csv" \
    python3 tools/device/replay.py "$d" --out "$W/ncu-$name.json" > "$R/$name.ncu.log" 2>&1
  echo "ncu $name rc=$? $(wc -l < "$R/$name.ncu.csv" 2>/dev/null) lines" >> "$S"
  tar -czf "$OUT/results.tar.gz" -C "$R" .
done
# MLT's splats: its global reductions and the L2's atomic traffic (a metric
# the GPU lacks fails this pass alone)
ATOMICS=smsp__inst_executed_op_global_red.sum,lts__t_requests_op_red.sum,lts__t_sectors_op_red.sum,gpu__time_duration.sum
for d in "$REC"/fig9-* "$REC"/lambert-mlt; do
  [ -d "$d" ] || continue
  name=$(basename "$d")
  timeout 400 ncu --csv --metrics "$ATOMICS" --log-file "$R/$name.ncu-atomics.csv" \
    python3 tools/device/replay.py "$d" --out "$W/ncu-atomics-$name.json" > "$R/$name.ncu-atomics.log" 2>&1
  echo "ncu atomics $name rc=$? $(wc -l < "$R/$name.ncu-atomics.csv" 2>/dev/null) lines" >> "$S"
  tar -czf "$OUT/results.tar.gz" -C "$R" .
done
tar -czf "$OUT/results.tar.gz" -C "$R" .
cat "$S"
