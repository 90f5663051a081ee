#!/usr/bin/env python3
"""Replays a warplight recording on an NVIDIA GPU (docs/gpu-replay.md).

A recording (`warplight render ... --variant emulated --record DIR`) holds
what the host did with each emulated device: allocations, host writes,
launches (module PTX, kernel, grid, block, arguments, changed __constant__
variables) and host reads with the emulator's bytes. This script does the
same on the GPU through CuPy (the driver's JIT loads the recorded PTX):

  * every allocation is a zeroed device buffer, every pointer argument is
    moved to the buffer (and offset) holding the emulator's address;
  * every read is compared with the emulator's bytes: equal or not, the
    FNV-1a (64-bit) hash of the GPU's bytes, and for differing reads the
    number of differing 4-byte words and the largest difference as f32;
  * with --time N, after the replay each launch is run N more times in
    order (state moves on, as frames accumulate) and timed with CUDA events;
    right for independent launches (a path tracer's frames), not for a
    sequence whose launches consume each other's state (a wavefront's
    levels: after the replay every path has ended);
  * with --passes K, the whole replay runs K times, each from fresh buffers,
    and each launch's first-run time is kept per pass (ms_passes, and their
    median ms_pass_median): the times of such sequences.

  replay.py DIR [--out FILE] [--time N] [--passes K]

FILE (default DIR/replay.json): {"gpu", "cupy", "recordings": [...]}, one
entry per device with "reads" and "launches". Exits 1 when a read differs or
a launch fails (the JSON is written first), 2 on a bad recording.
"""
import argparse
import json
import os
import statistics
import sys


def fnv1a64(b):
    h = 0xCBF29CE484222325
    for x in b:
        h ^= x
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


class Memory:
    """The device's buffers by the emulator's addresses."""

    def __init__(self, cp):
        self.cp = cp
        self.allocs = []  # (addr, bytes, cupy uint8 array)

    def alloc(self, addr, n):
        self.allocs.append((addr, n, self.cp.zeros(max(n, 1), dtype=self.cp.uint8)))

    def find(self, addr, n, one_past=False):
        for base, size, arr in self.allocs:
            end = base + size + (1 if one_past else 0)
            if base <= addr and addr + n <= end:
                return arr, addr - base
        raise ValueError(f"{n} bytes at {addr:#x} lie in no recorded allocation")

    def pointer(self, addr):
        arr, off = self.find(addr, 0, one_past=True)
        return arr.data.ptr + off


def argument(np, mem, a):
    (kind, v), = a.items()
    if kind == "ptr":
        return np.uint64(mem.pointer(v))
    return {"u32": np.uint32, "i32": np.int32, "u64": np.uint64, "i64": np.int64,
            "f32": np.uint32, "f64": np.uint64}[kind](v)


def compare(np, want, got):
    r = {"bytes": len(want), "equal": want == got, "hash": fnv1a64(got)}
    if not r["equal"]:
        r["emulator_hash"] = fnv1a64(want)
        n = len(want) // 4
        w = np.frombuffer(want[:4 * n], dtype="<u4")
        g = np.frombuffer(got[:4 * n], dtype="<u4")
        diff = w != g
        r["differing_words"] = int(diff.sum())
        if diff.any():
            r["first_differing_word"] = int(np.argmax(diff))
            wf, gf = w.view("<f4").astype(np.float64), g.view("<f4").astype(np.float64)
            with np.errstate(invalid="ignore"):
                d = np.abs(wf - gf)[diff]
            r["max_abs_difference_f32"] = float(np.nanmax(d)) if np.isfinite(d).any() else None
    return r


def replay_device(np, cp, folder, data, dev, timing):
    out = {"modules": [m["name"] for m in dev["modules"]], "reads": [], "launches": []}
    if dev.get("unreplayable"):
        out["skipped"] = dev["unreplayable"]
        return out
    mods = [cp.RawModule(path=os.path.join(folder, m["file"])) for m in dev["modules"]]
    mem = Memory(cp)
    launches = []
    for op in dev["ops"]:
        kind = op["op"]
        if kind == "alloc":
            mem.alloc(op["addr"], op["bytes"])
        elif kind == "write":
            o, n = op["data"]["offset"], op["data"]["len"]
            arr, off = mem.find(op["addr"], n)
            arr[off:off + n] = cp.asarray(data[o:o + n])
        elif kind == "constant":
            o, n = op["data"]["offset"], op["data"]["len"]
            ptr = mods[op["module"]].get_global(op["name"])
            ptr.copy_from_host(data[o:o + n].ctypes.data, n)
        elif kind == "launch":
            f = mods[op["module"]].get_function(op["kernel"])
            args = tuple(argument(np, mem, a) for a in op["args"])
            launches.append((op, f, args))
            entry = {"kernel": op["kernel"], "grid": op["grid"], "block": op["block"]}
            start, end = cp.cuda.Event(), cp.cuda.Event()
            try:
                start.record()
                f(tuple(op["grid"]), tuple(op["block"]), args, shared_mem=op["shared"])
                end.record()
                end.synchronize()
                entry["ms_first"] = cp.cuda.get_elapsed_time(start, end)
            except Exception as e:  # a fault on the GPU ends this device's replay
                entry["error"] = str(e)
                out["launches"].append(entry)
                return out
            out["launches"].append(entry)
        elif kind == "read":
            o, n = op["data"]["offset"], op["data"]["len"]
            arr, off = mem.find(op["addr"], n)
            got = cp.asnumpy(arr[off:off + n]).tobytes()
            out["reads"].append(compare(np, data[o:o + n].tobytes(), got))
        else:
            raise ValueError(f"unknown operation {kind}")
    for i, (op, f, args) in enumerate(launches):
        times = []
        for _ in range(timing):
            start, end = cp.cuda.Event(), cp.cuda.Event()
            start.record()
            f(tuple(op["grid"]), tuple(op["block"]), args, shared_mem=op["shared"])
            end.record()
            end.synchronize()
            times.append(cp.cuda.get_elapsed_time(start, end))
        if times:
            out["launches"][i]["ms_median"] = statistics.median(times)
            out["launches"][i]["ms_min"] = min(times)
            out["launches"][i]["timed"] = len(times)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", help="the recording's folder")
    ap.add_argument("--out", help="result JSON (default DIR/replay.json)")
    ap.add_argument("--time", type=int, default=0, metavar="N", help="time each launch N more times")
    ap.add_argument("--passes", type=int, default=1, metavar="K", help="replay K times from fresh buffers")
    a = ap.parse_args()
    import numpy as np
    import cupy as cp
    try:
        rec = json.load(open(os.path.join(a.dir, "recording.json")))
        data = np.fromfile(os.path.join(a.dir, "data.bin"), dtype=np.uint8)
    except (OSError, ValueError) as e:
        print(f"replay.py: {a.dir}: {e}", file=sys.stderr)
        return 2
    if rec.get("format") != 1:
        print(f"replay.py: {a.dir}: recording format {rec.get('format')}, expected 1", file=sys.stderr)
        return 2
    # deep call chains of non-inlined device functions need more than the default 1 KiB stack
    cp.cuda.runtime.deviceSetLimit(0, 16384)
    props = cp.cuda.runtime.getDeviceProperties(0)
    result = {"what": rec["what"], "gpu": props["name"].decode(), "cupy": cp.__version__,
              "driver": cp.cuda.runtime.driverGetVersion(), "devices": []}
    for dev in rec["devices"]:
        out = replay_device(np, cp, a.dir, data, dev, a.time)
        if a.passes > 1 and "skipped" not in out:
            times = [[l.get("ms_first")] for l in out["launches"]]
            for _ in range(a.passes - 1):
                again = replay_device(np, cp, a.dir, data, dev, 0)
                out["reads"] += [r for r in again["reads"] if not r["equal"]]
                for t, l in zip(times, again["launches"]):
                    t.append(l.get("ms_first"))
            for l, t in zip(out["launches"], times):
                l["ms_passes"] = t
                l["ms_pass_median"] = statistics.median(x for x in t if x is not None)
        result["devices"].append(out)
    out = a.out or os.path.join(a.dir, "replay.json")
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    bad = [r for d in result["devices"] for r in d["reads"] if not r["equal"]]
    failed = [l for d in result["devices"] for l in d["launches"] if "error" in l]
    reads = sum(len(d["reads"]) for d in result["devices"])
    print(f"{a.dir}: {reads - len(bad)}/{reads} reads equal the emulator's, "
          f"{sum(len(d['launches']) for d in result['devices'])} launches, {len(failed)} failed")
    return 1 if bad or failed else 0


if __name__ == "__main__":
    sys.exit(main())
