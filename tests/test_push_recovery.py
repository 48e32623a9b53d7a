"""PushRecovery-v0: a standing body that really falls, a wall of cubes that holds only where a cube is,
and the eom_brace baseline (Eom et al. 2019, section 7) against its references.

The family-independent checks (API checkers, docstring tables, determinism, pickling, bad input,
reward terms, constant observations) run for every rung in tests/test_families.py."""

from __future__ import annotations

import math

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.assets import asset_path
from visuomotor_gym.body import standing as sn
from visuomotor_gym.control.hand import HandControlParams
from visuomotor_gym.tasks import push_recovery as pr

ENV = "PushRecovery-v0"


def _model():
    return mujoco.MjModel.from_xml_path(str(asset_path(sn.SCENE)))


def _bare_stance(force_n: float, duration_s: float = pr.PUSH_DURATION_S, seconds: float = 3.0,
                 direction: tuple = (0.0, -1.0)):
    """The standing body with its leg and arm servos holding still, a push toward the wall (``direction``, -y by
    default) on the torso at t = 1 s: (fell, largest pelvis roll in rad)."""
    m = _model()
    d = mujoco.MjData(m)
    body = sn.StandingBody(m, HandControlParams(), 0.02)
    torso = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "torso")
    mujoco.mj_resetData(m, d)
    body.reset_pose(d)
    mujoco.mj_forward(m, d)
    roll = 0.0
    while d.time < seconds:
        d.ctrl[body._leg_act] = sn.STANCE_RAD
        d.ctrl[body._act] = 0.0  # the arm and waist hold their setpoints
        push = (direction[0] * force_n, direction[1] * force_n, 0.0)
        d.xfrc_applied[torso, :3] = push if 1.0 <= d.time < 1.0 + duration_s else (0.0, 0.0, 0.0)
        mujoco.mj_step(m, d)
        r = d.xmat[body.pelvis]
        roll = max(roll, math.atan2(float(r[7]), float(r[8])))
    return body.head_height(d) < pr.FALL_HEAD_HEIGHT_M, roll


# eom_brace's defaults before PushRecovery's fourth pass (the wall beside the body): tests of the brace's
# physics that were measured there pin them.
THIRD_PASS = ("fall_direction=false,hold_lean_gain=0,hold_lean_damp=0,drop_crowded=false,fuse_max_ecc_deg=20,"
              "choose_by_ray=false,verge_on_ray=false,hand_on_cut=false")


# The scene and agent before PushRecovery's eleventh pass (no loose cubes, the push at 0.6-1.4 s; eom_brace without
# the identification looks and the vergence search): tests of the brace's physics measured there pin them.
TENTH_AGENT = {"identify": "false", "depth_search": "false", "verge_on_sample": "false", "cut_until_w": "400"}


def _tenth(spec: str) -> str:
    """An eom_brace spec with the tenth pass's defaults for every option it does not set."""
    name, _, opts = spec.partition(":")
    given = {kv.split("=")[0] for kv in opts.split(",") if kv}
    extra = ",".join(f"{k}={v}" for k, v in TENTH_AGENT.items() if k not in given)
    return f"{name}:{opts + ',' if opts else ''}{extra}"


@pytest.fixture
def tenth_pass(monkeypatch):
    monkeypatch.setattr(pr, "LOOSE_CUBES", False)
    monkeypatch.setattr(pr, "PUSH_TIME_S", (0.6, 1.4))


def _play(agent_spec: str, seed: int, env_id: str = ENV, **env_kwargs):
    env = gym.make(env_id, **env_kwargs)
    agent = make_agent(agent_spec, env_id, env.action_space.shape[0], seed=seed)
    obs, info = env.reset(seed=seed)
    while True:
        action, _ = agent.predict(obs)
        obs, _r, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            return env, agent, info


# --- the scene and the body --------------------------------------------------------------------
def test_every_name_exists_and_nothing_is_gravity_compensated():
    m = _model()
    kinds = {"body": mujoco.mjtObj.mjOBJ_BODY, "joint": mujoco.mjtObj.mjOBJ_JOINT,
             "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR, "geom": mujoco.mjtObj.mjOBJ_GEOM,
             "site": mujoco.mjtObj.mjOBJ_SITE, "camera": mujoco.mjtObj.mjOBJ_CAMERA}
    for kind, names in sn.ALL_NAMES.items():
        for name in names:
            assert mujoco.mj_name2id(m, kinds[kind], name) >= 0, (kind, name)
    env = gym.make(ENV)
    assert np.all(env.unwrapped.model.body_gravcomp == 0.0)  # the shared head asks for it: switched off


def test_the_body_stands_on_its_feet_at_the_stance_origin():
    env = gym.make(ENV, push_force_n=(0.0, 0.0))
    env.reset(seed=0)
    u = env.unwrapped
    np.testing.assert_allclose(u.data.xpos[u.body.pelvis], sn.STANCE_ORIGIN, atol=0.01)
    a = np.zeros(env.action_space.shape, np.float32)
    a[:3] = sn.hand_target_action(u.body.hand_pos(u.data))
    for _ in range(100):  # 2 s, no push
        _obs, _r, terminated, _t, _info = env.step(a)
        assert not terminated
    cop = env.unwrapped.body.centre_of_pressure(u.data)
    assert cop[2] > 0.3 and cop[3] > 0.3  # both feet carry the body
    assert abs(cop[2] + cop[3] - 1.0) < 0.05  # ... all of it: nothing else holds it up
    assert u.body.head_height(u.data) > 1.4


@pytest.mark.parametrize("force_n", [150.0, 250.0])
def test_a_small_push_on_the_bare_stance_does_not_tip_it(force_n):
    fell, roll = _bare_stance(force_n)
    assert not fell and roll < 0.15, roll


@pytest.mark.parametrize("force_n", [pr.PUSH_FORCE_N[0], pr.PUSH_FORCE_N[1]])
def test_the_task_s_push_tips_the_bare_stance_over(force_n):
    """Physics, not script: every push of the task's range topples the stance held by its servos."""
    fell, roll = _bare_stance(force_n)
    assert fell and roll > 1.0, roll


def test_the_push_is_on_the_torso_for_its_duration_only():
    env = gym.make(ENV)
    _obs, info = env.reset(seed=3)
    u = env.unwrapped
    torso = mujoco.mj_name2id(u.model, mujoco.mjtObj.mjOBJ_BODY, "torso")
    a = np.zeros(env.action_space.shape, np.float32)
    impulse = np.zeros(3)
    for _ in range(int((info["push_time"] + 0.5) / u.dt)):
        u.task.before_physics(u.data)
        impulse += u.data.xfrc_applied[torso, :3] * u.dt
        env.step(a)
    np.testing.assert_allclose(impulse, info["push_force"] * pr.PUSH_DURATION_S * info["push_dir"], rtol=1e-9)


# --- falls and braces --------------------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_body_falls_without_bracing(seed):
    """eom_brace with its hand kept at the ready point (use_hand=false): the same look, no hand: falls."""
    env, _agent, info = _play("eom_brace:use_hand=false", seed)
    assert info["fallen"] and not info["is_success"]
    assert env.unwrapped.task.fall_geoms is not None


def _drive_hand(env, info, point):
    """Drive the right hand (brace command on) beside ``point`` (world) until the push, then 2 cm beyond it, to the
    episode's end: the last step's info."""
    u = env.unwrapped
    a = np.zeros(env.action_space.shape, np.float32)
    a[3] = 1.0
    while True:
        pushed = u.data.time >= info["push_time"]
        target = point + (0.0, -0.02, 0.0) if pushed else np.array([point[0], -0.4, point[2]])
        a[:3] = sn.hand_target_action(target)
        _obs, _r, terminated, truncated, step_info = env.step(a)
        if terminated or truncated:
            return step_info


def test_a_hand_in_a_gap_does_not_hold(monkeypatch, tenth_pass):
    """The hand driven (true geometry) to the middle of the gap beside the cube nearest the shoulder: it
    passes between the cubes and the body falls; the same hand on that cube's face holds it. (The wall beside
    the body, yaw 0: the target's geometry below assumes it.)"""
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (0.0, 0.0))
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)  # the wall on the right, as when measured
    outcomes = {}
    for where in ("gap", "face"):
        env = gym.make(ENV, vision="oracle")
        _obs, info = env.reset(seed=4)
        faces, halves = info["block_faces"], info["block_half_sizes"]
        i = int(np.argmin(np.abs(faces[:, 0] - 0.05)))
        j = i + 1
        gap = 0.5 * ((faces[i, 0] + halves[i]) + (faces[j, 0] - halves[j]))
        point = faces[i].copy() if where == "face" else np.array([gap, faces[i, 1], 0.5 * (faces[i, 2] + faces[j, 2])])
        step_info = _drive_hand(env, info, point)
        outcomes[where] = (step_info["is_success"], step_info["fallen"], step_info["first_contact_time"])
    assert outcomes["gap"][1] and outcomes["gap"][2] < 0, outcomes  # fell, never touched a cube
    assert outcomes["face"][2] > 0, outcomes  # touched the cube


def test_eom_brace_keeps_the_body_upright_on_a_few_seeds():
    for seed in (1, 2, 4):
        env, agent, info = _play("eom_brace", seed)
        assert info["is_success"] and not info["fallen"], (seed, env.unwrapped.task.fall_geoms)
        kinds = [e for _t, e in agent.events if not e.startswith(("identified", "search"))]
        assert kinds[:1] == ["detect"] and "hold" in kinds, kinds
        assert info["first_contact_time"] > env.unwrapped.task.push_time


def test_a_brace_that_keeps_pushing_throws_the_body_over_its_other_foot(monkeypatch, tenth_pass):
    """Seed 8, the wall beside the body (yaw 0), the third pass's brace (a strut, no ankle response): the hand
    strikes the cube; an arm that keeps pushing as the body moves back (yield off) throws it away from the
    wall, over its left foot; the arm that yields keeps it upright."""
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (0.0, 0.0))
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)  # the wall on the right, as when measured
    monkeypatch.setattr(sn, "ANKLE_STRATEGY_GAIN", 0.0)
    third = _tenth("eom_brace:" + THIRD_PASS)
    _env, _agent, info = _play(third, 8)
    assert info["is_success"], info
    _env, _agent, info = _play(third + ",yield_speed_m_s=-1", 8)
    assert info["fallen"] and info["first_contact_time"] > 0, info  # it touched a cube, then fell ...
    assert info["pelvis_pos"][1] > 0.2, info["pelvis_pos"]  # ... away from the wall (the wall is at -y)


def test_the_gaze_blind_twin_falls_where_eom_brace_stands():
    """Held gaze looks straight ahead: the wall is outside the field of view, no cube is ever believed."""
    for seed in (1, 2):
        _env, _agent, info = _play("gaze_blind:eom_brace", seed)
        assert not info["is_success"], seed


# --- metrics -------------------------------------------------------------------------------------
def test_the_summary_and_realism_of_eom_brace_episodes():
    from visuomotor_gym.bench.evaluate import evaluate

    # Seeds 16-18: upright, gaze on the face centre before the hand. (Not on every seed under the human
    # periphery: on seeds 3-5 gaze gets there after the contact on the mean; docs/reproductions/eom.md, the
    # median over 200 seeds is +0.08 s.)
    result = evaluate("eom_brace", ENV, episodes=3, seed=16, workers=1, keep_traces=True)
    s = result.summary
    assert s["episodes"] == 3 and s["success"] == 3
    components = s["gaze_realism"]["components"]
    lead = components["gaze_hand_lead_s"]["value"]
    # gaze reaches the cube before the hand (Land et al. 1999): the last stretch of gaze on it before the contact
    # (the identification look before the push, broken off, does not count)
    assert 0.0 < lead < 1.5, lead
    reaction = components["hand_reaction_s"]["value"]
    assert 0.0 < reaction < 0.4, reaction


def test_the_gaze_hand_lead_counts_from_the_last_arrival_of_gaze_on_the_cube():
    from types import SimpleNamespace

    from visuomotor_gym.metrics.push_realism import push_measures

    # 11 steps of 0.1 s; one cube face 1 m ahead of an eye at the origin; the hand touches it at step 9.
    # Gaze: on it (0 deg) at steps 1-3, away (90 deg) at 4-5, on it again from step 6: the lead is 0.9 - 0.6 s.
    n, dt = 11, 0.1
    on = [False, True, True, True, False, False, True, True, True, True, True]
    gaze = [[1.0, 0.0, 0.0] if o else [0.0, 1.0, 0.0] for o in on]
    hand = [[0.5 + 0.05 * k, 0.0, 0.0] for k in range(n)]
    touch = [k >= 9 for k in range(n)]
    faces = [[1.0, 0.0, 0.0]] + [[1.0, 5.0, 0.0]] * 5
    tr = SimpleNamespace(t=[dt * k for k in range(n)], dt=dt, hand_pos=hand, push_time=0.35,
                         saccade_onset=[False] * n, hand_on_block=touch, block_faces=faces, gaze_dir=gaze,
                         eye_pos=[[0.0, 0.0, 0.0]] * n)
    assert push_measures(tr)["gaze_hand_lead_s"] == pytest.approx(0.9 - 0.6)
    # the same episode without the break: gaze on the cube from step 1, a lead of 0.8 s
    tr.gaze_dir = [[1.0, 0.0, 0.0] if k >= 1 else [0.0, 1.0, 0.0] for k in range(n)]
    assert push_measures(tr)["gaze_hand_lead_s"] == pytest.approx(0.8)
    # gaze only after the contact: undefined
    tr.gaze_dir = [[1.0, 0.0, 0.0] if k >= 10 else [0.0, 1.0, 0.0] for k in range(n)]
    assert math.isnan(push_measures(tr)["gaze_hand_lead_s"])


# --- robustness ----------------------------------------------------------------------------------
def test_random_actions_give_no_nan_and_no_mujoco_warning():
    env = gym.make(ENV)
    rng = np.random.default_rng(0)
    steps = 0
    for seed in range(6):
        env.reset(seed=seed)
        while True:
            obs, _r, terminated, truncated, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
            steps += 1
            assert np.all(np.isfinite(obs)) and not info["physics_diverged"]
            if terminated or truncated:
                break
    assert sum(w.number for w in env.unwrapped.data.warning) == 0
    assert steps > 200


# --- opt-in variants of the third pass (off in the definition) ---------------------------------
def test_the_postural_response_is_off_by_default_and_flexes_the_hips_when_falling_backward(monkeypatch):
    """Off (gains 0): the leg setpoints are the stance, exactly. On: a centre of mass moving backward
    (a shove toward -x) flexes both hips and dorsiflexes both ankles, POSTURAL_LATENCY_S after it."""
    m = _model()
    d = mujoco.MjData(m)
    body = sn.StandingBody(m, HandControlParams(), 0.02)
    mujoco.mj_resetData(m, d)
    body.reset_pose(d)
    mujoco.mj_forward(m, d)
    assert body._postural_response(d) == list(sn.STANCE_RAD)
    monkeypatch.setattr(sn, "HIP_STRATEGY_GAIN", 4.0)
    monkeypatch.setattr(sn, "ANKLE_STRATEGY_GAIN", 1.0)
    body.reset_pose(d)
    mujoco.mj_forward(m, d)
    lag = round(sn.POSTURAL_LATENCY_S / 0.02)
    outs = []
    for _k in range(lag + 2):
        d.qvel[body._root_v] = -0.5  # the pelvis moving backward at 0.5 m/s
        mujoco.mj_step(m, d, 10)
        outs.append(body._postural_response(d))
    # The extrapolated CoM is seen lag steps late: the first lag responses use the quiet stance's.
    assert outs[0][1] == sn.STANCE_RAD[1]
    hip, ankle = outs[-1][1] - sn.STANCE_RAD[1], outs[-1][3] - sn.STANCE_RAD[3]
    assert 0.0 < hip <= sn.HIP_STRATEGY_MAX_RAD and outs[-1][6] - sn.STANCE_RAD[6] == hip
    assert 0.0 < ankle <= sn.ANKLE_STRATEGY_MAX_RAD
    if hip < sn.HIP_STRATEGY_MAX_RAD and ankle < sn.ANKLE_STRATEGY_MAX_RAD:  # neither clipped: gains 4 : 1
        assert abs(hip / ankle - 4.0) < 1e-9


def test_a_turned_wall_is_a_plane_at_its_yaw_and_the_push_goes_toward_it(monkeypatch):
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (30.0, 30.0))
    env = gym.make(ENV)
    _obs, info = env.reset(seed=4)
    task = env.unwrapped.task
    yaw = math.radians(30.0)
    normal = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
    np.testing.assert_allclose(task.wall_normal, normal, atol=1e-12)
    depth = task.block_faces @ normal  # every face on a plane parallel to the wall, 0-10 cm out of it
    assert np.ptp(depth) <= pr.BLOCK_OFFSET_M[1] + 1e-9
    assert pr.WALL_DISTANCE_M[0] - pr.BLOCK_OFFSET_M[1] - 1e-9 <= depth.min() and depth.max() <= pr.WALL_DISTANCE_M[1]
    assert math.degrees(math.acos(float(info["push_dir"] @ normal))) <= pr.PUSH_AZIMUTH_DEG + 1e-9
    q = env.unwrapped.data.mocap_quat[task._mocap[0]]
    np.testing.assert_allclose(q, (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)), atol=1e-12)


def test_a_crowded_row_keeps_every_cube_near_the_first_one_s_height_and_the_other_draws(monkeypatch):
    """ROW_HEIGHT_JITTER_M (fifth pass, opt-in): the cubes after the first within +-jitter of its height; the
    sizes, the along-wall positions and the push are the definition's draws (their order is unchanged)."""
    env = gym.make(ENV)
    env.reset(seed=7)
    task = env.unwrapped.task
    faces, sizes, push = task.block_faces.copy(), task.block_half_sizes.copy(), task.push_time
    monkeypatch.setattr(pr, "ROW_HEIGHT_JITTER_M", 0.02)
    env.reset(seed=7)
    z = task.block_faces[:, 2]
    assert np.ptp(faces[:, 2]) > 0.1  # the definition's cubes at independent heights (seed 7)
    assert np.all(np.abs(z[1:] - z[0]) <= 0.02 + 1e-12) and z[0] == faces[0, 2]
    np.testing.assert_array_equal(task.block_half_sizes, sizes)
    np.testing.assert_array_equal(task.block_faces[:, :2], faces[:, :2])
    assert task.push_time == push


def test_eom_brace_braces_along_the_fall_toward_a_turned_wall(monkeypatch):
    """fall_direction=true: the push is detected from the vestibular fall direction, which points at the
    turned wall, and the hand braces on a cube there (Oracle rung: the brace, not the eye)."""
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (25.0, 25.0))
    env, agent, info = _play("eom_brace:fall_direction=true", 4, env_id="PushRecoveryOracle-v0")
    normal = env.unwrapped.task.wall_normal
    assert agent.detected_at is not None
    assert math.degrees(math.acos(float(agent.normal[:2] @ normal[:2]))) < 25.0
    assert info["is_success"] and env.unwrapped.task.first_contact_time is not None


@pytest.mark.parametrize("spec", ["eom_brace:verge_on_sample=maybe", "eom_brace:fall_direction=2",
                                  "eom_brace:scan_blocks=-1"])
def test_the_new_options_refuse_bad_values(spec):
    with pytest.raises(ValueError, match="EomBraceParams"):
        make_agent(spec, ENV, 9)


# --- fourth pass: the active hold, crowded samples, choosing by the line of sight ----------
def test_the_active_hold_keeps_a_body_upright_that_the_strut_lets_lean_over(monkeypatch, tenth_pass):
    """Oracle rung, seed 6, the third pass's scene (wall beside the body, no ankle response) and agent: with
    the plain strut the hand rests on the cube's edge while the body leans on its right foot's outer edge and
    slowly tips into the wall (upper arm on a cube); the arm that pushes with the trunk's lean
    (hold_lean_gain) brings it back over its feet. The brace, not the eye."""
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (0.0, 0.0))
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)  # the wall on the right, as when measured
    monkeypatch.setattr(sn, "ANKLE_STRATEGY_GAIN", 0.0)
    _env, _agent, info = _play(_tenth("eom_brace:" + THIRD_PASS), 6, env_id="PushRecoveryOracle-v0")
    assert info["fallen"] and not info["is_success"]
    active = THIRD_PASS.replace("hold_lean_gain=0,hold_lean_damp=0", "hold_lean_gain=2,hold_lean_damp=0.1")
    env, _agent, info = _play(_tenth("eom_brace:" + active), 6, env_id="PushRecoveryOracle-v0")
    assert info["is_success"] and env.unwrapped.task.first_contact_time is not None


def _still_obs(block_pos: dict) -> np.ndarray:
    """A flat observation: eye at the stance origin looking along +x (identity rotation), the given cube
    samples (eye frame) visible, no foot contact (no detection)."""
    from visuomotor_gym.baselines.eom_brace.agent import _LAYOUT, _S

    obs = np.zeros(_LAYOUT.size)
    obs[_S["eye_rot"]] = np.eye(3).reshape(-1)
    obs[_S["fixation"]] = 1.0
    pos = obs[_S["block_pos"]].reshape(sn.N_BLOCKS, 3)
    vis = obs[_S["block_visible"]]
    for i, p in block_pos.items():
        pos[i] = p
        vis[i] = 1.0
    obs[_S["block_pos"]] = pos.reshape(-1)
    obs[_S["block_visible"]] = vis
    return obs


@pytest.mark.parametrize("drop", [False, True])
def test_drop_crowded_leaves_two_cubes_within_the_critical_spacing_unfused(drop):
    """Two cube samples 30 and 35 deg off the line of sight: 5 deg apart, within Bouma's 0.5 x 30 deg, so
    either may carry the other's position (compulsory averaging); a third, alone at 0 deg, is fused either way."""
    agent = make_agent(f"eom_brace:drop_crowded={str(drop).lower()},fuse_max_ecc_deg=40", ENV, 9)
    d = 0.8
    samples = {0: (d, 0.0, 0.0)}
    for i, deg in ((1, 30.0), (2, 35.0)):
        a = math.radians(deg)
        samples[i] = (d * math.cos(a), -d * math.sin(a), 0.0)
    agent.predict(_still_obs(samples))
    assert agent.w[0] > 0
    assert (agent.w[1] > 0) == (not drop) and (agent.w[2] > 0) == (not drop)


def test_choose_by_ray_cuts_each_belief_s_line_of_sight_with_the_expected_wall_plane():
    agent = make_agent("eom_brace:choose_by_ray=true,ray_plane_m=0.7", ENV, 9)
    eye = np.array([0.05, 0.0, 0.55])
    n = np.array([0.0, -1.0, 0.0])
    ray = np.array([0.3, -0.8, -0.4]) / np.linalg.norm([0.3, -0.8, -0.4])
    faces = np.array([eye + 2.0 * ray, eye + 0.4 * ray])  # one believed far, one near, on the same line
    cuts = agent._ray_cuts(faces, eye, n)
    for c in cuts:
        assert float(c @ n) == pytest.approx(0.7)
        np.testing.assert_allclose(np.cross(c - eye, ray), 0.0, atol=1e-12)
    behind = agent._ray_cuts(np.array([eye + np.array([1.0, 0.1, 0.0])]), eye, n)
    np.testing.assert_allclose(behind[0], eye + np.array([1.0, 0.1, 0.0]))  # does not reach the plane: kept


@pytest.mark.parametrize("spec", ["eom_brace:drop_crowded=1", "eom_brace:choose_by_ray=yes",
                                  "eom_brace:hold_lean_gain=-1", "eom_brace:wall_normal=0"])
def test_the_fourth_pass_options_refuse_bad_values(spec):
    with pytest.raises(ValueError, match="EomBraceParams"):
        make_agent(spec, ENV, 9)


@pytest.mark.parametrize("spec", ["eom_brace:verify_reach=1", "eom_brace:reach_max_m=-0.5",
                                  "eom_brace:verify_w=-1", "eom_brace:verify_dwell_s=-0.1"])
def test_the_fifth_pass_options_refuse_bad_values(spec):
    with pytest.raises(ValueError, match="EomBraceParams"):
        make_agent(spec, ENV, 9)


def test_a_back_row_sets_the_odd_cubes_behind_the_wall_plane(monkeypatch):
    """BACK_ROW_M (fifth pass, opt-in): the odd cubes this far behind their definition place along the wall's
    normal, the even ones where they were."""
    env = gym.make(ENV)
    env.reset(seed=3)
    task = env.unwrapped.task
    faces = task.block_faces.copy()
    monkeypatch.setattr(pr, "BACK_ROW_M", 0.4)
    env.reset(seed=3)
    moved = task.block_faces - faces
    np.testing.assert_allclose(moved[0::2], 0.0, atol=1e-12)
    np.testing.assert_allclose(moved[1::2], np.outer(np.ones(len(moved[1::2])), 0.4 * task.wall_normal), atol=1e-12)


def test_reach_max_keeps_the_oracle_s_brace_off_a_back_cube(monkeypatch, tenth_pass):
    """On the fifth pass's crowded row with a back row (seed 5), the brace that picks the cube nearest the fall
    line goes for back cube 1 and falls; with reach_max_m it holds on front cube 0."""
    for name, value in (("BACK_ROW_M", 0.4), ("BLOCK_HALF_SIZE_M", (0.04, 0.05)), ("GAP_M", (0.05, 0.08)),
                        ("WALL_YAW_DEG", (0.0, 30.0)), ("ROW_HEIGHT_JITTER_M", 0.02)):
        monkeypatch.setattr(pr, name, value)
    monkeypatch.setattr(sn, "ANKLE_STRATEGY_GAIN", 1.0)
    brace = "eom_brace:fall_direction=true,hold_lean_gain=2,hold_lean_damp=0.1"
    outcomes = {}
    for spec in (_tenth(brace), _tenth(brace + ",reach_max_m=0.7")):
        env = gym.make("PushRecoveryOracle-v0")
        agent = make_agent(spec, "PushRecoveryOracle-v0", env.action_space.shape[0], seed=5)
        obs, info = env.reset(seed=5)
        touched = set()
        while True:
            action, _ = agent.predict(obs)
            obs, _r, terminated, truncated, info = env.step(action)
            if info["hand_block"] >= 0:
                touched.add(info["hand_block"])
            if terminated or truncated:
                break
        outcomes[spec] = (info["fallen"], touched)
    assert outcomes[_tenth(brace)] == (True, {1})
    assert outcomes[_tenth(brace + ",reach_max_m=0.7")] == (False, {0})


# --- the sixth pass: the vergence search (depth_search, opt-in) ----------------------------------------------


def _samples_along_minus_y(agent, distance: float, vergence: float, n: int, rng) -> None:
    """``n`` samples of cube 0 straight ahead of an eye that looks along the stance frame's -y (toward the
    wall), drawn with the env's own depth law (``foveation.perceive``) at ``distance`` with the eye verged at
    ``vergence``, recorded through the agent's depth_search path."""
    from visuomotor_gym.vision import foveation

    rot = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # eye x (line of sight) -> stance -y
    eye = np.array([0.0, 0.0, 0.5])
    for _ in range(n):
        pos, _vel, seen = foveation.perceive([distance, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0, agent.vision, rng,
                                             fixation=vergence)
        assert seen
        agent._fuse(0, np.array(pos), rot, eye, vergence)


@pytest.mark.parametrize("distance, within", [(0.75, True), (1.15, False)])
def test_depth_search_tells_a_cube_within_reach_from_one_behind_by_its_samples_scatter(distance, within):
    """An eye verged at 0.7 m: a cube 0.75 m away gives tight samples, one 1.15 m away (a back-row cube) samples
    scattered ~0.7 m by the disparity pedestal. The posterior over the cube's distance under the depth law says
    which (reach along -y from the shoulder: distance - 0.2 m <= 0.7 m), where the plain precision-weighted mean
    of the same samples (``estimate``: each weighted at its own distance) is pulled toward the vergence distance."""
    agent = make_agent("eom_brace:depth_search=true,reach_max_m=0.7", ENV, 9)
    _samples_along_minus_y(agent, distance, 0.7, 20, np.random.default_rng(4))
    points, prob, reach = agent.posterior(0, np.array([0.0, -1.0, 0.0]))
    assert prob.sum() == pytest.approx(1.0)
    if within:
        assert reach > 0.95
    else:
        assert reach < 0.05
        assert -float(agent.estimate(0)[1]) < 0.9  # the plain weighted mean: within reach (the fifth pass's failure)
    believed = -float(prob @ points[:, 1])
    assert believed == pytest.approx(distance, abs=0.15)


def test_a_sample_put_behind_the_eye_is_kept_as_a_negative_distance():
    agent = make_agent("eom_brace:depth_search=true,reach_max_m=0.7", ENV, 9)
    rot = np.eye(3)
    agent._record(2, np.array([-0.4, 0.0, 0.0]), rot, np.zeros(3), 0.7)
    _eye, u, signed, ecc, _verg, _w = agent.samples[2][0]
    np.testing.assert_allclose(u, [1.0, 0.0, 0.0])
    assert signed == pytest.approx(-0.4) and ecc == pytest.approx(0.0)


SEED_BACK = 2  # seeds 2 and 5 of 0-5 show it under the one eye (angular lateral noise); 3 did before


def test_the_vergence_search_holds_on_a_back_row_where_the_fifth_pass_agent_falls(monkeypatch, tenth_pass):
    """The fifth pass's back row (odd cubes 0.4 m behind the wall plane, crowded row, wall 0..30 deg), seed
    SEED_BACK: the agent whose fixations are verged at the expected wall falls; with the vergence search it
    fixates the cubes nearest the fall line before the push, knows which are out of reach, and stands."""
    for name, value in (("BACK_ROW_M", 0.4), ("BLOCK_HALF_SIZE_M", (0.04, 0.05)), ("GAP_M", (0.05, 0.08)),
                        ("WALL_YAW_DEG", (0.0, 30.0)), ("ROW_HEIGHT_JITTER_M", 0.02)):
        monkeypatch.setattr(pr, name, value)
    monkeypatch.setattr(sn, "ANKLE_STRATEGY_GAIN", 1.0)
    _env, _agent, info = _play(_tenth("eom_brace:reach_max_m=0.7"), SEED_BACK)
    assert info["fallen"]
    _env, agent, info = _play(_tenth("eom_brace:reach_max_m=0.7,depth_search=true"), SEED_BACK)
    assert not info["fallen"]
    assert any(name.startswith("search") for _t, name in agent.events)
    n = agent.normal
    for i in range(sn.N_BLOCKS):
        if agent.samples[i] and agent.w[i] > 0:
            _p, _q, reach = agent.posterior(i, n)
            if i == agent.chosen:
                assert i % 2 == 0 and reach > 0.5  # a front cube, believed within reach


@pytest.mark.parametrize("spec", ["eom_brace:depth_search=1", "eom_brace:search_sure=0.4",
                                  "eom_brace:search_sure=1", "eom_brace:depth_grid_step_m=0",
                                  "eom_brace:search_blocks=-1", "eom_brace:search_yaw_deg=120"])
def test_the_sixth_pass_options_refuse_bad_values(spec):
    with pytest.raises(ValueError, match="EomBraceParams"):
        make_agent(spec, ENV, 9)


# --- the seventh pass: visual-only clutter of the cubes' kind ---------------------------------------------
def test_visual_only_clutter_is_placed_behind_the_wall_beside_the_cubes_and_leaves_the_rest_alone(monkeypatch):
    """CLUTTER_PER_CUBE (seventh pass, opt-in): retina targets of the cubes' kind, CLUTTER_BEHIND_M behind the wall
    plane, never over a cube's silhouette on the wall, each within the cube's half-size + CLUTTER_SPREAD_M of it
    along the wall and on one side of it; the cubes, the push and the observation's size are the definition's."""
    env = gym.make(ENV)
    obs0, _ = env.reset(seed=4)
    task = env.unwrapped.task
    faces, push = task.block_faces.copy(), (task.push_time, task.push_force)
    monkeypatch.setattr(pr, "CLUTTER_PER_CUBE", 4)
    env = gym.make(ENV)
    obs, _ = env.reset(seed=4)
    task = env.unwrapped.task
    np.testing.assert_array_equal(task.block_faces, faces)
    assert (task.push_time, task.push_force) == push and obs.shape == obs0.shape
    clutter = task.clutter_faces
    assert len(clutter) >= 3 * sn.N_BLOCKS and all(t.kind == "block" for t in task.targets)
    assert sum(not t.hidden for t in task.clutter) == len(clutter)
    n = task.wall_normal
    along = np.array([-n[1], n[0], 0.0])
    behind = clutter @ n - task.wall_distance
    assert np.all(behind >= pr.CLUTTER_BEHIND_M[0] - 1e-9) and np.all(behind <= pr.CLUTTER_BEHIND_M[1] + 1e-9)
    for f, h in zip(task.block_faces, task.block_half_sizes):
        du, dz = np.abs((clutter - f) @ along), np.abs(clutter[:, 2] - f[2])
        assert np.all((du >= h + pr.CLUTTER_HALF_SIZE_M[0] - 1e-9) | (dz >= h + pr.CLUTTER_HALF_SIZE_M[0] - 1e-9))
    # no geom of the model is a clutter cube: nothing to touch
    assert all("clutter" not in (mujoco.mj_id2name(task.model, mujoco.mjtObj.mjOBJ_GEOM, g) or "")
               for g in range(task.model.ngeom))


def test_trust_ecc_restarts_a_cube_s_belief_at_its_first_trusted_sample_and_then_ignores_the_periphery():
    """trust_ecc_deg (seventh pass, opt-in): a peripheral sample places a cube until one within trust_ecc_deg
    comes; that one restarts the belief, and later peripheral samples (possibly pooled with the clutter) are
    not fused."""
    agent = make_agent("eom_brace:trust_ecc_deg=8,fuse_max_ecc_deg=40", ENV, 9)
    agent.reset()
    rot, eye = np.eye(3), np.zeros(3)
    a = math.radians(20.0)
    agent._fuse(0, np.array([0.7 * math.cos(a), -0.7 * math.sin(a), 0.0]), rot, eye, 0.7)
    assert agent.w[0] > 0 and not agent.trusted[0]
    agent._fuse(0, np.array([0.7, 0.01, 0.0]), rot, eye, 0.7)
    assert agent.trusted[0]
    np.testing.assert_allclose(agent.estimate(0), (0.7, 0.01, 0.0))
    w = agent.w[0]
    agent._fuse(0, np.array([0.7 * math.cos(a), 0.7 * math.sin(a), 0.0]), rot, eye, 0.7)
    assert agent.w[0] == w
    np.testing.assert_allclose(agent.estimate(0), (0.7, 0.01, 0.0))
    with pytest.raises(ValueError, match=r"EomBraceParams\.trust_ecc_deg"):
        make_agent("eom_brace:trust_ecc_deg=-1", ENV, 9)


# --- eighth pass: the wall on a random side, two arms ------------------------------------------------------
def _left_seed(monkeypatch, start: int = 0) -> int:
    """The first seed from ``start`` whose wall the side draw puts on the left (WALL_SIDE_RANDOM on)."""
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", True)
    env = gym.make(ENV)
    for seed in range(start, start + 40):
        env.reset(seed=seed)
        if env.unwrapped.task.wall_side > 0:
            return seed
    raise AssertionError("no left wall in 40 seeds")


def test_the_left_arm_mirrors_the_right_one():
    """The same joint angles put the left palm at the right palm's mirror image (y -> -y), whatever the angles."""
    m = _model()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    body = sn.StandingBody(m, HandControlParams(), 0.02)
    arm = body._qpos[3:]
    left = body._l_qpos[3:]
    for _ in range(5):
        q = rng.uniform(body.joint_range[3:, 0], body.joint_range[3:, 1])
        d.qpos[arm] = q
        d.qpos[left] = q
        mujoco.mj_kinematics(m, d)
        r, lft = d.site_xpos[body.catch_site], d.site_xpos[body.left_site]
        np.testing.assert_allclose(lft, (r[0], -r[1], r[2]), atol=1e-9)
    np.testing.assert_array_equal(m.jnt_range[[m.jnt_qposadr.tolist().index(a) for a in left]],
                                  m.jnt_range[[m.jnt_qposadr.tolist().index(a) for a in arm]])


def test_a_wall_on_the_left_is_the_right_wall_mirrored_and_drawn_last(monkeypatch):
    seed = _left_seed(monkeypatch)
    env = gym.make(ENV)
    env.reset(seed=seed)
    task = env.unwrapped.task
    faces, push = task.block_faces.copy(), task.push_dir.copy()
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)
    env.reset(seed=seed)
    assert task.wall_side == -1
    np.testing.assert_allclose(faces, task.block_faces * (1.0, -1.0, 1.0), atol=1e-12)
    assert push[1] > 0.5 and task.push_dir[1] < -0.5  # toward the wall on each side
    sides = []
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", True)
    for s in range(40):
        env.reset(seed=s)
        sides.append(task.wall_side)
    assert 10 <= sides.count(1) <= 30  # about half on each side


@pytest.mark.parametrize("force_n", [pr.PUSH_FORCE_N[0]])
def test_the_task_s_push_to_the_left_tips_the_bare_stance_over(force_n):
    fell, _roll = _bare_stance(-force_n)  # a push toward +y (the left)
    assert fell


def test_the_left_brace_saves_a_leftward_push_and_the_body_falls_without_it(monkeypatch):
    """Oracle rung, a wall on the left: eom_brace takes the left arm (arm action > 0), its palm lands on a cube and
    the body stays upright; the same agent without the hand falls toward the wall."""
    seed = _left_seed(monkeypatch, 7)
    assert seed == 7  # (seed 6, also on the left, falls onto cube 1 on the Oracle rung: 195/200 there)
    env, agent, info = _play("eom_brace", seed, env_id="PushRecoveryOracle-v0")
    assert info["is_success"] and info["arm"] == 1, (seed, env.unwrapped.task.fall_geoms)
    assert agent.side == 1 and agent.normal[1] > 0.5
    assert info["first_contact_time"] > env.unwrapped.task.push_time
    env, agent, info = _play("eom_brace:use_hand=false", seed, env_id="PushRecoveryOracle-v0")
    assert info["fallen"] and info["pelvis_pos"][1] > 0.0, info["pelvis_pos"]


def test_eom_brace_finds_the_wall_s_side_before_the_push(monkeypatch):
    """Foveated: the cubes' first samples (far periphery) give the side before the push; a twin whose eye looks
    away from the wall learns it only from the fall."""
    seed = _left_seed(monkeypatch)
    env = gym.make(ENV)
    agent = make_agent("eom_brace", ENV, env.action_space.shape[0], seed=seed)
    obs, _info = env.reset(seed=seed)
    push = env.unwrapped.task.push_time
    while env.unwrapped.data.time < push:
        action, _ = agent.predict(obs)
        obs, *_ = env.step(action)
    assert agent.side == 1 and agent._side_known and action[4] > 0


# --- no hidden truth: the wall's side is seen, not given ---------------------------------------------------
PERCEPT_KEYS = ("block_pos", "block_visible", "block_firm", "block_age")


def _first_left_seed():
    for seed in range(20):
        env = gym.make(ENV)
        env.reset(seed=seed)
        left = env.unwrapped.task.wall_side > 0
        env.close()
        if left:
            return seed
    raise AssertionError("no left wall in seeds 0-19")


@pytest.mark.parametrize("vision", ["foveated", "oracle"])
def test_no_observation_leak_of_the_wall_before_the_push(monkeypatch, vision):
    """The same seed with its wall on the left and (WALL_SIDE_RANDOM off, drawn last) on the right: until the
    push, every block but the cube percepts is identical, and a cube percept is non-zero only on a step
    that produced a sample of it (so the side and the faces are known only through the eye). On both rungs
    the percepts themselves do differ (the foveated eye sees the cubes in its field before the push; the
    Oracle rung sees the true faces), so the comparison is not vacuous."""
    seed = _first_left_seed()
    a = gym.make(ENV, vision=vision, obs_mode="dict")
    oa, _ = a.reset(seed=seed)
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)
    b = gym.make(ENV, vision=vision, obs_mode="dict")
    ob, _ = b.reset(seed=seed)
    assert a.unwrapped.task.wall_side > 0 > b.unwrapped.task.wall_side
    push = a.unwrapped.task.push_time
    assert b.unwrapped.task.push_time == push
    zero = np.zeros(a.action_space.shape, dtype=np.float32)  # gaze held, hand at its ready point
    percepts_differ = False
    while a.unwrapped.data.time + a.unwrapped.dt < push:
        for key in oa:
            if key in PERCEPT_KEYS:
                percepts_differ |= not np.array_equal(oa[key], ob[key])
            else:
                np.testing.assert_array_equal(oa[key], ob[key], err_msg=key)
        for o in (oa, ob):
            unseen = np.repeat(o["block_visible"] < 0.5, 3)
            assert not np.any(o["block_pos"][unseen]), "a cube percept without a sample"
        oa, *_ = a.step(zero)
        ob, *_ = b.step(zero)
    assert percepts_differ  # the two walls are seen differently (both rungs see them before the push)
    a.close()
    b.close()


def test_a_wall_in_front_is_the_side_wall_turned_about_the_body_axis_and_drawn_last(monkeypatch):
    """WALL_FRONT_P (opt-in, tenth pass): the same seed with the front draw forced is its side wall turned by
    -side x 90 deg about the vertical through the stance origin (faces and push) and slid along the wall so that
    the row is centred on the midline (FRONT_ROW_CENTRED), every other draw unchanged; off, the front draw is not
    made (the definition's scenes); at 1/3 about a third of the walls stand in front."""
    env = gym.make(ENV)
    task = env.unwrapped.task
    monkeypatch.setattr(pr, "WALL_FRONT_P", 0.0)
    env.reset(seed=3)
    faces, push, side, t0 = task.block_faces.copy(), task.push_dir.copy(), task.wall_side, task.push_time
    assert not task.wall_front
    monkeypatch.setattr(pr, "WALL_FRONT_P", 1.0)
    env.reset(seed=3)
    assert task.wall_front and task.wall_side == side and task.push_time == t0
    a = -side * 0.5 * math.pi
    turn = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
    # the side's cubes turned, then slid along the wall so that the row is centred on the body's midline
    shift = task.block_faces - faces @ turn.T
    np.testing.assert_allclose(shift, np.broadcast_to(shift[0], shift.shape), atol=1e-12)  # one rigid slide
    np.testing.assert_allclose(shift[0][2], 0.0, atol=1e-12)
    n = task.wall_normal
    np.testing.assert_allclose(float(shift[0] @ n), 0.0, atol=1e-12)  # along the wall only
    xa = task.block_faces @ np.array([-n[1], n[0], 0.0])  # each face's place along the wall
    np.testing.assert_allclose(xa.max() + xa.min(), 0.0, atol=1e-9)  # the row centred on the body's axis
    np.testing.assert_allclose(task.push_dir, turn @ push, atol=1e-12)
    assert task.push_dir[0] > 0.8  # from behind, toward the wall ahead
    monkeypatch.setattr(pr, "WALL_FRONT_P", 1.0 / 3.0)
    fronts = 0
    for s in range(60):
        env.reset(seed=s)
        fronts += task.wall_front
    assert 10 <= fronts <= 30


def test_the_forward_push_tips_the_bare_stance_over():
    """The task's weakest push toward a wall in front (tenth pass: the side push x FRONT_PUSH_SCALE) tips the bare
    stance, and FRONT_PUSH_SCALE's thresholds hold: forward it tips from 185 N, not at 170 N; sideways not at 270 N."""
    assert _bare_stance(pr.PUSH_FORCE_N[0] * pr.FRONT_PUSH_SCALE, direction=(1.0, 0.0))[0]
    assert _bare_stance(185.0, direction=(1.0, 0.0))[0]
    assert not _bare_stance(170.0, direction=(1.0, 0.0))[0]
    assert not _bare_stance(270.0)[0]


def test_eom_brace_reads_a_wall_in_front_from_the_cubes_lines_of_sight():
    """front_wall: the line fitted through the cubes' lines of sight cut at the prior height: a row across the
    body's path (normal ahead) is in front, a row along its side is not; off, never."""
    from baselines.eom_brace.agent import PRIOR_FACE_Z_M, EomBraceAgent, EomBraceParams

    eye = np.array([0.05, 0.0, 0.7])
    for row, front in (([(0.7, y) for y in (-0.3, 0.1, 0.5, 0.9)], True),
                       ([(x, -0.7) for x in (-0.2, 0.2, 0.6, 1.0)], False)):
        for on in (True, False):
            ag = EomBraceAgent(EomBraceParams(front_wall=on))
            for i, (x, y) in enumerate(row):
                u = np.array([x, y, PRIOR_FACE_Z_M]) - eye
                ag._los[i] = u / np.linalg.norm(u)
                ag._los_eye[i] = eye
                ag._los_n[i] = 1
            assert ag._front_from_lines() is (front and on)


# --- the eleventh pass: loose cubes and the foveal identity percept ----------------------------------------
def _drive_hand_into(cube_loose: bool, seed: int = 4):
    """The hand driven (true geometry, Oracle rung) onto the face of the cube nearest x = 0.05 m, 2 cm beyond it,
    after the push, with that cube made loose or firm: (fell, first contact time)."""
    env = gym.make(ENV, vision="oracle")
    _obs, info = env.reset(seed=seed)
    u = env.unwrapped
    faces = info["block_faces"]
    i = int(np.argmin(np.abs(faces[:, 0] - 0.05)))
    mask = np.zeros(sn.N_BLOCKS, dtype=bool)
    mask[i] = cube_loose
    u.task.set_loose(mask)
    step_info = _drive_hand(env, info, faces[i].copy())
    env.close()
    return step_info["fallen"], step_info["first_contact_time"], i


def test_a_loose_cube_lets_the_hand_through_where_a_firm_one_holds_it(monkeypatch):
    """The same hand path onto the same cube (the wall beside the body, on the right): firm, the palm touches it;
    loose, the palm never touches a cube and the body falls (through it: a loose cube collides with nothing)."""
    monkeypatch.setattr(pr, "WALL_YAW_DEG", (0.0, 0.0))
    monkeypatch.setattr(pr, "WALL_SIDE_RANDOM", False)
    _fell, firm_contact, i = _drive_hand_into(False)
    fell, loose_contact, j = _drive_hand_into(True)
    assert i == j
    assert firm_contact > 0
    assert loose_contact < 0 and fell


def test_a_loose_cube_makes_no_contact_with_a_body_inside_it_where_a_firm_one_does():
    """Physics alone: a pool cube moved into the standing body's head has contacts with it over 20 physics steps when
    firm and none when loose (the collision bits the task sets)."""
    env = gym.make(ENV, vision="oracle")
    u = env.unwrapped
    task = u.task
    contacts = {}
    for loose in (False, True):
        env.reset(seed=0)
        task.set_loose(np.full(sn.N_BLOCKS, loose))
        d = u.data
        head = d.xpos[mujoco.mj_name2id(u.model, mujoco.mjtObj.mjOBJ_BODY, "head")].copy()
        d.mocap_pos[task._mocap[0]] = head + (0.0, 0.0, -0.05)
        mujoco.mj_forward(u.model, d)
        n = 0
        for _ in range(20):
            mujoco.mj_step(u.model, d)
            n += sum(1 for g1, g2 in d.contact.geom.tolist() if task._block_geom[0] in (g1, g2))
        contacts[loose] = n
    assert contacts[False] > 0 and contacts[True] == 0, contacts
    env.close()


class _Eye:
    def __init__(self):
        self.pos = np.zeros(3)
        self.rot = np.eye(3)  # column 0: the line of sight, +x


@pytest.mark.parametrize("distance", [0.6, 0.8])
def test_the_identity_percept_is_given_only_within_the_texture_s_crowding_limit(distance):
    """A cube face of half-size 0.1 m at ``distance`` on a line of sight theta off the eye's: identified (its truth)
    when theta - atan(0.1 / d) <= 2 atan(0.01 / d) (Bouma's 0.5 and the 1 cm texture, computed by hand here), not
    beyond; and never on a step without a sample (a saccade, outside the field)."""
    env = gym.make(ENV)
    env.reset(seed=0)
    task = env.unwrapped.task
    task.attach_eye(_Eye(), env.unwrapped.retina, "foveated", 0.5)
    limit = math.atan(0.1 / distance) + 2.0 * math.atan(0.01 / distance)
    assert abs(pr.ident_eccentricity(distance) - 2.0 * math.atan(0.01 / distance)) < 1e-12
    assert math.radians(1.3) < pr.ident_eccentricity(distance) < math.radians(2.0)
    task._half[:] = 0.0
    task._half[2] = 0.1
    for loose, truth in ((True, -1.0), (False, 1.0)):
        mask = np.zeros(sn.N_BLOCKS, dtype=bool)
        mask[2] = loose
        task.set_loose(mask)
        for theta, expected in ((limit - 0.002, truth), (limit + 0.002, 0.0), (0.0, truth), (0.5, 0.0)):
            task.targets[2].place(distance * math.cos(theta), distance * math.sin(theta), 0.0)
            seen = [([0.0] * 3, [0.0] * 3, True)] * sn.N_BLOCKS
            assert task._identify(seen)[2] == expected, (theta, limit)
            unseen = [([0.0] * 3, [0.0] * 3, False)] * sn.N_BLOCKS
            assert task._identify(unseen)[2] == 0.0  # no sample this step (saccadic suppression, field)
    env.close()


def test_no_identity_during_a_saccade_and_the_truth_on_the_oracle_and_full_view_rungs():
    """On the foveated rung block_firm is 0 on every step whose observation was taken during a saccade (no
    sample); the Oracle rung gives every placed cube's truth, the full-view rung every sampled cube's."""
    env = gym.make(ENV, obs_mode="dict")
    obs, _ = env.reset(seed=1)
    loose = env.unwrapped.task.loose.copy()
    a = np.zeros(env.action_space.shape, np.float32)
    saccades = 0
    for k in range(40):
        a[5] = -1.0 if k % 8 == 0 else 0.0  # a 60 deg saccade to the right every 8 steps
        obs, *_ = env.step(a)
        if not np.any(obs["block_visible"]):
            saccades += 1
            assert not np.any(obs["block_firm"])
        assert np.all(obs["block_firm"][obs["block_visible"] < 0.5] == 0.0)
    assert saccades > 0
    env.close()
    n = len(env.unwrapped.task.block_faces)
    for vision in ("oracle", "full_view"):
        e = gym.make(ENV, vision=vision, obs_mode="dict")
        o, _ = e.reset(seed=1)
        np.testing.assert_array_equal(e.unwrapped.task.loose, loose)  # one seed, one scenario on every rung
        np.testing.assert_array_equal(o["block_firm"][:n], np.where(loose[:n], -1.0, 1.0))
        e.close()


def test_exactly_one_of_the_two_cubes_nearest_the_shoulder_is_loose_and_the_geometry_is_unchanged(monkeypatch):
    """Over 200 seeds: of the two cubes nearest the bracing shoulder (horizontal distance to the face centre)
    exactly one is loose, and each of the others about half the time. The draws take nothing from the episode's
    generator: with LOOSE_CUBES off, the same seed gives the same wall, push, side and (20 steps of a held pose)
    every observation but the identity percept."""
    others, n_others = 0, 0
    for seed in range(200):
        env = gym.make(ENV)
        env.reset(seed=seed)
        t = env.unwrapped.task
        d = np.linalg.norm(t.block_faces[:, :2] - t.shoulder_world()[:2], axis=1)
        order = np.argsort(d)
        assert int(t.loose[order[:2]].sum()) == 1, seed
        others += int(t.loose[order[2:]].sum())
        n_others += len(order) - 2
        env.close()
    assert 0.4 < others / n_others < 0.6
    zero = None
    for seed in (0, 7):
        runs = []
        for on in (True, False):
            monkeypatch.setattr(pr, "LOOSE_CUBES", on)
            env = gym.make(ENV, obs_mode="dict")
            obs, info = env.reset(seed=seed)
            zero = np.zeros(env.action_space.shape, np.float32)
            seq = [obs]
            for _ in range(20):
                seq.append(env.step(zero)[0])
            t = env.unwrapped.task
            runs.append((info, seq, t.loose.copy()))
            env.close()
        (ia, sa, la), (ib, sb, lb) = runs
        assert la.any() and not lb.any()
        for key in ("block_faces", "block_half_sizes", "push_time", "push_force", "push_dir", "wall_distance",
                    "wall_side"):
            np.testing.assert_array_equal(ia[key], ib[key], err_msg=key)
        for oa, ob in zip(sa, sb):
            for key in oa:
                if key != "block_firm":
                    np.testing.assert_array_equal(oa[key], ob[key], err_msg=key)


def _lockstep(env_id: str, seed: int, flip: int, steps: int = 80):
    """eom_brace plays ``seed``; a second env of the same seed with cube ``flip``'s identity flipped gets the same
    actions. Returns the dict observations of both and the first step at which the played env's block_firm of that
    cube is non-zero (None if never)."""
    a = gym.make(env_id, obs_mode="dict")
    b = gym.make(env_id, obs_mode="dict")
    oa, _ = a.reset(seed=seed)
    ob, _ = b.reset(seed=seed)
    mask = b.unwrapped.task.loose.copy()
    mask[flip] = not mask[flip]
    b.unwrapped.task.set_loose(mask)
    agent = make_agent("eom_brace", env_id, a.action_space.shape[0], seed=seed)
    flat = a.unwrapped.layout
    seq, first = [], None
    for k in range(steps):
        seq.append((oa, ob))
        if first is None and oa["block_firm"][flip] != 0.0:
            first = k
            break
        vec = np.concatenate([np.asarray(oa[blk.name], dtype=np.float32).reshape(-1) for blk in flat.blocks])
        act, _ = agent.predict(vec)
        oa, *_ = a.step(act)
        ob, *_ = b.step(act)
    a.close()
    b.close()
    return seq, first


def test_no_observation_carries_a_cube_s_identity_until_it_is_fixated():
    """The counterfactual scene: the same seed with the identity of the cube eom_brace looks at first flipped. Every
    observation is identical until the step the eye identifies that cube (far outside the fovea before), and on
    that step the identity percepts differ; on the Oracle rung they differ from the first observation."""
    env = gym.make(ENV)
    env.reset(seed=1)
    t = env.unwrapped.task
    cube = int(np.argmin(np.linalg.norm(t.block_faces[:, :2] - t.shoulder_world()[:2], axis=1)))
    env.close()
    seq, first = _lockstep(ENV, 1, cube)
    assert first is not None and first > 5, first  # identified by a look, some steps in
    for oa, ob in seq[:-1]:
        for key in oa:
            np.testing.assert_array_equal(oa[key], ob[key], err_msg=key)
    oa, ob = seq[-1]
    assert oa["block_firm"][cube] == -ob["block_firm"][cube] != 0.0
    # The Oracle rung sees the flip on the first step after it (the flip is made after reset's observation).
    a_, b_ = gym.make("PushRecoveryOracle-v0", obs_mode="dict"), gym.make("PushRecoveryOracle-v0", obs_mode="dict")
    a_.reset(seed=1)
    b_.reset(seed=1)
    mask = b_.unwrapped.task.loose.copy()
    mask[cube] = not mask[cube]
    b_.unwrapped.task.set_loose(mask)
    zero = np.zeros(a_.action_space.shape, np.float32)
    oa, ob = a_.step(zero)[0], b_.step(zero)[0]
    assert oa["block_firm"][cube] == -ob["block_firm"][cube] != 0.0


def test_eom_brace_chooses_the_firm_cube_of_the_pair_it_identified():
    """On the Oracle rung (every identity known) eom_brace's chosen cube is firm on seeds 0-9 (whichever of the two
    nearest it is)."""
    for seed in range(10):
        env, agent, _info = _play("eom_brace", seed, "PushRecoveryOracle-v0")
        assert agent.chosen is not None and not env.unwrapped.task.loose[agent.chosen], seed
