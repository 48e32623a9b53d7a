"""Checks every walker-family env suite runs the same way (walk, stones, dodge): one place for the
rollout helper, the Gymnasium/SB3 checkers and the determinism-and-pickling check."""

from __future__ import annotations

import pickle

import numpy as np


def rollout(env, seed, actions):
    """Observations (and each step's reward appended) of ``actions`` from ``reset(seed)``, to the end."""
    obs, info = env.reset(seed=seed)
    out = [obs.copy()]
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        out.append(np.append(obs, r))
        if term or trunc:
            break
    return out


def run_env_checkers(make) -> None:
    """Gymnasium's and SB3's env checkers on ``make()``, and Gymnasium's on the dict observation."""
    from gymnasium.utils.env_checker import check_env as gym_check
    from stable_baselines3.common.env_checker import check_env as sb3_check

    gym_check(make(), skip_render_check=True)
    sb3_check(make(), warn=True)
    gym_check(make(obs_mode="dict"), skip_render_check=True)


def assert_reproducible_and_picklable(make, actions, seed: int = 3) -> None:
    """The same seed and actions give the same episode, and a mid-episode pickle goes on identically."""
    a = rollout(make(), seed, actions)
    b = rollout(make(), seed, actions)
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))
    env = make()
    env.reset(seed=seed)
    for act in actions[:20]:
        env.step(act)
    clone = pickle.loads(pickle.dumps(env))
    for act in actions[20:40]:
        o1, r1, t1, _, _ = env.step(act)
        o2, r2, t2, _, _ = clone.step(act)
        assert np.array_equal(o1, o2) and r1 == r2 and t1 == t2
