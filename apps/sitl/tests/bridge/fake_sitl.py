#!/usr/bin/env python3
"""A fake pair of ArduPilot SITL instances against the real kelp-sitl, on loopback UDP.

fake_sitl.py KELP_SITL OUTDIR

It plays ArduSub (16-channel servo packets) and ArduRover (32-channel packets) the way SITL's
JSON backend does (ArduPilot libraries/SITL/SIM_JSON.cpp): binary servo packets, one reply
expected per packet, frame_count +1 per accepted reply, the same frame_count again for a
re-send, a smaller one after a restart. Every reply is checked the way SIM_JSON's parser reads
it (strstr for each key, exactly '":' after it, vectors read by sscanf("[%f, %f, %f]"), the
record between two newlines) and as strict JSON. Then it checks the physics (vertical thrust up
makes the ROV rise, throttle moves the boat forward), garbage (KELP_SITL_GARBAGE_SECONDS of
it, 2 by default, 60 for the hardening soak), a restart, a silent peer, the counters in
summary.json, the loopback bind, and that plot_run.py plots the log. Standard library only.
"""
import json
import math
import os
import random
import re
import signal
import socket
import struct
import subprocess
import sys
import time

RATE = 1200.0
H = 1.0 / RATE
MAGIC16, MAGIC32 = 18458, 29569
FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what, flush=True)
    return cond


def free_udp_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def packet(magic, frame, pwm, rate=int(RATE)):
    n = 16 if magic == MAGIC16 else 32
    pwm = list(pwm) + [1000] * (n - len(pwm))
    return struct.pack("<HHI%dH" % n, magic, rate, frame, *pwm[:n])


def sitl_read(record, section, key, count):
    """Reads a value as SIM_JSON::parse_sensors does: strstr for the section (the top level is
    the empty section: the record from its second character), then strstr for the bare key
    after it, skip the key and 2 characters (which must be '":' here), then atof or
    sscanf('[%f, %f, ...]')."""
    start = record.find(section)
    if start < 0:
        return None
    start += len(section) + 1
    i = record.find(key, start)
    if i < 0:
        return None
    j = i + len(key)
    if record[j:j + 2] != '":':
        return None
    rest = record[j + 2:]
    if count == 1:
        m = re.match(FLOAT, rest)
        return float(m.group(0)) if m else None
    m = re.match(r"\[\s*" + r"\s*,\s*".join(["(" + FLOAT + ")"] * count) + r"\s*\]", rest)
    return [float(x) for x in m.groups()] if m else None


def validate(raw):
    """Checks one reply like SITL's parser and as JSON; returns the decoded state or None."""
    ok = check(raw.startswith(b"\n") and raw.endswith(b"\n") and raw.count(b"\n") == 2,
               "reply is not '\\n' + one record + '\\n': %r" % raw[:80])
    if not ok:
        return None
    record = raw[1:-1].decode("ascii")
    check(not re.search(r'"\s+:|:\s', record), "whitespace around a colon: " + record[:80])
    try:
        obj = json.loads(record)
    except ValueError as e:
        check(False, "reply is not JSON (%s): %s" % (e, record[:80]))
        return None
    st = {
        "timestamp": sitl_read(record, "", "timestamp", 1),
        "gyro": sitl_read(record, "imu", "gyro", 3),
        "accel": sitl_read(record, "imu", "accel_body", 3),
        "position": sitl_read(record, "", "position", 3),
        "velocity": sitl_read(record, "", "velocity", 3),
        "quaternion": sitl_read(record, "", "quaternion", 4),
    }
    for k, v in st.items():
        if not check(v is not None, "SITL's parser would not find '%s' in %s" % (k, record[:120])):
            return None
    # The strstr reading must agree with the JSON reading (no key shadowed by an earlier one).
    check(st["position"] == obj["position"] and st["velocity"] == obj["velocity"]
          and st["timestamp"] == obj["timestamp"] and st["gyro"] == obj["imu"]["gyro"],
          "strstr and JSON readings differ: " + record[:120])
    q = st["quaternion"]
    check(abs(math.sqrt(sum(c * c for c in q)) - 1) < 1e-6, "quaternion not unit: %r" % q)
    return st


class Sitl:
    def __init__(self, name, port, magic):
        self.name, self.port, self.magic = name, port, magic
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.frame = 0
        self.last_raw = None
        self.last = None

    def send(self, pwm, frame=None):
        self.sock.sendto(packet(self.magic, self.frame if frame is None else frame, pwm),
                         ("127.0.0.1", self.port))

    def send_raw(self, data):
        self.sock.sendto(data, ("127.0.0.1", self.port))

    def receive(self, timeout=2.0):
        self.sock.settimeout(timeout)
        try:
            raw, _ = self.sock.recvfrom(65536)
        except socket.timeout:
            return None
        st = validate(raw)
        self.last_raw, self.last = raw, st
        return st

    def accepted(self):
        self.frame += 1


def heading_vector(q):
    w, x, y, z = q
    # First column of the rotation body -> NED: the bow direction in NED.
    return (1 - 2 * (y * y + z * z), 2 * (x * y + w * z))


def frames(sub, rover, n, sub_pwm, rover_pwm, expect_t=None):
    """n lockstep frames, the two vehicles' packets in random order; checks the shared clock."""
    for _ in range(n):
        order = [sub, rover] if random.random() < 0.5 else [rover, sub]
        order[0].send(sub_pwm if order[0] is sub else rover_pwm)
        order[1].send(sub_pwm if order[1] is sub else rover_pwm)
        a, b = sub.receive(), rover.receive()
        if not check(a is not None and b is not None, "no reply in lockstep"):
            return False
        check(a["timestamp"] == b["timestamp"], "the two vehicles' clocks differ")
        if expect_t is not None:
            expect_t[0] += H
            check(abs(a["timestamp"] - expect_t[0]) < 1e-8,
                  "timestamp %.9f, expected %.9f" % (a["timestamp"], expect_t[0]))
        sub.accepted()
        rover.accepted()
    return True


def main(program, outdir):
    here = os.path.dirname(os.path.abspath(__file__))
    # The calm sea (no current, no waves): a vehicle at rest is at rest.
    scenario = os.path.join(here, "..", "..", "..", "tethered_pair", "scenarios", "calm_hold.json")
    random.seed(7)
    os.makedirs(outdir, exist_ok=True)
    log = os.path.join(outdir, "run")
    sub_port, rover_port = free_udp_port(), free_udp_port()
    proc = subprocess.Popen([program, "--sub-port", str(sub_port), "--rover-port", str(rover_port),
                             "--log", log, "--peer-timeout", "1.5", "--log-rate", "50",
                             "--status-interval", "1", "--scenario", scenario])
    try:
        # Wait (at most 20 s, the machine may be loaded) until both ports are bound; they must be
        # bound to loopback only, since no --bind was given.
        deadline = time.time() + 20
        while True:
            bound = {}
            with open("/proc/net/udp") as f:
                for line in f.readlines()[1:]:
                    addr, port = line.split()[1].split(":")
                    if int(port, 16) in (sub_port, rover_port):
                        bound.setdefault(int(port, 16), set()).add(addr)
            if len(bound) == 2 or time.time() > deadline or proc.poll() is not None:
                break
            time.sleep(0.05)
        check(proc.poll() is None, "kelp-sitl exited at start")
        check(len(bound) == 2 and all(a == {"0100007F"} for a in bound.values()),
              "kelp-sitl is not bound to 127.0.0.1 only on both ports: %r" % bound)

        sub = Sitl("ArduSub", sub_port, MAGIC16)
        rover = Sitl("ArduRover", rover_port, MAGIC32)
        neutral_sub = [1500] * 8
        neutral_rover = [1500] * 4

        # 1. Start together: ArduSub alone waits.
        sub.send(neutral_sub)
        check(sub.receive(0.4) is None, "ArduSub answered before ArduRover joined")
        sub.send(neutral_sub)  # its re-send while waiting
        check(sub.receive(0.3) is None, "a waiting re-send was answered")
        rover.send(neutral_rover)
        a, b = sub.receive(), rover.receive()
        check(a is not None and b is not None, "no replies once both joined")
        t = [H]
        check(a and abs(a["timestamp"] - H) < 1e-9, "first timestamp is not 1/rate")
        sub.accepted()
        rover.accepted()
        # At rest the accelerometer reads about (0, 0, -g) in body axes.
        check(a and abs(a["accel"][2] + 9.80665) < 0.3 and math.hypot(*a["accel"][:2]) < 0.3,
              "ArduSub's specific force at rest is %r" % (a and a["accel"]))

        # 2. Lockstep, interleaved both ways: 600 frames with thrusters neutral.
        frames(sub, rover, 600, neutral_sub, neutral_rover, t)

        # 3. A re-send gets the same bytes, and no step.
        before = sub.last_raw
        sub.send(neutral_sub, frame=sub.frame - 1)
        check(sub.receive() is not None and sub.last_raw == before, "re-send answered differently")
        frames(sub, rover, 1, neutral_sub, neutral_rover, t)  # timestamps still +h

        # 4. Physics: vertical thrusters (motors 5-8) below 1500 = climb; boat throttle ahead.
        z0 = sub.last["position"][2]
        p0 = rover.last["position"]
        hv = heading_vector(rover.last["quaternion"])
        frames(sub, rover, 2400, [1500] * 4 + [1300] * 4, [1800, 1500, 1800, 1500], t)
        z1 = sub.last["position"][2]
        p1 = rover.last["position"]
        ahead = (p1[0] - p0[0]) * hv[0] + (p1[1] - p0[1]) * hv[1]
        print("2 s of climb: ROV depth %.3f -> %.3f m; boat %.2f m ahead" % (z0, z1, ahead))
        check(z1 < z0 - 0.2, "vertical thrust up did not make the depth decrease (%.3f -> %.3f)"
              % (z0, z1))
        check(ahead > 1.0, "Rover throttle did not move the boat forward (%.2f m)" % ahead)

        # 5. Garbage on both ports: no reply, counted; then lockstep goes on.
        garbage = [b"", b"x", os.urandom(39), os.urandom(41), os.urandom(3000),
                   struct.pack("<HHI16H", 1234, 1200, sub.frame, *([1500] * 16)),  # bad magic
                   struct.pack("<HHI32H", MAGIC16, 1200, sub.frame, *([1500] * 32)),  # size/magic
                   b"\n{\"timestamp\":1}\n"]
        for g in garbage:
            sub.send_raw(g)
            rover.send_raw(g)
        check(sub.receive(0.3) is None and rover.receive(0.1) is None, "garbage was answered")
        frames(sub, rover, 10, neutral_sub, neutral_rover, t)

        # 5b. A minute of garbage (KELP_SITL_GARBAGE_SECONDS, 2 s by default in CTest): random
        # datagrams of every size but the two valid ones, 50 between consecutive lockstep frames
        # on both ports; every frame must still be answered, every datagram counted.
        seconds = float(os.environ.get("KELP_SITL_GARBAGE_SECONDS", "2"))
        rng = random.Random(5)
        flood = 0
        end = time.time() + seconds
        while time.time() < end:
            for _ in range(50):
                g = rng.randbytes(rng.choice([0, 1, 7, 39, 41, 71, 73, 200, 1400]))
                sub.send_raw(g)
                rover.send_raw(g)
                flood += 1
            frames(sub, rover, 1, neutral_sub, neutral_rover, t)
        print("%.0f s of garbage: %d datagrams on each port" % (seconds, flood))
        garbage_sent = len(garbage) + flood

        # 6. ArduSub restarts (frame_count back to 0): the ROV is reset, the boat keeps going.
        boat_before = rover.last["position"]
        sub.frame = 0
        sub.send(neutral_sub)
        rover.send(neutral_rover)
        a, b = sub.receive(), rover.receive()
        sub.accepted()
        rover.accepted()
        t[0] += H
        check(a is not None and b is not None, "no replies after the restart")
        if a and b:
            check(abs(a["position"][2] - z0) < 0.3,
                  "restarted ROV not back near its start depth (%.2f vs %.2f)"
                  % (a["position"][2], z0))
            jump = math.dist(b["position"], boat_before)
            check(jump < 0.05, "the boat jumped %.3f m when ArduSub restarted" % jump)
            check(abs(a["timestamp"] - t[0]) < 1e-8, "the clock moved on a restart")

        # 7. ArduRover falls silent: after the peer time-out ArduSub's frame is answered alone.
        sub.send(neutral_sub)
        start = time.time()
        a = sub.receive(4.0)
        waited = time.time() - start
        check(a is not None and 1.0 < waited < 3.5,
              "ArduSub's frame not answered alone after the time-out (%.2f s)" % waited)
        sub.accepted()
        t[0] += H
        for _ in range(5):
            sub.send(neutral_sub)
            check(sub.receive() is not None, "ArduSub alone not answered")
            sub.accepted()
            t[0] += H
        # ArduRover comes back with its next frame (sent first: were ArduSub's first, it would
        # still be stepped alone), and the two are in lockstep again.
        rover.send(neutral_rover)
        check(rover.receive(0.3) is None, "ArduRover answered before ArduSub's frame")
        sub.send(neutral_sub)
        a, b = sub.receive(), rover.receive()
        check(a is not None and b is not None and a["timestamp"] == b["timestamp"],
              "no common step after ArduRover came back")
        sub.accepted()
        rover.accepted()
        t[0] += H
        frames(sub, rover, 5, neutral_sub, neutral_rover, t)
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = "hung"
    check(code == 0, "kelp-sitl did not stop cleanly on SIGINT (%s)" % code)

    with open(os.path.join(log, "summary.json")) as f:
        summary = json.load(f)
    s, r = summary["ardusub"], summary["ardurover"]
    print("counters: ArduSub", json.dumps(s), "\n          ArduRover", json.dumps(r))
    check(s["malformed"] == garbage_sent and r["malformed"] == garbage_sent,
          "malformed counters %d/%d, sent %d each" % (s["malformed"], r["malformed"], garbage_sent))
    check(s["restarts"] == 1 and r["restarts"] == 0, "restart counters")
    check(s["repeats"] == 1 and s["waiting_resends"] == 1, "re-send counters")
    check(r["timeouts"] == 1 and s["timeouts"] == 0, "time-out counters")
    check(abs(summary["physics_s"] - t[0]) < 1e-6, "physics time %.6f, expected %.6f"
          % (summary["physics_s"], t[0]))
    # The tether solver's work: one report per physics step, every step converged implicitly.
    ts = summary.get("tether_solver", {})
    print("tether solver:", json.dumps(ts))
    check(ts.get("steps") == summary["steps"] and ts.get("explicit_fallbacks") == 0
          and ts.get("newton_iterations", 0) >= ts.get("tether_steps", 1) > 0
          and ts.get("worst_residual_m_s", 1) <= ts.get("residual_tolerance_m_s", 0),
          "tether_solver in summary.json: %r" % ts)
    with open(os.path.join(log, "events.log")) as f:
        events = f.read()
    for what in ("ArduSub joined", "ArduRover joined", "ArduSub restarted",
                 "ArduRover silent", "ArduRover is back"):
        check(what in events, "events.log lacks '%s'" % what)
    with open(os.path.join(log, "timeseries.csv")) as f:
        header = f.readline().strip().split(",")
        rows = f.readlines()
    check("tension_auv" in header and "auv_thrust_8" in header and len(rows) > 100,
          "timeseries.csv: %d rows" % len(rows))
    # The run's 3-D replay (its data marked as kelp-sitl's) and its ROS 2 bag, whose contents
    # tests/ros2's ros2_mcap_node_check compares with timeseries.csv.
    replay = os.path.join(log, "replay.html")
    check(os.path.exists(replay), "no replay.html in the SITL log")
    if os.path.exists(replay):
        with open(replay, encoding="utf-8") as f:
            page = f.read()
        check(re.search(r'"source"\s*:\s*"kelp-sitl"', page) is not None,
              "replay.html does not hold kelp-sitl's run")
    mcap = os.path.join(log, "run.mcap")
    check(os.path.exists(mcap) and os.path.getsize(mcap) > 1000, "no run.mcap in the SITL log")
    plot = os.path.join(here, "..", "..", "..", "tethered_pair", "plot_run.py")
    python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    check(subprocess.call([python, plot, log]) == 0, "plot_run.py failed on the SITL log")
    check(os.path.exists(os.path.join(log, "trajectories.png")), "no trajectories.png")

    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("fake SITL: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
