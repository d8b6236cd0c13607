"""kelp.Batch: n worlds of seeds seed..seed+n-1, the same numbers whatever the thread count,
(n, ...) read-only numpy views of the batch's memory that outlive it, errors for bad input."""
import gc

import numpy as np
import pytest

import kelp

SHORT = {"duration": 3.0}
ARRAYS = ("auv_position", "auv_attitude", "auv_velocity", "asv_position", "asv_attitude",
          "asv_velocity", "tension", "observation", "reward", "time", "terminated", "truncated")


def snapshot(b):
    return {k: np.array(getattr(b, k)) for k in ARRAYS}


def actions(n, call, size=6):
    k = np.arange(n * size, dtype=float).reshape(n, size)
    return np.sin(0.7 * k + 1.3 * call)


def run(threads, n=5):
    b = kelp.Batch(SHORT, n=n, seed=11, threads=threads)
    assert b.threads == min(threads, n)
    out = [snapshot(b)]
    b.step(3)  # the controllers fly
    out.append(snapshot(b))
    for call in range(3):
        b.step(2, actions(n, call))
        out.append(snapshot(b))
    return out


def test_shapes_and_zero_copy_views():
    b = kelp.Batch(SHORT, n=4, seed=1, threads=2)
    assert len(b) == b.n == 4 and b.action_size == 6
    shapes = {"auv_position": (4, 3), "auv_attitude": (4, 4), "auv_velocity": (4, 6),
              "asv_position": (4, 3), "asv_attitude": (4, 4), "asv_velocity": (4, 6),
              "tension": (4, 2), "observation": (4, 20), "reward": (4,), "time": (4,),
              "terminated": (4,), "truncated": (4,)}
    for name, shape in shapes.items():
        a = getattr(b, name)
        assert a.shape == shape, name
        assert np.shares_memory(a, getattr(b, name)), name  # a view of the batch, not a copy
        assert not a.flags.writeable, name
    assert b.terminated.dtype == np.bool_
    # A view read once follows the batch.
    p, t = b.auv_position, b.time
    before = p.copy()
    b.step(2)
    assert np.all(t == pytest.approx(0.2))
    assert not np.array_equal(p, before)
    assert np.array_equal(p, b.auv_position)
    with pytest.raises(ValueError):
        p[0, 0] = 1.0
    # Unit quaternions, positions where the scenario puts them (the ROV ~5 m down).
    assert np.allclose(np.linalg.norm(b.auv_attitude, axis=1), 1.0)
    assert np.all(b.auv_position[:, 2] > 3.0)


def test_a_view_keeps_its_batch_alive():
    b = kelp.Batch(SHORT, n=3, seed=1, threads=2)
    b.step(1)
    p, obs, term = b.auv_position, b.observation, b.truncated
    expected = p.copy()
    del b
    gc.collect()
    junk = [np.random.rand(1000) for _ in range(100)]  # reuse freed memory, if any
    assert np.array_equal(p, expected)
    assert obs.shape == (3, 20) and np.all(np.isfinite(obs)) and not term.any()
    del junk


def test_the_numbers_do_not_depend_on_the_thread_count():
    one = run(1)
    for threads in (2, 3, 5):
        other = run(threads)
        for a, b in zip(one, other):
            for k in ARRAYS:
                assert np.array_equal(a[k], b[k]), (threads, k)  # bit for bit


def test_world_i_is_the_scenario_with_seed_plus_i():
    b = kelp.Batch(SHORT, n=3, seed=20, threads=2)
    b.step(4)
    for i in range(3):
        alone = kelp.Batch(SHORT, n=1, seed=20 + i, threads=1)
        alone.step(4)
        assert np.array_equal(b.auv_position[i], alone.auv_position[0])
        assert b.summary(i)["scenario"]["seed"] == 20 + i
    assert not np.array_equal(b.auv_position[0], b.auv_position[1])  # other seas
    # With actions, world i is TetheredPairEnv's episode of seed 20 + i.
    a = actions(3, 0)
    b2 = kelp.Batch(SHORT, n=3, seed=20, threads=2)
    b2.step(5, a)
    env = kelp.TetheredPairEnv(SHORT)
    for i in range(3):
        env.reset(seed=20 + i)
        total = 0.0
        for _ in range(5):
            obs, r, *_ = env.step(a[i])
            total += r
        assert np.array_equal(b2.observation[i], obs)
        assert b2.reward[i] == total


def test_episodes_end_and_reset():
    b = kelp.Batch({"duration": 1.0}, n=2, seed=1, threads=2)
    b.step(9)
    assert not b.truncated.any()
    b.step(5)
    assert b.truncated.all() and not b.terminated.any()
    assert np.all(b.time == pytest.approx(1.0))
    b.reset(seed=1)
    assert not b.truncated.any() and np.all(b.time == 0.0)
    # Off the path: terminated.
    off = kelp.Batch(SHORT, n=2, seed=1, threads=1, max_path_error=0.3)
    off.step(20, np.tile([0, 1.0, 0, 0, 0, 0], (2, 1)))
    assert off.terminated.all() and not off.truncated.any()
    assert off.error(0) == ""


def test_bad_input_raises_with_the_message():
    b = kelp.Batch(SHORT, n=2, seed=1, threads=1)
    with pytest.raises(kelp.InvalidArgument, match=r"shape \(2, 6\), got \(3, 6\)"):
        b.step(1, np.zeros((3, 6)))
    with pytest.raises(ValueError, match=r"actions\[1, 2\] is not finite"):
        a = np.zeros((2, 6))
        a[1, 2] = np.nan
        b.step(1, a)
    assert np.all(b.time == 0.0)  # nothing stepped
    with pytest.raises(kelp.InvalidArgument, match="n_steps"):
        b.step(-1)
    with pytest.raises(kelp.ScenarioError, match="/tether/lenght"):
        kelp.Batch({"tether": {"lenght": 10}}, n=2)
    with pytest.raises(kelp.InvalidArgument, match="n must be"):
        kelp.Batch(SHORT, n=0)
    with pytest.raises(kelp.InvalidArgument, match="control_period"):
        kelp.Batch(SHORT, n=1, control_period=0.015)
    with pytest.raises(IndexError):
        b.summary(5)


def test_no_memory_growth_over_1e5_steps():
    b = kelp.Batch({"duration": 1001.0}, n=2, seed=1, threads=2, control_period=0.01,
                   max_path_error=1e9)
    a = actions(2, 0) * 0.2

    def rss():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096

    for _ in range(10000):
        b.step(1, a)
        _ = b.auv_position
    before = rss()
    for _ in range(90000):
        b.step(1, a)
        _ = b.auv_position
    grown = rss() - before
    assert np.all(b.time == pytest.approx(1000.0))
    assert not b.terminated.any()
    assert grown < 2 * 2**20, f"resident memory grew by {grown} bytes over 9e4 steps"
