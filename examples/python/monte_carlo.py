#!/usr/bin/env python3
"""A Monte Carlo over the sea's seed with kelp.Batch: n worlds of one scenario, each with its own
waves and gusts (seeds seed .. seed + n - 1), flown by the scenario's controllers on all CPUs;
prints the spread of the ROV's path error, the boat's distance and the tether's peak force.

    PYTHONPATH=<build>/python python3 examples/python/monte_carlo.py [scenario.json]
        [--n 32] [--seed 1] [--duration S] [--threads T] [--hist mc.png]
"""
import argparse
import json
import time

import numpy as np

import kelp


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario", nargs="?", help="scenario file (default: the embedded run)")
    p.add_argument("--n", type=int, default=32, help="worlds (seeds)")
    p.add_argument("--seed", type=int, default=1, help="seed of the first world")
    p.add_argument("--duration", type=float, help="simulated time [s] (default: the scenario's)")
    p.add_argument("--threads", type=int, help="threads (default: one per CPU)")
    p.add_argument("--hist", help="also write a histogram of the path errors (PNG)")
    a = p.parse_args()

    scenario = {}
    if a.scenario:
        with open(a.scenario, encoding="utf-8") as f:
            scenario = json.load(f)
    if a.duration is not None:
        scenario["duration"] = a.duration
    batch = kelp.Batch(scenario, n=a.n, seed=a.seed, threads=a.threads, control_period=0.1)
    steps = round(batch.summary(0)["scenario"]["duration"] / 0.1)
    wall = time.perf_counter()
    peak = np.zeros(batch.n)
    for _ in range(steps):  # step by step to follow the peak force between the summaries' samples
        batch.step()
        peak = np.maximum(peak, batch.tension.max(axis=1))
    wall = time.perf_counter() - wall
    summaries = [batch.summary(i) for i in range(batch.n)]
    rov = np.array([s["auv"]["rms_path_error_m"] for s in summaries])
    boat = np.array([s["asv"]["rms_distance_to_auv_m"] for s in summaries])
    failed = [i for i in range(batch.n) if batch.terminated[i]]
    print(f"{batch.n} worlds x {steps} steps of 0.1 s on {batch.threads} threads in {wall:.2f} s "
          f"({batch.n * steps * 10 / wall:.0f} world-steps of 10 ms per second)")
    for name, x, unit in (("ROV RMS path error", rov, "m"), ("boat RMS distance to ROV", boat, "m"),
                          ("peak tether force", peak, "N")):
        print(f"{name:26s} mean {x.mean():7.3f} {unit}  std {x.std(ddof=1) if len(x) > 1 else 0:7.3f}"
              f"  min {x.min():7.3f}  max {x.max():7.3f}  (worst seed {a.seed + int(x.argmax())})")
    if failed:
        print("terminated:", [(a.seed + i, batch.error(i)) for i in failed])
    if a.hist:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.hist(rov, bins=max(5, batch.n // 4))
        ax.set(xlabel="ROV RMS path error [m]", ylabel="seeds",
               title=f"{batch.n} seeds of the sea")
        fig.tight_layout()
        fig.savefig(a.hist, dpi=100)
        print(f"wrote {a.hist}")


if __name__ == "__main__":
    main()
