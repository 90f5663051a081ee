#!/usr/bin/env python3
"""Whether bfs's L1 hit sectors depend on timing (issue 20): runs the
validation suite's bfs case (kernels/validation/suite.cu, both dialects, the
buffers and launches of tools/device/validation.py) REPS times each from fresh
buffers, under Nsight Compute (tools/device/issue20_tex_bfs.sh), and writes
the fixture of what it counted per run.

  bfs_repeat.py run OUT REPS       run on the GPU; OUT/bfs_launches.txt
                                   (id dialect rep kernel) and
                                   OUT/bfs_outputs.json (FNV-1a of cost per run)
  bfs_repeat.py fixture OUT FILE   OUT/{bfs_launches.txt,bfs_outputs.json,
                                   bfs_ncu.csv,env.txt} -> FILE: per dialect,
                                   per run, every metric summed over the
                                   run's 20 launches
"""
import csv, json, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import validation as V  # noqa: E402


def bfs_case():
    return [c for c in V.cases() if c["name"] == "bfs"][0]


def run(out, reps):
    import numpy as np
    import cupy as cp
    c = bfs_case()
    log = open(f"{out}/bfs_launches.txt", "w")
    outputs = {}
    lid = 0
    for dialect, _ in V.DIALECTS:
        mod = cp.RawModule(path=V.LOAD[dialect])
        for rep in range(reps):
            bufs = {b["name"]: cp.asarray(np.array(V.init_words(b["init"], b["n"]), dtype=np.uint32))
                    for b in c["buffers"]}
            for l in c["launches"]:
                args = tuple(bufs[a["buf"]] if "buf" in a else np.int32(a["i32"]) for a in l["args"])
                mod.get_function(l["kernel"])(tuple(l["grid"]), tuple(l["block"]), args)
                cp.cuda.runtime.deviceSynchronize()
                log.write(f"{lid} {dialect} {rep} {l['kernel']}\n")
                lid += 1
            outputs[f"{dialect}/{rep}"] = V.fnv1a64(cp.asnumpy(bufs["cost"]).astype("<u4").tobytes())
    log.close()
    json.dump(outputs, open(f"{out}/bfs_outputs.json", "w"), indent=1)


def fixture(out, path):
    launches = [l.split() for l in open(f"{out}/bfs_launches.txt")]
    rows = [r for r in csv.reader(open(f"{out}/bfs_ncu.csv")) if r and not r[0].startswith("==")]
    col = {h: k for k, h in enumerate(rows[0])}
    runs = {}
    for r in rows[1:]:
        i = int(r[col["ID"]])
        _, dialect, rep, kernel = launches[i]
        assert kernel == r[col["Kernel Name"]].split("(")[0], (i, r[col["Kernel Name"]])
        v = int(float(r[col["Metric Value"]].replace(",", "")))
        m = runs.setdefault(dialect, {}).setdefault(int(rep), {})
        m[r[col["Metric Name"]]] = m.get(r[col["Metric Name"]], 0) + v
    outputs = json.load(open(f"{out}/bfs_outputs.json"))
    # every run computed the same costs
    assert len(set(outputs.values())) == 1, outputs
    fx = {"note": "made by tools/device/issue20_tex_bfs.sh and tools/device/bfs_repeat.py fixture",
          "env": open(f"{out}/env.txt").read().splitlines()[:12],
          "case": "bfs", "launches_per_run": len(bfs_case()["launches"]),
          "cost_fnv1a64": outputs, "runs": {}}
    for dialect, reps in runs.items():
        fx["runs"][dialect] = [reps[k] for k in sorted(reps)]
    json.dump(fx, open(path, "w"), indent=1)


if __name__ == "__main__":
    if sys.argv[1] == "run":
        run(sys.argv[2], int(sys.argv[3]))
    elif sys.argv[1] == "fixture":
        fixture(sys.argv[2], sys.argv[3])
