#!/usr/bin/env python3
"""Plots a kelp-tethered-pair run: plot_run.py OUTPUT_DIR.

Reads timeseries.csv and nodes.csv from OUTPUT_DIR and writes there: trajectories.png (top view
with the AUV's targets), depth.png, tension.png, errors.png and tether.png (side view of the
tether at a few instants). Needs Debian's python3-matplotlib (and nothing else).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    cols = {name: [] for name in header}
    for row in data:
        for name, value in zip(header, row):
            cols[name].append(float(value))
    return cols


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=100)
    plt.close(fig)


def main(out):
    ts = read_columns(os.path.join(out, "timeseries.csv"))
    nodes = read_columns(os.path.join(out, "nodes.csv"))
    t = ts["t"]

    # Top view, NED: east to the right, north up.
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot(ts["asv_y"], ts["asv_x"], label="BlueBoat (ASV)")
    ax.plot(ts["auv_y"], ts["auv_x"], label="BlueROV2 Heavy (AUV)")
    targets = sorted(set(zip(ts["auv_target_y"], ts["auv_target_x"])), key=lambda p: p)
    ax.plot([p[0] for p in targets], [p[1] for p in targets], "k+", ms=12, label="waypoints")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend()
    ax.set_title("Trajectories (top view)")
    save(fig, out, "trajectories.png")

    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t, ts["auv_z"], label="AUV depth")
    ax.plot(t, ts["auv_target_z"], "k--", label="target")
    ax.plot(t, ts["asv_z"], label="ASV heave")
    ax.invert_yaxis()
    ax.set_xlabel("time [s]")
    ax.set_ylabel("depth (NED z) [m]")
    ax.legend()
    save(fig, out, "depth.png")

    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t, ts["tension_asv"], label="at the ASV")
    ax.plot(t, ts["tension_auv"], label="at the AUV")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tether force [N]")
    ax.legend()
    save(fig, out, "tension.png")

    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t, ts["auv_error"], label="AUV: distance from the survey path")
    ax.plot(t, ts["asv_error"], label="ASV: horizontal distance from the AUV")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("error [m]")
    ax.legend()
    save(fig, out, "errors.png")

    # Side view: horizontal distance along the line's start direction vs depth, a few snapshots.
    times = sorted(set(nodes["t"]))
    picks = [times[int(i * (len(times) - 1) / 4)] for i in range(5)] if len(times) > 1 else times
    fig, ax = plt.subplots(figsize=(7, 4))
    for tp in picks:
        idx = [i for i, tt in enumerate(nodes["t"]) if tt == tp]
        x = [nodes["x"][i] for i in idx]
        y = [nodes["y"][i] for i in idx]
        z = [nodes["z"][i] for i in idx]
        s = [((xi - x[0]) ** 2 + (yi - y[0]) ** 2) ** 0.5 for xi, yi in zip(x, y)]
        ax.plot(s, z, "o-", ms=2, label="t = %.0f s" % tp)
    ax.invert_yaxis()
    ax.set_xlabel("horizontal distance from the boat's end [m]")
    ax.set_ylabel("depth [m]")
    ax.legend()
    ax.set_title("Tether (side view)")
    save(fig, out, "tether.png")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_run.py OUTPUT_DIR")
    main(sys.argv[1])
