"""The free-gaze cloning recipe on a walker (``bc_teacher``, docs/baselines/rl.md "The same idea on
SteppingStones-v0"): the family's scripted agent labels the env's own observations, a bad teacher is refused."""

import json

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.ppo import train

from visuomotor_gym.agents import make_agent

RECIPE = ["--env", "SteppingStones-v0", "--recipe", "free_clone_stones"]


def test_the_teacher_round_is_the_lookahead_agent_on_the_env_own_observations(tmp_path):
    """With no played noise, the teacher's round is exactly the lookahead agent's own episode on the same seed
    (same length, same outcome): it is reset at the episode start and fed every observation in order."""
    env = gym.make("SteppingStones-v0")
    agent = make_agent("lookahead", "SteppingStones-v0", 9)
    x, _ = env.reset(seed=1_000_000)
    agent.reset()
    steps, done = 0, False
    while not done:
        x, _, terminated, truncated, info = env.step(agent.predict(x)[0])
        steps, done = steps + 1, terminated or truncated
    run = train.main([*RECIPE, "--timesteps", "1", "--out", str(tmp_path), "--run-name", "c", "--no-progress-bar",
                      "--set", "bc_episodes=1", "bc_dagger_rounds=1", "bc_epochs=2", "bc_noise=0"])
    bc = json.loads((run / "bc.json").read_text())
    assert bc["teacher"] == "lookahead"
    assert [r["player"] for r in bc["rounds"]] == ["teacher", "policy"]
    assert bc["rounds"][0]["transitions"] == steps and bc["rounds"][0]["caught"] == int(info["is_success"])
    assert np.isfinite(bc["policy_mse_per_epoch"]).all() and len(bc["policy_mse_per_epoch"]) == 4


def test_a_bad_teacher_is_refused_naming_the_option():
    for bad, match in (("bc_teacher=nosuch", "bc_teacher='nosuch'"),
                       ("bc_teacher=eyecatch", "bc_teacher='eyecatch'.*not SteppingStones-v0"),
                       ("belief=true", "needs the env's own observation")):
        with pytest.raises(train.TrainArgumentError, match=match):
            train.load_config(train.parse_args([*RECIPE, "--set", bad]))
