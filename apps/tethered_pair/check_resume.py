#!/usr/bin/env python3
"""kelp-tethered-pair killed and resumed from its checkpoint (CTest: example_tethered_pair_resume;
docs/checkpoints.md).

  check_resume.py PROGRAM SCENARIO_DIR WORK

For each scenario, a reference run goes uninterrupted; a second run with --checkpoint-every is
SIGKILLed at random moments, each time resumed with --resume DIR (started again from nothing
when a kill came before its first checkpoint), then left to finish. Its timeseries.csv,
nodes.csv, events.csv and run.mcap must equal the reference's byte for byte, and its
summary.json too less the wall time (wall_s, realtime_factor); no checkpoint or temporary file is
left. The scenarios: the embedded default (600 s, 20 kills), the winch dive, navigation from
sensors and the pile wrap (120 s, 4 kills each). The delays come from a seed, printed, that
KELP_RESUME_TEST_SEED replays.

Then the refusals, each leaving the directory as it was: a checkpoint truncated, one with a
flipped bit, one of another scenario (--seed given again), and none at all end the program with
status 3 and a message that names the problem.
"""

import hashlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from stop_checks import check, failures  # noqa: E402


def digest(d):
    """The content of every file of a run directory (summary.json less its wall time)."""
    out = {}
    for name in sorted(os.listdir(d)):
        path = os.path.join(d, name)
        if name == "summary.json":
            with open(path) as f:
                s = json.load(f)
            s.pop("wall_s", None)
            s.pop("realtime_factor", None)
            out[name] = json.dumps(s, sort_keys=True)
        elif name != "replay.html":  # the page embeds summary.json, wall time and all
            with open(path, "rb") as f:
                out[name] = hashlib.sha256(f.read()).hexdigest()
    return out


def run(args, timeout=300):
    return subprocess.run(args, capture_output=True, text=True, timeout=timeout)


def killed_and_resumed(program, base, d, kills, rng, wall):
    """Runs `base` in `d` with checkpoints, SIGKILLed `kills` times, each at a random moment in
    the first 1.5 `wall` / `kills` s of a start (`wall`: the reference's wall time, so that the
    kills spread over the whole run), resumed after each; returns the kills that landed."""
    landed = 0
    for _ in range(kills):
        resuming = os.path.exists(os.path.join(d, "checkpoint.bin"))
        args = [program, "--resume", d, "--quiet", "--no-plots"] if resuming else \
            base + ["--out", d, "--checkpoint-every", "2"]
        p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0.0, 1.5 * wall / kills))
        if p.poll() is not None:  # finished before the kill
            err = p.stderr.read()
            check(p.returncode == 0, "%s: status %s before its kill: %s" % (d, p.returncode, err))
            return landed
        p.send_signal(signal.SIGKILL)
        p.wait()
        p.stderr.close()
        landed += 1
    if os.path.exists(os.path.join(d, "checkpoint.bin")):
        r = run([program, "--resume", d, "--quiet", "--no-plots"])
    else:
        r = run(base + ["--out", d, "--checkpoint-every", "2"])
    check(r.returncode == 0, "%s: the last resume ended with status %s: %s"
          % (d, r.returncode, r.stderr))
    return landed


def main():
    program, scenarios, work = sys.argv[1:]
    seed = int(os.environ.get("KELP_RESUME_TEST_SEED", random.randrange(1 << 30)))
    print("check_resume: seed %d (KELP_RESUME_TEST_SEED=%d replays the delays)" % (seed, seed))
    rng = random.Random(seed)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    sensors = os.path.join(work, "sensors.json")
    with open(sensors, "w") as f:
        json.dump({"sea": "moderate", "navigation": {"mode": "sensors", "seed": 11}}, f)
    cases = [
        ("default", [], 600, 20),
        ("winch", ["--scenario", os.path.join(scenarios, "winch_dive.json")], 120, 4),
        ("sensors", ["--scenario", sensors], 120, 4),
        ("pile", ["--scenario", os.path.join(scenarios, "pile_wrap.json")], 120, 4),
    ]
    for name, scenario, duration, kills in cases:
        base = [program] + scenario + ["--duration", str(duration), "--quiet", "--no-plots"]
        ref = os.path.join(work, name + "_ref")
        t0 = time.monotonic()
        r = run(base + ["--out", ref])
        wall = time.monotonic() - t0
        if not check(r.returncode == 0, "%s: the reference run failed: %s" % (name, r.stderr)):
            continue
        cut = os.path.join(work, name + "_cut")
        landed = killed_and_resumed(program, base, cut, kills, rng, wall)
        a, b = digest(ref), digest(cut)
        check(sorted(a) == sorted(b), "%s: files %s, the reference's %s" % (name, sorted(b), sorted(a)))
        for f in a:
            check(a[f] == b.get(f), "%s: %s differs from the uninterrupted run's" % (name, f))
        print("%s: %d s simulated, %d of %d kills landed (reference %.2f s wall), files equal: %s"
              % (name, duration, landed, kills, wall, a == b))

    # Refusals: status 3, a message, nothing changed.
    d = os.path.join(work, "refused")
    r = run([program, "--duration", "60", "--quiet", "--no-plots", "--out", d,
             "--checkpoint-every", "1"])
    check(r.returncode == 0, "the run for the refusals failed: %s" % r.stderr)
    # A completed run leaves no checkpoint: stop one with SIGTERM to get one.
    p = subprocess.Popen([program, "--duration", "7200", "--quiet", "--no-plots", "--out", d,
                          "--checkpoint-every", "1"], stderr=subprocess.PIPE, text=True)
    cp = os.path.join(d, "checkpoint.bin")
    deadline = time.monotonic() + 60
    while not os.path.exists(cp) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.2)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    check(p.returncode == 143 and "--resume" in err,
          "SIGTERM with checkpoints: status %s, %r" % (p.returncode, err))
    with open(cp, "rb") as f:
        good = f.read()
    for what, bytes_, extra, message in [
            ("truncated", good[:len(good) // 2], [], "truncated"),
            ("a flipped bit", good[:100] + bytes([good[100] ^ 4]) + good[101:], [], "checksum mismatch"),
            ("another scenario", good, ["--seed", "99"], "another scenario")]:
        with open(cp, "wb") as f:
            f.write(bytes_)
        before = digest(d)
        r = run([program, "--resume", d, "--quiet", "--no-plots"] + extra)
        check(r.returncode == 3 and message in r.stderr,
              "%s: status %s (expected 3), %r" % (what, r.returncode, r.stderr))
        check(digest(d) == before, "%s: the refused resume changed the directory" % what)
    os.remove(cp)
    r = run([program, "--resume", d, "--quiet", "--no-plots"])
    check(r.returncode == 3 and "no checkpoint" in r.stderr,
          "no checkpoint: status %s (expected 3), %r" % (r.returncode, r.stderr))
    if failures:
        print("check_resume: %d failure(s)" % len(failures), file=sys.stderr)
        return 1
    print("check_resume: PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
