#!/usr/bin/env python3
"""Turns Google Benchmark JSON files (one or more, with repetitions) into a Markdown table with the
minimum and median over repetitions of the real and CPU time per iteration, plus the median of
any user counters. Usage: summarize.py build/bench/results/*.json"""
import json
import statistics
import sys
from collections import OrderedDict

STANDARD = {"family_index", "per_family_instance_index", "repetitions", "repetition_index",
            "threads", "iterations", "real_time", "cpu_time"}
UNIT = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def fmt_ns(ns):
    if ns >= 1e6:
        return f"{ns / 1e6:.3g} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.3g} µs"
    return f"{ns:.3g} ns"


def main(paths):
    runs = OrderedDict()
    counters = OrderedDict()
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        for b in data["benchmarks"]:
            if b.get("run_type") != "iteration":
                continue
            name = b.get("run_name", b["name"])
            scale = UNIT[b.get("time_unit", "ns")]
            runs.setdefault(name, []).append((b["real_time"] * scale, b["cpu_time"] * scale))
            for key, value in b.items():
                if key not in STANDARD and isinstance(value, (int, float)):
                    counters.setdefault(name, {}).setdefault(key, []).append(value)
    print("| benchmark | reps | real min | real median | CPU min | CPU median | counters (median) |")
    print("|---|---|---|---|---|---|---|")
    for name, samples in runs.items():
        real = [s[0] for s in samples]
        cpu = [s[1] for s in samples]
        extra = ", ".join(f"{k} {statistics.median(v):.4g}"
                          for k, v in counters.get(name, {}).items())
        print(f"| {name} | {len(samples)} | {fmt_ns(min(real))} | {fmt_ns(statistics.median(real))}"
              f" | {fmt_ns(min(cpu))} | {fmt_ns(statistics.median(cpu))} | {extra} |")


if __name__ == "__main__":
    main(sys.argv[1:])
