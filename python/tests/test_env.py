"""kelp.TetheredPairEnv: gymnasium's reset/step contract, shapes and bounds, the same episode
for a seed, the documented reward, truncation and termination, errors for bad input, and no
memory growth over 1e5 steps."""
import numpy as np
import pytest

import kelp

SHORT = {"duration": 3.0}


def rollout(env, seed, steps=10):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    rng = np.random.default_rng(0)
    for _ in range(steps):
        obs, r, *_ = env.step(rng.uniform(-1, 1, env.action_shape))
        out.append(obs)
        out.append(np.array([r]))
    return np.concatenate(out)


def test_reset_and_step_follow_gymnasiums_contract():
    env = kelp.TetheredPairEnv(SHORT)
    assert env.action_shape == (6,) and env.observation_shape == (20,)
    assert np.array_equal(env.action_low, -np.ones(6)) and np.array_equal(env.action_high, np.ones(6))
    assert env.action_space.shape == (6,) and env.observation_space.shape == (20,)
    assert np.all(np.isinf(env.observation_space.low))
    assert np.array_equal(env.action_scale, [80, 80, 100, 10, 10, 15])
    out = env.reset(seed=3)
    assert isinstance(out, tuple) and len(out) == 2
    obs, info = out
    assert isinstance(obs, np.ndarray) and obs.shape == (20,) and obs.dtype == np.float64
    assert env.observation_space.contains(obs)
    assert isinstance(info, dict) and info["seed"] == 3 and info["time"] == 0.0
    action = env.action_space.sample()
    assert env.action_space.contains(action)
    out = env.step(action)
    assert len(out) == 5
    obs, reward, terminated, truncated, info = out
    assert obs.shape == (20,) and np.all(np.isfinite(obs))
    assert isinstance(reward, float) and reward <= 0.0
    assert terminated is False and truncated is False
    assert info["time"] == pytest.approx(0.1)
    assert set(info) >= {"time", "path_error", "energy_j", "saturated", "seed"}
    assert env.unwrapped is env
    env.close()


def test_the_same_seed_gives_the_same_episode():
    env = kelp.TetheredPairEnv(SHORT)
    a = rollout(env, 7)
    assert np.array_equal(a, rollout(env, 7))  # bit for bit
    assert np.array_equal(a, rollout(kelp.TetheredPairEnv(SHORT), 7))
    assert not np.array_equal(a, rollout(env, 8))
    # reset() without a seed continues the generator of the last seed given.
    e1, e2 = kelp.TetheredPairEnv(SHORT), kelp.TetheredPairEnv(SHORT)
    e1.reset(seed=5)
    e2.reset(seed=5)
    _, i1 = e1.reset()
    _, i2 = e2.reset()
    assert i1["seed"] == i2["seed"] != 5


def test_the_reward_is_minus_path_error_and_energy():
    env = kelp.TetheredPairEnv(SHORT, path_weight=2.0, energy_weight=0.05)
    _, info = env.reset(seed=1)
    for _ in range(5):
        e0 = info["energy_j"]
        obs, r, _, _, info = env.step(np.array([0.5, 0, 0.5, 0, 0, 0]))
        assert info["energy_j"] > e0
        assert obs[19] == info["path_error"]
        assert r == pytest.approx(-2.0 * obs[19] - 0.05 * (info["energy_j"] - e0), rel=1e-12)


def test_the_action_flies_the_rov():
    ahead, astern = kelp.TetheredPairEnv({"sea": "calm"}), kelp.TetheredPairEnv({"sea": "calm"})
    ahead.reset(seed=1)
    astern.reset(seed=1)
    for _ in range(20):
        fwd, *_ = ahead.step(np.array([1.0, 0, 0, 0, 0, 0]))
        back, *_ = astern.step(np.array([-1.0, 0, 0, 0, 0, 0]))
    assert fwd[6] > 0.2 and back[6] < -0.2  # surge speed u either way
    big, _ = kelp.TetheredPairEnv(SHORT).reset(seed=1)  # clipping: 5 acts as 1
    e1, e2 = kelp.TetheredPairEnv(SHORT), kelp.TetheredPairEnv(SHORT)
    e1.reset(seed=1)
    e2.reset(seed=1)
    assert np.array_equal(e1.step(np.array([5.0, 0, 0, 0, 0, 0]))[0],
                          e2.step(np.array([1.0, 0, 0, 0, 0, 0]))[0])
    boat = kelp.TetheredPairEnv({"sea": "calm"}, asv_action=True)
    assert boat.action_shape == (8,)
    with pytest.warns(DeprecationWarning, match="asv_action"):
        assert kelp.TetheredPairEnv({"sea": "calm"}, boat_action=True).action_shape == (8,)
    boat.reset(seed=1)
    for _ in range(10):
        obs, *_ = boat.step(np.array([0, 0, 0, 0, 0, 0, 1.0, -1.0]))
    assert obs[15] > 0.05  # the boat turned to starboard


def test_truncated_at_the_end_terminated_off_the_path():
    env = kelp.TetheredPairEnv({"duration": 1.0})
    env.reset(seed=1)
    for k in range(10):
        _, _, terminated, truncated, _ = env.step(np.zeros(6))
        assert truncated == (k == 9) and not terminated
    obs, r, terminated, truncated, info = env.step(np.zeros(6))
    assert r == 0.0 and truncated and info["time"] == pytest.approx(1.0)  # nothing happens
    tight = kelp.TetheredPairEnv(SHORT, max_path_error=0.3)
    tight.reset(seed=1)
    for _ in range(30):
        obs, _, terminated, truncated, info = tight.step(np.array([0, 1.0, 0, 0, 0, 0]))
        if terminated:
            break
    assert terminated and not truncated and obs[19] > 0.3 and "error" not in info
    _, info = tight.reset(seed=2)
    assert info["time"] == 0.0


def test_bad_input_raises_with_the_message():
    env = kelp.TetheredPairEnv(SHORT)
    env.reset(seed=1)
    with pytest.raises(kelp.InvalidArgument, match=r"shape \(6,\)"):
        env.step(np.zeros(5))
    with pytest.raises(ValueError, match=r"action\[2\] is not finite"):
        env.step(np.array([0, 0, np.nan, 0, 0, 0]))
    _, _, _, _, info = env.step(np.zeros(6))
    assert info["time"] == pytest.approx(0.1)  # the bad steps stepped nothing
    with pytest.raises(kelp.InvalidArgument, match="control_period"):
        kelp.TetheredPairEnv(SHORT, control_period=0.015)
    with pytest.raises(kelp.ScenarioError, match="/sea"):
        kelp.TetheredPairEnv({"sea": "stormy"})
    with pytest.raises(kelp.InvalidArgument, match="seed"):
        env.reset(seed=-1)
    with pytest.raises(kelp.InvalidArgument, match="scenario"):
        kelp.TetheredPairEnv(42)


def test_no_memory_growth_over_1e5_steps():
    env = kelp.TetheredPairEnv({"duration": 1001.0}, control_period=0.01, max_path_error=1e9)
    env.reset(seed=1)
    action = np.array([0.1, 0, 0.2, 0, 0, 0.05])

    def rss():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096

    for _ in range(10000):
        env.step(action)
    before = rss()
    for _ in range(90000):
        obs, r, terminated, truncated, info = env.step(action)
    grown = rss() - before
    assert info["time"] == pytest.approx(1000.0) and not terminated
    assert grown < 2 * 2**20, f"resident memory grew by {grown} bytes over 9e4 steps"
