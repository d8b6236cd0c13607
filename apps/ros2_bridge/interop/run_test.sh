#!/usr/bin/env bash
# The ROS 2 interop tests: kelp-tethered-pair --ros2 (Cyclone DDS) against an independent Fast DDS
# program (fastdds_peer.cpp), on loopback only.
#   run_test.sh interop|refusals <kelp-tethered-pair> <fastdds_peer> <scenario> <out dir>
# Isolation: inside a network namespace of its own when the test may make one (unshare -n, e.g. as
# root), with only lo up; always with both DDS implementations restricted to 127.0.0.1 (unicast
# discovery) and on a random DDS domain, so that nothing else on the host is reached and no fixed
# port other processes may hold is needed.
set -euo pipefail
mode=$1 program=$2 peer=$3 scenario=$4 out=$5

# KELP_ROS2_NO_NETNS=1 skips the namespace (loopback only, as where unshare is not allowed).
if [ -z "${KELP_ROS2_IN_NETNS:-}" ] && [ -z "${KELP_ROS2_NO_NETNS:-}" ] && command -v unshare >/dev/null && command -v ip >/dev/null &&
  unshare -n true 2>/dev/null; then
  exec env KELP_ROS2_IN_NETNS=1 unshare -n bash -c 'ip link set lo up && exec bash "$0" "$@"' \
    "$0" "$@"
fi
echo "run_test: $mode, $([ -n "${KELP_ROS2_IN_NETNS:-}" ] && echo "own network namespace" || echo "host network, loopback only")"

ROS_DOMAIN_ID=$(((RANDOM % 200) + 1))
export ROS_DOMAIN_ID
# Cyclone DDS 0.10: loopback only, no multicast, discovery by unicast to 127.0.0.1.
export CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'

rm -rf "$out"
mkdir -p "$out"
kelp_pid=
cleanup() { [ -n "$kelp_pid" ] && kill "$kelp_pid" 2>/dev/null || true; }
trap cleanup EXIT

summary_check() {  # python3 expressions over the summary `s`, each must hold
  python3 - "$out/run/summary.json" "$@" <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
sub = s["ros2"]["subscriptions"]
w, v, b, p = (sub[k] for k in ("/rov/cmd_wrench", "/rov/cmd_vel", "/boat/cmd_vel", "/tether/cmd_payout"))
bad = 0
for expr in sys.argv[2:]:
    ok = bool(eval(expr))
    print(("ok   " if ok else "FAIL ") + expr)
    bad += not ok
sys.exit(1 if bad else 0)
PY
}

case "$mode" in
  interop)
    duration=12
    "$program" --scenario "$scenario" --duration $duration --out "$out/run" --no-plots --quiet \
      --ros2-lockstep --ros2-clock-timeout 20 >"$out/kelp.log" 2>&1 &
    kelp_pid=$!
    rc=0
    "$peer" interop "$out" $duration || rc=$?
    wait "$kelp_pid" || { echo "kelp-tethered-pair failed:"; cat "$out/kelp.log"; exit 1; }
    kelp_pid=
    cat "$out/kelp.log"
    [ $rc -eq 0 ] || exit 1
    "$peer" check "$out"
    summary_check 's["ros2"]["mode"] == "lockstep"' 's["ros2"]["stopped_early"] == False' \
      's["ros2"]["subscriptions"]["/rov/cmd_wrench"]["accepted"] >= 40' \
      's["ros2"]["subscriptions"]["/rov/cmd_wrench"]["refused"] == 0' \
      's["ros2"]["published"]["/rov/odom"] == 121' '"/clock" not in s["ros2"]["published"]'
    ;;
  refusals)
    "$program" --scenario "$scenario" --duration 20 --out "$out/run" --no-plots --quiet \
      --ros2 >"$out/kelp.log" 2>&1 &
    kelp_pid=$!
    "$peer" refusals "$out"
    wait "$kelp_pid" || { echo "kelp-tethered-pair failed:"; cat "$out/kelp.log"; exit 1; }
    kelp_pid=
    cat "$out/kelp.log"
    summary_check 's["ros2"]["mode"] == "paced"' \
      'w["received"] >= 70 and w["accepted"] == 0 and w["refused_not_finite"] >= 40 and w["refused_out_of_range"] >= 30 and w["received"] == w["refused"]' \
      'v["received"] >= 20 and v["refused_not_finite"] == v["received"]' \
      'b["received"] >= 10 and b["refused_out_of_range"] == b["received"]' \
      'p["received"] >= 10 and p["refused_unavailable"] == p["received"]' \
      's["ros2"]["published"]["/clock"] == 2000' \
      'math.isfinite(s["energy_j"]) and s["auv"]["second_half_max_depth_error_m"] < 0.3' \
      's["auv"]["max_path_error_m"] < 0.5'
    ;;
  *)
    echo "run_test.sh: unknown mode $mode" >&2
    exit 2
    ;;
esac
