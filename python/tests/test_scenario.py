"""kelp.run_scenario runs what kelp-tethered-pair runs: the same summary, bit for bit, for the
same scenario and seed; its time series equals the program's CSV; bad scenarios are named."""

import csv
import json
import math
import subprocess

import numpy as np
import pytest

import kelp

WALL = ("wall_s", "realtime_factor")


def without_wall(summary):
    return {k: v for k, v in summary.items() if k not in WALL}


def cli_summary(cli, out, *args):
    subprocess.run([cli, "--quiet", "--no-plots", "--out", str(out), *args], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        return json.load(f)


def test_summary_equals_the_cli_bit_for_bit(tethered_pair_cli, scenarios_dir, tmp_path):
    # A shipped scenario with a seed and a duration other than its own: every number of
    # summary.json (parsed from its shortest round-trip decimal form) equals the dict's exactly.
    scenario = str(scenarios_dir / "paper_10m_moderate.json")
    expected = cli_summary(tethered_pair_cli, tmp_path / "cli", "--scenario", scenario,
                           "--duration", "8", "--seed", "7")
    got = kelp.run_scenario(scenario, duration=8, seed=7)
    assert set(WALL) <= set(got)
    assert without_wall(got) == without_wall(expected)
    assert got["scenario"]["seed"] == 7 and got["simulated_s"] == 8
    assert got["scenario_file"] == scenario
    assert got["kelp_version"] == kelp.__version__
    # Floats compared by their bits too (== would let -0.0 equal 0.0).
    a, b = got["auv"]["rms_path_error_m"], expected["auv"]["rms_path_error_m"]
    assert a.hex() == b.hex() and a > 0


def test_default_scenario_equals_the_cli_and_another_seed_differs(tethered_pair_cli, tmp_path):
    expected = cli_summary(tethered_pair_cli, tmp_path / "cli", "--duration", "5", "--seed", "3")
    got = kelp.run_scenario(duration=5, seed=3)
    assert without_wall(got) == without_wall(expected)
    assert got["scenario_file"] == "(embedded default)"
    other = kelp.run_scenario(duration=5, seed=4)
    assert other["energy_j"] != got["energy_j"]


def test_a_dict_runs_like_its_file(scenarios_dir):
    path = scenarios_dir / "calm_hold.json"
    with open(path) as f:
        d = json.load(f)
    from_file = without_wall(kelp.run_scenario(path, duration=3))
    from_dict = without_wall(kelp.run_scenario(d, duration=3))
    assert from_dict["scenario_file"] == "(dict)"
    from_file.pop("scenario_file"), from_dict.pop("scenario_file")
    assert from_dict == from_file


def test_out_writes_the_programs_files_and_timeseries_equals_the_csv(tmp_path):
    summary, ts = kelp.run_scenario(duration=3, seed=2, out=tmp_path, timeseries=True)
    assert {p.name for p in tmp_path.iterdir()} >= {"summary.json", "timeseries.csv",
                                                     "nodes.csv"}
    with open(tmp_path / "summary.json") as f:
        assert without_wall(json.load(f)) == without_wall(summary)
    with open(tmp_path / "timeseries.csv") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    # kelp.run_scenario returns every column of the CSV, in the CSV's order (both come from
    # kelp::sim::timeseries_columns).
    names = list(ts)
    assert names == header
    assert {"t", "auv_x", "asv_yaw", "tension_auv", "auv_soc", "auv_current_8", "tether_turns",
            "tether_length", "winch_pull"} <= set(names)
    n = len(rows)
    assert n == 31  # t = 0 and 10 samples a second for 3 s
    for name in names:
        col = ts[name]
        assert col.shape == (n,) and col.dtype == np.float64
        printed = np.array([float(r[header.index(name)]) for r in rows])
        # The CSV prints 6 significant digits (%.6g); the arrays are the full doubles.
        np.testing.assert_allclose(col, printed, rtol=6e-6, atol=1e-300, equal_nan=True,
                                   err_msg=name)
    assert ts["t"][0] == 0 and ts["t"][-1] == pytest.approx(3.0)
    # The columns are views of one table: no copy per column, kept alive by the arrays.
    assert np.shares_memory(ts["t"], ts["auv_x"]) or ts["t"].base is ts["auv_x"].base
    t = ts["t"]
    del ts
    assert t[-1] == pytest.approx(3.0)


def test_bad_scenarios_are_named():
    with pytest.raises(kelp.ScenarioError, match=r"\(dict\): /sea/nonsense") as info:
        kelp.run_scenario({"sea": {"nonsense": 1}}, duration=1)
    assert isinstance(info.value, ValueError)
    with pytest.raises(kelp.ScenarioError, match="/tether/length"):
        kelp.run_scenario({"tether": {"length": -3}}, duration=1)
    with pytest.raises(kelp.ScenarioError, match="no_such_file.json: cannot be read"):
        kelp.run_scenario("no_such_file.json")
    with pytest.raises(kelp.InvalidArgument, match="duration"):
        kelp.run_scenario(duration=-1)
    with pytest.raises(kelp.InvalidArgument, match="duration"):
        kelp.run_scenario(duration=math.nan)
    with pytest.raises(kelp.InvalidArgument, match="duration"):
        kelp.run_scenario(duration=1e300)  # beyond the scenario file's range (no step count)
    with pytest.raises(kelp.InvalidArgument, match="seed"):
        kelp.run_scenario(duration=1, seed=-2)
    with pytest.raises(kelp.InvalidArgument, match="deterministic"):
        kelp.run_scenario(duration=1, kernel="avx2", deterministic=True)


def test_a_fleet_scenario_runs_and_returns_its_parts(scenarios_dir, tmp_path):
    # The ROV returning to its dock, cut to 20 s: the summary names the fleet's parts, the
    # columns are the program's CSV's, and the files are the program's (or none without `out`).
    path = scenarios_dir / "rov_docking.json"
    summary, columns = kelp.run_scenario(path, duration=20, timeseries=True)
    assert summary["completed"] is True
    assert summary["simulated_s"] == pytest.approx(20.0)
    assert summary["tethers"]["tether"]["from"] == "dock"
    assert set(summary["vehicles"]) == {"rov"}
    assert columns["t"][-1] == pytest.approx(20.0)
    # The ROV heads from 20 m down towards its dock at 28.5 m, and from x = 20 m towards 1 m.
    assert columns["rov.z"][-1] > columns["rov.z"][0] + 1.0
    assert columns["rov.x"][-1] < columns["rov.x"][0] - 1.0
    with open(path) as f:
        text = json.load(f)
    again = kelp.run_scenario(text, duration=20, out=tmp_path)
    assert again["vehicles"]["rov"]["final_position_m"] == summary["vehicles"]["rov"]["final_position_m"]
    assert {p.name for p in tmp_path.iterdir()} == {"summary.json", "timeseries.csv", "nodes.csv",
                                                     "run.mcap"}


def test_ctrl_c_stops_a_run_cleanly_and_raises_keyboard_interrupt(tmp_path):
    # Ctrl-C (SIGINT) during a long run: the run stops within a simulated second (kelp::sim polls
    # Python's signal flag), its files are whole, summary.json says "completed": false, and
    # KeyboardInterrupt is raised. Before, Ctrl-C waited for the run's end (7200 s: half a minute).
    import os
    import signal
    import sys
    import time
    out = tmp_path / "run"
    child = subprocess.Popen(
        [sys.executable, "-c",
         "import signal, sys, kelp\n"
         "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
         "try:\n"
         "    kelp.run_scenario(duration=7200, out=sys.argv[1])\n"
         "except KeyboardInterrupt:\n"
         "    sys.exit(5)\n",
         str(out)], env=dict(os.environ))
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and child.poll() is None:
        if (out / "timeseries.csv").exists() and (out / "timeseries.csv").stat().st_size > 100000:
            break
        time.sleep(0.01)
    start = time.monotonic()
    child.send_signal(signal.SIGINT)
    try:
        code = child.wait(timeout=10)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()
        pytest.fail("Ctrl-C did not stop kelp.run_scenario within 10 s")
    assert code == 5, "no KeyboardInterrupt (exit status %s)" % code
    assert time.monotonic() - start < 10
    with open(out / "summary.json") as f:
        summary = json.load(f)
    assert summary["completed"] is False
    assert 0 < summary["simulated_s"] < 7200
    for name in ("timeseries.csv", "nodes.csv", "events.csv"):
        with open(out / name, "rb") as f:
            assert f.read().endswith(b"\n"), name


def test_a_run_stopped_by_ctrl_c_resumes_from_its_checkpoint_to_an_uninterrupted_runs_files(
        tmp_path):
    # Ctrl-C with checkpoint_every: the run stops and leaves out/checkpoint.bin; run_scenario with
    # resume=True goes on from there, and its files equal those of a run never stopped (summary
    # less its wall time). A completed run removes its checkpoint.
    import os
    import signal
    import sys
    import time
    ref, out = tmp_path / "ref", tmp_path / "run"
    whole = kelp.run_scenario(duration=120, out=ref)
    assert not (ref / "checkpoint.bin").exists()
    child = subprocess.Popen(
        [sys.executable, "-c",
         "import signal, sys, kelp\n"
         "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
         "try:\n"
         "    kelp.run_scenario(duration=120, out=sys.argv[1], checkpoint_every=1.0)\n"
         "except KeyboardInterrupt:\n"
         "    sys.exit(5)\n",
         str(out)], env=dict(os.environ))
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and child.poll() is None:
        if (out / "checkpoint.bin").exists():
            break
        time.sleep(0.005)
    child.send_signal(signal.SIGINT)
    code = child.wait(timeout=30)
    if code == 0:
        pytest.skip("the run finished before Ctrl-C reached it")
    assert code == 5
    assert (out / "checkpoint.bin").exists()
    with open(out / "summary.json") as f:
        assert json.load(f)["completed"] is False
    resumed = kelp.run_scenario(duration=120, out=out, resume=True)
    assert resumed["completed"] is True
    assert not (out / "checkpoint.bin").exists()
    for s in (whole, resumed):
        s.pop("wall_s")
        s.pop("realtime_factor")
    assert resumed == whole
    for name in ("timeseries.csv", "nodes.csv", "events.csv", "run.mcap"):
        assert (out / name).read_bytes() == (ref / name).read_bytes(), name


def test_resume_refuses_what_it_cannot_resume(tmp_path):
    # No checkpoint, another scenario's: kelp.StateError, the directory unchanged.
    with pytest.raises(kelp.StateError, match="no checkpoint"):
        kelp.run_scenario(duration=5, out=tmp_path / "none", resume=True)
    with pytest.raises(kelp.InvalidArgument, match="need out"):
        kelp.run_scenario(duration=5, checkpoint_every=1.0)
