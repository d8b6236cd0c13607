#!/usr/bin/env python3
"""The paper's default grid with the library's defaults: check_default_grid.py KELP_SWEEP WORKDIR

Runs kelp-sweep's embedded sweep (tether length 5/10/15 m x moderate/rough sea x compensation
off/on x seeds 1-5, 300 s each: 60 runs) on every core, and checks that
- every run completes: no tether step fails (the explicit fallback is off by default, so a step
  Newton's method cannot converge even in halves would fail its run, naming time and residual);
- every run's result reports the tether solver (`tether_solver`): BDF2 with the library's Newton
  budget, 0 explicit fallbacks, the worst residual within the tolerance, 30 000 steps;
- table.csv carries the solver's columns.
Prints the mean Newton iterations per step over the grid and the worst run's figures.
"""
import csv
import json
import os
import shutil
import subprocess
import sys

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what, flush=True)
    return cond


def main(program, work):
    shutil.rmtree(work, ignore_errors=True)
    p = subprocess.run([program, "--out", work, "--no-plot", "--quiet"], capture_output=True,
                       text=True)
    print(p.stdout + p.stderr, flush=True)
    check(p.returncode == 0, "the default grid failed (exit %d)" % p.returncode)
    runs = os.path.join(work, "runs")
    results = []
    if os.path.isdir(runs):
        for f in sorted(os.listdir(runs)):
            with open(os.path.join(runs, f)) as fh:
                results.append(json.load(fh))
    check(len(results) == 60, "%d results, expected 60" % len(results))
    newton, worst = 0.0, None
    for r in results:
        s = r["summary"]
        t = s.get("tether_solver")
        name = "run %d %s seed %d" % (r["index"], r["point"], r["seed"])
        if not check(t is not None, name + ": no tether_solver in its summary"):
            continue
        check(s["simulated_s"] == 300 and t["steps"] == 30000,
              name + ": %s s simulated in %d steps" % (s["simulated_s"], t["steps"]))
        check(t["integrator"] == "bdf2" and not t["explicit_fallback"],
              name + ": not the defaults (%s, explicit_fallback %s)"
              % (t["integrator"], t["explicit_fallback"]))
        check(t["explicit_fallbacks"] == 0, name + ": %d explicit fallbacks" % t["explicit_fallbacks"])
        check(t["worst_residual_m_s"] <= t["residual_tolerance_m_s"],
              name + ": worst residual %g above the tolerance %g"
              % (t["worst_residual_m_s"], t["residual_tolerance_m_s"]))
        newton += t["newton_iterations_per_step_mean"] / len(results)
        if worst is None or t["newton_iterations_per_step_max"] > worst[1]["newton_iterations_per_step_max"]:
            worst = (name, t)
    if worst:
        w = worst[1]
        print("tether solver over the grid (Newton budget %d): %.3f Newton iterations per step on "
              "average; worst run %s: %.3f on average, at most %d in one step, %d retried steps, "
              "%d explicit fallbacks"
              % (w["newton_budget"], newton, worst[0], w["newton_iterations_per_step_mean"],
                 w["newton_iterations_per_step_max"], w["retried_steps"], w["explicit_fallbacks"]))
    table = os.path.join(work, "table.csv")
    if check(os.path.exists(table), "no table.csv"):
        with open(table, newline="") as fh:
            rows = list(csv.DictReader(fh))
        check(len(rows) == 12, "table.csv has %d grid points, expected 12" % len(rows))
        for row in rows:
            check(float(row["worst_explicit_fallbacks"]) == 0 and
                  float(row["newton_iterations_per_step_mean"]) >= 1,
                  "table.csv row %s: solver columns %s / %s" % (
                      row.get("/tether/length"), row.get("newton_iterations_per_step_mean"),
                      row.get("worst_explicit_fallbacks")))
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("default grid: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
