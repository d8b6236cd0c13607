#!/usr/bin/env python3
"""Runs a scenario from Python and plots it with matplotlib: the ROV's and the boat's tracks seen
from above, the ROV's depth and the tether's end forces against time.

    PYTHONPATH=<build>/python python3 examples/python/scenario_plot.py [scenario.json]
        [--duration S] [--seed N] [--out run.png]

The world is kelp.Batch with one world, flown by the scenario's controllers (the run
kelp-tethered-pair makes), sampled every 0.1 s through the batch's numpy views.
"""
import argparse
import json

import numpy as np

import kelp


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenario", nargs="?", help="scenario file (default: the embedded run)")
    p.add_argument("--duration", type=float, help="simulated time [s] (default: the scenario's)")
    p.add_argument("--seed", type=int, default=1, help="the sea's seed")
    p.add_argument("--out", default="scenario_plot.png", help="the figure (PNG)")
    a = p.parse_args()

    scenario = {}
    if a.scenario:
        with open(a.scenario, encoding="utf-8") as f:
            scenario = json.load(f)
    if a.duration is not None:
        scenario["duration"] = a.duration
    world = kelp.Batch(scenario, n=1, seed=a.seed, threads=1, control_period=0.1)
    steps = round(world.summary(0)["scenario"]["duration"] / 0.1)

    # The views are read once; they change in place at every step.
    rov, boat, tension, t = world.auv_position, world.asv_position, world.tension, world.time
    log = {"t": [], "rov": [], "boat": [], "tension": []}
    for _ in range(steps):
        world.step()
        log["t"].append(t[0])
        log["rov"].append(rov[0].copy())
        log["boat"].append(boat[0].copy())
        log["tension"].append(tension[0].copy())
    time_s = np.array(log["t"])
    rov_xyz, boat_xyz, forces = (np.array(log[k]) for k in ("rov", "boat", "tension"))
    summary = world.summary(0)
    print(f"{time_s[-1]:.1f} s simulated: ROV RMS path error "
          f"{summary['auv']['rms_path_error_m']:.2f} m, boat RMS distance "
          f"{summary['asv']['rms_distance_to_auv_m']:.2f} m, max tension "
          f"{summary['tether']['max_tension_n']:.1f} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, depth, pull) = plt.subplots(1, 3, figsize=(14, 4.5))
    # NED: east (y) to the right, north (x) up.
    top.plot(rov_xyz[:, 1], rov_xyz[:, 0], label="ROV")
    top.plot(boat_xyz[:, 1], boat_xyz[:, 0], label="boat")
    top.set(xlabel="east [m]", ylabel="north [m]", title="tracks", aspect="equal")
    top.legend()
    depth.plot(time_s, rov_xyz[:, 2])
    depth.invert_yaxis()
    depth.set(xlabel="time [s]", ylabel="depth [m]", title="ROV depth")
    pull.plot(time_s, forces[:, 0], label="at the boat")
    pull.plot(time_s, forces[:, 1], label="at the ROV")
    pull.set(xlabel="time [s]", ylabel="force [N]", title="tether end forces")
    pull.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
