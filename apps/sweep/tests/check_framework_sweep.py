#!/usr/bin/env python3
"""sweeps/framework.json expands to the intended grid: check_framework_sweep.py KELP_SWEEP SWEEPS_DIR WORKDIR

Runs nothing (kelp-sweep --dry-run: the sweep is read, expanded and every run's scenario
validated, then listed). Checks that the set is the paper's framework as its Gazebo worlds run it
(README, "The paper's framework as it runs"): 3 chains x 2 survey depths x compensation off/on x
seeds 1-10 = 120 runs, each a rigid bead chain of whole 0.5 m links between the vehicles' origins,
no current, no wind, the FFT sea's Hs/Tp, the paper's controllers, one start for every length; and
that --dry-run writes nothing.
"""
import itertools
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


def main(program, sweeps, work):
    shutil.rmtree(work, ignore_errors=True)
    out = os.path.join(work, "out")
    p = subprocess.run([program, "--sweep", os.path.join(sweeps, "framework.json"), "--dry-run",
                        "--out", out], capture_output=True, text=True)
    check(p.returncode == 0, "dry run failed (%d): %s" % (p.returncode, p.stderr))
    check(not os.path.exists(out), "--dry-run wrote its output directory")
    lines = p.stdout.strip().split("\n")
    check(lines[-1] == "kelp-sweep: 120 runs (12 grid points x 10 seeds); dry run, nothing ran",
          "last line: " + lines[-1])
    runs = [json.loads(line) for line in lines[:-1]]
    check(len(runs) == 120, "%d runs listed, expected 120" % len(runs))

    # The grid: the first axis varies slowest, the seeds fastest.
    grid = list(itertools.product([3.5, 5.5, 10.5], [5, 2], [False, True]))
    expected = [(list(g), seed) for g in grid for seed in range(1, 11)]
    check([(r["point"], r["seed"]) for r in runs] == expected, "grid points and seeds differ")
    check([r["index"] for r in runs] == list(range(120)), "run indices are not 0..119")
    check(len({r["hash"] for r in runs}) == 120, "two runs share a scenario hash")

    for r in runs:
        s = r["scenario"]
        length, depth, compensation = r["point"]
        where = "run %d" % r["index"]
        t = s["tether"]
        check(t["kind"] == "bead_chain" and t["length"] == length,
              where + ": tether " + json.dumps(t))
        # 6, 10, 20 spheres give 7, 11, 21 links of 0.5 m between the vehicles' origins.
        check(round(length / 0.5) in (7, 11, 21) and length / 0.5 == round(length / 0.5),
              where + ": %g m is not 7, 11 or 21 whole 0.5 m links" % length)
        v = s["vehicles"]
        check(v["asv_attachment"] == [0, 0, 0] and v["auv_attachment"] == [0, 0, 0],
              where + ": the chain is not joined at the vehicles' origins")
        check(v.get("auv_start") == [-3, 0, 0.3], where + ": auv_start " + str(v.get("auv_start")))
        sea = s["sea"]
        check(isinstance(sea, dict), where + ": sea is a preset, not the FFT sea's values")
        if isinstance(sea, dict):
            check(sea["current_speed"] == 0 and sea["wind_speed"] == 0,
                  where + ": current or wind is not 0")
            check(sea["significant_height"] == 0.085 and sea["peak_period"] == 1.5,
                  where + ": Hs/Tp " + json.dumps(sea))
        check(s["mission"]["depth"] == depth, where + ": mission depth")
        check(s["control"]["compensation"] == compensation and s["control"]["preset"] == "paper",
              where + ": control")
        check(s["duration"] == 300 and s["seed"] == r["seed"], where + ": duration or seed")

    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("framework.json: 120 runs as intended")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]))
