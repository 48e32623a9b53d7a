"""The catch family's own API and consistency tests (EyeCatchEnv: every catch id of
``visuomotor_gym.ENV_SPECS``): rendering, checkers on the catch-only variants, the divergence fallback,
control modes, rewards term by term, the throw, the bounce wall, spawned processes.

The family-independent checks (checkers, docstring tables, determinism, pickling, bad input, reward
terms, memory) run for every family and rung in tests/test_families.py.
"""

from __future__ import annotations

import copy
import functools
import math
import multiprocessing
import os
import pickle
import re
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from gymnasium.utils.env_checker import data_equivalence

import visuomotor_gym
from visuomotor_gym.envs.catch import RENDER_CAMERAS, EyeCatchEnv
from visuomotor_gym.envs.observation import ObservationLayout
from visuomotor_gym.tasks.catch_rewards import REWARD_TERMS, SHAPED_WEIGHTS

# The catch family (EyeCatchEnv); the walk and reach families have their own suites
# (tests/test_obstacle_walk.py, tests/test_reach.py).
CATCH_SPECS = [s for s in visuomotor_gym.ENV_SPECS if s.family == "catch"]
ENV_IDS = [s.id for s in CATCH_SPECS]
SPECS = {s.id: s for s in CATCH_SPECS}
BOUNCE_IDS = [s.id for s in CATCH_SPECS if s.kwargs.get("bounce_wall")]

# Warnings that check_env may legitimately raise for these envs; anything else fails the test.
ALLOWED_CHECK_ENV_WARNINGS = (
    # MuJoCo-style observations are unbounded on purpose.
    r"A Box observation space minimum value is -infinity",
    r"A Box observation space maximum value is infinity",
    # check_env makes render_mode="human" through env.spec; headless, the env warns and returns None.
    r"render_mode='human' needs a display",
)


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------
def action_sequence(n_act: int, seed: int, length: int = 200) -> np.ndarray:
    """A seeded sequence of actions uniform in [-1, 1]."""
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=(length, n_act)).astype(np.float32)


def unexpected(records, allowed=ALLOWED_CHECK_ENV_WARNINGS) -> list[str]:
    messages = [str(r.message) for r in records]
    return [m for m in messages if not any(re.search(p, m) for p in allowed)]


def rollout(env, seed: int, actions, stop_on_done: bool = True) -> list[tuple]:
    """Reset with ``seed`` and step ``actions``; return deep copies of every transition."""
    obs, info = env.reset(seed=seed)
    out = [(copy.deepcopy(obs), None, False, False, copy.deepcopy(info))]
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        out.append((copy.deepcopy(obs), reward, terminated, truncated, copy.deepcopy(info)))
        if stop_on_done and (terminated or truncated):
            break
    return out


def assert_same_transitions(a: list[tuple], b: list[tuple]) -> None:
    assert len(a) == len(b), f"episode lengths differ: {len(a)} vs {len(b)}"
    for k, (ta, tb) in enumerate(zip(a, b)):
        obs_a, rew_a, term_a, trunc_a, info_a = ta
        obs_b, rew_b, term_b, trunc_b, info_b = tb
        assert data_equivalence(obs_a, obs_b, exact=True), f"observations differ at step {k}"
        assert rew_a == rew_b, f"rewards differ at step {k}: {rew_a} vs {rew_b}"
        assert (term_a, trunc_a) == (term_b, trunc_b), f"terminated/truncated differ at step {k}"
        np.testing.assert_array_equal(info_a["ball_pos"], info_b["ball_pos"], err_msg=f"ball_pos step {k}")
        assert data_equivalence(info_a, info_b, exact=True), f"infos differ at step {k}"


def flat_size() -> int:
    return ObservationLayout().size


# ----------------------------------------------------------------------------------------------
# registry
# ----------------------------------------------------------------------------------------------
def test_registry_matches_env_specs():
    assert len(ENV_IDS) == len(set(ENV_IDS)), "duplicate ids in ENV_SPECS"
    assert "EyeCatch-v0" in ENV_IDS and "EyeCatchOracle-v0" in ENV_IDS and "EyeCatchBounce-v0" in ENV_IDS
    assert set(visuomotor_gym.CATCH_ENV_IDS) <= set(ENV_IDS)
    for spec in visuomotor_gym.ENV_SPECS:
        registered = gym.spec(spec.id)
        assert registered.entry_point == spec.entry_point
        assert registered.kwargs == spec.kwargs
        assert registered.max_episode_steps == spec.max_episode_steps
    visuomotor_gym.register_envs()  # idempotent: registering again must not raise or duplicate
    assert all(gym.spec(i) is not None for i in ENV_IDS)


# ----------------------------------------------------------------------------------------------
# API checkers
# ----------------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.render
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_check_env(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    try:
        with warnings.catch_warnings(record=True) as records:
            warnings.simplefilter("always")
            gym_check_env(env.unwrapped, skip_render_check=False)
    finally:
        env.close()
    assert not unexpected(records), unexpected(records)


@pytest.mark.parametrize("kwargs", [{"control": "joint"}, {"reward": "shaped"}], ids=lambda k: str(k))
def test_gymnasium_check_env_variants(kwargs):
    env = gym.make("EyeCatch-v0", **kwargs)
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped, skip_render_check=True)
    assert not unexpected(records), unexpected(records)


@pytest.mark.parametrize(
    "env_id,kwargs", [("EyeCatch-v0", {"obs_mode": "dict"}), ("EyeCatch-v0", {"control": "joint"})]
)
def test_sb3_check_env(env_id, kwargs):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(env_id, **kwargs)
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        sb3_check_env(env.unwrapped, warn=True, skip_render_check=True)
    assert not [str(r.message) for r in records]


# ----------------------------------------------------------------------------------------------
# determinism, pickling, memory
# ----------------------------------------------------------------------------------------------


@pytest.mark.render
def test_pickle_after_render_and_render_on_clone():
    env = gym.make("EyeCatch-v0", render_mode="rgb_array", width=64, height=48).unwrapped
    env.reset(seed=0)
    env.step(np.zeros(env.action_space.shape, np.float32))
    frame = env.render()
    twin = pickle.loads(pickle.dumps(env))
    frame_twin = twin.render()
    assert frame_twin.shape == frame.shape and frame_twin.dtype == np.uint8
    np.testing.assert_array_equal(frame_twin, frame)
    env.close()
    twin.close()


@pytest.mark.parametrize("obs_mode", ["flat", "dict"])
@pytest.mark.parametrize("steps_before", [0, 2], ids=["after-reset", "after-step"])
def test_mutating_returned_observation_does_not_change_env(obs_mode, steps_before):
    """The observation returned on physics divergence is the env's last one, not the caller's edit.

    Regression: in obs_mode="flat" the env kept the very array it returned as its fallback.
    """
    env = gym.make("EyeCatch-v0", obs_mode=obs_mode).unwrapped
    zero = np.zeros(env.action_space.shape, np.float32)
    obs, _ = env.reset(seed=5)
    for _ in range(steps_before):
        obs, *_ = env.step(zero)
    expected = copy.deepcopy(obs)
    for leaf in obs.values() if obs_mode == "dict" else [obs]:
        leaf[...] = np.nan
    env.data.qvel[:] = 1e12
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fallback, _reward, terminated, _truncated, info = env.step(zero)
    assert info["physics_diverged"] and terminated  # precondition (tested on its own below)
    assert data_equivalence(fallback, expected, exact=True), "the caller's edit leaked into the env"


# ----------------------------------------------------------------------------------------------
# observations and rewards
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observations_finite_over_random_rollouts(env_id):
    env = gym.make(env_id)
    n_act = env.action_space.shape[0]
    rng = np.random.default_rng(11)
    sequences = [action_sequence(n_act, seed) for seed in (0, 1)]
    sequences.append(rng.choice([-1.0, 1.0], size=(200, n_act)).astype(np.float32))  # bang-bang
    for ep, actions in enumerate(sequences):
        obs, info = env.reset(seed=100 + ep)
        assert env.observation_space.contains(obs)
        steps = 0
        for action in actions:
            obs, reward, terminated, truncated, info = env.step(action)
            steps += 1
            assert obs.dtype == np.float32 and obs.shape == (env.unwrapped.layout.size,)
            assert np.all(np.isfinite(obs)), f"non-finite observation at step {steps} of episode {ep}"
            assert env.observation_space.contains(obs)
            assert isinstance(reward, float) and math.isfinite(reward)
            assert not info["physics_diverged"], f"physics diverged at step {steps} of episode {ep}"
            for key in ("ball_pos", "ball_vel", "hand_pos", "gaze_dir", "eye_pos"):
                assert np.all(np.isfinite(info[key])), key
            if terminated or truncated:
                break
        assert terminated or truncated, "episode did not end within 200 steps"
        assert steps <= SPECS[env_id].max_episode_steps


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("reward", ["sparse", "shaped"])
def test_reward_is_sum_of_terms(env_id, reward):
    env = gym.make(env_id, reward=reward)
    expected_terms = {"catch"} if reward == "sparse" else {k for k, w in SHAPED_WEIGHTS.items() if w != 0}
    n_act = env.action_space.shape[0]
    for ep in range(2):
        _, info = env.reset(seed=40 + ep)
        assert info["reward_terms"] == {}
        for action in action_sequence(n_act, 50 + ep):
            _, r, terminated, truncated, info = env.step(action)
            terms = info["reward_terms"]
            assert set(terms) == expected_terms
            assert r == pytest.approx(sum(terms.values()), rel=0, abs=1e-12)
            if reward == "sparse":
                assert r == (1.0 if info["caught"] else 0.0)
            else:
                assert terms["miss"] == (SHAPED_WEIGHTS["miss"] if info["missed"] else 0.0)
                assert terms["approach"] <= 0.0 and terms["effort"] <= 0.0 and terms["foveation"] >= 0.0
                hand_ball = np.linalg.norm(info["hand_pos"] - info["ball_pos"])
                assert terms["approach"] == pytest.approx(SHAPED_WEIGHTS["approach"] * hand_ball, rel=1e-9)
                assert terms["effort"] == pytest.approx(
                    SHAPED_WEIGHTS["effort"] * float(np.mean(np.square(np.clip(action, -1, 1)))), rel=1e-6
                )
            if terminated or truncated:
                break


def test_reward_weights_override():
    env = gym.make("EyeCatch-v0", reward="shaped", reward_weights={"effort": 0.0, "approach": -0.5})
    env.reset(seed=0)
    for action in action_sequence(9, 0)[:20]:
        _, r, terminated, _, info = env.step(action)
        assert set(info["reward_terms"]) == set(REWARD_TERMS) - {"effort"}
        hand_ball = np.linalg.norm(info["hand_pos"] - info["ball_pos"])
        assert info["reward_terms"]["approach"] == pytest.approx(-0.5 * hand_ball, rel=1e-9)
        assert r == pytest.approx(sum(info["reward_terms"].values()), rel=0, abs=1e-12)
        if terminated:
            break


# ----------------------------------------------------------------------------------------------
# control modes
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_joint_control(env_id):
    env = gym.make(env_id, control="joint")
    u = env.unwrapped
    assert env.action_space.shape == (16,) and env.action_space.dtype == np.float32
    assert sum(u.action_structure.values()) == 16 and u.action_structure["body_joints"] == 10
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(9, np.float32))
    # Constant joint setpoints are reached (the action maps linearly onto each joint's range).
    setpoint = np.linspace(-0.5, 0.5, 10)
    action = np.zeros(16, np.float32)
    action[:10] = setpoint
    u.reset(seed=1)
    for _ in range(60):
        obs, *_ = u.step(action)
    lo, hi = u.body.joint_range[:, 0], u.body.joint_range[:, 1]
    target = lo + (setpoint + 1.0) * 0.5 * (hi - lo)
    np.testing.assert_allclose(obs[ObservationLayout().slices["body_qpos"]], target, atol=0.02)
    assert np.all(np.isfinite(obs))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_joint_control_random_actions_do_not_diverge(env_id):
    """Regression: with explicit Euler, a straight elbow made shoulder_rot's servo damping unstable
    (kv * dt / M = 30 * 0.002 / 0.022 > 2) and random joint actions diverged in every episode."""
    env = gym.make(env_id, control="joint")
    for seed in range(3):
        ep = rollout(env, seed, action_sequence(16, seed))
        assert ep[-1][2] or ep[-1][3]
        assert all(np.all(np.isfinite(t[0])) for t in ep)
        diverged = [k for k, t in enumerate(ep) if t[4]["physics_diverged"]]
        assert not diverged, f"seed {seed}: physics diverged at step {diverged[0]} under random joint actions"


@pytest.mark.parametrize("target", [(1.0, -1.0, 0.0), (1.0, 1.0, 1.0)], ids=str)
def test_hand_target_at_workspace_edge_does_not_diverge(target):
    """Regression: the same instability in control="hand", with the arm stretched to a workspace corner."""
    env = gym.make("EyeCatch-v0").unwrapped
    action = np.zeros(9, np.float32)
    action[:3] = target
    for seed in range(2):
        env.reset(seed=seed)
        for k in range(60):
            obs, _, _, _, info = env.step(action)  # keep stepping after the ball's end: the arm matters
            assert not info["physics_diverged"], f"seed {seed}: physics diverged at step {k}"
        assert np.all(np.isfinite(obs))


def test_hand_control_reaches_target():
    from visuomotor_gym.body.seated import HAND_WORKSPACE

    env = gym.make("EyeCatch-v0").unwrapped
    target_seat = np.array([0.35, -0.3, 0.6])
    lo, hi = HAND_WORKSPACE[:, 0], HAND_WORKSPACE[:, 1]
    action = np.zeros(9, np.float32)
    action[:3] = 2.0 * (target_seat - lo) / (hi - lo) - 1.0
    env.reset(seed=0)
    for _ in range(50):
        obs, *_ = env.step(action)
    np.testing.assert_allclose(obs[ObservationLayout().slices["hand_pos"]], target_seat, atol=0.02)


# ----------------------------------------------------------------------------------------------
# documentation consistency
# ----------------------------------------------------------------------------------------------


def test_docstring_observation_table_is_the_layouts_and_documents_joint_control():
    """The table and index rows of every family are checked in tests/test_families.py; here the whole
    generated table (units, descriptions) and the joint-control action shape, which only catch has."""
    doc = EyeCatchEnv.__doc__
    assert ObservationLayout().markdown_table() in doc
    assert "``(16,)``" in doc


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observation_structure_sums_to_observation_size(env_id):
    env = gym.make(env_id)
    u = env.unwrapped
    structure = u.observation_structure
    layout = u.layout  # the single-ball layout; with n_balls=2 followed by the second ball's blocks
    single = ObservationLayout()
    assert sum(structure.values()) == env.observation_space.shape[0] == layout.size
    assert layout.size == flat_size() if u.n_balls == 1 else layout.size > flat_size()
    assert structure == layout.structure
    assert list(structure.items())[: len(single.blocks)] == list(single.structure.items())
    start = 0
    for name, size in structure.items():
        assert layout.slices[name] == slice(start, start + size)
        start += size
    assert sum(u.action_structure.values()) == env.action_space.shape[0] == 9


# ----------------------------------------------------------------------------------------------
# rendering
# ----------------------------------------------------------------------------------------------
@pytest.mark.render
@pytest.mark.parametrize("camera", RENDER_CAMERAS)
def test_render_rgb_array(camera):
    width, height = 96, 64
    env = gym.make("EyeCatch-v0", render_mode="rgb_array", render_camera=camera, width=width, height=height)
    env.reset(seed=0)
    env.step(np.zeros(9, np.float32))
    frame = env.render()
    expected_width = 2 * width if camera == "both" else width
    assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
    assert frame.shape == (height, expected_width, 3)
    assert frame.std() > 0, "blank frame"
    env.close()


@pytest.mark.slow
@pytest.mark.render
def test_render_default_size_and_no_side_effects():
    env_r = gym.make("EyeCatch-v0", render_mode="rgb_array")
    env_n = gym.make("EyeCatch-v0")
    actions = action_sequence(9, 5)[:15]
    env_r.reset(seed=9)
    env_n.reset(seed=9)
    assert env_r.render().shape == (360, 960, 3)
    for action in actions:
        obs_r, rew_r, *_ = env_r.step(action)
        env_r.render()
        obs_n, rew_n, *_ = env_n.step(action)
        np.testing.assert_array_equal(obs_r, obs_n)  # rendering must not change the simulation
        assert rew_r == rew_n
    env_r.close()


def test_render_without_mode_warns_and_returns_none():
    env = gym.make("EyeCatch-v0")
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.unwrapped.render() is None


def test_render_human_headless_warns_once_and_returns_none():
    if os.environ.get("MUJOCO_GL") not in ("egl", "osmesa") and (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        pytest.skip("a display is available: human mode would open a viewer")
    env = gym.make("EyeCatch-v0", render_mode="human")
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="needs a display") as records:
        env.step(np.zeros(9, np.float32))
        assert env.render() is None
        env.step(np.zeros(9, np.float32))
    assert sum("needs a display" in str(r.message) for r in records) == 1
    env.close()


# ----------------------------------------------------------------------------------------------
# timing
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_dt_and_render_fps(env_id):
    env = gym.make(env_id)
    assert env.unwrapped.dt == pytest.approx(0.02, abs=1e-12)
    assert env.unwrapped.metadata["render_fps"] == 50 and env.metadata["render_fps"] == 50
    obs, info = env.reset(seed=0)
    assert info["time"] == 0.0
    t_slice = ObservationLayout().slices["time"]
    for k in range(1, 11):
        obs, _, terminated, _, info = env.step(np.zeros(9, np.float32))
        assert info["time"] == pytest.approx(0.02 * k, abs=1e-9)
        assert obs[t_slice][0] == pytest.approx(info["time"], abs=1e-6)
        assert not terminated


def test_control_dt_changes_dt_and_fps_per_instance():
    env = gym.make("EyeCatch-v0", control_dt=0.01)
    assert env.unwrapped.dt == pytest.approx(0.01, abs=1e-12)
    assert env.unwrapped.metadata["render_fps"] == 100
    assert EyeCatchEnv.metadata["render_fps"] == 50, "an instance changed the class-level metadata"
    assert gym.make("EyeCatch-v0").unwrapped.metadata["render_fps"] == 50


# ----------------------------------------------------------------------------------------------
# the observability ladder shares the throw sampler
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2, 3, 12345])
def test_same_seed_same_throw_across_ladder(seed):
    reference = None
    infos = {}
    for env_id in ENV_IDS:
        _, info = gym.make(env_id).reset(seed=seed)
        infos[env_id] = info
    reference = infos["EyeCatchOracle-v0"]
    assert reference["wall_y"] is None
    for env_id, info in infos.items():
        np.testing.assert_array_equal(info["release_pos"], reference["release_pos"], err_msg=env_id)
        np.testing.assert_array_equal(info["arrival_pos"], reference["arrival_pos"], err_msg=env_id)
        assert info["flight_time"] == reference["flight_time"], env_id
        np.testing.assert_array_equal(info["gaze_dir"], reference["gaze_dir"], err_msg=env_id)
        if env_id in BOUNCE_IDS:
            assert info["wall_y"] is not None
            assert not np.allclose(info["release_vel"], reference["release_vel"]), env_id
            assert info["release_vel"][0] == pytest.approx(reference["release_vel"][0], abs=1e-12)
            assert info["release_vel"][2] == pytest.approx(reference["release_vel"][2], abs=1e-12)
        else:
            np.testing.assert_array_equal(info["release_vel"], reference["release_vel"], err_msg=env_id)
            assert info["wall_y"] is None
        np.testing.assert_array_equal(info["ball_pos"], info["release_pos"])
        np.testing.assert_array_equal(info["ball_vel"], info["release_vel"])
    assert "EyeCatchBounce-v0" in BOUNCE_IDS


@pytest.mark.parametrize("env_id", BOUNCE_IDS)
def test_bounce_wall_deflects_ball_to_arrival_point(env_id):
    gravity, physics_dt = np.array([0.0, 0.0, -9.81]), 0.002
    env = gym.make(env_id)
    away = np.array([-1, 1, -1, -1, 0, 0, 0, 0, 0], np.float32)  # hand far left/back, open
    errors = []
    for seed in range(10):
        _, info = env.reset(seed=seed)
        wall_y, side = info["wall_y"], np.sign(info["wall_y"] - info["release_pos"][1])
        flight_time, arrival = info["flight_time"], info["arrival_pos"]
        last = (0.0, info["ball_pos"], info["ball_vel"])
        while True:
            _, _, terminated, truncated, info = env.step(away)
            # The ball centre reflects at wall_y: it must never get (much) beyond it.
            assert side * (info["ball_pos"][1] - wall_y) < 0.02, f"seed {seed}: the ball passed the wall"
            if info["time"] <= flight_time + 1e-9:
                last = (info["time"], info["ball_pos"], info["ball_vel"])
            if terminated or truncated or info["time"] > flight_time:
                break
        t, p, v = last
        n = round((flight_time - t) / physics_dt)
        at_arrival = p + n * physics_dt * v + gravity * physics_dt**2 * n * (n + 1) / 2
        errors.append(float(np.linalg.norm(at_arrival - arrival)))
    # MuJoCo's soft contact delays the bounce (throws.py documents 4-9 cm): centimetres, not metres
    # (a ball that flies through the wall ends up metres away, at the mirrored aim point).
    assert max(errors) < 0.1, errors


# ----------------------------------------------------------------------------------------------
# physics divergence
# ----------------------------------------------------------------------------------------------
def _corrupt(env, how: str) -> None:
    d = env.data
    if how == "qvel_huge":
        d.qvel[:] = 1e12
    elif how == "qvel_nan":
        d.qvel[:] = np.nan
    elif how == "ball_qpos_nan":
        q = env.task.balls[0].qpos_adr
        d.qpos[q : q + 3] = np.nan
    elif how == "qfrc_nan":  # produces a NaN qacc
        d.qfrc_applied[:] = np.nan
    else:
        raise AssertionError(how)


@pytest.mark.parametrize(
    "env_id,how,steps_before",
    [(i, "qvel_huge", 3) for i in ENV_IDS]
    + [("EyeCatch-v0", h, 3) for h in ("qvel_nan", "ball_qpos_nan", "qfrc_nan")]
    # in the very first control step, MuJoCo's autoreset leaves d.time where it would have been anyway
    + [("EyeCatch-v0", h, 0) for h in ("qvel_huge", "ball_qpos_nan", "qfrc_nan")],
)
def test_physics_divergence_terminates_with_finite_observation(env_id, how, steps_before):
    env = gym.make(env_id).unwrapped
    actions = action_sequence(9, 4)
    last_obs, _ = env.reset(seed=6)
    for action in actions[:steps_before]:
        last_obs, _, terminated, _, _ = env.step(action)
        assert not terminated
    last_obs = last_obs.copy()
    _corrupt(env, how)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        obs, reward, terminated, truncated, info = env.step(actions[steps_before])
    assert info["physics_diverged"] is True
    assert terminated is True and truncated is False
    assert info["is_success"] is False
    assert np.all(np.isfinite(obs))
    np.testing.assert_array_equal(obs, last_obs)  # the last finite observation
    assert isinstance(reward, float) and math.isfinite(reward)

    # The next reset recovers completely: same episode as a fresh env.
    fresh = gym.make(env_id).unwrapped
    assert_same_transitions(rollout(env, 6, actions[:40]), rollout(fresh, 6, actions[:40]))


# ----------------------------------------------------------------------------------------------
# "visuomotor_gym:<id>" from a fresh interpreter
# ----------------------------------------------------------------------------------------------
def test_module_prefixed_id_in_spawned_process(spawn_worker):
    env_id, seed = "visuomotor_gym:EyeCatch-v0", 3
    actions = action_sequence(9, 13)[:5]
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        child = pool.apply_async(spawn_worker, (env_id, seed, actions.tolist())).get(timeout=240)
    assert child["imported_before"] is False, "the worker module imported visuomotor_gym by itself"
    assert child["mujoco_gl"] == os.environ["MUJOCO_GL"]  # set by conftest, inherited by the child

    env = gym.make(env_id)
    obs, _ = env.reset(seed=seed)
    local = [obs]
    for action in actions:
        obs, *_ = env.step(action)
        local.append(obs)
    assert len(child["observations"]) == len(local)
    for k, (theirs, ours) in enumerate(zip(child["observations"], local)):
        np.testing.assert_array_equal(np.asarray(theirs, dtype=np.float32), ours, err_msg=f"step {k}")


def test_async_vector_env_spawn():
    env_id = "visuomotor_gym:EyeCatch-v0"
    seeds = [11, 12]
    actions = np.stack([action_sequence(9, 20), action_sequence(9, 21)], axis=1)[:6]  # (steps, 2, 9)
    venv = gym.vector.AsyncVectorEnv([functools.partial(gym.make, env_id) for _ in seeds], context="spawn")
    try:
        assert venv.single_action_space.shape == (9,)
        obs, _ = venv.reset(seed=seeds)
        vector_obs = [obs.copy()]
        for step_actions in actions:
            obs, rewards, terminated, truncated, _ = venv.step(step_actions)
            assert obs.shape == (2, flat_size()) and rewards.shape == (2,)
            assert not terminated.any() and not truncated.any()
            vector_obs.append(obs.copy())
    finally:
        venv.close()
    for i, seed in enumerate(seeds):
        env = gym.make(env_id)
        obs, _ = env.reset(seed=seed)
        np.testing.assert_array_equal(vector_obs[0][i], obs)
        for k, step_actions in enumerate(actions):
            obs, *_ = env.step(step_actions[i])
            np.testing.assert_array_equal(vector_obs[k + 1][i], obs, err_msg=f"env {i} step {k}")
