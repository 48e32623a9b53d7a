"""The free-gaze PPO recipe on EyeCatch-v0 (``gaze_action="free_belief"``, docs/baselines/rl.md "A learned gaze
without a gate"): the gated mode's inputs, the env's own 9 action values with nothing between the policy's
gaze and the env, the named recipe, the gaze block's initial std, and the committed policy."""

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.ppo import train
from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

from visuomotor_gym.bench.evaluate import evaluate

POLICY = Path(__file__).parents[1] / "baselines" / "ppo" / "policies" / "ppo-free-belief__EyeCatch-v0.npz"


def _seen(feats, env, obs):
    """Step with the zero action until the believed ball is off the line of sight (> 1 deg)."""
    zero = np.zeros(feats.action_dim, np.float32)
    for _ in range(60):
        if feats.look_gaze is not None and np.hypot(*feats.look_gaze) > np.radians(1.0):
            return obs
        obs, *_ = env.step(feats.env_action(zero))
        feats(obs)
    raise AssertionError("the ball was never believed off the line of sight")


def test_free_belief_sees_the_gated_inputs_and_its_env_action_is_the_policy_own():
    """Inputs: the gated mode's (belief, interception point, believed ball on the retina) and the log of the
    believed ball's distance from the eye (the filter's estimate one step ahead, the Eyecatch vergence target).
    Action:
    the env's 9 values; gaze, fixation, head and grasp pass through unchanged (no gate, no residual around the
    believed ball: the zero gaze action holds gaze while the ball is off the line of sight); only the hand
    block is the intercept residual, the same as the gated mode's."""
    env = gym.make("EyeCatch-v0")
    obs, _ = env.reset(seed=5)
    free = BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="free_belief")
    gated = BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="gated")
    assert free.action_dim == 9 and gated.size == 10 + 4 + 3 and free.size == gated.size + 1
    x = free(obs)
    np.testing.assert_array_equal(x[:-1], gated(obs))
    if not free._agent.filter.initialised:
        assert x[-1] == 0.0  # nothing believed yet
    obs = _seen(free, env, obs)
    gated.reset()
    assert free.look_gaze is not None
    obs, *_ = env.step(free.env_action(np.zeros(9, np.float32)))
    x = free(obs)
    agent = free._agent
    eye = obs[8:11] + train_frames_seat()
    ahead = agent.filter.extrapolate(agent.delay_steps * agent.dt + agent.dt)[0]
    assert np.isclose(x[-1], np.log(np.linalg.norm(ahead - eye)), atol=1e-5)
    assert 0.3 < np.exp(x[-1]) < 10.0  # a believed ball between the thrower and the catcher
    rng = np.random.default_rng(0)
    for a in [np.zeros(9, np.float32), *rng.uniform(-1, 1, (20, 9)).astype(np.float32)]:
        out = free.env_action(a)
        assert out.shape == (9,)
        np.testing.assert_array_equal(out[3:9], a[3:9])  # grasp, gaze, fixation, head: the policy's, bit for bit
    zero = free.env_action(np.zeros(9, np.float32))
    np.testing.assert_array_equal(zero[4:6], [0.0, 0.0])  # nothing looks at the believed ball for the policy
    hand = np.array([0.2, -0.1, 0.3], np.float32)
    expected = free.env_action(np.concatenate([hand, np.zeros(6, np.float32)]))[:3]
    # the gated mode's hand residual around the same interception point
    gated.intercept_point = free.intercept_point
    np.testing.assert_array_equal(expected, gated.env_action(np.concatenate([hand, np.zeros(7, np.float32)]))[:3])
    with pytest.raises(ValueError, match="shape"):
        free.env_action(np.zeros(10, np.float32))


def train_frames_seat():
    from visuomotor_gym.core.frames import SEAT_ORIGIN

    return SEAT_ORIGIN


def test_bad_gaze_options_are_refused_with_the_option_named():
    with pytest.raises(ValueError, match=r"gaze_action must be one of .*free_belief.*'free-belief'"):
        BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="free-belief")
    with pytest.raises(ValueError, match="needs hand_action='intercept'"):
        BeliefFeatures("EyeCatch-v0", "absolute", gaze_action="free_belief")
    with pytest.raises(train.TrainArgumentError, match=r"--gaze-action must be one of .*free_belief"):
        train.check_args(train.parse_args(["--env", "EyeCatch-v0", "--gaze-action", "belief"]))
    with pytest.raises(train.TrainArgumentError, match=r"--recipe must be one of \['free_belief', 'free_belief_bc', 'free_clone_stones'\], got 'nope'"):
        train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--recipe", "nope"]))
    for key in ("gaze_log_std_init", "eye_head_log_std_init"):
        for bad in ("yes", "5", "-11", "[1]"):
            with pytest.raises(train.TrainArgumentError, match=f"{key} must be null or a number in"):
                train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--set", f"{key}={bad}"]))
    for key in ("gaze_shaping", "vergence_shaping", "eye_centre_shaping"):
        for bad in ("-0.1", "null", "abc", "101"):
            with pytest.raises(train.TrainArgumentError, match=f"{key} must be a number in"):
                train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--set", f"{key}={bad}"]))
    with pytest.raises(train.TrainArgumentError, match="free_belief needs hand_action=intercept"):
        train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--recipe", "free_belief", "--hand-action",
                                            "absolute"]))


def test_free_belief_recipe_resolves_over_the_catch_recipe():
    config = train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--recipe", "free_belief"]))
    assert config["gaze_action"] == "free_belief" and config["gaze_log_std_init"] == -3.0
    assert config["eye_head_log_std_init"] == -2.0
    assert config["gaze_shaping"] == 0.5 and config["vergence_shaping"] == 0.5
    assert config["eye_centre_shaping"] == 0.3
    assert config["hand_action"] == "intercept" and config["belief"] is True
    # the recipe changes one reward weight and keeps the others
    assert config["env_kwargs"]["reward_weights"] == {"catch": 10.0, "miss": -1.0, "approach": -0.05,
                                                      "foveation": 0.05, "effort": -0.001}
    plain = train.load_config(train.parse_args(["--env", "EyeCatch-v0"]))
    assert plain["gaze_action"] == "free" and plain["gaze_log_std_init"] is None
    assert plain["gaze_shaping"] == plain["vergence_shaping"] == plain["eye_centre_shaping"] == 0.0


def test_gaze_block_starts_with_its_own_std_and_the_run_records_it(tmp_path):
    """With learning rate 0 the saved policy keeps its initial log std: -3 on the gaze block (4-5), -2 on
    fixation and head (6-8), the recipe's log_std_init -1 on hand and grasp; meta records them."""
    from stable_baselines3 import PPO

    run = train.main(["--env", "EyeCatch-v0", "--recipe", "free_belief", "--timesteps", "256", "--out", str(tmp_path),
                      "--run-name", "f", "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128",
                      "eval_freq=100000", "eval_episodes=1", "checkpoint_freq=100000", "learning_rate=0"])
    log_std = PPO.load(run / "model.zip", device="cpu").policy.log_std.detach().numpy()
    np.testing.assert_allclose(log_std, [-1, -1, -1, -1, -3, -3, -2, -2, -2])
    meta = json.loads((run / "ppo_meta.json").read_text())
    assert meta["gaze_action"] == "free_belief" and meta["gaze_log_std_init"] == -3.0
    assert meta["eye_head_log_std_init"] == -2.0
    assert len(meta["obs_mean"]) == 57 + 18


def test_look_shaping_terms_are_the_true_angle_and_depth_mismatch():
    """The training-only terms: -w x the angle between gaze_dir and the true ball, -w x |ln(fixation /
    true distance)|, -w x the eye's angle in the head, added to the reward and named in reward_terms."""
    env = train.LookShaping(gym.make("EyeCatch-v0"), 0.5, 0.25, 0.3)
    env.reset(seed=3)
    base = gym.make("EyeCatch-v0")
    base.reset(seed=3)
    for _ in range(15):
        obs, reward, _, _, info = env.step(np.zeros(9, np.float32))
        _, reward0, _, _, _ = base.step(np.zeros(9, np.float32))
    to_ball = info["ball_pos"] - info["eye_pos"]
    angle = np.arccos(np.dot(info["gaze_dir"], to_ball) / np.linalg.norm(to_ball))
    assert angle > np.radians(2.0)
    assert np.isclose(info["reward_terms"]["gaze"], -0.5 * angle)
    assert np.isclose(info["reward_terms"]["vergence"], -0.25 * abs(np.log(obs[22] / np.linalg.norm(to_ball))))
    assert np.isclose(info["reward_terms"]["eye_centre"], -0.3 * np.hypot(*obs[20:22]))
    assert info["reward_terms"]["eye_centre"] < 0
    added = sum(info["reward_terms"][k] for k in ("gaze", "vergence", "eye_centre"))
    assert np.isclose(reward, reward0 + added)


def test_committed_free_policy_loads_and_plays_one_episode():
    from visuomotor_gym.baselines.ppo.agent import PPOAgent

    agent = PPOAgent(POLICY)
    assert agent.meta["gaze_action"] == "free_belief" and agent.features.action_dim == 9
    trace = evaluate(f"ppo:{POLICY}", "EyeCatch-v0", 1, 0, workers=1).traces[0]
    assert trace.action.shape[1] == 9 and len(trace.action) > 10
    assert trace.saccade_onset.sum() >= 1  # its own gaze moves the eye


def test_look_teacher_acts_from_the_policy_inputs_and_catches():
    """The warm start's scripted teacher: hand residual 0, grasp closed, the gaze request to the believed ball,
    vergence on its believed distance, the head toward it; it plays only free_belief features, and it catches
    (the recipe's premise: the free action can catch when it looks)."""
    from visuomotor_gym.baselines.ppo.belief import BeliefObservation, LookTeacher

    from visuomotor_gym.envs.actions import eye_head_action

    with pytest.raises(ValueError, match="LookTeacher needs gaze_action='free_belief'"):
        LookTeacher(BeliefFeatures("EyeCatch-v0", "intercept", gaze_action="gated"))
    env = BeliefObservation(gym.make("EyeCatch-v0"), "EyeCatch-v0", "intercept", 0.15, "free_belief")
    teacher = LookTeacher(env.features)
    caught = 0
    for seed in range(3):
        x, _ = env.reset(seed=seed)
        done, checked = False, False
        while not done:
            a = teacher(x)
            assert a.shape == (9,) and np.all(a[:3] == 0) and a[3] == 1.0
            look = env.features.look_gaze
            if look is not None and not checked:
                want = eye_head_action(look, np.exp(x[-1]), x[25:27] + 0.5 * np.asarray(look), np.radians(60.0))
                np.testing.assert_allclose(a[4:9], want, atol=1e-6)
                checked = True
            x, _, terminated, truncated, info = env.step(a)
            done = terminated or truncated
        caught += info["is_success"]
        assert checked
    assert caught == 3


def test_behaviour_cloning_warm_start_runs_and_records_its_rounds(tmp_path):
    run = train.main(["--env", "EyeCatch-v0", "--recipe", "free_belief_bc", "--timesteps", "256", "--out", str(tmp_path),
                      "--run-name", "b", "--no-progress-bar", "--set", "n_envs=2", "n_steps=128", "batch_size=128",
                      "eval_freq=100000", "eval_episodes=1", "checkpoint_freq=100000", "bc_episodes=2",
                      "bc_dagger_rounds=1", "bc_epochs=3"])
    bc = json.loads((run / "bc.json").read_text())
    assert [r["player"] for r in bc["rounds"]] == ["teacher", "policy"]
    assert len(bc["policy_mse_per_epoch"]) == 6 and bc["policy_mse_per_epoch"][-1] < bc["policy_mse_per_epoch"][0]
    for bad, match in (("bc_episodes=-1", "bc_episodes must be an integer"), ("bc_epochs=0", "bc_epochs must be"),
                       ("bc_noise=2", "bc_noise must be a number"), ("bc_dagger_rounds=1.5", "bc_dagger_rounds must")):
        with pytest.raises(train.TrainArgumentError, match=match):
            train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--recipe", "free_belief_bc", "--set", bad]))
    with pytest.raises(train.TrainArgumentError, match="bc_episodes needs gaze_action=free_belief"):
        train.load_config(train.parse_args(["--env", "EyeCatch-v0", "--set", "bc_episodes=5"]))
