#!/usr/bin/env python3
"""The Python overhead of kelp.System.step over the C++ call it makes.

Times N steps of the default system (kelp.System(): the paper's 10 m tether in the moderate sea,
dt = 10 ms) from Python, one System.step call each, and the same N steps in one C++ loop
(kelp._kelp._step_loop: kelp::system::step, no Python), both from copies of the same state (so
the same work), in R alternating pairs; the overhead per step is the median over the pairs of
(Python - C++) / N. Pairs of short blocks keep a busy machine's drift out of the difference.

    PYTHONPATH=build/dev/python /usr/bin/python3 benchmarks/python_step_overhead.py
"""

import argparse
import statistics
import time

import kelp


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=201)
    args = ap.parse_args()
    system = kelp.System()
    u = system.inputs()
    u.auv_commands[:] = 0.1
    start = system.initial_state()
    for _ in range(100):  # past the first steps (history, kept Newton matrix)
        system.step(start, u, 0.01)
    step = system.step
    py_times, cpp_times = [], []
    for _ in range(args.repeats):
        x = start.copy()
        t0 = time.perf_counter()
        for _ in range(args.steps):
            step(x, u, 0.01)
        py_times.append(time.perf_counter() - t0)
        x = start.copy()
        cpp_times.append(kelp._kelp._step_loop(system, x, u, 0.01, args.steps))
    py = statistics.median(py_times) / args.steps
    cpp = statistics.median(cpp_times) / args.steps
    diffs = sorted((a - b) / args.steps for a, b in zip(py_times, cpp_times))
    q = len(diffs) // 4
    print(f"System.step from Python: {py * 1e6:.2f} us/step; the C++ loop: {cpp * 1e6:.2f} "
          f"us/step; Python overhead: {statistics.median(diffs) * 1e6:.2f} us/step (median of "
          f"{args.repeats} pairs of {args.steps} steps; quartiles {diffs[q] * 1e6:.2f} to "
          f"{diffs[-q - 1] * 1e6:.2f} us)")


if __name__ == "__main__":
    main()
