"""The Python examples (examples/python/) run to the end, briefly, and write what they say."""
import os
import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


def run(script, *args, cwd):
    env = dict(os.environ, MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_scenario_plot(tmp_path):
    pytest.importorskip("matplotlib")
    out = run("scenario_plot.py", "--duration", "5", "--out", "run.png", cwd=tmp_path)
    assert "ROV RMS path error" in out
    assert (tmp_path / "run.png").stat().st_size > 10000


def test_monte_carlo(tmp_path):
    pytest.importorskip("matplotlib")
    out = run("monte_carlo.py", "--n", "4", "--duration", "3", "--threads", "2", "--hist",
              "mc.png", cwd=tmp_path)
    assert "4 worlds x 30 steps" in out and "ROV RMS path error" in out
    assert (tmp_path / "mc.png").exists()


def test_random_rollout(tmp_path):
    out = run("random_rollout.py", "--duration", "5", "--episodes", "2", cwd=tmp_path)
    # ": 50 steps," per episode line (the throughput at the end, "N steps per CPU second", may
    # end in 50 too).
    assert out.count(": 50 steps,") == 2 and "truncated" in out
