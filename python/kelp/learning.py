"""kelp.TetheredPairEnv: the tethered pair as a reinforcement-learning environment with
gymnasium's API (https://gymnasium.farama.org/api/env/), without depending on gymnasium.

    import kelp, numpy as np
    env = kelp.TetheredPairEnv()                 # the default world, 0.1 s per step
    obs, info = env.reset(seed=1)
    while True:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break

With gymnasium installed, one line makes it a ``gymnasium.Env`` (its spaces are then
``gymnasium.spaces.Box``)::

    class Env(kelp.TetheredPairEnv, gymnasium.Env): pass
"""

import warnings as _warnings

import numpy as _np

from . import _kelp
from .batch import _scenario_source

__all__ = ["Box", "TetheredPairEnv"]


class Box:
    """A box in R^n, shaped and bounded like ``gymnasium.spaces.Box`` (``low``, ``high``,
    ``shape``, ``dtype``, ``sample()``, ``contains()``, ``seed()``)."""

    def __init__(self, low, high, shape, dtype=_np.float64):
        self.shape = tuple(shape)
        self.dtype = _np.dtype(dtype)
        self.low = _np.broadcast_to(_np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = _np.broadcast_to(_np.asarray(high, dtype=self.dtype), self.shape).copy()
        self._rng = _np.random.default_rng()

    def seed(self, seed=None):
        """Seeds sample()'s generator."""
        self._rng = _np.random.default_rng(seed)
        return [seed]

    def sample(self):
        """A uniform sample of the box (of a standard normal where it is unbounded)."""
        finite = _np.isfinite(self.low) & _np.isfinite(self.high)
        x = self._rng.standard_normal(self.shape)
        u = self._rng.uniform(_np.where(finite, self.low, 0.0), _np.where(finite, self.high, 1.0))
        return _np.where(finite, u, x).astype(self.dtype)

    def contains(self, x):
        """True when x has the box's shape and lies within its bounds."""
        x = _np.asarray(x)
        return bool(x.shape == self.shape and _np.all(x >= self.low) and _np.all(x <= self.high))

    __contains__ = contains

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


def _box(low, high, shape):
    """A gymnasium.spaces.Box when gymnasium is importable, else kelp's Box."""
    try:
        import gymnasium  # noqa: F401  (optional)
        return gymnasium.spaces.Box(low=low, high=high, shape=shape, dtype=_np.float64)
    except ImportError:
        return Box(low, high, shape)


class TetheredPairEnv:
    """The tethered pair of a scenario (a BlueBoat and a BlueROV2 Heavy on a tether, in its sea)
    as an environment with gymnasium's API: ``reset(seed=None, options=None) -> (obs, info)``,
    ``step(action) -> (obs, reward, terminated, truncated, info)``.

    **Action** (``action_shape`` (6,), or (8,) with ``asv_action``; ``action_space`` is the box
    [-1, 1]^n, values outside are clipped): the ROV's body wrench [X, Y, Z, K, M, N] as fractions
    of ``action_scale`` = (80 N, 80 N, 100 N, 10 N m, 10 N m, 15 N m) (the ROV controller's PID
    output limits), allocated to its eight T200 thrusters through the same allocation and
    saturation as the ROV's controller (``control::allocate_wrench``, split saturation), at its
    battery's voltage; with ``asv_action`` two more entries, the boat's port and starboard thrust
    as fractions of the scenario's ``asv_thrust_clip`` (25 N); otherwise the boat's controller
    follows the ROV. The action is held for ``control_period`` seconds (0.1 s by default; a
    multiple of the system's 10 ms step).

    **Observation** (``observation_shape`` (20,), float64, unbounded): [0:3] the ROV's position
    minus its current survey waypoint (NED, m); [3:6] its roll, pitch, yaw (rad); [6:12] its body
    velocity (u, v, w m/s; p, q, r rad/s); [12:15] the boat's position minus the ROV's (NED, m);
    [15] the boat's yaw (rad); [16:19] the tether's force on the ROV (NED, N); [19] the ROV's
    path error e: its distance from the survey leg it flies (m), as in kelp-tethered-pair's
    summary.

    **Reward** per step: ``-path_weight * e - energy_weight * dE``, e the path error after the
    step (m) and dE the energy the ROV's battery delivered during it (J; 0 without propulsion).
    Defaults 1 /m and 0.01 /J: 1 m of error costs as much as 100 J.

    **Episode**: the scenario's survey (by default an 8 m square at 5 m depth, the ROV's
    controller's waypoints advance as the ROV reaches them). ``truncated`` once the scenario's
    duration (120 s by default, i.e. 1200 steps) is simulated; ``terminated`` when the path error
    exceeds ``max_path_error`` (20 m) or a step fails (``info["error"]`` says why; the world is
    as before the failing step). Stepping an ended episode does nothing (reward 0) until reset().

    **Seeds**: ``reset(seed=s)`` builds the world with sea seed s (waves, gusts): the same seed
    gives the same episode bit for bit. ``reset()`` without a seed draws the next episode's seed
    from a generator seeded by the last given seed (from entropy if none was).

    ``info``: ``time`` (s), ``path_error`` (m), ``energy_j`` (ROV battery since reset, J),
    ``saturated`` (the action asked for more than the thrusters give), ``seed``, and ``error``
    when a step failed.
    """

    metadata = {"render_modes": []}
    render_mode = None
    reward_range = (-float("inf"), 0.0)

    def __init__(self, scenario=None, control_period=0.1, asv_action=False,
                 max_path_error=20.0, path_weight=1.0, energy_weight=0.01, boat_action=None):
        """An environment over `scenario` (None: the embedded default run; a dict; a path to a
        scenario file). Raises kelp.ScenarioError naming a bad key, kelp.InvalidArgument for bad
        options (a control period that is not a positive multiple of 0.01 s, ...). `boat_action` is
        asv_action's former name (deprecated)."""
        if boat_action is not None:
            _warnings.warn("kelp.TetheredPairEnv: boat_action is now asv_action",
                           DeprecationWarning, stacklevel=2)
            asv_action = boat_action
        text, name = _scenario_source(scenario)
        self._core = _kelp.PairEnvCore(text, name, float(control_period), bool(asv_action),
                                       float(max_path_error), float(path_weight),
                                       float(energy_weight))
        self.control_period = float(control_period)
        self.action_shape = (self._core.action_size,)
        self.observation_shape = (_kelp.PairEnvCore.observation_size,)
        self.action_low = -_np.ones(self.action_shape)
        self.action_high = _np.ones(self.action_shape)
        self.observation_low = _np.full(self.observation_shape, -_np.inf)
        self.observation_high = _np.full(self.observation_shape, _np.inf)
        self.action_scale = _np.array(_kelp.PairEnvCore.action_scale)
        self.action_space = _box(-1.0, 1.0, self.action_shape)
        self.observation_space = _box(-_np.inf, _np.inf, self.observation_shape)
        self._seeds = None  # generator of the seeds of reset() without one
        self._seed = None

    def reset(self, *, seed=None, options=None):
        """Starts a new episode; returns (observation, info). `seed`: the sea's seed (an int
        >= 0); None: the next seed of the environment's generator. `options` is unused."""
        if seed is not None:
            seed = int(seed)
            if seed < 0:
                raise _kelp.InvalidArgument(f"reset: seed must be >= 0, got {seed}")
            self._seeds = _np.random.default_rng(seed)
        else:
            if self._seeds is None:
                self._seeds = _np.random.default_rng()
            seed = int(self._seeds.integers(0, 2**63 - 1))
        self._seed = seed
        self._core.reset(seed)
        return self._core.observation(), self._info()

    def step(self, action):
        """Applies `action` (shape action_shape) for one control period; returns (observation,
        reward, terminated, truncated, info). Raises kelp.InvalidArgument for a wrongly shaped
        or non-finite action (nothing is stepped)."""
        reward, terminated, truncated = self._core.step(action)
        return self._core.observation(), reward, terminated, truncated, self._info()

    def _info(self):
        c = self._core
        info = {"time": c.time, "path_error": c.path_error, "energy_j": c.energy_drawn,
                "saturated": c.saturated, "seed": self._seed}
        if c.error:
            info["error"] = c.error
        return info

    def summary(self):
        """The episode so far as kelp-tethered-pair's summary.json (without the wall time)."""
        return self._core.summary()

    @property
    def unwrapped(self):
        """The environment itself (gymnasium's API)."""
        return self

    @property
    def np_random(self):
        """The generator of the seeds of reset() without a seed (gymnasium's API)."""
        if self._seeds is None:
            self._seeds = _np.random.default_rng()
        return self._seeds

    def render(self):
        """No rendering (render_modes is empty)."""
        return None

    def close(self):
        """Nothing to release."""

    def __repr__(self):
        return f"kelp.TetheredPairEnv(action_shape={self.action_shape}, " \
               f"control_period={self.control_period})"
