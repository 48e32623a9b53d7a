"""PPO baseline: a tiny-budget training run, saved, loaded as ``ppo:<path>``, evaluated."""

import json

import numpy as np
import pytest

from visuomotor_gym.agents import make_agent
from visuomotor_gym.baselines.ppo import train
from visuomotor_gym.bench.evaluate import evaluate


@pytest.mark.parametrize(
    "extra",
    [["--belief", "no", "--hand-action", "absolute"], ["--belief", "yes", "--hand-action", "absolute"],
     ["--belief", "yes"], ["--recurrent", "--belief", "no", "--hand-action", "absolute"]],
    ids=["ppo", "belief", "intercept", "recurrent"],
)
def test_tiny_training_saves_loads_and_evaluates(tmp_path, extra):
    run = train.main(["--env", "EyeCatch-v0", "--timesteps", "512", "--out", str(tmp_path), "--run-name", "t",
                      "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128", "eval_freq=256",
                      "eval_episodes=1", "checkpoint_freq=256", *extra])
    for name in ("model.zip", "ppo_meta.json", "config.yml", "args.json", "command.txt", "progress.csv"):
        assert (run / name).is_file(), name
    meta = json.loads((run / "ppo_meta.json").read_text())
    n_obs = 57 + (10 if "yes" in extra else 0) + (4 if "absolute" not in extra else 0)
    assert meta["timesteps"] >= 512 and len(meta["obs_mean"]) == n_obs
    assert meta["hand_action"] == ("absolute" if "absolute" in extra else "intercept")
    assert "--timesteps 512" in (run / "command.txt").read_text()
    result = evaluate(f"ppo:{run}", "EyeCatch-v0", 2, 0, workers=1)
    assert result.summary["episodes"] == 2
    # Deterministic: the same policy gives the same actions on the same seeds.
    again = evaluate(f"ppo:{run}", "EyeCatch-v0", 2, 0, workers=1)
    for a, b in zip(result.traces, again.traces):
        np.testing.assert_array_equal(a.action[1:], b.action[1:])


def test_run_folders_are_never_overwritten(tmp_path):
    (tmp_path / "EyeCatchOracle-v0" / "same").mkdir(parents=True)
    with pytest.raises(SystemExit, match="already exists"):
        train.main(["--env", "EyeCatchOracle-v0", "--out", str(tmp_path), "--run-name", "same", "--timesteps", "10"])


def test_hyperparameters_resolve_default_then_env_then_overrides():
    args = train.parse_args(["--env", "EyeCatch-v0", "--set", "learning_rate=1e-4"])
    config = train.load_config(args)
    assert config["belief"] is True and config["intercept_shaping"] == 0.5
    assert config["learning_rate"] == 1e-4  # override
    assert config["n_envs"] == 8  # default
    with pytest.raises(SystemExit, match="key=value"):
        train.load_config(train.parse_args(["--set", "not_a_key=1"]))


def test_ppo_agent_needs_a_policy_file():
    with pytest.raises(ValueError, match="needs a policy file"):
        make_agent("ppo", "EyeCatch-v0", 9)
    with pytest.raises(FileNotFoundError, match="no PPO model"):
        make_agent("ppo:/nonexistent/model.zip", "EyeCatch-v0", 9)
