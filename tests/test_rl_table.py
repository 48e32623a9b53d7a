"""The RL baseline table: free-gaze PPO / RecurrentPPO trains on every family, its pickle-free
policy file reloads with the trained model's actions (LSTM state carried), and the table runner writes
a cell and collects cells into Markdown."""

import json
import zipfile

import gymnasium as gym
import numpy as np
import pytest
import yaml
from visuomotor_gym.baselines.ppo import table, train
from visuomotor_gym.baselines.ppo.agent import (
    PolicyFileError,
    PPOAgent,
    _write_npz,
    pack_npz,
    prove_npz_equals_model,
    read_npz,
)

import visuomotor_gym

TINY = ["--no-progress-bar", "--belief", "no", "--hand-action", "absolute", "--gaze-action", "free",
        "--set", "n_envs=2", "n_steps=128", "batch_size=128", "eval_freq=100000", "eval_episodes=1",
        "checkpoint_freq=100000"]
# One id per family; PPO on the foveated rung, RecurrentPPO on the Oracle rung (the two together cover
# both algorithms, both rungs and every family's observation and action sizes).
CASES = [("SteppingStones-v0", False), ("ShelfReachOracle-v0", True), ("ObstacleDodge-v0", False),
         ("EyeCatchOracle-v0", True), ("ObstacleWalk-v0", False), ("SteppingStonesOracle-v0", True)]


def _rollout_actions(policy: PPOAgent, env_id: str, seed: int, steps: int, drive: PPOAgent | None = None):
    """Actions of ``policy`` on the observations an episode of ``env_id`` gives when ``drive`` (default:
    ``policy``) acts; with two policies both see the same observations."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=seed)
    policy.reset()
    if drive is not None:
        drive.reset()
    out = []
    for i in range(steps):
        start = np.array([i == 0])
        action, _ = policy.predict(obs, episode_start=start)
        out.append(action)
        if drive is not None:
            action, _ = drive.predict(obs, episode_start=start)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    env.close()
    return np.array(out)


@pytest.mark.parametrize("env_id,recurrent", CASES, ids=[f"{e}-{'lstm' if r else 'mlp'}" for e, r in CASES])
def test_free_gaze_training_on_every_family_reloads_pickle_free_with_the_same_actions(tmp_path, env_id, recurrent):
    run = train.main(["--env", env_id, "--timesteps", "256", "--out", str(tmp_path), "--run-name", "t", *TINY,
                      *(["--recurrent"] if recurrent else [])])
    meta = json.loads((run / "ppo_meta.json").read_text())
    assert meta["algo"] == ("RecurrentPPO" if recurrent else "PPO") and meta["belief"] is False
    assert meta["hand_action"] == "absolute" and "gaze_action" not in meta  # free gaze
    env = gym.make(env_id)
    assert len(meta["obs_mean"]) == env.observation_space.shape[0]  # the env's own observation, nothing added
    data = pack_npz(run)  # proves equal actions on 2000 sampled observations (LSTM: one stream, resets)
    assert len(data) < 1_000_000
    record, arrays = read_npz(data)
    assert record["network"]["kind"] == ("lstm_mlp" if recurrent else "mlp")
    assert record["network"]["action_dim"] == env.action_space.shape[0]
    with zipfile.ZipFile(__import__("io").BytesIO(data)) as zf:
        assert all(n == "policy.json" or n.endswith(".npy") for n in zf.namelist())  # nothing to unpickle
    # The reloaded file plays the trained model's actions on an episode's observations (the trained model
    # acting: PPOAgent on the run folder calls SB3's predict, carrying the LSTM state for RecurrentPPO).
    trained = PPOAgent(run, env_id=env_id)
    npz = tmp_path / "p.npz"
    npz.write_bytes(data)
    reloaded = PPOAgent(npz, env_id=env_id)
    expected = _rollout_actions(trained, env_id, 3, 60)
    got = _rollout_actions(reloaded, env_id, 3, 60, drive=trained)
    assert len(expected) > 5
    np.testing.assert_array_equal(got, expected)
    # ...and the comparison can fail: one weight changed changes the actions (the LSTM's recurrent
    # weights only act from the second step on, so the state really is carried).
    key = "lstm.weight_hh" if recurrent else "pi.0.weight"
    bad = {k: np.array(v) for k, v in arrays.items()}
    bad[key][0] += 0.5
    bad[key][:, 0] += 0.5
    npz.write_bytes(_write_npz(record, bad))
    wrong = _rollout_actions(PPOAgent(npz, env_id=env_id), env_id, 3, 60, drive=trained)
    assert not np.array_equal(wrong, expected)
    model = __import__("visuomotor_gym.baselines.ppo.agent", fromlist=["_algo_class"])._algo_class(
        meta["algo"]).load(run / "model.zip", device="cpu")
    with pytest.raises(ValueError, match="differs from the SB3 model"):
        prove_npz_equals_model(npz.read_bytes(), model, n=200)


def test_recurrent_actor_carries_its_state_and_resets_it_per_episode(tmp_path):
    run = train.main(["--env", "ShelfReach-v0", "--timesteps", "256", "--out", str(tmp_path), "--run-name", "t",
                      *TINY, "--recurrent"])
    npz = tmp_path / "r.npz"
    npz.write_bytes(pack_npz(run))
    agent = PPOAgent(npz, env_id="ShelfReach-v0")
    obs = gym.make("ShelfReach-v0").reset(seed=0)[0]
    first, _ = agent.predict(obs, episode_start=np.array([True]))
    later = [agent.predict(obs, episode_start=np.array([False]))[0] for _ in range(5)]
    assert any(not np.array_equal(first, a) for a in later)  # same input, other state: other action
    again, _ = agent.predict(obs, episode_start=np.array([True]))  # a new episode starts from zeros
    np.testing.assert_array_equal(again, first)
    agent.reset()
    np.testing.assert_array_equal(agent.predict(obs)[0], first)


def test_recurrent_record_must_match_its_algorithm_and_shapes(tmp_path):
    run = train.main(["--env", "EyeCatchOracle-v0", "--timesteps", "256", "--out", str(tmp_path), "--run-name", "t",
                      *TINY, "--recurrent"])
    record, arrays = read_npz(pack_npz(run))
    rec = json.loads(json.dumps(record))
    rec["meta"]["algo"] = "PPO"
    with pytest.raises(PolicyFileError, match="algo must be 'RecurrentPPO'"):
        PPOAgent.from_npz(_write_npz(rec, arrays))
    bad = dict(arrays)
    bad["lstm.weight_hh"] = np.zeros((512, 64), np.float32)
    with pytest.raises(PolicyFileError, match=r"lstm.weight_hh.*needs \(512, 128\)"):
        PPOAgent.from_npz(_write_npz(record, bad))
    rec = json.loads(json.dumps(record))
    rec["network"]["lstm"]["bias_ih"] = "nope"
    with pytest.raises(PolicyFileError, match=r"lstm\.bias_ih: array 'nope' is missing"):
        PPOAgent.from_npz(_write_npz(rec, arrays))


def test_every_registered_id_has_hyperparameters_and_the_non_catch_ones_play_free_gaze():
    table_yml = yaml.safe_load((train.Path(train.__file__).parent / "hyperparams.yml").read_text())
    missing = sorted(set(visuomotor_gym.ENV_IDS) - set(table_yml))
    assert not missing, f"hyperparams.yml has no entry for {missing}"
    for env_id in visuomotor_gym.ENV_IDS:
        config = train.load_config(train.parse_args(["--env", env_id]))
        if env_id.startswith("EyeCatch"):
            continue
        assert config["belief"] is False and config["hand_action"] == "absolute", env_id
        shaping = config["env_kwargs"]
        assert "catch" not in json.dumps(shaping), env_id  # the catch family's reward is not merged in
        if env_id.startswith(("ShelfReach", "PushRecovery")):
            assert shaping["reward"] == "shaped"  # the env's own shaped terms
        else:
            assert shaping["reward_weights"]["progress"] > 0  # the named training-only progress term
        gym.make(env_id, **shaping).close()  # the env accepts its training kwargs


def test_table_cell_trains_evaluates_and_collects(tmp_path, capsys):
    out = tmp_path / "t"
    argv = ["--env", "SteppingStonesOracle-v0", "--algo", "recurrentppo", "--timesteps", "512", "--out", str(out),
            "--episodes", "3", "--policy-dir", str(tmp_path / "pol"),
            "--set", "n_envs=2", "n_steps=128", "batch_size=128"]
    assert table.main(argv) == 0
    cell = json.loads((out / "cells" / "SteppingStonesOracle-v0__recurrentppo__s0__512.json").read_text())
    assert cell["algo"] == "RecurrentPPO" and cell["episodes"] == 3 and cell["transitions"] >= 512
    assert cell["results"]["episodes"] == 3 and cell["success_rate"] == cell["results"]["success_rate"]
    assert cell["foveation"]["component"] == "stone_fixation_share" and cell["saccades_per_episode"] >= 0
    assert cell["learning_curve"] and cell["learning_curve"][0]["wall_s"] is not None
    assert "train_shaped_return" in cell["learning_curve"][-1]  # from progress.csv
    assert "--episodes 3" in cell["command"] and "--set n_envs=2" in cell["command"]
    assert (tmp_path / "pol" / "recurrentppo-free-512__SteppingStonesOracle-v0.npz").is_file()
    cell_path = out / "cells" / "SteppingStonesOracle-v0__recurrentppo__s0__512.json"
    assert table.main(["--twin", str(cell_path)]) == 0  # the held twin on the same (3) seeds
    cell = json.loads(cell_path.read_text())
    twin = cell["held_twin"]
    assert twin["agent"].startswith("gaze_blind:ppo:") and twin["agent"].endswith(".npz")
    assert twin["held_difference"] == pytest.approx(cell["success_rate"] - twin["success_rate"])
    assert table.main(argv) == 2  # never overwritten
    assert "never overwritten" in capsys.readouterr().err
    # Collect: a 3-episode cell is not a table cell; a 200-episode cell at the budget fills its row.
    doc = tmp_path / "rl.md"
    doc.write_text(f"# x\n{table.MARK_BEGIN}\nold\n{table.MARK_END}\nafter\n")
    full = dict(cell, episodes=200, budget_transitions=512, cell="x")
    (out / "cells" / "full.json").write_text(json.dumps(full))
    assert table.main(["--collect", str(out), "--doc", str(doc), "--images", str(tmp_path / "img"),
                       "--budget", "512"]) == 0
    text = doc.read_text()
    assert "old" not in text and text.endswith("after\n")
    rows = [line for line in text.splitlines() if line.startswith("| stones | SteppingStonesOracle-v0")]
    assert len(rows) == 3 and "RecurrentPPO (seed 0)" in rows[1] and "not run" in rows[0]
    assert "| SAC | not run" in rows[2]
    assert text.count("not run") == 29  # 5 families x 2 rungs x 3 algorithms, one filled
    assert "--env SteppingStones-v0 --algo ppo --timesteps 512" in text
    assert (tmp_path / "img" / "rl_curves_512.png").is_file()


def test_table_refuses_bad_arguments(capsys):
    assert table.main(["--env", "EyeCatchPoorVision-v0"]) == 2
    assert "--env must be one of the table's ids" in capsys.readouterr().err
    assert table.main(["--env", "SteppingStones-v0", "--timesteps", "0"]) == 2
    assert "--timesteps must be in" in capsys.readouterr().err
    assert table.main(["--collect"]) == 2
