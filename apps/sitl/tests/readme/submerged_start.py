#!/usr/bin/env python3
"""kelp-sitl's default world keeps the ROV below z = 0 while ArduSub waits to arm.

Usage: submerged_start.py KELP_SITL FAKE_ARDUPILOT MODERATE_JSON WORK_DIR

ArduSub moves its depth zero up whenever its pressure sensor reads a height above the mean
surface (ArduPilot ArduSub/sensors.cpp), and SITL's pressure is hydrostatic about z = 0, so a ROV
riding the crests of kelp's waves biases ArduSub's depth for the rest of the run. kelp-sitl's
embedded default (the paper's moderate sea) therefore starts the ROV below the troughs. This
runs that default for 60 s of physics with two idle fake autopilots (neutral PWM: a disarmed ROV,
slightly buoyant, drifting in the waves and the current; ephemeral ports) and checks that the
ROV stays at least 1 m below z = 0 throughout, and that scenarios/moderate.json is the same world.
"""
import csv
import json
import os
import socket
import subprocess
import sys
import time


def fail(msg):
    print("submerged_start: FAILED: " + msg, flush=True)
    sys.exit(1)


def free_port(kind):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def main():
    sitl, fake, moderate, work = sys.argv[1:5]
    subprocess.run(["rm", "-rf", work], check=True)
    for d in ["sub", "boat"]:
        os.makedirs(os.path.join(work, d))
    ju, jr = free_port(socket.SOCK_DGRAM), free_port(socket.SOCK_DGRAM)
    mu, mr = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    run = os.path.join(work, "run")
    physics = subprocess.Popen([sitl, "--log", run, "--sub-port", str(ju), "--rover-port",
                                str(jr), "--duration", "60", "--quiet"])
    fakes = []
    for vehicle, inst, j, m in [("sub", 0, ju, mu), ("rover", 1, jr, mr)]:
        fakes.append(subprocess.Popen(
            [fake, "--vehicle", vehicle, "--model", "JSON", "-I%d" % inst, "--home",
             "33.810313,-118.393867,0,0", "-w", "--defaults", os.devnull, "--json-port", str(j),
             "--mavlink-port", str(m)], cwd=os.path.join(work, "sub" if inst == 0 else "boat"),
            stderr=subprocess.DEVNULL))
    clients = []
    deadline = time.time() + 10
    for port in [mu, mr]:  # a ground station that connects and says nothing
        while True:
            try:
                clients.append(socket.create_connection(("127.0.0.1", port)))
                break
            except OSError:
                if time.time() > deadline:
                    fail("the fake autopilots do not listen")
                time.sleep(0.1)
    try:
        physics.wait(timeout=300)
    except subprocess.TimeoutExpired:
        physics.kill()
        fail("kelp-sitl did not reach 60 s of physics within 300 s")
    finally:
        for f in fakes:
            f.kill()
        for c in clients:
            c.close()
    if physics.returncode != 0:
        fail("kelp-sitl exited %d" % physics.returncode)

    rows = list(csv.DictReader(open(os.path.join(run, "timeseries.csv"))))
    z = [float(r["auv_z"]) for r in rows]
    t = [float(r["t"]) for r in rows]
    if not rows or t[-1] < 59.0:
        fail("the run is shorter than 60 s")
    shallowest = min(z)
    print("submerged_start: the ROV's shallowest point over %.0f s: %.2f m (start %.2f m)"
          % (t[-1], shallowest, z[0]))
    if shallowest < 1.0:
        fail("the ROV came within 1 m of z = 0 (%.2f m) in the first 60 s" % shallowest)

    summary = json.load(open(os.path.join(run, "summary.json")))
    shipped = json.load(open(moderate))
    default = summary["scenario"]
    if default.get("sea") != shipped.get("sea") or \
            default["vehicles"].get("auv_start") != shipped["vehicles"].get("auv_start"):
        fail("scenarios/moderate.json (%s) is not kelp-sitl's embedded default (%s)"
             % (shipped, default))


if __name__ == "__main__":
    main()
