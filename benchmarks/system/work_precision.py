#!/usr/bin/env python3
"""Work-precision figure and table from kelp-system-work-precision's CSV.

Usage: work_precision.py system_work_precision.csv [--png system_work_precision.png]
                         [--targets 1e-2,1e-3,1e-4]

Plots, per case, the error of the tether's force on the ROV (relative RMS against the converged
reference) against the CPU time per simulated second for every scheme, and prints a Markdown
table of the points and, per case and target, each scheme's cost there and the cheapest: along
each scheme's curve (points ordered by dt) the first crossing of the target, interpolated in
log-log between the two points that bracket it (benchmarks/moordyn/work_precision.py's rule).
"""
import argparse
import csv
import importlib.util
import os
import sys
from collections import defaultdict

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
# The crossing rule of the tether's figure, loaded by path (both scripts are work_precision.py).
_spec = importlib.util.spec_from_file_location(
    "moordyn_work_precision",
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "moordyn", "work_precision.py"))
_moordyn = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_moordyn)
crossing_cost = _moordyn.crossing_cost


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--png", default="system_work_precision.png")
    ap.add_argument("--targets", default="1e-2,1e-3,1e-4")
    a = ap.parse_args()
    targets = [float(t) for t in a.targets.split(",")]
    rows = list(csv.DictReader(open(a.csv)))
    curves = defaultdict(list)  # (case, scheme) -> [(dt, cost, err, position, newton, tether_dt)]
    for r in rows:
        if r["scheme"] == "reference_check":
            continue
        stable = r["stable"] == "1"
        err = float(r["force_rel_rms"]) if stable else None
        pos = float(r["position_max_m"]) if stable else None
        curves[(r["case"], r["scheme"])].append(
            (float(r["dt"]), float(r["cpu_per_simulated_s"]), err, pos,
             float(r["newton_per_step"]), float(r["tether_dt"])))
    cases = list(dict.fromkeys(r["case"] for r in rows))

    for r in rows:
        if r["scheme"] == "reference_check":
            print(f"{r['case']}: the reference at twice its step differs from it by "
                  f"{float(r['force_rel_rms']):.2e} (force, relative RMS) and "
                  f"{float(r['position_max_m']):.2e} m (ROV position)")
    print()
    print("| case | scheme | dt [ms] | tether sub-step [ms] | CPU s per simulated s | "
          "real-time factor | force error (rel. RMS) | ROV position error [m] | "
          "Newton per step |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (case, scheme), pts in curves.items():
        for dt, cost, err, pos, newton, tdt in sorted(pts, key=lambda p: -p[0]):
            e = f"{err:.2e}" if err is not None else "unstable"
            p = f"{pos:.2e}" if pos is not None else ""
            print(f"| {case} | {scheme} | {dt * 1e3:.4g} | {tdt * 1e3:.3g} | {cost:.3g} | "
                  f"{1 / cost:.3g} | {e} | {p} | {newton:.2f} |")
    print()
    schemes = list(dict.fromkeys(scheme for (_, scheme) in curves))
    print("CPU seconds per simulated second at which each scheme reaches the target (relative "
          "RMS of the force on the ROV; — where none of its steps does):")
    print()
    print("| case | target | " + " | ".join(schemes) + " | cheapest (real-time factor) |")
    print("|---|---|" + "---|" * len(schemes) + "---|")
    for case in cases:
        for target in targets:
            costs = {}
            for scheme in schemes:
                pts = curves.get((case, scheme), [])
                cost = crossing_cost([(p[0], p[1], p[2]) for p in pts], target)
                if cost is not None:
                    costs[scheme] = cost
            cells = [f"{costs[s]:.3g}" if s in costs else "—" for s in schemes]
            best = min(costs, key=costs.get) if costs else None
            cheapest = f"{best} ({1 / costs[best]:.3g}×)" if best else "not reached"
            print(f"| {case} | {target:g} | " + " | ".join(cells) + f" | {cheapest} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.6), squeeze=False)
    style = {"bdf2": ("tab:green", "v-"), "bdf2_corrected": ("tab:green", "v--"),
             "implicit_euler": ("tab:orange", "^-"), "rk4": ("tab:blue", "o-"),
             "rk4_corrected": ("tab:blue", "o--")}
    for ax, case in zip(axes[0], cases):
        for (c, scheme), pts in curves.items():
            if c != case:
                continue
            pts = [p for p in sorted(pts, key=lambda p: -p[0]) if p[2] is not None]
            if not pts:
                continue
            colour, marker = style.get(scheme, (None, "x-"))
            ax.loglog([p[1] for p in pts], [p[2] for p in pts], marker, color=colour,
                      label=scheme, ms=4)
        for target in targets:
            ax.axhline(target, color="red", lw=0.8, ls=":")
        ax.set_title(case)
        ax.set_xlabel("CPU seconds per simulated second")
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].set_ylabel("force on the ROV: error (relative RMS)")
    axes[0][-1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"\nwrote {a.png}")


if __name__ == "__main__":
    main()
