#!/usr/bin/env python3
"""A random-policy rollout of kelp.TetheredPairEnv (gymnasium's API): uniform random ROV wrenches
at 10 Hz until the episode ends; prints the return, the steps per second and why it ended.

    PYTHONPATH=<build>/python python3 examples/python/random_rollout.py [--seed 1]
        [--episodes 1] [--duration S] [--scale 0.3]
"""
import argparse
import time

import numpy as np

import kelp


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seed", type=int, default=1, help="seed of the first episode (and the policy)")
    p.add_argument("--episodes", type=int, default=1)
    p.add_argument("--duration", type=float, help="episode length [s] (default: the scenario's)")
    p.add_argument("--scale", type=float, default=0.3, help="the actions' amplitude (<= 1)")
    a = p.parse_args()

    scenario = {} if a.duration is None else {"duration": a.duration}
    env = kelp.TetheredPairEnv(scenario, control_period=0.1)
    policy = np.random.default_rng(a.seed)
    for episode in range(a.episodes):
        obs, info = env.reset(seed=a.seed + episode)
        assert obs.shape == env.observation_shape
        ret, steps = 0.0, 0
        cpu = time.process_time()
        while True:
            action = a.scale * policy.uniform(env.action_low, env.action_high)
            obs, reward, terminated, truncated, info = env.step(action)
            ret += reward
            steps += 1
            if terminated or truncated:
                break
        cpu = time.process_time() - cpu
        why = "truncated (end of the scenario)" if truncated else \
            f"terminated ({info.get('error', 'the ROV left the path')})"
        print(f"episode {episode} (seed {info['seed']}): {steps} steps, return {ret:.1f}, "
              f"final path error {info['path_error']:.2f} m, ROV energy {info['energy_j']:.0f} J, "
              f"{why}; {steps / cpu:.0f} steps per CPU second")


if __name__ == "__main__":
    main()
