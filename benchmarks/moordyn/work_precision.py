#!/usr/bin/env python3
"""Work-precision figure and table from kelp-moordyn-work-precision's CSV.

Usage: work_precision.py work_precision.csv [--png work_precision.png] [--target 1e-3]

Plots, per case, the end-B tension error (relative RMS against the converged reference) against
the CPU time per simulated second for every (code, scheme), and prints a Markdown table of the
points and, per case, the cheapest CPU time at which each code reaches the target error: along
each scheme's curve (points ordered by dt) the first crossing of the target, interpolated
linearly in log-log between the two points that bracket it; a code's figure is the cheapest of
its schemes. "X = MoorDyn / kelp" is the ratio of the two at the target.
"""
import argparse
import csv
import math
from collections import defaultdict


def crossing_cost(points, target):
    """CPU time at which the curve (dt descending) first reaches `target`, or None."""
    pts = sorted(points, key=lambda p: -p[0])  # largest dt (cheapest) first
    prev = None
    for dt, cost, err in pts:
        if err is None or not math.isfinite(err):
            prev = None
            continue
        if err <= target:
            if prev is None:
                return cost  # already below at its cheapest stable point
            c0, e0 = prev
            if e0 == err:
                return cost
            f = (math.log(target) - math.log(e0)) / (math.log(err) - math.log(e0))
            return math.exp(math.log(c0) + f * (math.log(cost) - math.log(c0)))
        prev = (cost, err)
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--png", default="work_precision.png")
    ap.add_argument("--target", type=float, default=1e-3)
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    curves = defaultdict(list)  # (case, code, scheme) -> [(dt, cost, err)]
    for r in rows:
        err = float(r["rel_rms_error"]) if r["stable"] == "1" else None
        curves[(r["case"], r["code"], r["scheme"])].append(
            (float(r["dt_s"]), float(r["cpu_s_per_sim_s"]), err))
    cases = list(dict.fromkeys(r["case"] for r in rows))

    print("| case | code | scheme | dt [ms] | CPU s per simulated s | real-time factor | "
          "end-B tension error (rel. RMS) |")
    print("|---|---|---|---|---|---|---|")
    for (case, code, scheme), pts in curves.items():
        for dt, cost, err in sorted(pts, key=lambda p: -p[0]):
            e = f"{err:.2e}" if err is not None else "unstable"
            print(f"| {case} | {code} | {scheme} | {dt * 1e3:.4g} | {cost:.3g} | "
                  f"{1 / cost:.3g} | {e} |")
    print()
    print(f"At equal accuracy ({a.target:g} relative RMS of the end-B tension):")
    print()
    print("| case | cheapest MoorDyn: scheme, CPU s/s | cheapest kelp: scheme, CPU s/s | "
          "X = MoorDyn / kelp |")
    print("|---|---|---|---|")
    for case in cases:
        best = {}
        for (c, code, scheme), pts in curves.items():
            if c != case:
                continue
            cost = crossing_cost(pts, a.target)
            if cost is not None and (code not in best or cost < best[code][1]):
                best[code] = (scheme, cost)
        md, kp = best.get("moordyn"), best.get("kelp")
        x = f"{md[1] / kp[1]:.2f}" if md and kp else "n/a"
        fmt = lambda b: f"{b[0]}, {b[1]:.3g}" if b else "not reached"
        print(f"| {case} | {fmt(md)} | {fmt(kp)} | {x} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.6), squeeze=False)
    style = {("moordyn", "RK2"): ("tab:gray", "s--"), ("moordyn", "RK4"): ("black", "s-"),
             ("kelp", "RK4"): ("tab:blue", "o-"), ("kelp", "implicit_euler"): ("tab:orange", "^-"),
             ("kelp", "BDF2"): ("tab:green", "v-")}
    for ax, case in zip(axes[0], cases):
        for (c, code, scheme), pts in curves.items():
            if c != case:
                continue
            pts = [p for p in sorted(pts, key=lambda p: -p[0]) if p[2] is not None]
            if not pts:
                continue
            colour, marker = style.get((code, scheme), (None, "x-"))
            ax.loglog([p[1] for p in pts], [p[2] for p in pts], marker, color=colour,
                      label=f"{'MoorDyn' if code == 'moordyn' else 'kelp'} {scheme}", ms=4)
        ax.axhline(a.target, color="red", lw=0.8, ls=":")
        ax.set_ylim(top=1.0)  # errors above 1 (a scheme going unstable) are off the figure
        ax.set_title(case)
        ax.set_xlabel("CPU seconds per simulated second")
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].set_ylabel("end-B tension error (relative RMS)")
    axes[0][-1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"\nwrote {a.png}")


if __name__ == "__main__":
    main()
