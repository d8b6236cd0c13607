"""kelp.Batch: many independent worlds of one scenario at once, for Monte Carlo over seeds and
for learning (a vectorised environment).

    import kelp
    b = kelp.Batch("scenario.json", n=64, seed=1)   # or a dict, or None for the default run
    b.step(1200)                                     # 120 s at 0.1 s per step, controllers flying
    rms = [b.summary(i)["auv"]["rms_path_error_m"] for i in range(b.n)]

See ``help(kelp.Batch)`` for the arrays it exposes (numpy views, no copy).
"""

import json as _json
import os as _os
import warnings as _warnings

from . import _kelp

__all__ = ["Batch"]


def _scenario_source(scenario):
    """(JSON text, name for errors) of a scenario given as None (the embedded default run), a
    dict (the scenario file's content) or a path to a scenario file."""
    if scenario is None:
        return "{}", "(embedded default)"
    if isinstance(scenario, dict):
        return _json.dumps(scenario), "(dict)"
    if isinstance(scenario, (str, bytes, _os.PathLike)):
        path = _os.fsdecode(scenario)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read(), path
        except OSError as e:
            raise _kelp.InvalidArgument(f"{path}: cannot read the scenario file ({e.strerror})")
    raise _kelp.InvalidArgument(
        "scenario must be None, a dict or a path to a scenario file, got "
        + type(scenario).__name__)


class Batch(_kelp.Batch):
    __doc__ = _kelp.Batch.__doc__

    def __init__(self, scenario=None, n=64, seed=1, threads=None, control_period=0.1,
                 asv_action=False, max_path_error=20.0, path_weight=1.0, energy_weight=0.01,
                 boat_action=None):
        """n worlds of `scenario` (None: the embedded default run; a dict; a path) with sea
        seeds seed, seed + 1, ..., seed + n - 1, stepped on `threads` threads (None: one per
        CPU, at most n). One step() is `control_period` seconds (a multiple of 0.01 s); the
        environment options (asv_action, max_path_error, path_weight, energy_weight) are
        TetheredPairEnv's (`boat_action`: asv_action's former name, deprecated). Raises
        kelp.ScenarioError naming a bad key, kelp.InvalidArgument."""
        if boat_action is not None:
            _warnings.warn("kelp.Batch: boat_action is now asv_action", DeprecationWarning,
                           stacklevel=2)
            asv_action = boat_action
        text, name = _scenario_source(scenario)
        if int(n) < 1:
            raise _kelp.InvalidArgument(f"Batch: n must be at least 1, got {n}")
        if threads is not None and int(threads) < 1:
            raise _kelp.InvalidArgument(f"Batch: threads must be at least 1, got {threads}")
        super().__init__(text, name, int(n), int(seed), 0 if threads is None else int(threads),
                         float(control_period), bool(asv_action), float(max_path_error),
                         float(path_weight), float(energy_weight))

    def __repr__(self):
        return f"kelp.Batch(n={self.n}, seed={self.seed}, threads={self.threads})"
