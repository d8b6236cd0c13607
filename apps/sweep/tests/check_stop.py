#!/usr/bin/env python3
"""kelp-sweep stopped mid-way, then resumed (CTest: example_paper_sweep_stop).

  check_stop.py KELP_SWEEP WORK

A sweep of 4 runs of 60 s (one job, --keep-series) gets SIGTERM once its first result is stored:
exit status 143; status.json says "completed": false, lists the runs done (those with a stored
result), the one under way as interrupted (its series whole: CSV files ending on a full line,
summary.json "completed": false; no stored result) and the rest as not started. Run again, it
resumes: status 0, only the runs not done run, status.json "completed": true with every run done.
With --checkpoint-every, the interrupted run left runs/<hash>.checkpoint.bin and goes on from it
("resumed from its checkpoint at" the time it reached); its series and result equal those of the
same sweep run without a stop (less wall time), and no checkpoint is left. About 2 s of one core.
Before the clean stop, the first SIGTERM killed kelp-sweep (status -15, no status.json).
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "common"))
from stop_checks import check, check_csv, failures  # noqa: E402


def stored_hashes(out):
    return sorted(n[:-5] for n in os.listdir(os.path.join(out, "runs")) if n.endswith(".json"))


def main(program, work):
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    sweep = os.path.join(work, "stop.json")
    with open(sweep, "w") as f:
        json.dump({"base": {"duration": 60}, "axes": [{"path": "/sea", "values": ["moderate"]}],
                   "seeds": 4}, f)
    out = os.path.join(work, "out")
    args = [program, "--sweep", sweep, "--out", out, "--jobs", "1", "--keep-series", "--quiet",
            "--no-plot", "--checkpoint-every", "5"]
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    runs = os.path.join(out, "runs")
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and p.poll() is None:
        if os.path.isdir(runs) and any(n.endswith(".json") for n in os.listdir(runs)):
            break
        time.sleep(0.005)
    time.sleep(0.05)  # the second run under way (about 15 s of its 60 s)
    p.send_signal(signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=60)
    print(stdout.strip())
    print(stderr.strip())
    check(p.returncode == 143, "SIGTERM: exit status %s, expected 143" % p.returncode)
    try:
        with open(os.path.join(out, "status.json")) as f:
            status = json.load(f)
    except (OSError, ValueError) as e:
        check(False, "SIGTERM: no status.json (%s)" % e)
        status = {}
    print("status.json:", json.dumps(status))
    done = status.get("done", [])
    interrupted = status.get("interrupted", [])
    not_started = status.get("not_started", [])
    check(status.get("completed") is False, "status.json: completed is not false")
    check(status.get("stopped_by") == "SIGTERM", "status.json: stopped_by is not SIGTERM")
    check(len(done) >= 1 and len(done) + len(interrupted) + len(not_started) == 4 and
          len(interrupted) <= 1, "status.json: not 4 runs done, interrupted and not started")
    stored = sorted(n[:-5] for n in os.listdir(runs) if n.endswith(".json"))
    check(len(stored) == len(done), "%d results stored, %d runs done" % (len(stored), len(done)))
    for run in interrupted:
        d = os.path.join(runs, run["hash"])
        check(run["hash"] not in stored, "the interrupted run %s stored a result" % run["hash"])
        for name in ("timeseries.csv", "nodes.csv", "events.csv"):
            check_csv(os.path.join(d, name))  # the interrupted run's series: whole lines
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        check(s["completed"] is False and 0 <= s["simulated_s"] < 60 and
              abs(s["simulated_s"] - run["simulated_s"]) < 1e-9,
              "the interrupted run's summary.json: completed %r, simulated_s %r"
              % (s["completed"], s["simulated_s"]))
        check(run.get("checkpoint") is True and
              os.path.exists(os.path.join(runs, run["hash"] + ".checkpoint.bin")),
              "the interrupted run %s left no checkpoint" % run["hash"])

    # Resumed: only what was not done runs.
    r = subprocess.run(args, capture_output=True, text=True, timeout=120)
    print(r.stdout.strip())
    check(r.returncode == 0, "resumed: exit status %s\n%s" % (r.returncode, r.stderr))
    check("%d ran, %d reused" % (4 - len(done), len(done)) in r.stdout,
          "resumed: not %d ran, %d reused" % (4 - len(done), len(done)))
    try:
        with open(os.path.join(out, "status.json")) as f:
            status = json.load(f)
    except (OSError, ValueError) as e:
        status = {"error": str(e)}
    check(status.get("completed") is True and status.get("done") == [0, 1, 2, 3] and
          not status.get("interrupted") and not status.get("not_started"),
          "resumed: status.json %s" % json.dumps(status))
    for run in interrupted:
        check("resumed from its checkpoint at %.2f s" % run["simulated_s"] in r.stderr,
              "resumed: run %s did not go on from its checkpoint:\n%s" % (run["hash"], r.stderr))
    check(not [n for n in os.listdir(runs) if "checkpoint" in n],
          "resumed: checkpoints left in runs/: %s" % os.listdir(runs))

    # The same sweep without a stop: the same results and series, byte for byte.
    ref = os.path.join(work, "ref")
    r = subprocess.run([program, "--sweep", sweep, "--out", ref, "--jobs", "1", "--keep-series",
                        "--quiet", "--no-plot"], capture_output=True, text=True, timeout=120)
    check(r.returncode == 0, "uninterrupted: exit status %s\n%s" % (r.returncode, r.stderr))

    def without_wall(path):
        with open(path) as f:
            j = json.load(f)
        s = j.get("summary", j)
        s.pop("wall_s", None)
        s.pop("realtime_factor", None)
        return j

    for h in stored_hashes(ref):
        check(without_wall(os.path.join(runs, h + ".json")) ==
              without_wall(os.path.join(ref, "runs", h + ".json")),
              "run %s: its result differs from the uninterrupted sweep's" % h)
        for name in ("timeseries.csv", "nodes.csv", "events.csv"):
            with open(os.path.join(runs, h, name), "rb") as a, \
                    open(os.path.join(ref, "runs", h, name), "rb") as b:
                check(a.read() == b.read(), "run %s: %s differs from the uninterrupted sweep's"
                      % (h, name))
    if failures:
        print("check_stop: %d failures" % len(failures), file=sys.stderr)
        return 1
    print("check_stop: all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
