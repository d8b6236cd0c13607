#!/usr/bin/env python3
"""Follows apps/sitl/README.md's launch lines as a newcomer would, with fake autopilots.

Usage: readme_launch.py README BUILD_DIR FAKE_ARDUPILOT WORK_DIR [CMAKE]

1. Installs the `sitl` component of BUILD_DIR (kelp-sitl, kelp-mission, params/, scenarios/) into
   WORK_DIR/prefix with `cmake --install`, as the README's install step does, and checks that
   every file the launch lines name is there.
2. Takes the fenced block between <!-- launch:begin --> and <!-- launch:end --> in the README
   and splits it at its "# Terminal N" comments; the lines before the first terminal (the
   exports) run at the top of each terminal, as the README says.
3. HOME is WORK_DIR/home, so `~` and `$HOME/ardupilot` land there; the ArduPilot tree there has
   fake `build/sitl/bin/ardusub` and `ardurover` (kelp-fake-ardupilot) and the default
   parameter files the lines name. The only other rewrites: KELP_PREFIX points at the test's
   prefix, and kelp-sitl, kelp-mission and the fakes get ephemeral ports (tests never take the
   fixed SITL ports 9002/9012/5760/5770 a running kelp-sitl or SITL may hold).
4. Runs terminals 1-3 in the background, each in its own process group, and terminal 4 (the
   mission) to its end; then the README's stop step: Ctrl-C (SIGINT to the process group) in
   terminal 1, then in terminals 2 and 3.
5. Checks: the mission completed (exit 0, no mode change it did not command); each program ran
   in its own directory, side by side (SITL's eeprom.bin in sub/ and boat/); kelp-sitl wrote
   summary.json where the stop step says, with the scenario's sea, both autopilots joined and
   nothing malformed; kelp-mission's CSV logs are where the README says.
"""
import json
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time


def fail(msg):
    print("readme_launch: FAILED: " + msg, flush=True)
    sys.exit(1)


def free_port(kind):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def launch_block(readme):
    text = open(readme, encoding="utf-8").read()
    m = re.search(r"<!-- launch:begin -->\s*```sh\n(.*?)```\s*<!-- launch:end -->", text, re.S)
    if not m:
        fail("no ```sh block between <!-- launch:begin --> and <!-- launch:end --> in " + readme)
    block = m.group(1)
    parts = re.split(r"^(# Terminal \d+.*)$", block, flags=re.M)
    preamble = parts[0]
    terminals = []
    for i in range(1, len(parts), 2):
        terminals.append((parts[i], parts[i + 1]))
    if len(terminals) != 4:
        fail("expected 4 '# Terminal N' sections in the launch block, found %d" % len(terminals))
    return text, preamble, terminals


def replace_once(script, old, new, what):
    n = script.count(old)
    if n != 1:
        fail("%s: expected '%s' once in the README's lines, found %d" % (what, old, n))
    return script.replace(old, new)


def main():
    if len(sys.argv) < 5:
        fail(__doc__)
    readme, build, fake, work = sys.argv[1:5]
    cmake = sys.argv[5] if len(sys.argv) > 5 else "cmake"
    subprocess.run(["rm", "-rf", work], check=True)
    os.makedirs(work)
    prefix = os.path.join(work, "prefix")
    home = os.path.join(work, "home")

    # 1. The install.
    r = subprocess.run([cmake, "--install", build, "--prefix", prefix, "--component", "sitl"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fail("cmake --install --component sitl: " + r.stdout + r.stderr)
    share = os.path.join(prefix, "share", "kelp", "sitl")
    for f in ["bin/kelp-sitl", "bin/kelp-mission"]:
        if not os.access(os.path.join(prefix, f), os.X_OK):
            fail(f + " was not installed")

    text, preamble, terminals = launch_block(readme)

    # 3. The fake ArduPilot tree.
    ap = os.path.join(home, "ardupilot")
    os.makedirs(os.path.join(ap, "build", "sitl", "bin"))
    os.makedirs(os.path.join(ap, "Tools", "autotest", "default_params"))
    for p in ["sub-6dof", "rover", "motorboat", "rover-skid"]:
        with open(os.path.join(ap, "Tools", "autotest", "default_params", p + ".parm"), "w") as f:
            f.write("# stands in for ArduPilot's %s.parm\n" % p)
    ports = {
        "sub_json": free_port(socket.SOCK_DGRAM),
        "rover_json": free_port(socket.SOCK_DGRAM),
        "sub_mav": free_port(socket.SOCK_STREAM),
        "rover_mav": free_port(socket.SOCK_STREAM),
    }
    for name, vehicle, j, m in [("ardusub", "sub", "sub_json", "sub_mav"),
                                ("ardurover", "rover", "rover_json", "rover_mav")]:
        path = os.path.join(ap, "build", "sitl", "bin", name)
        with open(path, "w") as f:
            f.write("#!/bin/sh\nexec %s --vehicle %s --json-port %d --mavlink-port %d \"$@\"\n"
                    % (shlex.quote(fake), vehicle, ports[j], ports[m]))
        os.chmod(path, 0o755)

    # The rewrites.
    preamble = replace_once(preamble, "KELP_PREFIX=/usr/local", "KELP_PREFIX=" + prefix,
                            "the install prefix")
    scripts = []
    for title, body in terminals:
        if re.search(r"^kelp-sitl ", body, re.M):
            body = re.sub(r"^(kelp-sitl .*)$",
                          r"\1 --sub-port %d --rover-port %d" % (ports["sub_json"],
                                                                 ports["rover_json"]),
                          body, count=1, flags=re.M)
        if re.search(r"^kelp-mission", body, re.M):
            body = re.sub(r"^(kelp-mission.*)$",
                          r"\1 --sub tcp:127.0.0.1:%d --rover tcp:127.0.0.1:%d"
                          % (ports["sub_mav"], ports["rover_mav"]), body, count=1, flags=re.M)
        scripts.append((title, "set -e\n" + preamble + body))
    for what, pattern in [("kelp-sitl", r"^kelp-sitl "), ("ardusub", r"/ardusub "),
                          ("ardurover", r"/ardurover "), ("kelp-mission", r"^kelp-mission")]:
        if sum(1 for _, s in scripts if re.search(pattern, s, re.M)) != 1:
            fail("the launch block should start %s in exactly one terminal" % what)

    env = dict(os.environ)
    env["HOME"] = home
    env["PATH"] = os.path.join(prefix, "bin") + os.pathsep + env.get("PATH", "")
    os.makedirs(home, exist_ok=True)
    logs = os.path.join(work, "terminals")
    os.makedirs(logs)

    # 4. Terminals 1-3 in the background (own process groups: Ctrl-C goes to a group).
    procs = []
    for i, (title, script) in enumerate(scripts[:3]):
        out = open(os.path.join(logs, "terminal%d.log" % (i + 1)), "w")
        out.write("$ " + script.replace("\n", "\n$ ") + "\n")
        out.flush()
        procs.append(subprocess.Popen(["bash", "-c", script], cwd=home, env=env, stdout=out,
                                      stderr=subprocess.STDOUT, start_new_session=True))
    time.sleep(0.5)
    for (title, _), p in zip(scripts[:3], procs):
        if p.poll() is not None:
            fail("%s exited at once (status %d); see %s" % (title, p.returncode, logs))

    def stop_all():
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)

    try:
        mission = subprocess.run(["bash", "-c", scripts[3][1]], cwd=home, env=env,
                                 capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        stop_all()
        fail("kelp-mission did not finish within 600 s")
    with open(os.path.join(logs, "terminal4.log"), "w") as f:
        f.write(mission.stdout + mission.stderr)
    print(mission.stdout + mission.stderr)

    # The stop step: Ctrl-C in terminal 1 (kelp-sitl writes summary.json), then 2 and 3.
    stop = re.search(r"^# Stop:(.*)$", text, re.M)
    for p in procs:
        os.killpg(p.pid, signal.SIGINT)
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            stop_all()
            fail("a terminal did not stop on Ctrl-C; see " + logs)

    # 5. Checks.
    if mission.returncode != 0:
        fail("kelp-mission exited %d; see %s" % (mission.returncode, logs))
    for needle in ["mission complete", "sub: 0 mode changes not commanded by kelp-mission",
                   "boat: 0 mode changes not commanded by kelp-mission"]:
        if needle not in mission.stdout:
            fail("kelp-mission's output lacks '%s'" % needle)
    run = os.path.join(home, "kelp-sitl-run")
    for d in ["physics", "sub", "boat", "mission"]:
        if not os.path.isdir(os.path.join(run, d)):
            fail("no directory ~/kelp-sitl-run/%s: the programs do not run side by side" % d)
    for d in ["sub", "boat"]:
        if not os.path.exists(os.path.join(run, d, "eeprom.bin")):
            fail("SITL's eeprom.bin is not in ~/kelp-sitl-run/%s" % d)
    if os.path.exists(os.path.join(run, "sub", "boat")):
        fail("boat/ was made inside sub/")
    summary_path = os.path.join(run, "physics", "sitl-run", "summary.json")
    if not stop or "~/kelp-sitl-run/physics/sitl-run/summary.json" not in stop.group(1):
        fail("the README's stop step should name ~/kelp-sitl-run/physics/sitl-run/summary.json")
    if not os.path.exists(summary_path):
        fail("kelp-sitl did not write " + summary_path + " on Ctrl-C")
    s = json.load(open(summary_path))
    if s["scenario"].get("sea") != "calm":
        fail("the README's run is not the calm sea: %s" % s["scenario"].get("sea"))
    for port in ["ardusub", "ardurover"]:
        c = s[port]
        if not c["joined"] or c["frames"] < 1000 or c["malformed"] != 0:
            fail("%s in summary.json: %s" % (port, c))
    for f in ["local_position_ned.csv", "global_position_int.csv", "command_ack.csv"]:
        if not os.path.exists(os.path.join(run, "mission", "mission-run", f)):
            fail("kelp-mission's log %s is not in ~/kelp-sitl-run/mission/mission-run" % f)
    # The depth: ArduSub reads SITL's sea water (1024 kg/m^3, g 9.80665) through BARO_SPEC_GRAV
    # (9800 Pa/m x it); the params file must set it, and the fake ArduSub reads depth that way,
    # so the mission's 5 m is 5 m of true depth only with the right value.
    parm = os.path.join(prefix, "share", "kelp", "sitl", "params", "bluerov2-heavy.parm")
    grav = re.search(r"^BARO_SPEC_GRAV\s+(\S+)", open(parm).read(), re.M)
    if not grav:
        fail("params/bluerov2-heavy.parm does not set BARO_SPEC_GRAV (ArduSub's depth 2.5 % deep)")
    if abs(float(grav.group(1)) * 9800.0 / (1024.0 * 9.80665) - 1.0) > 2e-4:
        fail("BARO_SPEC_GRAV %s does not match SITL's water (1024 x 9.80665 / 9800 = 1.0247)"
             % grav.group(1))
    true_depth = float(open(os.path.join(run, "sub", "true_depth.txt")).read())
    if abs(true_depth - 5.0) > 0.1:
        fail("the ROV ended at %.3f m of true depth for kelp-mission's 5 m" % true_depth)
    print("readme_launch: the README's launch lines ran: %.1f s of physics, %d frames per "
          "autopilot; the mission completed" % (s["physics_s"], s["ardusub"]["frames"]))


if __name__ == "__main__":
    main()
