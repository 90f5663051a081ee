#!/usr/bin/env bash
# Compiles every kernels/**/*.cu to PTX.
#   kernels/x.ptx       clang-16 (the PTX warplight runs by default; committed)
#   kernels/x.nvcc.ptx  nvcc, when NVCC points at one (the second dialect; committed)
# Usage: kernels/build.sh [--check]   (--check: compile to a temp dir and fail on drift)
# Environment: CLANG (default clang-16), NVCC (default: `nvcc` on PATH, if any).
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG=${CLANG:-clang-16}
NVCC=${NVCC:-$(command -v nvcc || true)}
check=0
[ "${1:-}" = "--check" ] && check=1
out_dir=.
[ $check = 1 ] && out_dir=$(mktemp -d)
status=0
# .file paths: the sources relative to the repository (-fdebug-compilation-dir),
# clang's own headers as clang/include/... rather than its install location
clang_include=$("$CLANG" -print-resource-dir)/include
clang_ptx() { # src out
  "$CLANG" -x cuda --cuda-device-only -nocudainc -nocudalib --cuda-gpu-arch=sm_90 \
    -Xclang -target-feature -Xclang +ptx78 -O3 -ffp-contract=on -gline-tables-only -fdebug-compilation-dir=. \
    -fdebug-prefix-map="$clang_include"=clang/include -Ikernels -S -o "$2" "$1"
}
nvcc_ptx() { # src out
  "$NVCC" -arch=sm_90 -O3 -ptx -lineinfo -Ikernels -o "$2" "$1"
  # keep the SDK's install location out of the file
  sed -i -E 's#"[^"]*/include/#"cuda/include/#' "$2"
  # and the build machine's checkout: paths relative to the repository, as clang writes them
  sed -i -E "s#\"$(pwd)/#\"./#" "$2"
}
while IFS= read -r cu; do
  base=${cu%.cu}
  mkdir -p "$out_dir/$(dirname "$cu")"
  clang_ptx "$cu" "$out_dir/$base.ptx"
  if [ $check = 1 ] && ! cmp -s "$base.ptx" "$out_dir/$base.ptx"; then
    echo "drift: $base.ptx differs from what $CLANG makes of $cu (run kernels/build.sh)" >&2
    status=1
  fi
  if [ -n "$NVCC" ] && [ $check = 0 ]; then
    nvcc_ptx "$cu" "$base.nvcc.ptx"
  fi
done < <(find kernels -name '*.cu' | sort)
[ $check = 1 ] && rm -rf "$out_dir"
exit $status
