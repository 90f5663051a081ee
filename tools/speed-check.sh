#!/usr/bin/env bash
# Byte-identical output check for emulator speed work (docs/performance.md,
# "Counting instructions instead of seconds"): writes, for the binary $1, into
# folder $2: `launch --json --per-line` of every example spec and `render
# --json` plus the PNG of five ray-tracing variants (Sponza 64², frame 3,
# SIROH). Compare two folders with `diff -r` (the render JSON's
# `render_seconds` is dropped before writing).
# Usage: tools/speed-check.sh BINARY OUTDIR   (from the repository root)
set -euo pipefail
bin=$1
out=$2
mkdir -p "$out"
find examples -name '*.toml' | sort | while read -r spec; do
    name=$(echo "$spec" | tr '/' '_')
    "$bin" launch "$spec" --json --per-line --threads 1 > "$out/$name.json" 2> "$out/$name.err" || echo "exit $?" >> "$out/$name.err"
done
for v in stack stackless short-stack push-down node-cache-1+stack-cache-1; do
    "$bin" render --scene sponza --frame 3 --resolution 64x64 --heuristic siroh --variant "$v" \
        -o "$out/render-$v.png" --json "$out/render-$v.raw.json" > /dev/null 2>&1
    grep -v '"render_seconds"' "$out/render-$v.raw.json" > "$out/render-$v.json"
    rm "$out/render-$v.raw.json"
done
echo "written: $out"
