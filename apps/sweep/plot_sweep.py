#!/usr/bin/env python3
"""Draws a sweep's table like the paper's figure: plot_sweep.py DIR.

Reads DIR/table.csv (written by kelp-sweep) and writes DIR/errors.png: RMS position errors
against the first axis (the tether length in the paper's sweep), one panel per value of the
second axis (the sea state), one series per combination of the remaining axes (compensation
off/on), AUV and ASV errors in two rows, error bars one standard deviation over the seeds.
Needs Debian's python3-matplotlib.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METRICS = [("auv_rms_error_m", "AUV RMS error [m]"), ("asv_rms_error_m", "ASV RMS error [m]")]


def main(out):
    with open(os.path.join(out, "table.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    header = list(rows[0].keys())
    axes = header[:header.index("seeds")]
    if not axes:
        axes = ["(none)"]
        for r in rows:
            r["(none)"] = "0"
    x_axis = axes[0]
    panel_axis = axes[1] if len(axes) > 1 else None
    series_axes = axes[2:]
    panels = sorted({r[panel_axis] for r in rows}, key=rows_order(rows, panel_axis)) \
        if panel_axis else [None]
    fig, grid = plt.subplots(len(METRICS), len(panels), figsize=(4.2 * len(panels), 6.5),
                             squeeze=False, sharex=True)
    for col, panel in enumerate(panels):
        sub = [r for r in rows if panel is None or r[panel_axis] == panel]
        series = sorted({tuple(r[a] for a in series_axes) for r in sub})
        for row, (metric, label) in enumerate(METRICS):
            ax = grid[row][col]
            for k, key in enumerate(series):
                pts = [r for r in sub if tuple(r[a] for a in series_axes) == key]
                pts.sort(key=lambda r: float(r[x_axis]) if is_number(r[x_axis]) else r[x_axis])
                xs = [to_x(r[x_axis]) for r in pts]
                offset = 0.08 * (k - (len(series) - 1) / 2) * spacing(xs)
                name = ", ".join("%s = %s" % (a.split("/")[-1], v) for a, v in zip(series_axes, key))
                ax.errorbar([x + offset for x in xs], [float(r[metric + "_mean"]) for r in pts],
                            yerr=[float(r[metric + "_sd"]) for r in pts], marker="o", capsize=3,
                            label=name or None)
            if row == 0 and panel is not None:
                ax.set_title("%s = %s" % (panel_axis.split("/")[-1], panel))
            if col == 0:
                ax.set_ylabel(label)
            if row == len(METRICS) - 1:
                ax.set_xlabel(x_axis.split("/")[-1] + (" [m]" if x_axis == "/tether/length" else ""))
            ax.grid(alpha=0.3)
            if series_axes and row == 0:
                ax.legend(fontsize=8)
    fig.suptitle("Position errors, mean ± sd over %s seeds" % rows[0]["seeds"])
    fig.tight_layout()
    fig.savefig(os.path.join(out, "errors.png"), dpi=100)


def is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def to_x(s):
    return float(s) if is_number(s) else s


def spacing(xs):
    nums = sorted(x for x in xs if isinstance(x, float))
    gaps = [b - a for a, b in zip(nums, nums[1:]) if b > a]
    return min(gaps) if gaps else 1.0


def rows_order(rows, axis):
    order = []
    for r in rows:
        if r[axis] not in order:
            order.append(r[axis])
    return order.index


if __name__ == "__main__":
    main(sys.argv[1])
