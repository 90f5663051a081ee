#!/usr/bin/env python3
"""Turns the output of tools/gpu/measure_micro.sh (launches.txt, ncu.csv,
gpu.txt) into tests/fixtures/h100_micro.json.
Usage: micro_to_json.py DIR > tests/fixtures/h100_micro.json"""
import csv, json, sys

d = sys.argv[1]
launches = []
for line in open(f"{d}/launches.txt"):
    i, name, a, b = line.split()
    launches.append({"id": int(i), "kernel": name, "a": int(a), "b": int(b), "grid": 64, "block": 256, "metrics": {}})
rows = [r for r in csv.reader(open(f"{d}/ncu.csv")) if r and not r[0].startswith("==")]
head = rows[0]
col = {h: k for k, h in enumerate(head)}
for r in rows[1:]:
    i = int(r[col["ID"]])
    assert launches[i]["kernel"] == r[col["Kernel Name"]].split("(")[0], (i, r[col["Kernel Name"]])
    v = r[col["Metric Value"]].replace(",", "")
    launches[i]["metrics"][r[col["Metric Name"]]] = int(float(v))
gpu = open(f"{d}/gpu.txt").read().splitlines()
print(json.dumps({
    "gpu": gpu[0].split(" (UUID")[0],
    "profiler": next((l for l in gpu if l.startswith("Version")), ""),
    "note": "grid 64 x block 256 per launch; made by tools/gpu/measure_micro.sh",
    "launches": launches,
}, indent=1))
