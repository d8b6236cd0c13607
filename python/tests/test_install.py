"""The package installs under the prefix's Python directory (README's recipe, the `python`
component alone here) and imports from there, without the build tree."""

import os
import subprocess
import sys

import pytest


def test_installed_package_imports(tmp_path):
    build, cmake = os.environ.get("KELP_BUILD_DIR"), os.environ.get("KELP_CMAKE")
    if not build or not cmake:
        pytest.skip("run by CTest, which names the build tree")
    prefix = tmp_path / "prefix"
    subprocess.run([cmake, "--install", build, "--component", "python", "--prefix", str(prefix)],
                   check=True, stdout=subprocess.DEVNULL)
    site = prefix / os.environ["KELP_PYTHON_INSTALL_DIR"]
    assert (site / "kelp" / "__init__.py").exists()
    env = dict(os.environ, PYTHONPATH=str(site))
    out = subprocess.run(
        [sys.executable, "-c",
         "import kelp; print(kelp.__file__); "
         "print(kelp.catenary(horizontal=6, vertical=2, length=10, weight_per_length=1).status)"],
        check=True, capture_output=True, text=True, env=env, cwd=str(tmp_path)).stdout.split()
    assert out[0].startswith(str(site)) and out[1] == "converged"
