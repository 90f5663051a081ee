#!/usr/bin/env python3
"""The tables of docs/gpu-replay.md from the GPU-replay fixture.

  replay_report.py [FIXTURE]     (default tests/fixtures/gpu_replay.json)

Prints markdown: every case with its launches and reads; the timing cases
(the emulator's PTX warp instructions, the H200's SASS warp instructions
from Nsight Compute, the GPU's median milliseconds, registers, achieved
occupancy) with Russian roulette against a fixed depth; and, when the fixture
holds a compaction case with the emulator's per-level counts, thread
compaction's frame time against the normal wavefront per max depth (Fig. 17
of thesis 003), modelled by warp instructions and measured on the GPU.
"""
import json
import os
import re
import sys


def warp_instructions(lines):
    for l in lines:
        m = re.search(r"emulated \w+: (\d+) warp instructions", l)
        if m:
            return int(m.group(1))
    return None


def cases_table(fx):
    print("| case | command | launches | reads equal |")
    print("|---|---|---|---|")
    for name, c in sorted(fx["cases"].items()):
        launches = sum(len(d["launches"]) for d in c["devices"])
        reads = [r for d in c["devices"] for r in d["reads"]]
        equal = sum(1 for r in reads if r["equal"])
        # every case runs the hopper profile; the fidelity is named where it is not `instructions`
        args, skip = [], False
        for i, a in enumerate(c["args"]):
            if skip:
                skip = False
            elif a == "--device" or (a == "--fidelity" and c["args"][i + 1] == "instructions"):
                skip = True
            else:
                args.append(a)
        print(f"| {name} | `{' '.join(args)}` | {launches} | {equal} of {len(reads)} |")


def timing_table(fx):
    rows = {}
    for name, c in fx["cases"].items():
        if not name.startswith("time-") or "ncu" not in c:
            continue
        l = c["devices"][0]["launches"][0]
        n = c["ncu"][0]
        rows[name[5:]] = {
            "emu": warp_instructions(c["emulator"]),
            "sass": n["smsp__inst_executed.sum"],
            "ms": l["ms_median"],
            "regs": int(n["launch__registers_per_thread"]),
            "occ": n["sm__warps_active.avg.pct_of_peak_sustained_active"],
        }
    print("| integrator, ending | emulated warp instructions (PTX) | H200 warp instructions (SASS) | SASS / PTX | H200 ms (median of 20) | registers | achieved occupancy |")
    print("|---|---|---|---|---|---|---|")
    for k, r in rows.items():
        print(f"| {k.replace('-', ' ', 1)} | {r['emu'] / 1e6:.1f} M | {r['sass'] / 1e6:.1f} M | {r['sass'] / r['emu']:.3f} | {r['ms']:.3f} | {r['regs']} | {r['occ']:.1f} % |")
    print()
    print("| integrator | roulette / fixed depth: emulated instructions (the model) | SASS instructions | H200 time | model's speedup / H200's |")
    print("|---|---|---|---|---|")
    for i in ("pt", "nee", "bdpt"):
        a, b = rows.get(f"{i}-roulette"), rows.get(f"{i}-fixed-depth")
        if a and b:
            m, s, t = a["emu"] / b["emu"], a["sass"] / b["sass"], a["ms"] / b["ms"]
            print(f"| {i} | {m:.3f} ({1 / m:.2f} x faster) | {s:.3f} | {t:.3f} ({1 / t:.2f} x faster) | {t / m:.2f} |")


def compaction_table(fx, name):
    c = fx["cases"].get(name)
    if not c or len(c["devices"]) != 2 or c["devices"][0]["launches"][0]["kernel"] != "path_init":
        return
    normal, compact = c["devices"][0]["launches"], c["devices"][1]["launches"]
    key = "ms_pass_median" if "ms_pass_median" in normal[0] else "ms_first"
    # ncu's kernel durations (at its locked clocks), launch by launch over both devices
    ncu = c.get("ncu", [])
    if len(ncu) == len(normal) + len(compact):
        for l, n in zip(normal + compact, ncu):
            l["ncu_ms"] = n["gpu__time_duration.sum"] / 1e6

    def levels(launches, what):
        # [init, level 0, (flag, scan, sums, scatter)?, level 1, ...]: per level
        # its own and the compaction's after it, and the camera rays apart
        out, level = [], None
        for l in launches[1:]:
            if l["kernel"] == "path_level":
                if level:
                    out.append(level)
                level = [l[what], 0]
            else:
                level[1] += l[what]
        out.append(level)
        return launches[0][what], out

    def frame(launches, what, d):
        # up to max depth D: the camera rays, D levels and the compactions between them
        t0, lv = levels(launches, what)
        return t0 + sum(x[0] for x in lv[:d]) + sum(x[1] for x in lv[:d - 1])

    active = [x["active"] for x in c["levels"]["normal"]] if "levels" in c else []
    paths = normal[0]["grid"][0] * normal[0]["block"][0]
    print(f"{paths:,} paths, `{' '.join(c['args'])}`; H200 milliseconds: the median of "
          f"{len(normal[0].get('ms_passes', [1]))} whole replays.")
    print()
    print("| max depth D | active paths entering level D | modelled compact / normal (emulated warp instructions) | H200 compact / normal (time between launches' events) | H200 normal ms | H200 compact ms | H200 compact / normal (ncu's kernel durations) |")
    print("|---|---|---|---|---|---|---|")
    w = "emulated_warp_instructions"
    for d in list(range(1, 11)) + [20, 30]:
        if d > len(normal) - 1:
            break
        tn, tc = frame(normal, key, d), frame(compact, key, d)
        model = frame(compact, w, d) / frame(normal, w, d)
        a = f"{active[d - 1]:,}" if d - 1 < len(active) else "0"
        k = f"{frame(compact, 'ncu_ms', d) / frame(normal, 'ncu_ms', d):.3f}" if "ncu_ms" in normal[0] else "-"
        print(f"| {d} | {a} | {model:.3f} | {tc / tn:.3f} | {tn:.3f} | {tc:.3f} | {k} |")


def traversal_table(fx):
    rows = {}
    for t in ("stack", "restart", "backtrack"):
        c = fx["cases"].get(f"fig3-{t}")
        if not c or "ncu" not in c:
            return
        n = c["ncu"][0]
        rows[t] = {"emu": warp_instructions(c["emulator"]), "sass": n["smsp__inst_executed.sum"],
                   "ms": c["devices"][0]["launches"][0]["ms_median"], "dram": n["dram__bytes.sum"],
                   "l1": n["l1tex__t_sector_hit_rate.pct"], "occ": n["sm__warps_active.avg.pct_of_peak_sustained_active"],
                   "local": n["smsp__sass_inst_executed_op_local_ld.sum"] + n["smsp__sass_inst_executed_op_local_st.sum"]}
    # Fig. 3's printed seconds on the SAH tree (003:L181-189)
    thesis = {"stack": 6.235, "restart": 10.139, "backtrack": 30.516}
    s = rows["stack"]
    print("| traversal (SAH tree) | emulated warp instructions | modelled vs stack | H200 SASS warp instructions | H200 ms (median of 20) | H200 vs stack | thesis vs stack | DRAM MB | L1 hit | local ld+st | achieved occupancy |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for t, r in rows.items():
        print(f"| {t} | {r['emu'] / 1e6:.1f} M | {r['emu'] / s['emu'] - 1:+.1%} | {r['sass'] / 1e6:.1f} M | {r['ms']:.3f} | "
              f"{r['ms'] / s['ms'] - 1:+.1%} | {thesis[t] / thesis['stack'] - 1:+.1%} | {r['dram'] / 1e6:.1f} | {r['l1']:.1f} % | "
              f"{r['local'] / 1e6:.2f} M | {r['occ']:.1f} % |")


def regroup_table(fx):
    forms = {}
    for f in ("split", "split-compacted", "regrouped"):
        c = fx["cases"].get(f"regroup-{f}")
        if not c or "ncu" not in c:
            return
        launches = c["devices"][0]["launches"]
        key = "ms_pass_median" if "ms_pass_median" in launches[0] else "ms_first"
        shade = [i for i, l in enumerate(launches) if l["kernel"] == "regroup_shade"]
        forms[f] = {
            "emu": sum(l["emulated_warp_instructions"] for l in launches),
            "ms": sum(l[key] for l in launches),
            "ncu": sum(n["gpu__time_duration.sum"] for n in c["ncu"]) / 1e6,
            "shade_ncu": sum(c["ncu"][i]["gpu__time_duration.sum"] for i in shade) / 1e6,
            "shade_sass": sum(c["ncu"][i]["smsp__inst_executed.sum"] for i in shade),
            "shade_emu": sum(launches[i]["emulated_warp_instructions"] for i in shade),
            "launches": len(launches),
        }
    paths = fx["cases"]["regroup-regrouped"]["devices"][0]["launches"][0]["grid"][0] * 256
    print(f"`cornell-glossy`, NEE, one frame of {paths:,} paths, 16 bounces; milliseconds: the median of 5 whole replays (events) and ncu's kernel durations.")
    print()
    print("| form | launches | emulated warp instructions, frame | H200 ms (events) | H200 ms (kernels, ncu) | shade: emulated warp instructions | shade: SASS warp instructions | shade: ms (ncu) |")
    print("|---|---|---|---|---|---|---|---|")
    for f, r in forms.items():
        print(f"| {f} | {r['launches']} | {r['emu'] / 1e6:.1f} M | {r['ms']:.3f} | {r['ncu']:.3f} | {r['shade_emu'] / 1e6:.1f} M | {r['shade_sass'] / 1e6:.1f} M | {r['shade_ncu']:.3f} |")
    c, g = forms["split-compacted"], forms["regrouped"]
    print()
    print("| regrouped against compacted (speedup) | modelled (warp instructions) | H200 (events) | H200 (kernels) |")
    print("|---|---|---|---|")
    print(f"| whole frame | {c['emu'] / g['emu'] - 1:+.1%} | {c['ms'] / g['ms'] - 1:+.1%} | {c['ncu'] / g['ncu'] - 1:+.1%} |")
    print(f"| shade launches only | {c['shade_emu'] / g['shade_emu'] - 1:+.1%} | - | {c['shade_ncu'] / g['shade_ncu'] - 1:+.1%} |")


def fig9_table(fx):
    """Fig. 9: the second MLT frame against the second bdpt frame per scene."""
    rows = []
    for scene in ("lambert", "inverted"):
        m, b = fx["cases"].get(f"fig9-mlt-{scene}"), fx["cases"].get(f"fig9-bdpt-{scene}")
        if not m or not b or "ncu_atomics" not in m:
            return
        lm, lb = m["devices"][0]["launches"][3], b["devices"][0]["launches"][1]
        nm, nb = m["ncu"][3], b["ncu"][1]
        am, ab = m["ncu_atomics"][3], b["ncu_atomics"][1]
        em, eb = lm["emulated_warp_instructions"], lb["emulated_warp_instructions"]
        sm, sb = nm["smsp__inst_executed.sum"], nb["smsp__inst_executed.sum"]
        tm, tb = lm["ms_pass_median"], lb["ms_median"]
        occ = "sm__warps_active.avg.pct_of_peak_sustained_active"
        red, req = "smsp__inst_executed_op_global_red.sum", "lts__t_requests_op_red.sum"
        rows.append(f"| cornell-{scene} | {em / 1e6:.1f} M / {eb / 1e6:.1f} M = {em / eb:.3f} | "
                    f"{sm / 1e6:.1f} M / {sb / 1e6:.1f} M = {sm / sb:.3f} | {tm:.3f} / {tb:.3f} | **{tm / tb:.3f}** | "
                    f"{nm['gpu__time_duration.sum'] / nb['gpu__time_duration.sum']:.3f} | "
                    f"{nm['launch__registers_per_thread']:.0f} / {nb['launch__registers_per_thread']:.0f} | "
                    f"{nm[occ]:.1f} % / {nb[occ]:.1f} % | {nm['dram__bytes.sum'] / 1e6:.1f} / {nb['dram__bytes.sum'] / 1e6:.1f} | "
                    f"{am[red]:,.0f} / {ab[red]:,.0f} | {am[req] / 1e6:.2f} M / {ab[req]:,.0f} |")
    print("| scene | emulated warp instructions, mlt / bdpt (PTX) | SASS, mlt / bdpt | H200 ms, mlt / bdpt | H200 mlt / bdpt (events) | (ncu's durations) | registers | achieved occupancy | DRAM MB | global reductions (warp) | their L2 requests |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(r)


def splats_table(path):
    """Fig. 9's MLT frames with the splats not atomic, or none (tests/fixtures/gpu_mlt_splats.json):
    each variant's mlt_frame time over the atomic one's, per frame."""
    if not os.path.exists(path):
        return
    fx = json.load(open(path))
    print("| scene | frame | atomic ms | plain store / atomic (events; ncu) | load-add-store / atomic (events; ncu) | "
          "no splat / atomic (events; ncu) | atomic's own spread over 5 passes | mlt / bdpt frame (this run) |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in ("lambert", "inverted"):
        a = fx["cases"].get(f"fig9-mlt-{scene}")
        b = fx["cases"].get(f"fig9-bdpt-{scene}")
        variants = [fx["cases"].get(f"fig9-mlt-{scene}-{v}") for v in ("store", "rmw", "none")]
        if a is None or b is None or None in variants:
            continue
        la = a["devices"][0]["launches"]
        tb = b["devices"][0]["launches"][1]["ms_median"]
        for i, nth in ((2, "1st"), (3, "2nd")):
            cells = []
            for c in variants:
                ev = c["devices"][0]["launches"][i]["ms_pass_median"] / la[i]["ms_pass_median"]
                nc = c["ncu"][i]["gpu__time_duration.sum"] / a["ncu"][i]["gpu__time_duration.sum"]
                cells.append(f"{ev:.3f}; {nc:.3f}")
            p = la[i]["ms_passes"]
            spread = (max(p) - min(p)) / la[i]["ms_pass_median"]
            ratio = f"{la[i]['ms_pass_median'] / tb:.3f}" if i == 3 else ""
            print(f"| cornell-{scene} | {nth} | {la[i]['ms_pass_median']:.3f} | {cells[0]} | {cells[1]} | "
                  f"{cells[2]} | {100 * spread:.1f} % | {ratio} |")


def main():
    fx = json.load(open(sys.argv[1] if len(sys.argv) > 1 else "tests/fixtures/gpu_replay.json"))
    print("GPU:", "; ".join(fx["env"][2:3]))
    print()
    cases_table(fx)
    print()
    timing_table(fx)
    print()
    traversal_table(fx)
    print()
    regroup_table(fx)
    print()
    fig9_table(fx)
    print()
    splats_table("tests/fixtures/gpu_mlt_splats.json")
    for name in fx["cases"]:
        if name.startswith("compaction"):
            print()
            compaction_table(fx, name)


if __name__ == "__main__":
    main()
