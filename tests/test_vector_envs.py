"""``gymnasium.make_vec`` over every registered id, sync and async: a reset and 3 steps each.

Gymnasium stacks each ``info`` key into one array per key, shaped by the first sub-env's value, so every
family's reset and step ``info`` must have fixed shapes whatever the seed (ObstacleWalk's ``obstacles``
is padded to the scene's obstacle pool, with ``n_obstacles``).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # registers the ids

SEEDS = [10, 11]  # ObstacleWalk courses of 6 and 4 obstacles
IDS = sorted(i for i, spec in gym.registry.items()
             if isinstance(spec.entry_point, str) and spec.entry_point.startswith("visuomotor_gym"))


def test_every_id_of_the_package_is_listed():
    assert set(IDS) == set(visuomotor_gym.ENV_IDS) and len(IDS) >= 29


def _run(env_id: str, mode: str) -> None:
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode=mode)
    try:
        obs, info = envs.reset(seed=SEEDS)
        assert obs.shape == (2, *envs.single_observation_space.shape) and np.all(np.isfinite(obs))
        for _ in range(3):
            obs, reward, _, _, info = envs.step(np.zeros((2, *envs.single_action_space.shape),
                                                                          np.float32))
            assert np.all(np.isfinite(obs)) and reward.shape == (2,)
            assert info["time"].shape == (2,)
    finally:
        envs.close()


@pytest.mark.parametrize("env_id", IDS)
def test_make_vec_sync(env_id):
    _run(env_id, "sync")


@pytest.mark.parametrize("env_id", IDS)
def test_make_vec_async(env_id):
    _run(env_id, "async")


def test_walk_reset_info_is_padded_with_a_count():
    envs = gym.make_vec("ObstacleWalk-v0", num_envs=2, vectorization_mode="sync")
    try:
        _, info = envs.reset(seed=SEEDS)
    finally:
        envs.close()
    counts = info["n_obstacles"]
    assert counts[0] != counts[1], f"seeds {SEEDS} should give courses of different lengths"
    for k, seed in enumerate(SEEDS):
        single = gym.make("ObstacleWalk-v0").unwrapped
        single.reset(seed=seed)
        np.testing.assert_array_equal(info["obstacles"][k, : counts[k]], single.course.obstacles)
        assert np.isnan(info["obstacles"][k, counts[k]:]).all()
