#!/usr/bin/env python3
"""The validation suite on the GPU (issue 20): runs every launch of
kernels/validation/suite.cu, as the clang PTX (suite.ptx) and the nvcc PTX
(suite.nvcc.ptx), each loaded through the driver's JIT (CuPy RawModule), and
records the output buffers; Nsight Compute (tools/device/validation_run.sh)
measures the same launches. VALIDATION_SUITE=uniform_atomics does the same
for kernels/validation/uniform_atomics.cu (ptxas's warp-uniform atomics),
VALIDATION_SUITE=uniform_atomics64 for their 64-bit forms.

  validation.py plan               the cases as JSON (buffers, inits, launches)
  validation.py run OUT            run them on the GPU; OUT/outputs.json, OUT/launches.txt
  validation.py fixture OUT FILE   OUT/{outputs.json,launches.txt,ncu.csv,env.txt} -> FILE

Inputs are made from a 32-bit integer hash (lowbias32) of the element index,
the same formula tests/validation_suite.rs uses; the fixture carries an
FNV-1a hash of every input buffer so that a difference shows at once.
"""
import base64, csv, json, struct, sys

MASK = 0xFFFFFFFF


def hash32(x):
    x &= MASK
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK
    x ^= x >> 16
    return x


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


def init_words(init, n):
    """The 32-bit words of a buffer of n elements."""
    k = init["kind"]
    seed = init.get("seed", 0)
    if k == "zero":
        return [0] * n
    if k == "fill":  # every element v, the first one `first`
        w = [init["v"] & MASK] * n
        if "first" in init and n:
            w[0] = init["first"] & MASK
        return w
    if k == "iota":  # a*i + b
        return [(init["a"] * i + init["b"]) & MASK for i in range(n)]
    if k == "hash":  # hash(i + seed * 2^20) [mod m]
        m = init.get("mod")
        return [hash32(i + (seed << 20)) % m if m else hash32(i + (seed << 20)) for i in range(n)]
    if k == "hash_small":  # hash mod m, minus off (signed)
        return [((hash32(i + (seed << 20)) % init["mod"]) - init["off"]) & MASK for i in range(n)]
    if k == "f32":  # floats (hash & 0xffff) / 65536 - 0.5: exact in f32
        return [struct.unpack("<I", struct.pack("<f", (hash32(i + (seed << 20)) & 0xFFFF) / 65536.0 - 0.5))[0] for i in range(n)]
    raise ValueError(k)


def L(kernel, grid, block, args):
    g = list(grid) + [1] * (3 - len(grid))
    b = list(block) + [1] * (3 - len(block))
    return {"kernel": kernel, "grid": g, "block": b, "args": args}


def B(name):
    return {"buf": name}


def I(v):
    return {"i32": v}


def cases():
    if SUITE == "uniform_atomics":
        return uniform_atomics_cases()
    if SUITE == "uniform_atomics64":
        return uniform_atomics64_cases()
    cs = []
    n = 16384
    cs.append({"name": "reduce_shfl", "buffers": [
        {"name": "in", "n": n, "init": {"kind": "f32", "seed": 1}},
        {"name": "out", "n": 32, "init": {"kind": "zero"}, "output": True}],
        "launches": [L("reduce_shfl", [32], [256], [B("in"), B("out"), I(n)])]})
    m = 64
    cs.append({"name": "matmul_tiled", "buffers": [
        {"name": "A", "n": m * m, "init": {"kind": "f32", "seed": 2}},
        {"name": "B", "n": m * m, "init": {"kind": "f32", "seed": 3}},
        {"name": "C", "n": m * m, "init": {"kind": "zero"}, "output": True}],
        "launches": [L("matmul_tiled", [m // 16, m // 16], [16, 16], [B("A"), B("B"), B("C"), I(m)])]})
    cs.append({"name": "bitonic_shared", "buffers": [
        {"name": "keys", "n": 4096, "init": {"kind": "hash", "seed": 4}, "output": True}],
        "launches": [L("bitonic_shared", [4], [512], [B("keys")])]})
    cs.append({"name": "sort8_network", "buffers": [
        {"name": "keys", "n": 4096, "init": {"kind": "hash", "seed": 5, "mod": 1000}, "output": True}],
        "launches": [L("sort8_network", [2], [256], [B("keys")])]})
    cs.append({"name": "scan_shfl", "buffers": [
        {"name": "in", "n": 4096, "init": {"kind": "hash_small", "seed": 6, "mod": 201, "off": 100}},
        {"name": "out", "n": 4096, "init": {"kind": "zero"}, "output": True},
        {"name": "sums", "n": 8, "init": {"kind": "zero"}, "output": True}],
        "launches": [L("scan_shfl", [8], [512], [B("in"), B("out"), B("sums")])]})
    nh = 8192
    cs.append({"name": "histogram256", "buffers": [
        {"name": "data", "n": nh, "init": {"kind": "hash", "seed": 7}},
        {"name": "hist", "n": 256, "init": {"kind": "zero"}, "output": True}],
        "launches": [L("histogram256", [8], [256], [B("data"), B("hist"), I(nh)])]})
    nw = 64
    tiles = nw // 16
    cs.append({"name": "needleman_wunsch", "buffers": [
        {"name": "ref", "n": nw * nw, "init": {"kind": "hash_small", "seed": 8, "mod": 21, "off": 10}},
        {"name": "score", "n": (nw + 1) * (nw + 1), "init": {"kind": "zero"}, "output": True}],
        "launches": [L("nw_init", [1], [128], [B("score"), I(nw), I(10)])] +
        [L("nw_diag", [tiles], [16], [B("ref"), B("score"), I(nw), I(10), I(d)]) for d in range(2 * tiles - 1)]})
    ns = 4096
    cs.append({"name": "stencil_1d", "buffers": [
        {"name": "in", "n": ns + 6, "init": {"kind": "f32", "seed": 9}},
        {"name": "out", "n": ns, "init": {"kind": "zero"}, "output": True}],
        "launches": [L("stencil_1d", [ns // 256], [256], [B("in"), B("out")])]})
    nb, deg, levels = 2048, 3, 10
    bfs = []
    for _ in range(levels):
        bfs.append(L("bfs_expand", [nb // 256], [256],
                     [B("row"), B("col"), B("mask"), B("updating"), B("visited"), B("cost"), I(nb)]))
        bfs.append(L("bfs_update", [nb // 256], [256], [B("mask"), B("updating"), B("visited"), B("over"), I(nb)]))
    cs.append({"name": "bfs", "buffers": [
        {"name": "row", "n": nb + 1, "init": {"kind": "iota", "a": deg, "b": 0}},
        {"name": "col", "n": nb * deg, "init": {"kind": "hash", "seed": 10, "mod": nb}},
        {"name": "mask", "n": nb, "init": {"kind": "fill", "v": 0, "first": 1}},
        {"name": "updating", "n": nb, "init": {"kind": "zero"}},
        {"name": "visited", "n": nb, "init": {"kind": "fill", "v": 0, "first": 1}},
        {"name": "cost", "n": nb, "init": {"kind": "fill", "v": -1, "first": 0}, "output": True},
        {"name": "over", "n": 1, "init": {"kind": "zero"}, "output": True}],
        "launches": bfs})
    for k in ("lds128_probe", "lds64_probe"):
        for mode in range(7):
            cs.append({"name": f"{k}_{mode}", "buffers": [
                {"name": "out", "n": 32, "init": {"kind": "zero"}, "output": True}],
                "launches": [L(k, [1], [32], [B("out"), I(mode)])]})
    for stride, span, ret in [(1, 32, 0), (1, 32, 1), (0, 1, 0), (0, 1, 1), (1, 16, 0), (1, 16, 1),
                              (8, 256, 0), (8, 256, 1), (2, 64, 0), (2, 64, 1)]:
        cs.append({"name": f"atom_probe_{stride}_{span}_{ret}", "buffers": [
            {"name": "buf", "n": 256, "init": {"kind": "zero"}, "output": True},
            {"name": "out", "n": 32, "init": {"kind": "zero"}, "output": True}],
            "launches": [L("atom_probe", [1], [32], [B("buf"), B("out"), I(stride), I(span), I(ret)])]})
    return cs


def uniform_atomics_cases():
    """kernels/validation/uniform_atomics.cu: every kernel takes (c, in, out)."""
    cs = []

    def case(name, kernel, grid, block, init_in, n_out=256):
        cs.append({"name": name, "buffers": [
            {"name": "c", "n": 8, "init": {"kind": "zero"}, "output": True},
            {"name": "in", "n": 512, "init": init_in},
            {"name": "out", "n": n_out, "init": {"kind": "zero"}, "output": True}],
            "launches": [L(kernel, [grid], [block], [B("c"), B("in"), B("out")])]})

    h = {"kind": "hash", "seed": 11}
    # result unused: 2 CTAs of 2 full warps; and 48 threads (a full and a half warp)
    for k in ("ua_inc", "ua_add_val", "ua_min", "ua_max_u", "ua_or", "ua_xor", "ua_inc_wrap", "ua_block",
              "ua_loop", "ua_loaded", "ua_cond", "ua_lane", "ua_warp"):
        case(k, k, 2, 64, h)
    case("ua_f32", "ua_f32", 2, 64, {"kind": "f32", "seed": 12})
    for k in ("ua_inc", "ua_add_val", "ua_cond"):
        case(k + "_48", k, 1, 48, h)
    # result used, or the order of the lanes matters: one warp, and 24 lanes of one
    for k in ("ua_exch", "ua_inc_ret", "ua_add_val_ret", "ua_min_ret", "ua_cond_ret"):
        case(k, k, 1, 32, h)
    for k in ("ua_inc_ret", "ua_add_val_ret"):
        case(k + "_24", k, 1, 24, h)
    # set on packed halves: 5 results for each pair of input words
    for k in ("set_f16x2", "set_bf16x2"):
        case(k, k, 1, 256, {"kind": "hash", "seed": 13}, n_out=1280)
    return cs


def uniform_atomics64_cases():
    """kernels/validation/uniform_atomics64.cu: every kernel takes (c, in, out);
    c holds four 64-bit words, a 64-bit operand is two input words."""
    cs = []

    def case(name, kernel, grid, block, init_in):
        cs.append({"name": name, "buffers": [
            {"name": "c", "n": 8, "init": {"kind": "zero"}, "output": True},
            {"name": "in", "n": 512, "init": init_in},
            {"name": "out", "n": 256, "init": {"kind": "zero"}, "output": True}],
            "launches": [L(kernel, [grid], [block], [B("c"), B("in"), B("out")])]})

    h = {"kind": "hash", "seed": 21}
    # result unused: 2 CTAs of 2 full warps; and 48 threads (a full and a half warp)
    for k in ("ua64_inc", "ua64_add_val", "ua64_min", "ua64_max_u", "ua64_and", "ua64_or", "ua64_xor",
              "ua64_block", "ua64_cond", "ua64_lane"):
        case(k, k, 2, 64, h)
    case("ua64_f64", "ua64_f64", 1, 32, h)
    for k in ("ua64_inc", "ua64_add_val", "ua64_cond"):
        case(k + "_48", k, 1, 48, h)
    # result used, or the order of the lanes matters: one warp, and 24 lanes of one
    for k in ("ua64_exch", "ua64_inc_ret", "ua64_add_val_ret", "ua64_min_ret", "ua64_cas"):
        case(k, k, 1, 32, h)
    for k in ("ua64_inc_ret", "ua64_add_val_ret"):
        case(k + "_24", k, 1, 24, h)
    return cs


import os
# The suite: `suite` (kernels/validation/suite.cu), `uniform_atomics` or `uniform_atomics64`.
SUITE = os.environ.get("VALIDATION_SUITE", "suite")
DIALECTS = [("clang", f"kernels/validation/{SUITE}.ptx"), ("nvcc", f"kernels/validation/{SUITE}.nvcc.ptx")]
# The committed nvcc PTX says `.version 9.5` (nvcc 13.5); a CUDA 13.0 driver
# accepts PTX up to 9.0, so the run script loads a copy whose only change is
# that line (VALIDATION_NVCC_PTX names it).
LOAD = {"clang": DIALECTS[0][1], "nvcc": os.environ.get("VALIDATION_NVCC_PTX", DIALECTS[1][1])}


def run(out):
    import numpy as np
    import cupy as cp
    log = open(f"{out}/launches.txt", "w")
    results = {}
    lid = 0
    for dialect, ptx in DIALECTS:
        mod = cp.RawModule(path=LOAD[dialect])
        for c in cases():
            bufs = {}
            for b in c["buffers"]:
                bufs[b["name"]] = cp.asarray(np.array(init_words(b["init"], b["n"]), dtype=np.uint32))
            for l in c["launches"]:
                args = tuple(bufs[a["buf"]] if "buf" in a else np.int32(a["i32"]) for a in l["args"])
                mod.get_function(l["kernel"])(tuple(l["grid"]), tuple(l["block"]), args)
                cp.cuda.runtime.deviceSynchronize()
                log.write(f"{lid} {dialect} {c['name']} {l['kernel']}\n")
                lid += 1
            results[f"{dialect}/{c['name']}"] = {
                b["name"]: base64.b64encode(cp.asnumpy(bufs[b["name"]]).astype("<u4").tobytes()).decode()
                for b in c["buffers"] if b.get("output")}
    log.close()
    json.dump(results, open(f"{out}/outputs.json", "w"))


def fixture(out, path):
    launches = [l.split() for l in open(f"{out}/launches.txt")]
    rows = [r for r in csv.reader(open(f"{out}/ncu.csv")) if r and not r[0].startswith("==")]
    head = rows[0]
    col = {h: k for k, h in enumerate(head)}
    metrics = [dict() for _ in launches]
    for r in rows[1:]:
        i = int(r[col["ID"]])
        assert launches[i][3] == r[col["Kernel Name"]].split("(")[0], (i, r[col["Kernel Name"]])
        v = r[col["Metric Value"]].replace(",", "")
        metrics[i][r[col["Metric Name"]]] = int(float(v)) if v not in ("", "n/a") else None
    outputs = json.load(open(f"{out}/outputs.json"))
    cs = cases()
    fx = {"note": "made by tools/device/validation_run.sh and tools/device/validation.py fixture",
          "env": open(f"{out}/env.txt").read().splitlines()[:40], "cases": []}
    for dialect, ptx in DIALECTS:
        for c in cs:
            ls = [i for i, l in enumerate(launches) if l[1] == dialect and l[2] == c["name"]]
            assert len(ls) == len(c["launches"]), c["name"]
            summed = {}
            for i in ls:
                for k, v in metrics[i].items():
                    summed[k] = None if (v is None or summed.get(k, 0) is None) else summed.get(k, 0) + v
            ins = {b["name"]: fnv1a64(struct.pack(f"<{b['n']}I", *init_words(b["init"], b["n"])))
                   for b in c["buffers"]}
            fx["cases"].append(dict(c, dialect=dialect, ptx=ptx, input_fnv1a64=ins,
                                    outputs=outputs[f"{dialect}/{c['name']}"], metrics=summed))
    json.dump(fx, open(path, "w"), indent=1)


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "plan":
        cs = cases()
        print(json.dumps(cs, indent=1))
        print(sum(len(c["launches"]) for c in cs) * 2, "launches", file=sys.stderr)
    elif cmd == "run":
        run(sys.argv[2])
    elif cmd == "fixture":
        fixture(sys.argv[2], sys.argv[3])
