"""The rl-baselines3-zoo hyperparameter file we ship (``baselines/ppo/rl_zoo3.yml``) is usable as is:
every key is one rl_zoo3 or SB3's PPO understands, every id is registered, its ``policy_kwargs``
build an SB3 policy and its ``env_kwargs`` build the env. (rl_zoo3 itself is not a dependency; the
README gives the command.)"""

from __future__ import annotations

import inspect
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

import visuomotor_gym

ZOO_FILE = Path(__file__).resolve().parents[1] / "baselines" / "ppo" / "rl_zoo3.yml"
# Keys rl_zoo3's ExperimentManager reads itself (rl_zoo3/exp_manager.py, 2.x); the rest go to the algorithm.
ZOO_KEYS = {"n_envs", "n_timesteps", "policy", "normalize", "env_kwargs", "env_wrapper", "frame_stack",
            "callback", "vec_env_wrapper", "normalize_kwargs", "policy_kwargs"}


@pytest.fixture(scope="module")
def zoo():
    return yaml.safe_load(ZOO_FILE.read_text())


def test_every_entry_is_a_registered_id_with_known_keys(zoo):
    from stable_baselines3 import PPO

    ppo_args = set(inspect.signature(PPO.__init__).parameters) - {"self", "env", "policy"}
    assert zoo, "empty file"
    for env_id, params in zoo.items():
        assert env_id in visuomotor_gym.ENV_IDS, env_id
        unknown = set(params) - ZOO_KEYS - ppo_args
        assert not unknown, f"{env_id}: keys neither rl_zoo3 nor PPO accept: {sorted(unknown)}"
        assert params["policy"] == "MlpPolicy" and params["n_timesteps"] > 0 and params["n_envs"] >= 1


def test_policy_and_env_kwargs_build_a_real_model(zoo):
    from stable_baselines3 import PPO

    for env_id, params in zoo.items():
        env = gym.make(env_id, **params.get("env_kwargs", {}))
        policy_kwargs = eval(params["policy_kwargs"], {"dict": dict})  # rl_zoo3 evaluates this string too
        algo_args = {k: v for k, v in params.items() if k not in ZOO_KEYS}
        model = PPO("MlpPolicy", env, policy_kwargs=policy_kwargs, device="cpu", **algo_args)
        assert model.policy.action_space.shape == env.action_space.shape
        env.close()
