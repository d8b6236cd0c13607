#!/usr/bin/env python3
"""Throughput of kelp.Batch and kelp.TetheredPairEnv on the default world (moderate sea, 20-segment
tether, propulsion, 10 ms system steps): worlds x steps per second of wall clock on 1 and 2
threads (the scaling), and environment steps (0.1 s control period, random actions) per CPU
second. Prints min / median over repetitions, interleaving the thread counts so that a change in
the machine's load hits both.

    PYTHONPATH=<build>/python python3 benchmarks/python/batch_env.py [--reps 5] [--n 8]
"""
import argparse
import os
import platform
import statistics
import time

import numpy as np

import kelp


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def batch_rate(n, threads, steps, calls=1):
    """World-steps of 10 ms per wall second and per CPU second of the process (all its threads),
    controllers flying, after a warm-up; `calls` step() calls of steps / calls steps each."""
    b = kelp.Batch(None, n=n, seed=1, threads=threads, control_period=0.01)
    b.step(50)
    t, c = time.perf_counter(), time.process_time()
    for _ in range(calls):
        b.step(steps // calls)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    return n * steps / wall, n * steps / cpu


def env_rate(steps):
    """Environment steps (0.1 s) per CPU second with random actions, Python included."""
    env = kelp.TetheredPairEnv(None, control_period=0.1)
    env.reset(seed=1)
    rng = np.random.default_rng(1)
    acts = rng.uniform(-0.3, 0.3, (steps, 6))
    t = time.process_time()
    for k in range(steps):
        _, _, terminated, truncated, _ = env.step(acts[k])
        if terminated or truncated:
            env.reset(seed=k)
    return steps / (time.process_time() - t)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--n", type=int, default=8, help="worlds")
    p.add_argument("--steps", type=int, default=500, help="batch steps of 10 ms per repetition")
    p.add_argument("--env-steps", type=int, default=1000)
    a = p.parse_args()
    print(f"{cpu_name()}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    rows = {k: [] for k in ("1 thread, wall", "2 threads, wall", "wall ratio 2/1",
                            "1 thread, per CPU s", "2 threads, per CPU s",
                            "2 threads, per CPU s, step(1) x 50", "CPU-time efficiency 2/1",
                            "env steps per CPU s")}
    for _ in range(a.reps):
        w1, c1 = batch_rate(a.n, 1, a.steps)
        w2, c2 = batch_rate(a.n, 2, a.steps)
        _, c2s = batch_rate(a.n, 2, a.steps, calls=50)
        rows["1 thread, wall"].append(w1)
        rows["2 threads, wall"].append(w2)
        rows["wall ratio 2/1"].append(w2 / w1)
        rows["1 thread, per CPU s"].append(c1)
        rows["2 threads, per CPU s"].append(c2)
        rows["2 threads, per CPU s, step(1) x 50"].append(c2s)
        rows["CPU-time efficiency 2/1"].append(c2 / c1)
        rows["env steps per CPU s"].append(env_rate(a.env_steps))
    print(f"batch of {a.n} worlds, {a.steps} steps of 10 ms per repetition, {a.reps} repetitions")
    for name, v in rows.items():
        print(f"{name:42s} min {min(v):10.2f}  median {statistics.median(v):10.2f}  "
              f"max {max(v):10.2f}")


if __name__ == "__main__":
    main()
