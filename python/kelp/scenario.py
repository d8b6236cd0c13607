"""kelp.run_scenario: a whole run of the tethered pair, exactly as the kelp-tethered-pair program
runs it (both call the C++ function kelp::sim::run_scenario)."""

import json
import os

from . import _kelp

__all__ = ["run_scenario"]


def run_scenario(path_or_dict=None, duration=None, seed=None, out=None, timeseries=False,
                 kernel=None, deterministic=False, checkpoint_every=0.0, resume=False):
    """Runs a scenario of the tethered pair, or of any fleet, to its end and returns its summary.

    This is what ``kelp-tethered-pair`` runs: the same scenario, duration and seed give the same
    numbers, bit for bit (``--scenario``, ``--duration``, ``--seed``, ``--out``, ``--kernel``,
    ``--deterministic``).

    Parameters
    ----------
    path_or_dict : str, os.PathLike, dict or None
        A scenario file (JSON; its schema is in apps/tethered_pair/README.md), a scenario as a
        dict of the same keys, or None for the embedded default run. Errors in a dict name
        ``(dict)`` and the JSON path of the offending key.
    duration : float, optional
        Simulated time [s], overriding the scenario's.
    seed : int, optional
        Seed of the waves and gusts (>= 0), overriding the scenario's.
    out : str or os.PathLike, optional
        Directory to write the program's files in: timeseries.csv, nodes.csv and summary.json
        (no plots). None: nothing is written.
    timeseries : bool
        Also return the samples (the rows of timeseries.csv, at the scenario's log rate, at full
        precision instead of the CSV's 6 digits) as a dict of 1-D numpy arrays keyed by the CSV's
        column names ("t", "asv_x", ..., "tension_auv", ...). A fleet scenario (one with a
        ``"fleet"`` key: any vehicles, point masses, anchors and tethers) returns its own summary
        and columns ("t", "rov.x", ..., "tether.tension_end", ...), read back from its CSV (6
        significant digits).
    kernel : str, optional
        The wave kernel's instruction path: "auto", "portable", "avx2" or "avx512".
    deterministic : bool
        The same numbers on every CPU: the kernel "portable".
    checkpoint_every : float
        With ``out``: write ``out/checkpoint.bin`` every this many simulated seconds and when the
        run is stopped (Ctrl-C), for ``resume`` (docs/checkpoints.md). 0: none. A run that
        completes removes it.
    resume : bool
        Continue the run in ``out`` from its checkpoint instead of starting it: the scenario and
        overrides must be those it started with (else ``kelp.StateError``). Its files end as an
        uninterrupted run's; ``timeseries=True`` returns the samples from the checkpoint on.

    Returns
    -------
    dict, or (dict, dict of numpy.ndarray) with ``timeseries=True``
        The summary, equal to the program's summary.json (its wall time ``wall_s`` and
        ``realtime_factor`` aside, which differ from run to run); JSON's null (a NaN) is None.

    Raises
    ------
    kelp.ScenarioError
        A scenario kelp refuses (a ValueError), naming the file and the JSON path.
    kelp.InvalidArgument
        A bad override (duration <= 0, seed < 0, an unknown kernel).
    kelp.NumericalError
        A step that could not be completed.
    kelp.StateError
        ``resume`` with a checkpoint that is missing, corrupted, of another scenario or kelp
        version, or that does not match the files in ``out`` (nothing in ``out`` changed).
    KeyboardInterrupt
        Ctrl-C (or any exception a Python signal handler raises) during the run: the run stops
        within a simulated second, after the step it is in, and leaves its files in ``out``
        whole (summary.json with ``"completed": false`` and the time reached ``simulated_s``)
        before the exception is raised.
    """
    file = text = None
    if isinstance(path_or_dict, dict):
        text = json.dumps(path_or_dict, allow_nan=False)
    elif path_or_dict is not None:
        file = os.fspath(path_or_dict)
    if isinstance(seed, bool) or (seed is not None and int(seed) != seed):
        raise _kelp.InvalidArgument("run_scenario: seed must be an integer >= 0")
    summary, columns = _kelp._run_scenario(
        file, text, None if duration is None else float(duration),
        None if seed is None else int(seed), kernel, bool(deterministic),
        None if out is None else os.fspath(out), bool(timeseries), float(checkpoint_every),
        bool(resume))
    summary = json.loads(summary)
    return (summary, columns) if timeseries else summary
