"""kelp: dynamics of tethered marine robots (a BlueBoat ASV, a BlueROV2 Heavy ROV and the tether
between them in waves, wind and current), from Python.

The classes and functions are kelp's C++ library (header-only, Eigen) bound with pybind11 in the
extension module ``kelp._kelp``; every vector and matrix is a numpy array. Errors are
``kelp.InvalidArgument`` (a ``ValueError``: bad input, the message names the field),
``kelp.NumericalError`` (a ``RuntimeError``: a computation that could not proceed; the state is
left as it was), ``kelp.ScenarioError`` (an ``InvalidArgument`` naming a scenario's JSON path),
``kelp.StateError`` (an ``InvalidArgument``: a saved state that cannot be loaded), all
``kelp.Error``.

Areas: vehicles (``kelp.Vehicle``...), the environment (``kelp.Environment``, sea presets), the
catenary (``kelp.catenary``), the lumped-mass tether and the coupled system (``kelp.System``),
kelp::sim's scenarios (``kelp.run_scenario``), state files (``kelp.save_state``,
``kelp.load_state``; states pickle); see ``help(kelp.<name>)``.
"""

from ._kelp import *  # noqa: F401,F403
from ._kelp import (  # noqa: F401
    __version__,
    Error,
    InvalidArgument,
    NumericalError,
    ScenarioError,
    StateError,
)

from .scenario import run_scenario  # noqa: F401

# Pure-Python parts, one module each (their names are re-exported here).
from .batch import *  # noqa: F401,F403
from .learning import *  # noqa: F401,F403
