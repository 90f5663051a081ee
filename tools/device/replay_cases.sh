#!/usr/bin/env bash
# Records the GPU-replay cases (docs/gpu-replay.md) on this machine, with the
# emulator (no GPU needed): each case is one warplight command run with
# `--record`, into $REC/<case>/, and its output into $REC/<case>/emulator.txt.
# Then tools/device/replay_run.sh replays them on the GPU.
#   bash tools/device/replay_cases.sh [small|timing|all]   (default all)
# Environment: REC (default /tmp/replay-cases), WARPLIGHT (default target/release/warplight).
# small: 32 x 32 pixels, 2 frames (8 spp), every kernel and integrator of the
#        path tracer, thesis 003's compaction chart, thesis 000's ray caster
#        and photon map, seed 004's photon map: the bit-for-bit checks.
# timing: 256 x 256 pixels (262,144 paths, about four waves of an H200), one
#        frame, Russian roulette against a fixed depth for pt, nee and bdpt;
#        thesis 003's compaction chart at Fig. 17's 1,048,576 paths; the
#        Fresnel regroup's three forms at the same size; Fig. 3's
#        traversals on its SAH tree at 256 x 256; Fig. 9's MLT and bdpt
#        frames at 256 x 256 on its two scenes, and the MLT frames with
#        plain (not atomic) splats (about 9 minutes here).
set -euo pipefail
cd "$(dirname "$0")/../.."
REC=${REC:-/tmp/replay-cases}
W=${WARPLIGHT:-target/release/warplight}
which=${1:-all}
mkdir -p "$REC"

# case name, then the warplight arguments
record() {
  local name=$1
  shift
  rm -rf "${REC:?}/$name"
  mkdir -p "$REC/$name"
  echo "== $name: warplight $*" >&2
  "$W" "$@" --record "$REC/$name" -o "$REC/$name/image.exr" > "$REC/$name/emulator.txt"
  rm -f "$REC/$name/image.exr"
}

path="render --method path --variant emulated --device hopper --fidelity instructions"
if [ "$which" = small ] || [ "$which" = all ]; then
  s="--resolution 32x32 --spp 8"
  for i in pt nee mis mis-power bdpt mlt; do
    record "lambert-$i" $path $s --scene cornell-lambert --integrator $i
  done
  record lambert-nee-fixed $path $s --scene cornell-lambert --integrator nee --termination fixed-depth
  record lambert-bdpt-fixed $path $s --scene cornell-lambert --integrator bdpt --termination fixed-depth
  record lambert-nee-stratified $path $s --scene cornell-lambert --integrator nee --pixels stratified:2
  # 20 frames: past a round of 4 x 4 strata, two levels of the scramble
  record lambert-nee-progressive $path --resolution 32x32 --spp 80 --scene cornell-lambert --integrator nee --pixels progressive:4
  for t in stack12 restart backtrack; do
    record "lambert-nee-$t" $path $s --scene cornell-lambert --integrator nee --traversal $t
  done
  record rough-mis-power $path $s --scene cornell-rough --integrator mis-power
  # the anisotropic mirror (§5.1): its sampling, D and G, under MIS and under MLT's mutations
  record aniso-mis-power $path $s --scene cornell-anisotropic --integrator mis-power
  record aniso-mlt $path $s --scene cornell-anisotropic --integrator mlt
  record aniso-glass-pt $path $s --scene env-glass-anisotropic --integrator pt
  # the thesis' coated diffuse (§4.5): the coat's switch, Ashikhmin-Shirley's lobe and its light sample,
  # under bdpt and MLT's mutations, and drawn ahead by the Fresnel regroup
  record coated-mis-power $path $s --scene cornell-coated --integrator mis-power
  record coated-bdpt $path $s --scene cornell-coated --integrator bdpt
  record coated-mlt $path $s --scene cornell-coated --integrator mlt
  record regroup-coated $path $s --scene cornell-glossy-coated --integrator nee --form regrouped
  record caustic-nee $path $s --scene cornell-caustic --integrator nee
  record inverted-bdpt $path $s --scene cornell-inverted --integrator bdpt
  record fog-nee $path $s --scene fog-box --integrator nee
  record jade-nee $path $s --scene bunny-jade --integrator nee
  record scratched-nee $path $s --scene cornell-scratched --integrator nee
  record env-spheres-nee $path $s --scene env-spheres --integrator nee
  record env-glass-mis $path $s --scene env-glass --integrator mis
  # the megakernel, thread compaction and the Fresnel regroup, level by level (host reads between launches)
  rm -rf "$REC/compaction" && mkdir -p "$REC/compaction"
  echo "== compaction" >&2
  "$W" chart lin-compaction --size 32 --depth 30 --record "$REC/compaction" \
    -o "$REC/compaction/chart-{}.svg" > "$REC/compaction/emulator.txt"
  # the chart's data (per level: active paths, warp instructions) stays for the report
  rm -f "$REC"/compaction/chart-*.svg
  record raycast-short-stack render --method raycast --variant short-stack --device hopper --scene cornell-box --resolution 64x64
  record photon-map render --method photon-map --variant emulated --device hopper --scene cornell-box --resolution 32x32
fi
if [ "$which" = timing ] || [ "$which" = all ]; then
  # Fig. 17's 1,048,576 paths: the normal and the compacted wavefront, 30 levels
  rm -rf "$REC/compaction-512" && mkdir -p "$REC/compaction-512"
  echo "== compaction-512" >&2
  "$W" chart lin-compaction --size 512 --depth 30 --record "$REC/compaction-512" \
    -o "$REC/compaction-512/chart-{}.svg" > "$REC/compaction-512/emulator.txt"
  rm -f "$REC"/compaction-512/chart-*.svg
  # §6.3's regroup: trace and shade apart, compacted or regrouped by Fresnel branch, 1,048,576 paths
  for f in split split-compacted regrouped; do
    record "regroup-$f" $path --resolution 512x512 --spp 4 --scene cornell-glossy --integrator nee --form $f
  done
  # Fig. 9: an MLT frame against a bdpt frame (003:L332 "only slightly
  # slower"), 256 x 256, 2 frames, on both of its scenes; functional fidelity
  # (the same bytes; MLT's bootstrap takes minutes at instructions)
  fpath="render --method path --variant emulated --device hopper --fidelity functional"
  for scene in cornell-lambert cornell-inverted; do
    for i in bdpt mlt; do
      record "fig9-$i-${scene#cornell-}" $fpath --resolution 256x256 --spp 8 --scene $scene --integrator $i
    done
  done
  # and MLT's frames with their splats not atomic (timing only: -store, -rmw)
  python3 tools/device/mlt_splat_variants.py "$REC"
  # Fig. 3's three traversals on bunny-ball's SAH tree, 262,144 paths a frame
  for t in stack restart backtrack; do
    record "fig3-$t" $path --resolution 256x256 --spp 4 --scene bunny-ball --integrator nee --traversal $t
  done
  for i in pt nee bdpt; do
    for e in roulette fixed-depth; do
      record "time-$i-$e" $path --resolution 256x256 --spp 4 --scene cornell-lambert --integrator $i --termination $e
    done
  done
fi
du -sh "$REC"
