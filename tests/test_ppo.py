"""PPO baseline: a tiny-budget training run, saved, loaded as ``ppo:<path>``, evaluated."""

import json
from pathlib import Path

import numpy as np
import pytest
from visuomotor_gym.baselines.ppo import train

from visuomotor_gym.agents import make_agent
from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.envs.walk import WINDING_LAYOUT


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
    # EvalCallback's best model carries the normalisation it was evaluated with.
    best = json.loads((run / "eval" / "best_model.meta.json").read_text())
    assert best["selected"].startswith("best EvalCallback") and len(best["obs_mean"]) == n_obs
    assert evaluate(f"ppo:{run}/eval/best_model.zip", "EyeCatch-v0", 1, 0, workers=1).summary["episodes"] == 1
    # Deterministic: the same policy gives the same actions on the same seeds.
    again = evaluate(f"ppo:{run}", "EyeCatch-v0", 2, 0, workers=1)
    for a, b in zip(result.traces, again.traces):
        np.testing.assert_array_equal(a.action[1:], b.action[1:])


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ppo")
    return train.main(["--env", "EyeCatch-v0", "--timesteps", "256", "--out", str(out), "--run-name", "t",
                       "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128", "eval_freq=100000",
                       "eval_episodes=1", "checkpoint_freq=100000"])


def test_packed_policy_is_one_smaller_file_with_the_same_actions(tiny_run, tmp_path):
    from visuomotor_gym.baselines.ppo.agent import pack_policy

    data = pack_policy(tiny_run)
    assert data == pack_policy(tiny_run)  # byte-identical: the leaderboard hashes it
    assert len(data) < 0.6 * (tiny_run / "model.zip").stat().st_size  # no optimizer moments
    packed = tmp_path / "policy.zip"  # alone: no ppo_meta.json beside it
    packed.write_bytes(data)
    assert pack_policy(packed) == data
    a = evaluate(f"ppo:{tiny_run}", "EyeCatch-v0", 2, 0, workers=1)
    b = evaluate(f"ppo:{packed}", "EyeCatch-v0", 2, 0, workers=1)
    for x, y in zip(a.traces, b.traces):
        np.testing.assert_array_equal(x.action, y.action)
    with pytest.raises(ValueError, match="not a packed PPO policy"):
        from visuomotor_gym.baselines.ppo.agent import PPOAgent

        PPOAgent.from_bytes((tiny_run / "model.zip").read_bytes())


def test_ppo_entry_is_submitted_and_rescored_from_its_packed_file(tiny_run, tmp_path, capsys):
    from visuomotor_gym.cli import main

    root = tmp_path / "lb"
    (root / "results").mkdir(parents=True)
    proto = json.loads((Path(__file__).parents[1] / "leaderboard" / "protocol.json").read_text())
    proto["envs"] = [dict(e, episodes=2) for e in proto["envs"] if e["env_id"] == "EyeCatch-v0"]
    (root / "protocol.json").write_text(json.dumps(proto, indent=2))
    assert main(["leaderboard", "submit", "--agent", f"ppo:{tiny_run}", "--name", "ppo-tiny", "--env", "EyeCatch-v0",
                 "--dir", str(root), "--workers", "1", "--no-progress"]) == 0
    policy = root / "agents" / "ppo-tiny__EyeCatch-v0.npz"  # pickle-free, converted at submit
    assert policy.is_file()
    record = json.loads((root / "results" / "ppo-tiny__EyeCatch-v0.entry.json").read_text())
    assert record["policy"]["format"] == "ppo-npz"
    # The training run may be gone where the check runs: the packed file is the policy.
    moved = tiny_run.parent / "moved"
    tiny_run.rename(moved)
    try:
        capsys.readouterr()
        assert main(["leaderboard", "check", "--dir", str(root), "--base", "none", "--sample", "all"]) == 0, capsys.readouterr().out
    finally:
        moved.rename(tiny_run)


def test_run_folders_are_never_overwritten(tmp_path):
    (tmp_path / "EyeCatchOracle-v0" / "same").mkdir(parents=True)
    with pytest.raises(train.TrainArgumentError, match="already exists"):
        train.main(["--env", "EyeCatchOracle-v0", "--out", str(tmp_path), "--run-name", "same", "--timesteps", "10"])


def test_hyperparameters_resolve_default_then_env_then_overrides():
    args = train.parse_args(["--env", "EyeCatch-v0", "--set", "learning_rate=1e-4"])
    config = train.load_config(args)
    assert config["belief"] is True and config["intercept_shaping"] == 0.5
    assert config["learning_rate"] == 1e-4  # override
    assert config["n_envs"] == 8  # default
    with pytest.raises(train.TrainArgumentError, match="key=value"):
        train.load_config(train.parse_args(["--set", "not_a_key=1"]))


def test_walk_id_trains_without_the_catch_features_and_its_npz_walks(tmp_path):
    """ObstacleWalk-v0: its hyperparameters replace the catch family's shaped reward (only the
    env's own progress term is shaped), no belief features; a tiny run packs to ppo-npz and is scored."""
    config = train.load_config(train.parse_args(["--env", "ObstacleWalk-v0"]))
    assert config["belief"] is False and config["hand_action"] == "absolute" and config["intercept_shaping"] == 0.0
    assert config["env_kwargs"] == {"reward_weights": {"progress": 0.05}} and "replace" not in config
    catch = train.load_config(train.parse_args(["--env", "EyeCatch-v0"]))
    assert catch["env_kwargs"]["reward"] == "shaped"  # the catch ids still merge with the default
    run = train.main(["--env", "ObstacleWalk-v0", "--timesteps", "256", "--out", str(tmp_path), "--run-name", "t",
                      "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128", "eval_freq=100000",
                      "eval_episodes=1", "checkpoint_freq=100000"])
    meta = json.loads((run / "ppo_meta.json").read_text())
    assert meta["env_id"] == "ObstacleWalk-v0" and not meta["belief"] and len(meta["obs_mean"]) == WINDING_LAYOUT.size
    from visuomotor_gym.baselines.ppo.agent import pack_npz

    npz = tmp_path / "walk.npz"
    npz.write_bytes(pack_npz(run))
    result = evaluate(f"ppo:{npz}", "ObstacleWalk-v0", 1, 0, workers=1)
    assert result.summary["episodes"] == 1 and result.traces[0].action.shape[1] == 9  # the turning walker


def test_ppo_agent_needs_a_policy_file():
    with pytest.raises(ValueError, match="needs a policy file"):
        make_agent("ppo", "EyeCatch-v0", 9)
    with pytest.raises(FileNotFoundError, match="no PPO model"):
        make_agent("ppo:/nonexistent/model.zip", "EyeCatch-v0", 9)


def test_belief_intercept_base_catches_with_exact_vision_and_maps_residuals():
    """The residual's base (nothing learned) catches Oracle throws; a residual moves the hand target by
    exactly residual_m per unit, and hand_action='absolute' leaves actions alone."""
    result = evaluate("belief_intercept", "EyeCatchOracle-v0", 4, 0, workers=1)
    assert result.summary["caught"] >= 3

    import gymnasium as gym
    from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

    from visuomotor_gym.body.seated import HAND_WORKSPACE

    env = gym.make("EyeCatchOracle-v0")
    obs, _ = env.reset(seed=3)
    feats = BeliefFeatures("EyeCatchOracle-v0", "intercept", residual_m=0.1)
    x = feats(obs)
    assert x.shape == (57 + 14,) and feats.intercept_point is not None
    zero = feats.env_action(np.zeros(9, np.float32))
    push = feats.env_action(np.array([0.5, 0, 0, 0, 0, 0, 0, 0, 0], np.float32))
    scale = 2.0 / (HAND_WORKSPACE[0, 1] - HAND_WORKSPACE[0, 0])  # action units per metre along x
    assert push[0] - zero[0] == pytest.approx(0.05 * scale, abs=1e-6)
    np.testing.assert_array_equal(push[3:], np.zeros(6))
    plain = BeliefFeatures("EyeCatchOracle-v0", "absolute")
    plain(obs)
    a = np.linspace(-1, 1, 9).astype(np.float32)
    assert plain.env_action(a) is a
    with pytest.raises(ValueError, match="hand_action must be one of"):
        BeliefFeatures("EyeCatch-v0", "relative")


# ---------------------------------------------------------------- the gated gaze action


def test_gated_gaze_maps_the_look_gate_to_the_belief_request_and_zero_to_held_gaze():
    """gaze_action='gated': a tenth action value, the look gate. Gate > 0 sends the gaze request to the
    believed ball (the Eyecatch 4.1 request) plus the residual; gate <= 0 (the zero action) requests the
    residual alone around the line of sight (0: gaze held); before the filter's first sample the gate
    does nothing. The hand block stays the intercept residual."""
    import gymnasium as gym
    from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

    env = gym.make("EyeCatch-v0")
    obs, _ = env.reset(seed=5)
    feats = BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="gated", gaze_residual_deg=3.0)
    assert feats.action_dim == 10 and feats.size == 10 + 4 + 3
    x = feats(obs)
    assert x.shape == (57 + 17,)
    zero = np.zeros(10, np.float32)
    if feats.look_gaze is None:  # nothing seen yet: the gate cannot look anywhere
        look = zero.copy()
        look[9] = 1.0
        np.testing.assert_array_equal(feats.env_action(look)[4:6], [0.0, 0.0])
    for _ in range(60):  # until the ball is seen and believed somewhere off the line of sight
        obs, *_ = env.step(feats.env_action(zero))
        feats(obs)
        if feats.look_gaze is not None and np.hypot(*feats.look_gaze) > np.radians(1.0):
            break
    az, el = feats.look_gaze
    assert np.hypot(az, el) > np.radians(1.0)
    held = feats.env_action(zero)
    assert held.shape == (9,)
    np.testing.assert_array_equal(held[4:6], [0.0, 0.0])
    gate = zero.copy()
    gate[9] = 0.3
    np.testing.assert_allclose(feats.env_action(gate)[4:6], np.array([az, el]) / np.radians(60.0), atol=1e-6)
    gate[4] = 1.0  # + the full residual in azimuth
    np.testing.assert_allclose(feats.env_action(gate)[4], (az + np.radians(3.0)) / np.radians(60.0), atol=1e-6)
    off = gate.copy()
    off[9] = -0.2  # gate off: the residual alone
    np.testing.assert_allclose(feats.env_action(off)[4:6], [np.radians(3.0) / np.radians(60.0), 0.0], atol=1e-6)
    np.testing.assert_array_equal(feats.env_action(gate)[:4], held[:4])  # hand and grasp unchanged
    with pytest.raises(ValueError, match="shape"):
        feats.env_action(np.zeros(9, np.float32))
    with pytest.raises(ValueError, match="needs hand_action='intercept'"):
        BeliefFeatures("EyeCatch-v0", "absolute", gaze_action="gated")
    with pytest.raises(ValueError, match="gaze_action must be one of"):
        BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="look")


def test_frozen_gaze_action_sees_what_gated_sees_and_holds_gaze_and_head():
    """gaze_action="frozen" (a policy *trained* with its gaze held): the gated mode's inputs, the env's
    9 action values, gaze and head held at 0 whatever the policy says; hand, grasp, fixation its own."""
    import gymnasium as gym
    from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

    env = gym.make("EyeCatch-v0")
    obs, _ = env.reset(seed=5)
    frozen = BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="frozen")
    gated = BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="gated")
    assert frozen.action_dim == 9 and frozen.size == gated.size == 10 + 4 + 3
    np.testing.assert_array_equal(frozen(obs), gated(obs))
    a = np.array([0.2, -0.1, 0.3, 0.9, 1.0, -1.0, 0.4, 0.7, -0.6], np.float32)
    out = frozen.env_action(a)
    np.testing.assert_array_equal(out[4:6], [0.0, 0.0])  # gaze
    np.testing.assert_array_equal(out[7:9], [0.0, 0.0])  # head
    assert out[3] == np.float32(0.9) and out[6] == np.float32(0.4)  # grasp and fixation pass through
    np.testing.assert_array_equal(out[:3], gated.env_action(np.append(a, -1.0))[:3])  # the same hand residual
    with pytest.raises(ValueError, match="needs hand_action='intercept'"):
        BeliefFeatures("EyeCatch-v0", "absolute", gaze_action="frozen")


def test_gated_base_looks_only_with_the_gate_on():
    """The structure's fixed bases: gate 0 (the zero action) never saccades; gate on saccades to and
    pursues the believed ball, so the ball is much nearer the line of sight."""
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1] / "docs" / "baselines"))
    from ppo_gated import measure

    held = measure("belief_intercept:gaze_action=gated", "EyeCatch-v0", 2)
    look = measure("belief_intercept:gaze_action=gated,look=true", "EyeCatch-v0", 2)
    assert held["saccades_per_throw"] == 0
    assert look["saccades_per_throw"] >= 1
    assert look["ball_within_5deg"] > held["ball_within_5deg"] + 0.1


@pytest.fixture(scope="module")
def gated_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ppo_gated")
    return train.main(["--env", "EyeCatch-v0", "--gaze-action", "gated", "--timesteps", "256", "--out", str(out),
                       "--run-name", "g", "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128",
                       "eval_freq=100000", "eval_episodes=1", "checkpoint_freq=100000"])


def test_gated_policy_trains_packs_loads_and_its_twin_holds_gaze(gated_run, tmp_path):
    """A tiny gated run: 10 actions, meta says gated; the pickle-free file gives the zip's env actions;
    ``gaze_blind:ppo:<file>`` holds gaze and head and leaves the rest."""
    from visuomotor_gym.baselines.ppo.agent import PPOAgent, pack_npz, read_npz

    meta = json.loads((gated_run / "ppo_meta.json").read_text())
    assert meta["gaze_action"] == "gated" and meta["gaze_residual_deg"] == 3.0
    assert len(meta["obs_mean"]) == 57 + 17
    data = pack_npz(gated_run)
    record, _ = read_npz(data)
    assert record["network"]["action_dim"] == 10 and record["meta"]["gaze_action"] == "gated"
    npz = tmp_path / "gated.npz"
    npz.write_bytes(data)
    a = evaluate(f"ppo:{gated_run}", "EyeCatch-v0", 2, 0, workers=1)
    b = evaluate(f"ppo:{npz}", "EyeCatch-v0", 2, 0, workers=1)
    for x, y in zip(a.traces, b.traces):
        assert x.action.shape[1] == 9
        np.testing.assert_array_equal(x.action, y.action)
    twin = evaluate(f"gaze_blind:ppo:{npz}", "EyeCatch-v0", 1, 0, workers=1).traces[0]
    assert np.all(twin.action[1:, 4:6] == 0) and np.all(twin.action[1:, 7:9] == 0)
    assert twin.saccade_onset.sum() == 0
    agent = PPOAgent(npz)
    assert agent.features.action_dim == 10 and agent.features.gaze_action == "gated"


def test_old_policies_load_with_free_gaze():
    """A policy saved before the gated gaze (no gaze_action in its meta) keeps the 9-value free gaze."""
    from visuomotor_gym.baselines.ppo.agent import PPOAgent

    path = Path(__file__).parents[1] / "leaderboard" / "agents" / "ppo-intercept-v3__EyeCatch-v0.npz"
    agent = PPOAgent(path)
    assert "gaze_action" not in agent.meta
    assert agent.features.gaze_action == "free" and agent.features.action_dim == 9
    assert agent.actor.low.shape == (9,)


def test_frozen_holds_the_blocks_the_gaze_blind_twin_holds():
    """belief.GAZE_HEAD (the frozen mode's held slices) are the env's 'gaze' and 'head' blocks, as
    ``GazeBlind`` reads them from its action_structure."""
    import gymnasium as gym
    from visuomotor_gym.baselines.ppo.belief import ENV_ACTION_DIM, GAZE_HEAD

    from visuomotor_gym.agents import GazeBlind

    structure = gym.make("EyeCatch-v0").unwrapped.action_structure
    twin = GazeBlind(None, structure)
    mask = np.zeros(ENV_ACTION_DIM, dtype=bool)
    for block in GAZE_HEAD:
        mask[block] = True
    np.testing.assert_array_equal(mask, twin.held)
