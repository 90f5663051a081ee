#!/usr/bin/env python3
"""Prints the per-instruction error table of docs/gpu-measurements.md from
tests/fixtures/gpu_sfu_approx.json (python3 tools/device/sfu_report.py FIXTURE)."""
import json
import math
import sys

d = json.load(open(sys.argv[1] if len(sys.argv) > 1 else "tests/fixtures/gpu_sfu_approx.json"))


def bins(lo_exp, hi_exp, signs=(0, 1)):
    """Bin indices of inputs with unbiased exponent in [lo_exp, hi_exp]."""
    return [s * 256 + e + 127 for s in signs for e in range(lo_exp, hi_exp + 1)]


RANGES = {  # where an absolute error is the meaningful measure
    "lg2": ("[0.5, 2)", bins(-1, 0, (0,))),
    "sin": ("|x| < 4", bins(-126, 1)),
    "cos": ("|x| < 4", bins(-126, 1)),
    "tanh": ("all", list(range(512))),
}
RANGES_WIDE = {"sin": ("|x| < 512", bins(-126, 8)), "cos": ("|x| < 512", bins(-126, 8))}


def maxd(h):
    m = 0
    for b in range(89):
        if h[b]:
            m = max(m, abs(b - 16) if b <= 32 else (1 << ((b - 33 if b < 61 else b - 61) + 4)))
    return m


def pct(a, b):
    return "%.2f" % (100.0 * a / b)


print("| instruction | RN (exact) % | within 1 ulp % | max distance (ulp) | max error (ulp) at input | max abs error (range) | NaN/inf agree |")
print("|---|---|---|---|---|---|---|")
for o in d["ops"]:
    h = o["hist"]
    nonnan = o["inputs"] - h[89] - h[90] - h[91]
    key = o["name"].split(".")[0]
    label = o["name"] + (" (a = mix32(b))" if o.get("a_mode", "").startswith("a = mix32") else "")
    md = maxd(h)
    mds = ">= 2^%d" % int(math.log2(md)) if md > 16 else str(md)
    abs_txt = ""
    for table in (RANGES, RANGES_WIDE):
        if key in table:
            name, bs = table[key]
            vals = [o["worst_abs_per_bin"][b] for b in bs]
            v = None if any(x is None for x in vals) else max(vals)
            abs_txt += ("%s%.3g = 2^%.2f (%s)" % ("; " if abs_txt else "", v, math.log2(v), name)) if v else ""
    agree = "yes" if h[90] == 0 and h[91] == 0 else "no (%d, %d)" % (h[90], h[91])
    mu = o["max_ulp"]
    print("| `%s` | %s | %s | %s | %s at `%#010x` | %s | %s |" % (
        label, pct(h[16], nonnan), pct(o["within_1_ulp"], nonnan), mds,
        ("%.4g" % mu) if mu is not None else "inf", o["max_ulp_input"], abs_txt or "-", agree))
print()
print("| instruction | candidate | hits / eligible |")
print("|---|---|---|")
for o in d["ops"]:
    for c in o["candidates"]:
        if c["eligible"]:
            print("| `%s` | %s | %s %% |" % (o["name"], c["name"], pct(c["hits"], c["eligible"])))
