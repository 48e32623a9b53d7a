"""SB3 SAC in the RL baseline table: ``train.py --sac`` trains the free-gaze recipe with the hyperparameter
file's ``sac`` section, and its pickle-free ``ppo-npz`` file (``network.squash = "tanh"``) reproduces
``SAC.predict(obs, deterministic=True)`` bit for bit, rescaling to the action space."""

import json

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.ppo import table, train
from visuomotor_gym.baselines.ppo.agent import (
    PolicyFileError,
    PPOAgent,
    _write_npz,
    npz_from_model,
    pack_npz,
    prove_npz_equals_model,
    read_npz,
)

FREE = ["--no-progress-bar", "--belief", "no", "--hand-action", "absolute", "--gaze-action", "free"]


def test_sac_hyperparameters_are_the_zoo_mujoco_ones_over_the_free_gaze_recipe():
    for env_id in ("EyeCatch-v0", "EyeCatchOracle-v0", "ShelfReach-v0", "ShelfReachOracle-v0"):
        ppo = train.load_config(train.parse_args(["--env", env_id, *FREE]))
        sac = train.load_config(train.parse_args(["--env", env_id, "--sac", *FREE]))
        assert sac["algo"] == "SAC" and sac["n_envs"] == 1
        assert (sac["learning_rate"], sac["batch_size"], sac["tau"], sac["gamma"]) == (3e-4, 256, 0.005, 0.99)
        assert sac["learning_starts"] == 10_000 and sac["ent_coef"] == "auto" and sac["gradient_steps"] == 1
        assert sac["normalize_obs"] is True and sac["normalize_reward"] is False
        # the free-gaze recipe's env wrappers and named training-only shaping are the PPO cells'
        for key in ("env_kwargs", "intercept_shaping", "belief", "hand_action", "gaze_action"):
            assert sac[key] == ppo[key], (env_id, key)
    with pytest.raises(train.TrainArgumentError, match="no entry for ObstacleWalk-v0"):
        train.load_config(train.parse_args(["--env", "ObstacleWalk-v0", "--sac"]))
    with pytest.raises(train.TrainArgumentError, match="exclude each other"):
        train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--sac", "--recurrent"]))
    assert table.ALGOS["sac"] == "SAC"


def test_sac_trains_packs_pickle_free_and_plays_the_models_deterministic_actions(tmp_path):
    run = train.main(["--env", "EyeCatch-v0", "--sac", "--timesteps", "300", "--out", str(tmp_path),
                      "--run-name", "t", *FREE, "--set", "learning_starts=100", "eval_freq=100000",
                      "eval_episodes=1", "checkpoint_freq=100000"])
    meta = json.loads((run / "ppo_meta.json").read_text())
    assert meta["algo"] == "SAC" and meta["timesteps"] == 300 and "obs_mean" in meta
    data = pack_npz(run)  # proves equal actions on 2000 observations
    record, arrays = read_npz(data)
    assert record["network"]["squash"] == "tanh" and record["meta"]["algo"] == "SAC"
    assert sorted(arrays) == ["action.bias", "action.weight", "pi.0.bias", "pi.0.weight", "pi.1.bias",
                              "pi.1.weight"]
    model = __import__("stable_baselines3").SAC.load(run / "model.zip", device="cpu")
    # On an episode's observations, normalised as in training: the file's actor equals SAC.predict.
    npz = tmp_path / "sac.npz"
    npz.write_bytes(data)
    agent = PPOAgent(npz, env_id="EyeCatch-v0")
    env = gym.make("EyeCatch-v0")
    obs, _ = env.reset(seed=5)
    mean, std = np.asarray(meta["obs_mean"]), np.sqrt(np.asarray(meta["obs_var"]) + meta["epsilon"])
    for i in range(40):
        got, _ = agent.predict(obs, episode_start=np.array([i == 0]))
        x = np.clip((np.asarray(obs, np.float32) - mean) / std, -meta["clip_obs"], meta["clip_obs"])
        expected, _ = model.predict(x.astype(np.float32), deterministic=True)
        np.testing.assert_array_equal(got, np.asarray(expected, np.float32))
        obs, _, terminated, truncated, _ = env.step(got)
        if terminated or truncated:
            break
    env.close()
    # ...and the comparison can fail: one weight changed changes the actions.
    bad = {k: np.array(v) for k, v in arrays.items()}
    bad["pi.0.weight"][:, 0] += 0.5
    with pytest.raises(ValueError, match="differs from the SB3 model"):
        prove_npz_equals_model(_write_npz(record, bad), model, n=200)
    # A squashed network is SAC's, and SAC's network is squashed.
    rec = json.loads(json.dumps(record))
    rec["meta"]["algo"] = "PPO"
    with pytest.raises(PolicyFileError, match="algo must be 'SAC'"):
        PPOAgent.from_npz(_write_npz(rec, arrays))
    rec = json.loads(json.dumps(record))
    rec["network"]["squash"] = "sigmoid"
    with pytest.raises(PolicyFileError, match="squash must be one of"):
        PPOAgent.from_npz(_write_npz(rec, arrays))


def test_untrained_sac_on_an_asymmetric_action_space_is_rescaled_as_sb3_does():
    """Untrained weights suffice for the equality: a Box action space of [-2, 2] (Pendulum-v1) checks the
    rescaling from tanh's [-1, 1], which the [-1, 1] spaces of the table's envs leave as it is."""
    from stable_baselines3 import SAC

    env = gym.make("Pendulum-v1")
    model = SAC("MlpPolicy", env, seed=3, device="cpu", policy_kwargs={"net_arch": [32, 32]})
    data = npz_from_model(model, {"algo": "SAC", "env_id": "Pendulum-v1"})
    assert prove_npz_equals_model(data, model, n=500) == 500
    record, _ = read_npz(data)
    assert record["network"]["action_low"] == [-2.0] and record["network"]["action_high"] == [2.0]
    # the actor's tanh output is scaled by 2: far from zero the actions leave [-1, 1]
    rng = np.random.default_rng(0)
    actions = np.array([model.predict(o, deterministic=True)[0] for o in rng.normal(0, 30, (200, 3)).astype(np.float32)])
    assert np.abs(actions).max() > 1.0 and np.abs(actions).max() <= 2.0


def test_rl_zoo3_sac_file_has_the_table_ids_with_keys_sac_accepts():
    import inspect
    from pathlib import Path

    import yaml
    from stable_baselines3 import SAC

    zoo = yaml.safe_load((Path(train.__file__).parent / "rl_zoo3_sac.yml").read_text())
    section = yaml.safe_load((Path(train.__file__).parent / "hyperparams.yml").read_text())["sac"]
    assert sorted(zoo) == sorted(k for k in section if k != "default")
    zoo_keys = {"n_envs", "n_timesteps", "policy", "normalize", "env_kwargs", "policy_kwargs"}
    sac_args = set(inspect.signature(SAC.__init__).parameters) - {"self", "env", "policy"}
    for env_id, params in zoo.items():
        assert not set(params) - zoo_keys - sac_args, env_id
        config = train.load_config(train.parse_args(["--env", env_id, "--sac", *FREE]))
        for key in ("learning_rate", "buffer_size", "learning_starts", "batch_size", "tau", "gamma", "train_freq",
                    "gradient_steps", "ent_coef"):
            assert params[key] == config[key], (env_id, key)
        env = gym.make(env_id, **params["env_kwargs"])
        model = SAC("MlpPolicy", env, device="cpu", policy_kwargs=eval(params["policy_kwargs"], {"dict": dict}),
                    **{k: v for k, v in params.items() if k not in zoo_keys})
        assert model.policy.action_space.shape == env.action_space.shape
        env.close()
