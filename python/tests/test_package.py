"""The package itself: it imports from the build tree, has a version and docstrings, and turns
kelp's C++ exceptions into its Python ones with the C++ message."""

import pathlib
import re

import pytest

import kelp


def test_imports_with_version_and_docs():
    # kelp.__version__ is the string of include/kelp/version.hpp, the one place it is written.
    header = pathlib.Path(__file__).resolve().parents[2] / "include" / "kelp" / "version.hpp"
    written = re.search(r'#define KELP_VERSION_STRING "([^"]+)"', header.read_text()).group(1)
    assert kelp.__version__ == written
    assert kelp.__version__.count(".") == 2
    assert "tethered" in kelp.__doc__
    assert kelp._kelp.__file__.endswith(".so")


@pytest.mark.parametrize(
    "kind, python_type, builtin",
    [
        ("invalid_argument", kelp.InvalidArgument, ValueError),
        ("numerical_error", kelp.NumericalError, RuntimeError),
        ("scenario_error", kelp.ScenarioError, ValueError),
        ("state_error", kelp.StateError, ValueError),
        ("error", kelp.Error, RuntimeError),
    ],
)
def test_cpp_exceptions_become_kelp_exceptions_with_their_message(kind, python_type, builtin):
    with pytest.raises(python_type, match="the message from C\\+\\+") as info:
        kelp._kelp._raise_for_test(kind, "the message from C++")
    assert isinstance(info.value, builtin)
    assert isinstance(info.value, kelp.Error)
    assert str(info.value) == "the message from C++"


def test_exception_hierarchy_mirrors_cpp():
    assert issubclass(kelp.InvalidArgument, ValueError)
    assert issubclass(kelp.NumericalError, RuntimeError)
    assert issubclass(kelp.ScenarioError, kelp.InvalidArgument)
    assert issubclass(kelp.StateError, kelp.InvalidArgument)
    assert not issubclass(kelp.NumericalError, ValueError)
    # Other C++ exceptions keep pybind11's translation.
    with pytest.raises(RuntimeError) as info:
        kelp._kelp._raise_for_test("unknown", "x")
    assert not isinstance(info.value, kelp.Error)
