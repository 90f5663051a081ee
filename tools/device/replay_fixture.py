#!/usr/bin/env python3
"""Makes the GPU-replay fixture (docs/gpu-replay.md) from what
tools/device/replay_run.sh brought back and the recordings it replayed.

  replay_fixture.py [--merge] RESULTS.tar.gz REC FILE

--merge: FILE exists; the cases in RESULTS replace or join its cases and
the others stay. A merged case keeps its own run's environment lines (its
"env": date, GPU, driver, tools).

RESULTS.tar.gz: replay_run.sh's results; REC: the folder of recordings
(tools/device/replay_cases.sh), for each case's command and the emulator's
printed counts; FILE: the fixture (JSON). Per case: the command, the
emulator's output lines, every read (bytes, equal to the emulator's, the
GPU's FNV-1a hash and, when they differ, the emulator's and how), every
launch (kernel, grid, block, the first run's and the timed runs' GPU
milliseconds, the emulator's warp instructions where the recording has them) and, where ncu profiled the case, its metrics per launch.
"""
import csv
import io
import json
import os
import sys
import tarfile


def ncu_rows(text):
    """ncu --csv's rows: per launch ID, {metric: value}; kernels in order."""
    lines = text.splitlines()
    start = next((i for i, l in enumerate(lines) if l.startswith('"ID"')), None)
    if start is None:
        return []
    rows = list(csv.DictReader(io.StringIO("\n".join(lines[start:]))))
    launches = {}
    for r in rows:
        i = int(r["ID"])
        e = launches.setdefault(i, {"kernel": r["Kernel Name"].split("(")[0]})
        v = r["Metric Value"].replace(",", "")
        try:
            v = float(v)
        except ValueError:
            pass
        e[r["Metric Name"]] = v
    return [launches[i] for i in sorted(launches)]


def main():
    argv = sys.argv[1:]
    merge = bool(argv) and argv[0] == "--merge"
    if merge:
        argv = argv[1:]
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    results, rec, path = argv
    files = {}
    with tarfile.open(results) as t:
        for m in t.getmembers():
            if m.isfile():
                files[os.path.basename(m.name)] = t.extractfile(m).read().decode()
    env = files.get("env.txt", "").strip().splitlines()
    fixture = {
        "what": "GPU replays of emulated runs (tools/device/replay_cases.sh, replay_run.sh, replay_fixture.py); docs/gpu-replay.md",
        "env": env,
        "cases": {},
    }
    if merge:
        with open(path) as f:
            fixture = json.load(f)
    for name in sorted(n[:-5] for n in files if n.endswith(".json")):
        r = json.loads(files[name + ".json"])
        emulator = open(os.path.join(rec, name, "emulator.txt")).read().strip().splitlines()
        words = r["what"].split()[1:]
        args, output = [], None
        while words:
            w = words.pop(0)
            if w == "--record":
                words.pop(0)
            elif w in ("-o", "--output"):
                output = os.path.basename(words.pop(0))
            else:
                args.append(w)
        case = {"args": args, "output": output, "emulator": emulator, "devices": []}
        # a merged case ran in another call: its own date, GPU, driver and tools
        if merge:
            case["env"] = env
        recorded = json.load(open(os.path.join(rec, name, "recording.json")))
        for d, rd in zip(r["devices"], recorded["devices"]):
            dev = {"reads": d["reads"], "launches": []}
            # the emulator's warp instructions of each launch, where the recording has them
            emulated = [o.get("warp_instructions") for o in rd["ops"] if o["op"] == "launch"]
            if "skipped" in d:
                dev["skipped"] = d["skipped"]
            for l, w in zip(d["launches"], emulated):
                entry = {k: (round(v, 4) if isinstance(v, float) else v) for k, v in l.items()}
                if "ms_passes" in entry:
                    entry["ms_passes"] = [round(x, 4) for x in entry["ms_passes"]]
                if w is not None:
                    entry["emulated_warp_instructions"] = w
                dev["launches"].append(entry)
            case["devices"].append(dev)
        levels = os.path.join(rec, name, "chart-data.json")
        if os.path.exists(levels):
            case["levels"] = json.load(open(levels))
        if name + ".ncu.csv" in files:
            case["ncu"] = ncu_rows(files[name + ".ncu.csv"])
        if name + ".ncu-atomics.csv" in files:
            case["ncu_atomics"] = ncu_rows(files[name + ".ncu-atomics.csv"])
        fixture["cases"][name] = case
    with open(path, "w") as f:
        json.dump(fixture, f, indent=1)
        f.write("\n")
    print(f"{path}: {len(fixture['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
