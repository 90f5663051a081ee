#!/usr/bin/env python3
"""Makes timing-only variants of the Fig. 9 MLT recordings whose splats are
not atomic, or absent, so that the H200 can time what MLT's splats cost
(docs/gpu-replay.md, "MLT's splats without atomics"; thesis 003:L332: MLT is
"only slightly slower than MC estimator, cause of which mainly attributes to
the atomic memory write").

  mlt_splat_variants.py REC

For every recording REC/fig9-mlt-<scene>/ (tools/device/replay_cases.sh
timing) it writes three copies beside it, the same launches and data with the
module's PTX changed in mlt_frame only:

  fig9-mlt-<scene>-store  each splat `atom.global.add.u64 %r, [a], v` (ptxas
                          makes the unused-result atomics reductions, RED)
                          becomes a plain store `st.global.u64 [a], v`:
                          the same addresses and bytes written, no atomic;
  fig9-mlt-<scene>-rmw    it becomes a load, an add and a store of the same
                          address, not atomic: the atomic's traffic (a read
                          and a write of the sector) without its atomicity;
  fig9-mlt-<scene>-none   no splat at all: the atomic is dropped (its result
                          register set to 0), and ptxas drops what only fed
                          it: the splat's whole cost, writes and arithmetic.

All three make wrong images (lost updates, or none): their reads differ from
the emulator's, and only their times mean anything. Exits (status 1, with a
message) when a recording's PTX has no mlt_frame, when its mlt_frame has no
u64 atomic add, or an atomic this tool does not rewrite.
"""
import os
import re
import shutil
import sys

ATOM = re.compile(r"^(\s*)atom\.global\.add\.u64\s+(%rd\d+),\s*\[(%rd\d+)\],\s*(%rd\d+);\s*$")


def patch(ptx, kind):
    """The PTX with mlt_frame's u64 atomic adds replaced; (text, count)."""
    lines = ptx.split("\n")
    start = next((i for i, l in enumerate(lines) if l.startswith(".visible .entry mlt_frame(")), None)
    if start is None:
        sys.exit("the PTX has no mlt_frame entry")
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith(".visible .entry ")), len(lines))
    n = 0
    for i in range(start, end):
        line = lines[i]
        if "atom." not in line and "red." not in line:
            continue
        m = ATOM.match(line)
        if not m:
            sys.exit(f"mlt_frame has an atomic this tool does not rewrite: {line.strip()}")
        pad, old, addr, val = m.groups()
        if kind == "none":
            lines[i] = f"{pad}mov.u64 \t{old}, 0;"
        elif kind == "store":
            # the result register is never read (the splat ignores it); keep it defined
            lines[i] = f"{pad}st.global.u64 \t[{addr}], {val};\n{pad}mov.u64 \t{old}, 0;"
        else:
            lines[i] = (f"{pad}ld.global.u64 \t{old}, [{addr}];\n"
                        f"{pad}{{ .reg .u64 %splat; add.u64 \t%splat, {old}, {val}; "
                        f"st.global.u64 \t[{addr}], %splat; }}")
        n += 1
    return "\n".join(lines), n


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    rec = sys.argv[1]
    cases = sorted(d for d in os.listdir(rec)
                   if re.fullmatch(r"fig9-mlt-[a-z]+", d) and os.path.isdir(os.path.join(rec, d)))
    if not cases:
        sys.exit(f"{rec}: no fig9-mlt-<scene> recording (tools/device/replay_cases.sh timing)")
    for case in cases:
        src = os.path.join(rec, case)
        for kind in ("store", "rmw", "none"):
            dst = f"{src}-{kind}"
            shutil.rmtree(dst, ignore_errors=True)
            shutil.copytree(src, dst)
            for f in os.listdir(dst):
                if f.endswith(".ptx"):
                    p = os.path.join(dst, f)
                    text, n = patch(open(p).read(), kind)
                    if n == 0:
                        sys.exit(f"{p}: mlt_frame has no u64 atomic add")
                    open(p, "w").write(text)
                    print(f"{case}-{kind}: {f}: {n} splat atomics rewritten", file=sys.stderr)
            with open(os.path.join(dst, "emulator.txt"), "a") as o:
                o.write(f"(timing variant of {case}: mlt_frame's splats as {kind}, not atomic; reads differ)\n")


if __name__ == "__main__":
    main()
