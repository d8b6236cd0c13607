#!/usr/bin/env python3
"""kelp-tethered-pair stopped mid-run (CTest: example_tethered_pair_stop; docs/stopping-and-
resuming.md).

  check_stop.py PROGRAM NODE BAG_CHECK WORK [--fleet SCENARIO] [--replay KELP_REPLAY]

A run of 7200 s is started and stopped after a random short time (its seed printed, so that a
failure can be replayed with KELP_STOP_TEST_SEED):

1. SIGTERM: exit status 143; timeseries.csv, nodes.csv and events.csv end with a newline and
   every row has its header's column count; run.mcap has its summary and footer (BAG_CHECK closed:
   @mcap/core's indexed reader); summary.json says "completed": false and a simulated_s > 0, the
   time of the last row; no temporary file left.
2. SIGKILL: the CSV files as above; run.mcap without a footer, read by @mcap/core's stream reader
   up to its last completed chunk, every chunk with its message indexes (BAG_CHECK killed). The
   kill is SIGSTOP then SIGKILL: the process dies at an arbitrary instant in its own code, never
   while the kernel copies one of its writes (a window the library cannot close, documented in
   kelp/sim/run_log.hpp).
3. With --fleet: a fleet run (kelp/sim/fleet_run.hpp) stopped by SIGINT: exit status 130, its CSV
   files whole, summary.json "completed": false.
4. With --replay: kelp-replay on the stopped run's directory, SIGTERM'd at once (0-50 ms after its
   handler is installed, seen in /proc/PID/status): exit status 143 and no page (or, had it
   finished first, status 0 and a whole page).

Every run is stopped once its run.mcap holds a few chunks (a simulated minute or two, a fraction
of a second of one core). On the code before the clean stop, 1 fails (killed by the signal,
status -15), 2 fails (CSV lines and the last chunk's message index cut by the stdio buffers) and
so do 3 and 4.
"""

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
from stop_checks import check, check_csv, failures  # noqa: E402


def wait_for_size(path, size, proc, timeout=60.0):
    """Waits until `path` holds `size` bytes (the run is under way)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            return False
        try:
            if os.path.getsize(path) >= size:
                return True
        except OSError:
            pass
        time.sleep(0.005)
    return False


def wait_for_handler(proc, signum, timeout=60.0):
    """Waits until `proc` catches `signum` (its handler is installed: the SigCgt mask of
    /proc/PID/status) or has ended. A signal sent before that, while the loader and the static
    initialisers run, takes its default action: the process ends by it with nothing written, which
    no program can prevent."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            with open("/proc/%d/status" % proc.pid) as f:
                caught = next(int(line.split()[1], 16) for line in f if line.startswith("SigCgt:"))
            if caught >> (signum - 1) & 1:
                return
        except (OSError, StopIteration):
            pass
        time.sleep(0.0005)


def default_signals():
    """In the child: SIGINT as at a terminal. A shell's background job (and so CTest started as
    one) has SIGINT ignored, and a program started so keeps ignoring it (kelp/sim/stop.hpp)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(args, watch, size, rng):
    """Starts the program and returns it once `watch` holds `size` bytes and a random extra
    0-0.3 s has passed."""
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=default_signals)
    if not wait_for_size(watch, size, p):
        p.kill()
        out, err = p.communicate()
        raise SystemExit("FAIL: %s did not write %d bytes of %s (status %s):\n%s%s"
                         % (args[0], size, watch, p.returncode, out, err))
    time.sleep(rng.uniform(0.0, 0.3))
    return p


def check_bag(node, bag_check, mode, path):
    r = subprocess.run([node, bag_check, mode, path], capture_output=True, text=True)
    sys.stderr.write(r.stderr)
    check(r.returncode == 0, "run.mcap (%s): @mcap/core's check failed" % mode)
    return json.loads(r.stdout) if r.returncode == 0 else None


def no_temporaries(d):
    left = [f for f in os.listdir(d) if ".tmp" in f]
    check(not left, "temporary files left in %s: %s" % (d, left))


def main():
    args = sys.argv[1:]
    opts = {}
    for flag in ("--fleet", "--replay"):
        if flag in args:
            i = args.index(flag)
            opts[flag] = args[i + 1]
            del args[i:i + 2]
    program, node, bag_check, work = args
    seed = int(os.environ.get("KELP_STOP_TEST_SEED", random.randrange(1 << 30)))
    print("check_stop: seed %d (KELP_STOP_TEST_SEED=%d replays the delays)" % (seed, seed))
    rng = random.Random(seed)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    long_run = [program, "--duration", "7200", "--seed", "4", "--no-plots", "--quiet"]
    chunks = 3 << 20  # run.mcap past three 1 MiB chunks

    # 1. SIGTERM: a clean stop.
    d = os.path.join(work, "sigterm")
    p = start(long_run + ["--out", d], os.path.join(d, "run.mcap"), chunks, rng)
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=60)
    print(err.strip())
    check(p.returncode == 143, "SIGTERM: exit status %s, expected 143" % p.returncode)
    rows, last = check_csv(os.path.join(d, "timeseries.csv"))
    check_csv(os.path.join(d, "nodes.csv"))
    check_csv(os.path.join(d, "events.csv"))
    bag = check_bag(node, bag_check, "closed", os.path.join(d, "run.mcap"))
    try:
        with open(os.path.join(d, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        summary = {}
        check(False, "SIGTERM: no readable summary.json (%s)" % e)
    t = summary.get("simulated_s", 0)
    check(summary.get("completed") is False, "SIGTERM: summary.json's completed is %r, expected "
          "false" % summary.get("completed"))
    check(0 < t < 7200, "SIGTERM: summary.json's simulated_s %r is not in (0, 7200)" % t)
    if last is not None:
        check(0 <= t - float(last[0]) < 0.1 + 1e-6,
              "SIGTERM: the last row (t = %s) is not the last sample before %s s" % (last[0], t))
    if bag is not None:
        check(abs(bag["last_log_time_s"] - float(last[0])) < 1e-6 if last else False,
              "SIGTERM: run.mcap's last message (%s s) is not the last row's" % bag["last_log_time_s"])
    no_temporaries(d)
    print("SIGTERM: status %s, %d rows to t = %s s, run.mcap %s" % (p.returncode, rows, t, bag))

    # 2. SIGKILL (at an instant in the program's own code: SIGSTOP, then SIGKILL).
    d = os.path.join(work, "sigkill")
    p = start(long_run + ["--out", d], os.path.join(d, "run.mcap"), chunks, rng)
    p.send_signal(signal.SIGSTOP)
    p.send_signal(signal.SIGKILL)
    p.communicate(timeout=60)
    check(p.returncode == -signal.SIGKILL, "SIGKILL: status %s" % p.returncode)
    rows, last = check_csv(os.path.join(d, "timeseries.csv"))
    check_csv(os.path.join(d, "nodes.csv"))
    check_csv(os.path.join(d, "events.csv"))
    bag = check_bag(node, bag_check, "killed", os.path.join(d, "run.mcap"))
    # The CSV files are written out at least once a simulated second (and a row), run.mcap a
    # chunk at a time (about half a simulated minute): the bag ends at most 1.1 s after the rows.
    if bag is not None and last is not None:
        check(bag["last_log_time_s"] <= float(last[0]) + 1.1 + 1e-6,
              "SIGKILL: run.mcap's messages reach %s s, the rows only %s s: a CSV file was not "
              "written out for over a simulated second" % (bag["last_log_time_s"], last[0]))
    check(not os.path.exists(os.path.join(d, "summary.json")), "SIGKILL: a summary.json")
    print("SIGKILL: %d whole rows to t = %s s, run.mcap %s" % (rows, last[0] if last else None, bag))

    # 3. A fleet run, SIGINT.
    if "--fleet" in opts:
        d = os.path.join(work, "fleet")
        p = start([program, "--scenario", opts["--fleet"], "--duration", "7200", "--no-plots",
                   "--quiet", "--out", d], os.path.join(d, "run.mcap"), 1 << 20, rng)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
        print(err.strip())
        check(p.returncode == 130, "fleet, SIGINT: exit status %s, expected 130" % p.returncode)
        rows, last = check_csv(os.path.join(d, "timeseries.csv"))
        check_csv(os.path.join(d, "nodes.csv"))
        check_bag(node, bag_check, "closed", os.path.join(d, "run.mcap"))
        try:
            with open(os.path.join(d, "summary.json")) as f:
                summary = json.load(f)
        except (OSError, ValueError):
            summary = {}
        check(summary.get("completed") is False and 0 < summary.get("simulated_s", 0) < 7200,
              "fleet, SIGINT: summary.json's completed %r, simulated_s %r"
              % (summary.get("completed"), summary.get("simulated_s")))
        no_temporaries(d)
        print("fleet, SIGINT: status %s, %d rows to t = %s s" % (p.returncode, rows,
                                                               summary.get("simulated_s")))

    # 4. kelp-replay, SIGTERM'd at once: nothing written, or a whole page. Once its handler is
    # installed: a signal in the program's first milliseconds (seed 1055009337: 2 ms) killed it
    # before main() ran, status -15.
    if "--replay" in opts:
        d = os.path.join(work, "sigterm")
        page = os.path.join(work, "replay_stopped.html")
        p = subprocess.Popen([opts["--replay"], d, "--out", page], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, preexec_fn=default_signals)
        wait_for_handler(p, signal.SIGTERM)
        time.sleep(rng.uniform(0.0, 0.05))
        p.send_signal(signal.SIGTERM)
        out, err = p.communicate(timeout=60)
        print(err.strip())
        if p.returncode == 0:  # it was done before the signal
            with open(page, "rb") as f:
                check(f.read().rstrip().endswith(b"</html>"), "kelp-replay: a page cut short")
        else:
            check(p.returncode == 143, "kelp-replay, SIGTERM: status %s, expected 143"
                  % p.returncode)
            check(not os.path.exists(page), "kelp-replay, SIGTERM: a page was written")
        no_temporaries(work)
        print("kelp-replay, SIGTERM: status %s" % p.returncode)

    if failures:
        print("check_stop: %d failures (seed %d)" % (len(failures), seed), file=sys.stderr)
        return 1
    print("check_stop: all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
