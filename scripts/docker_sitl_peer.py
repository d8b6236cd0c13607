#!/usr/bin/env python3
"""kelp-sitl in the image against a fake ArduSub + ArduRover on the host, across the container
boundary (scripts/docker-test runs it).

docker_sitl_peer.py IMAGE OUTDIR SECONDS [DOCKER RUN OPTIONS...]

Starts `kelp-sitl --bind 0.0.0.0` in a container of IMAGE with its two JSON ports (9002, 9012)
published on the host's loopback at two free ephemeral UDP ports, and OUTDIR mounted as /out.
Plays the two SITL instances from the host the way apps/sitl/tests/bridge/fake_sitl.py does
(its packets, its reply checks as ArduPilot's SIM_JSON parser reads them, its lockstep), for
SECONDS of physics at 1200 Hz: thrusters neutral, then two seconds of the ROV's vertical
thrusters up and the boat's throttle ahead (the ROV must rise, the boat move forward), then
neutral again. Stops the bridge with SIGINT and checks its exit status, summary.json (every frame
stepped once, no malformed packet, no time-out, the tether solver never fell back), the CSV log,
and that the image's plot_run.py plots it. Standard library only.
"""
import json
import math
import os
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "apps",
                                "sitl", "tests", "bridge"))
import fake_sitl  # noqa: E402  (the fake peer: packets, reply validation, lockstep)

from fake_sitl import H, MAGIC16, MAGIC32, RATE, check, frames  # noqa: E402


def docker(*args, **kw):
    return subprocess.run(["docker", *args], check=False, text=True, capture_output=True, **kw)


def main(image, outdir, seconds, run_opts):
    os.makedirs(outdir, exist_ok=True)
    sub_port, rover_port = fake_sitl.free_udp_port(), fake_sitl.free_udp_port()
    name = "kelp-docker-test-sitl-%d" % os.getpid()
    total = int(round(seconds * RATE))
    cmd = ["run", "-d", "--name", name, *run_opts, "-v", "%s:/out" % os.path.abspath(outdir),
           "-p", "127.0.0.1:%d:9002/udp" % sub_port, "-p", "127.0.0.1:%d:9012/udp" % rover_port,
           image, "kelp-sitl", "--bind", "0.0.0.0", "--sub-port", "9002", "--rover-port", "9012",
           "--log", "/out/run", "--log-rate", "50", "--peer-timeout", "5", "--status-interval",
           "10", "--scenario", "/usr/local/share/kelp/scenarios/calm_hold.json"]
    print("docker " + " ".join(cmd), flush=True)
    r = docker(*cmd)
    if r.returncode != 0:
        print("FAIL: could not start the container: " + r.stderr)
        return 1
    wall0 = time.time()
    try:
        # kelp-sitl says when both sockets are bound; the published ports exist before that.
        deadline = time.time() + 60
        while "serving ArduSub" not in docker("logs", name).stderr:
            state = docker("inspect", "-f", "{{.State.Running}}", name).stdout.strip()
            if state != "true" or time.time() > deadline:
                print("FAIL: kelp-sitl did not start:\n" + docker("logs", name).stderr)
                return 1
            time.sleep(0.2)
        print("kelp-sitl serving in the container; ArduSub at 127.0.0.1:%d, ArduRover at "
              "127.0.0.1:%d on the host" % (sub_port, rover_port), flush=True)

        sub = fake_sitl.Sitl("ArduSub", sub_port, MAGIC16)
        rover = fake_sitl.Sitl("ArduRover", rover_port, MAGIC32)
        neutral_sub, neutral_rover = [1500] * 8, [1500] * 4
        # Both join: the first pair of frames is answered once both arrived.
        sub.send(neutral_sub)
        rover.send(neutral_rover)
        a, b = sub.receive(5.0), rover.receive(5.0)
        if not check(a is not None and b is not None, "no replies through the published ports"):
            return 1
        check(abs(a["timestamp"] - H) < 1e-9, "first timestamp %r is not 1/rate" % a["timestamp"])
        sub.accepted()
        rover.accepted()
        t = [H]
        done = 1
        # One second neutral, two seconds of climb and throttle, the rest neutral.
        frames(sub, rover, int(RATE) - done, neutral_sub, neutral_rover, t)
        done = int(RATE)
        z0, p0 = sub.last["position"][2], rover.last["position"]
        hv = fake_sitl.heading_vector(rover.last["quaternion"])
        frames(sub, rover, 2 * int(RATE), [1500] * 4 + [1300] * 4, [1800, 1500, 1800, 1500], t)
        done += 2 * int(RATE)
        z1, p1 = sub.last["position"][2], rover.last["position"]
        ahead = (p1[0] - p0[0]) * hv[0] + (p1[1] - p0[1]) * hv[1]
        print("2 s of climb: ROV depth %.3f -> %.3f m; boat %.2f m ahead" % (z0, z1, ahead))
        check(z1 < z0 - 0.2, "vertical thrust up did not make the depth decrease (%.3f -> %.3f)"
              % (z0, z1))
        check(ahead > 1.0, "Rover throttle did not move the boat forward (%.2f m)" % ahead)
        step = int(RATE)
        while done < total and not fake_sitl.failures:
            n = min(step, total - done)
            if not frames(sub, rover, n, neutral_sub, neutral_rover, t):
                break
            done += n
        wall = time.time() - wall0
        print("%d lockstep frames (%.1f s of physics) in %.1f s of wall time, %.0f frames/s"
              % (done, t[0], wall, done / wall), flush=True)
    finally:
        docker("kill", "--signal", "INT", name)
        code = docker("wait", name).stdout.strip()
        logs = docker("logs", name).stderr
        docker("rm", "-f", name)
    print("\n".join(logs.strip().splitlines()[-3:]))
    check(code == "0", "kelp-sitl in the container did not stop cleanly on SIGINT (%s)" % code)

    log = os.path.join(outdir, "run")
    with open(os.path.join(log, "summary.json")) as f:
        summary = json.load(f)
    s, r = summary["ardusub"], summary["ardurover"]
    print("counters: ArduSub", json.dumps(s), "\n          ArduRover", json.dumps(r))
    check(summary["steps"] == total, "%d steps, %d frames sent" % (summary["steps"], total))
    check(abs(summary["physics_s"] - total * H) < 1e-6, "physics time %.6f s, expected %.6f s"
          % (summary["physics_s"], total * H))
    for who, c in (("ArduSub", s), ("ArduRover", r)):
        check(c["malformed"] == 0 and c["timeouts"] == 0 and c["restarts"] == 0,
              "%s's counters: %r" % (who, c))
    ts = summary.get("tether_solver", {})
    check(ts.get("explicit_fallbacks") == 0 and ts.get("steps") == total,
          "tether_solver in summary.json: %r" % ts)
    with open(os.path.join(log, "timeseries.csv")) as f:
        header = f.readline().strip().split(",")
        rows = [line.split(",") for line in f]
    check("tension_auv" in header and len(rows) >= 50 * seconds - 2,
          "timeseries.csv: %d rows for %.0f s at 50 Hz" % (len(rows), seconds))
    check(not any(math.isinf(float(v)) for row in rows for v in row if v.strip()),
          "timeseries.csv has an infinite value")
    # The image's plotting script on the bridge's log.
    p = docker("run", "--rm", *run_opts, "-v", "%s:/out" % os.path.abspath(outdir), image,
               "python3", "/usr/local/share/kelp/plot_run.py", "/out/run")
    check(p.returncode == 0, "plot_run.py in the image failed on the SITL log: " + p.stderr[-500:])
    png = os.path.join(log, "trajectories.png")
    check(os.path.exists(png) and os.path.getsize(png) > 10000, "no trajectories.png")

    if fake_sitl.failures:
        print("%d check(s) failed" % len(fake_sitl.failures))
        return 1
    print("SITL across the container boundary: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4:]))
