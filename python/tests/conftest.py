"""Shared fixtures of kelp's Python tests. CTest runs each test_*.py with PYTHONPATH set to the
build tree's package (python/CMakeLists.txt); KELP_TETHERED_PAIR names the CLI when it is built
and KELP_TEST_SCENARIOS the shipped scenario files."""

import os
import pathlib

import pytest


@pytest.fixture(scope="session")
def scenarios_dir():
    """apps/tethered_pair/scenarios of the source tree."""
    d = os.environ.get("KELP_TEST_SCENARIOS")
    if d is None:
        d = pathlib.Path(__file__).resolve().parents[2] / "apps" / "tethered_pair" / "scenarios"
    return pathlib.Path(d)


@pytest.fixture(scope="session")
def tethered_pair_cli():
    """The kelp-tethered-pair program of this build (skips when it was not built)."""
    p = os.environ.get("KELP_TETHERED_PAIR")
    if not p or not os.path.exists(p):
        pytest.skip("kelp-tethered-pair is not built (KELP_BUILD_APPS=OFF)")
    return p
