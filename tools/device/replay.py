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

FILE (default DIR/replay.json): {"what", "gpu", "cupy", "driver",
"devices": [...]}, one entry per device with "reads" (the first pass's, in
the recording's order), "launches" and, if anything went wrong, "error" (a
pointer or read outside every recorded allocation, a fault on the GPU: the
replay of that device, and of every later one after a GPU fault, stops
there) and "later_pass_differences". The JSON is always written. Exits 1
when a read differs or a launch fails, 2 when the recording cannot be read
or replayed.

Arguments: pointers are moved to the replay's buffers; other scalars
(including U64 ones and a launch spec's numbers given as bytes) are passed
as recorded. Addresses stored inside buffers are not moved: a recording of
a kernel that follows pointers written by the host would need them.
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

    def find(self, addr, n):
        for base, size, arr in self.allocs:
            if base <= addr and addr + n <= base + size:
                return arr, addr - base
        raise BadRecording(f"{n} bytes at {addr:#x} lie in no recorded allocation")

    def pointer(self, addr):
        # a pointer may point one past its allocation's end (n = 0 allows it)
        arr, off = self.find(addr, 0)
        return arr.data.ptr + off


class BadRecording(Exception):
    """The recording asks for something the replay cannot do."""


SCALARS = {1: "<u1", 2: "<u2", 4: "<u4", 8: "<u8"}


def argument(np, mem, a):
    (kind, v), = a.items()
    if kind == "ptr":
        return np.uint64(mem.pointer(v))
    if kind == "bytes":
        return np.frombuffer(bytes(v), dtype=SCALARS[len(v)])[0]
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
        r["differing_trailing_bytes"] = sum(1 for x, y in zip(want[4 * n:], got[4 * n:]) if x != y)
        if diff.any():
            r["first_differing_word"] = int(np.argmax(diff))
            with np.errstate(invalid="ignore", over="ignore"):
                wf, gf = w.view("<f4").astype(np.float64), g.view("<f4").astype(np.float64)
                d = np.abs(wf - gf)[diff]
            d = d[np.isfinite(d)]
            # as f32 the words' largest finite difference (JSON has no infinity)
            r["max_abs_difference_f32"] = float(d.max()) if d.size else None
    return r


def replay_device(np, cp, folder, data, dev, timing):
    out = {"modules": [m["name"] for m in dev["modules"]], "reads": [], "launches": []}
    if dev.get("unreplayable"):
        out["skipped"] = dev["unreplayable"]
        return out
    try:
        replay_ops(np, cp, folder, data, dev, timing, out)
    except BadRecording as e:
        out["error"] = f"bad recording: {e}"
    except GpuFault as e:
        out["error"] = f"a launch faulted: {e}"
        out["fault"] = True
    return out


def launch(cp, f, op, args):
    """Runs one recorded launch and returns its milliseconds."""
    if op["shared"] > 48 * 1024:
        f.max_dynamic_shared_size_bytes = op["shared"]
    start, end = cp.cuda.Event(), cp.cuda.Event()
    start.record()
    f(tuple(op["grid"]), tuple(op["block"]), args, shared_mem=op["shared"])
    end.record()
    end.synchronize()
    return cp.cuda.get_elapsed_time(start, end)


def replay_ops(np, cp, folder, data, dev, timing, out):
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
            out["launches"].append(entry)
            try:
                entry["ms_first"] = launch(cp, f, op, args)
            except Exception as e:  # a fault on the GPU: its context is lost, the replay ends
                entry["error"] = str(e)
                raise GpuFault(str(e))
        elif kind == "read":
            o, n = op["data"]["offset"], op["data"]["len"]
            arr, off = mem.find(op["addr"], n)
            got = cp.asnumpy(arr[off:off + n]).tobytes()
            out["reads"].append(compare(np, data[o:o + n].tobytes(), got))
        else:
            raise BadRecording(f"unknown operation {kind}")
    for i, (op, f, args) in enumerate(launches):
        times = [launch(cp, f, op, args) for _ in range(timing)]
        if times:
            out["launches"][i]["ms_median"] = statistics.median(times)
            out["launches"][i]["ms_min"] = min(times)
            out["launches"][i]["timed"] = len(times)


class GpuFault(Exception):
    """A launch faulted: the CUDA context is unusable from here on."""


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
    faulted = False
    for dev in rec["devices"]:
        if faulted:
            result["devices"].append({"error": "not replayed: an earlier launch faulted", "reads": [], "launches": []})
            continue
        out = replay_device(np, cp, a.dir, data, dev, a.time)
        if a.passes > 1 and "skipped" not in out and "error" not in out:
            times = [[l.get("ms_first")] for l in out["launches"]]
            for p in range(1, a.passes):
                again = replay_device(np, cp, a.dir, data, dev, 0)
                if "error" in again:
                    out["error"] = f"pass {p + 1}: {again['error']}"
                    out["fault"] = again.get("fault", False)
                    break
                diffs = [r for r in again["reads"] if not r["equal"]]
                if diffs:
                    out.setdefault("later_pass_differences", []).extend(diffs)
                for t, l in zip(times, again["launches"]):
                    t.append(l.get("ms_first"))
            for l, t in zip(out["launches"], times):
                done = [x for x in t if x is not None]
                l["ms_passes"] = t
                if done:
                    l["ms_pass_median"] = statistics.median(done)
        faulted = out.pop("fault", False)
        result["devices"].append(out)
    out = a.out or os.path.join(a.dir, "replay.json")
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    devices = result["devices"]
    bad = [r for d in devices for r in d["reads"] if not r["equal"]]
    later = sum(len(d.get("later_pass_differences", [])) for d in devices)
    failed = [l for d in devices for l in d["launches"] if "error" in l]
    errors = [d["error"] for d in devices if "error" in d]
    reads = sum(len(d["reads"]) for d in devices)
    print(f"{a.dir}: {reads - len(bad)}/{reads} reads equal the emulator's"
          + (f" ({later} differ in later passes)" if later else "")
          + f", {sum(len(d['launches']) for d in devices)} launches, {len(failed)} failed"
          + "".join(f"; {e}" for e in errors))
    if any(e.startswith("bad recording") for e in errors):
        return 2
    return 1 if bad or later or failed or errors else 0


if __name__ == "__main__":
    sys.exit(main())
