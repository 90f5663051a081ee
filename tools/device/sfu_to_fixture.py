#!/usr/bin/env python3
"""Turns the output of tools/device/sfu_sweep.cu into two fixtures:

    python3 tools/device/sfu_to_fixture.py sfu_raw.json env.txt \
        tests/fixtures/gpu_sfu_approx.json tests/fixtures/gpu_sfu_samples.json

gpu_sfu_approx.json holds the statistics, gpu_sfu_samples.json the sample
inputs and result bits (same instruction order; both under 1 MB).

Keeps, per instruction: the error histogram and candidate hit rates over all
2^32 inputs, the worst error per input sign/exponent (with the input), and the
exact result bits of a sample (one exponent sweep, special values, and the
worst input of every sign/exponent bin). Errors that are infinite (a result
and its reference differ in being infinite or NaN) are written as null.
Pure standard library.
"""
import json
import math
import re
import struct
import sys


def f32(u):
    return struct.unpack("<f", struct.pack("<I", u & 0xFFFFFFFF))[0]


def num(x):
    """A finite float rounded to 6 significant digits; None for inf/nan."""
    if math.isinf(x) or math.isnan(x):
        return None
    return float("%.6g" % x)


def main(raw_path, env_path, out_path, samples_path):
    raw = json.load(open(raw_path))
    env = open(env_path).read()
    drv = re.search(r"Driver Version: (\S+)", env).group(1)
    nvcc = re.search(r"release (\S+), (V\S+)", env)
    out = {
        "device": raw["device"],
        "compute_capability": raw["compute_capability"],
        "driver": drv,
        "cuda": "%s (%s)" % (nvcc.group(1).rstrip(","), nvcc.group(2)),
        "command": "nvcc -O3 -arch=sm_90 -o /tmp/sfu_sweep tools/device/sfu_sweep.cu && /tmp/sfu_sweep",
        "reference": "the exact function computed in f64 on the GPU (1.0/x, 1.0/sqrt(x), sqrt, log2, exp2, sin, "
                     "cos, tanh, a/b); .ftz rows flush subnormal inputs and results of the reference to signed zero",
        "ulp": "ulp of the reference rounded to f32 (2^-149 at and below the smallest normal exponent)",
        "d": "ord(result) - ord(RN(reference)), ord = sign-magnitude bits as a signed integer (-0 == +0)",
        "hist_bins": raw["hist_bins"],
        "worst_bins": "index = input bits >> 23 (sign * 256 + biased exponent); for div rows, of the divisor b",
        "ops": [],
    }
    samples = {k: out[k] for k in ("device", "compute_capability", "driver", "cuda", "command")}
    samples["contents"] = ("per instruction: inputs x (f32 bits) and the GPU's result bits y; an exponent sweep "
                           "(every sign and biased exponent with mantissas 0, 0x7fffff and one from mix32), special "
                           "values, and the worst input of every sign/exponent bin of gpu_sfu_approx.json")
    samples["mix32"] = "x ^= x >> 16; x *= 0x7feb352d; x ^= x >> 15; x *= 0x846ca68b; x ^= x >> 16"
    samples["ops"] = []
    for op in raw["ops"]:
        h = op["hist"]
        nonnan = op["cand_eligible"][1]
        wu = op["worst_ulp"]
        wa = op["worst_abs"]
        k = max(range(512), key=lambda i: wu[i])
        ka = max(range(512), key=lambda i: wa[i])
        entry = {
            "name": op["name"],
            "inputs": sum(h),
            "exact": h[16],
            "within_1_ulp": h[15] + h[16] + h[17],
            "max_ulp": num(f32(wu[k] >> 32)),
            "max_ulp_input": wu[k] & 0xFFFFFFFF,
            "max_abs": num(f32(wa[ka] >> 32)),
            "max_abs_input": wa[ka] & 0xFFFFFFFF,
            "hist": h,
            "zero_sign_mismatch": op["zero_sign_mismatch"],
            "candidates": [{"name": n, "hits": hh, "eligible": e}
                           for n, hh, e in zip(op["candidates"], op["cand_hits"], op["cand_eligible"]) if n],
            "worst_ulp_per_bin": [num(f32(w >> 32)) if w else 0.0 for w in wu],
            "worst_ulp_input_per_bin": [w & 0xFFFFFFFF for w in wu],
            "worst_abs_per_bin": [num(f32(w >> 32)) if w else 0.0 for w in wa],
            "inexact_per_bin": op["inexact"],
        }
        if any(op["worst_ulp_reduced"]):
            wr = op["worst_ulp_reduced"]
            entry["worst_ulp_vs_reduced_argument_per_bin"] = [num(f32(w >> 32)) if w else 0.0 for w in wr]
        if op["binary"]:
            entry["a_mode"] = op["a_mode"]
            entry["mix32"] = "x ^= x >> 16; x *= 0x7feb352d; x ^= x >> 15; x *= 0x846ca68b; x ^= x >> 16"
        # sample: exponent sweep with mantissas 0, all ones, 1 and one pseudo-random; the specials; worst inputs
        xs, ys = op["sample_x"], op["sample_y"]
        keep_x, keep_y, seen = [], [], set()
        for i, (x, y) in enumerate(zip(xs, ys)):
            sweep = i < 4096
            if sweep and (i % 8) not in (0, 1, 3):
                continue
            if x in seen:
                continue
            seen.add(x)
            keep_x.append(x)
            keep_y.append(y)
        smp = {"name": op["name"], "x": keep_x, "y": keep_y}
        if op["binary"]:
            smp["a_mode"] = op["a_mode"]
            smp["note"] = "x holds the divisor b; the dividend a is a_mode applied to b"
        samples["ops"].append(smp)
        out["ops"].append(entry)
    with open(out_path, "w") as f:
        json.dump(out, f, separators=(",", ":"))
        f.write("\n")
    with open(samples_path, "w") as f:
        json.dump(samples, f, separators=(",", ":"))
        f.write("\n")


def mix32(x):
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    x ^= x >> 16
    return x


if __name__ == "__main__":
    main(*sys.argv[1:5])
