#!/usr/bin/env python3
"""Fixtures from what tools/device/issue20_leftovers.sh measured (its tex.tgz,
unpacked into DIR): checks that every texture's texels are the hash rule's
(tests/tex_filter.rs makes them again), then writes

  tests/fixtures/validation/h200_tex_filter.json   the cases and the sample kept
  tests/fixtures/validation/h200_tex_filter.bin.z  zlib: per case, the kept
      samples' coordinates (f32, dims each) then their results (f32 x 4 each)
  tests/fixtures/validation/h200_sured.json        sured.json as measured

usage: tex_filter_fixture.py DIR ENV_TXT [2|3]

With "2" (tools/device/issue20_tex_bfs.sh's tex2.tgz, the second set of
cases): h200_tex_filter2.{json,bin.z} instead, no surfaces, and more samples
kept of the large 3-D case (KEEP_MORE). With "3"
(tools/device/issue20_s8_stepped.sh's tex3.tgz, signed 8-bit texels):
h200_tex_filter3.{json,bin.z}, every sample kept.
"""
import json, struct, sys, zlib

MASK = 0xFFFFFFFF
KEEP = 1024
KEEP_MORE = {"r3big": 8192}
ESIZE = {"f32": 4, "f16": 2, "u16": 2, "s16": 2, "u8": 1, "s8": 1}


def hash32(x):
    x &= MASK
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK
    x ^= x >> 16
    return x


def texel_bits(c, e):
    """tools/device/tex_filter_host.cu's texel_bits."""
    ch, k = e % 4, e // 4
    if c["texels"] == "random":
        h = hash32(e + (c["seed"] << 20))
        if c["format"] == "f32":
            return (h & 0x807FFFFF) | ((120 + hash32(h) % 15) << 23)
        if c["format"] == "f16":
            return (h & 0x83FF) | ((8 + hash32(h) % 15) << 10)
        if c["format"] in ("u16", "s16"):
            return h & 0xFFFF
        return h & 0xFF
    w, h_ = c["size"][0], c["size"][1]
    x, y = k % w, (k // w % h_ if h_ else 0)
    if c["texels"] == "pair":
        v = [[0, 1, 1, -3], [1, 0, 2, 5]][x][ch]
    elif c["texels"] == "index":
        v = [x, 4096 - x, 1, 0][ch]
    else:
        v = [x, y, 1 if x == 0 and y == 0 else 0, 2 * x + 3 * y][ch]
    return struct.unpack("<I", struct.pack("<f", float(v)))[0]


def main(d, env, second=False, third=False):
    cases = json.load(open(f"{d}/tex.json"))
    stem = "tests/fixtures/validation/h200_tex_filter" + ("3" if third else "2" if second else "")
    blob = b""
    for c in cases:
        esize = ESIZE[c["format"]]
        raw = open(f"{d}/{c['name']}.tex", "rb").read()
        count = len(raw) // esize
        want = b"".join(struct.pack("<I", texel_bits(c, e))[:esize] for e in range(count))
        assert raw == want, c["name"]
        dims, n = c["dims"], c["n"]
        crd = struct.unpack(f"<{n * dims}I", open(f"{d}/{c['name']}.crd", "rb").read())
        out = struct.unpack(f"<{n * 4}I", open(f"{d}/{c['name']}.out", "rb").read())
        step = max(1, n // KEEP) if c["coords"] == "grid1" else 1
        keep = list(range(0, n, step))[:KEEP_MORE.get(c["name"], KEEP) if second else n if third else KEEP]
        c["kept"] = {"first": 0, "step": step, "count": len(keep)}
        words = [crd[i * dims + k] for i in keep for k in range(dims)] + [out[i * 4 + k] for i in keep for k in range(4)]
        blob += struct.pack(f"<{len(words)}I", *words)
    script = "issue20_s8_stepped.sh" if third else "issue20_tex_bfs.sh" if second else "issue20_leftovers.sh"
    meta = {"note": f"made by tools/device/tex_filter_fixture.py from tools/device/{script}",
            "env": open(env).read().splitlines()[:8], "cases": cases}
    json.dump(meta, open(f"{stem}.json", "w"), indent=1)
    open(f"{stem}.bin.z", "wb").write(zlib.compress(blob, 9))
    if second or third:
        return
    s = json.load(open(f"{d}/sured.json"))
    s["note"] = "made by tools/device/tex_filter_host.cu (kernels/validation/sured.cu) on the device"
    s["env"] = meta["env"]
    json.dump(s, open("tests/fixtures/validation/h200_sured.json", "w"), indent=1)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], len(sys.argv) > 3 and sys.argv[3] == "2", len(sys.argv) > 3 and sys.argv[3] == "3")
