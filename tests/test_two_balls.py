"""EyeCatchTwoBalls-v0: two staggered balls, catch both (Eom et al. 2019, section 7)."""

from __future__ import annotations

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401
from visuomotor_gym.assets import asset_path
from visuomotor_gym.body import names
from visuomotor_gym.body.seated import HAND_WORKSPACE
from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.envs.catch import EyeCatchEnv
from visuomotor_gym.envs.observation import SECOND_BALL_OBSERVATION, ObservationLayout, catch_observation
from visuomotor_gym.scenarios.throws import ThrowDistribution, sample_second_throw, sample_throw

ENV_ID = "EyeCatchTwoBalls-v0"
TWO = ObservationLayout(catch_observation(2))
S = TWO.slices
OBJ = {"body": mujoco.mjtObj.mjOBJ_BODY, "joint": mujoco.mjtObj.mjOBJ_JOINT, "geom": mujoco.mjtObj.mjOBJ_GEOM,
       "equality": mujoco.mjtObj.mjOBJ_EQUALITY}


def hand_action(target_world, grasp: bool) -> np.ndarray:
    a = np.zeros(9, np.float32)
    lo, hi = HAND_WORKSPACE[:, 0], HAND_WORKSPACE[:, 1]
    a[:3] = np.clip(2.0 * (np.asarray(target_world) - SEAT_ORIGIN - lo) / (hi - lo) - 1.0, -1, 1)
    a[3] = 1.0 if grasp else -1.0
    return a


def play_scripted(env, seed, skip_second=False, skip_first=False):
    """Hold the closed hand on each ball's path (true arrival points, as the Oracle agent does), the
    first ball's until it is released, then the second's. Returns the per-step records."""
    obs, info = env.reset(seed=seed)
    far = np.array([0.0, -0.7, 0.55])  # a hand out of the way
    targets = [far if skip_first else info["arrival_pos"], far if skip_second else info["arrival2_pos"]]
    records = [(obs, 0.0, False, False, info)]
    done = False
    while not done:
        current = 0 if info.get("balls_caught", 0) == 0 or info.get("holding", -1) == 0 else 1
        obs, reward, terminated, truncated, info = env.step(hand_action(targets[current], grasp=True))
        records.append((obs, reward, terminated, truncated, info))
        done = terminated or truncated
    return records


# ----------------------------------------------------------------------------------------------
def test_registered_with_its_own_layout_and_horizon():
    spec = gym.spec(ENV_ID)
    assert spec.kwargs == {"n_balls": 2} and spec.max_episode_steps == 150
    env = gym.make(ENV_ID)
    assert env.observation_space.shape == (TWO.size,) == (67,)
    assert env.unwrapped.observation_structure == TWO.structure
    single = ObservationLayout()
    assert list(TWO.structure)[: len(single.blocks)] == list(single.structure)  # the single-ball prefix
    doc = EyeCatchEnv.__doc__
    for block in SECOND_BALL_OBSERVATION:
        assert f"| {block.name} | {block.size} |" in doc
    assert "TWO_BALL_OBSERVATION_TABLE" not in doc and "(67,)" in doc
    dict_env = gym.make(ENV_ID, obs_mode="dict")
    obs, _ = dict_env.reset(seed=0)
    assert set(obs) == set(TWO.structure)


def test_single_ball_scene_and_envs_are_untouched():
    """The second ball lives in its own scene file; the single-ball scene has no trace of it."""
    one = mujoco.MjModel.from_xml_path(str(asset_path("catch.xml")))
    two = mujoco.MjModel.from_xml_path(str(asset_path(names.TWO_BALLS_SCENE)))
    for kind, items in names.TWO_BALL_NAMES.items():
        for name in items:
            assert mujoco.mj_name2id(one, OBJ[kind], name) < 0, name
            assert mujoco.mj_name2id(two, OBJ[kind], name) >= 0, name
    for kind, items in names.ALL_NAMES.items():  # the two-ball scene contains the whole single-ball one
        if kind in OBJ:
            assert all(mujoco.mj_name2id(two, OBJ[kind], n) >= 0 for n in items)
    assert (two.nv, two.nbody) == (one.nv + 6, one.nbody + 2)
    env = gym.make("EyeCatch-v0")
    obs, info = env.reset(seed=0)
    assert obs.shape == (ObservationLayout().size,) and "ball2_pos" not in info and env.unwrapped.n_balls == 1


def test_bad_arguments():
    with pytest.raises(ValueError, match="n_balls"):
        gym.make("EyeCatch-v0", n_balls=3)
    with pytest.raises(ValueError, match="bounce_wall"):
        gym.make(ENV_ID, bounce_wall=True)
    with pytest.raises(ValueError, match="release_after_catch_s"):
        gym.make(ENV_ID, release_after_catch_s=-1.0)


@pytest.mark.parametrize("seed", range(40))
def test_second_throw_distribution(seed):
    dist, dt, control_dt = ThrowDistribution(), 0.002, 0.02
    rng = np.random.default_rng(seed)
    first = sample_throw(rng, dist, dt)
    second = sample_second_throw(rng, dist, dt, control_dt, first)
    assert np.sign(second.release_pos[1]) == (-1.0 if first.release_pos[1] >= 0 else 1.0)  # the other side
    assert dist.second_release_lateral_m[0] <= abs(second.release_pos[1]) <= dist.second_release_lateral_m[1]
    assert dist.release_x_m[0] <= second.release_pos[0] <= dist.release_x_m[1]
    assert dist.arrival_z_m[0] <= second.arrival_pos[2] <= dist.arrival_z_m[1]
    steps = second.release_time / control_dt
    assert abs(steps - round(steps)) < 1e-9, "released between control steps"
    assert dist.second_stagger_s[0] - control_dt / 2 <= second.release_time
    gap = second.release_time + second.flight_time - first.flight_time
    assert dist.second_arrival_gap_s[0] - 0.002 <= gap <= dist.second_arrival_gap_s[1] + 0.002
    assert second.flight_time <= dist.second_max_flight_s + 0.002


@pytest.mark.parametrize("seed", [0, 5])
def test_second_ball_waits_then_flies_on_its_exact_path(seed):
    env = gym.make(ENV_ID)
    _obs, info = env.reset(seed=seed)
    throw2, dt = env.unwrapped.throw2, 0.002
    assert throw2.release_time == info["release2_time"] > 0
    # the launch velocity lands exactly on the arrival point after flight2_time (semi-implicit Euler)
    n2 = round(throw2.flight_time / dt)
    landing = throw2.release_pos + n2 * dt * throw2.release_vel + np.array([0, 0, -9.81]) * dt * dt * n2 * (n2 + 1) / 2
    np.testing.assert_allclose(landing, throw2.arrival_pos, atol=1e-9)
    away = hand_action([0.0, -0.7, 0.55], grasp=False)  # the hand out of both paths
    done, flying = False, 0
    while not done:
        _, _, terminated, truncated, info = env.step(away)
        done = terminated or truncated
        if info["time"] <= throw2.release_time + 1e-9:
            np.testing.assert_allclose(info["ball2_pos"], throw2.release_pos, atol=1e-9)  # held, weightless
            np.testing.assert_allclose(info["ball2_vel"], 0.0, atol=1e-9)
        else:  # in flight, on the path that reaches the arrival point
            n = round((info["time"] - throw2.release_time) / dt)
            path = throw2.release_pos + n * dt * throw2.release_vel + np.array([0, 0, -9.81]) * dt * dt * n * (n + 1) / 2
            np.testing.assert_allclose(info["ball2_pos"], path, atol=1e-6)
            flying += 1
    assert flying > 5


def test_success_needs_both_balls_and_the_first_is_released():
    env = gym.make(ENV_ID)
    for seed in range(12):
        records = play_scripted(env, seed)
        infos = [r[4] for r in records]
        if infos[-1]["is_success"]:
            break
    else:
        pytest.fail("the scripted catcher never caught both balls in 12 throws")
    release_delay = env.unwrapped.release_after_catch_s
    first = next(k for k, i in enumerate(infos) if i.get("balls_caught", 0) == 1)
    # first catch: rewarded, not a success, not the end; the ball is held and felt
    obs, reward, terminated, truncated, info = records[first]
    assert reward == 1.0 and info["caught"] and not info["is_success"] and not terminated
    assert info["holding"] == 0 and obs[S["holding"]][0] == 1.0
    np.testing.assert_array_equal(obs[S["balls_caught"]], [1.0, 0.0])
    # released after release_after_catch_s: out of the hand, out of play, out of sight
    t_catch = info["time"]
    released = next(k for k in range(first, len(infos)) if infos[k]["holding"] == -1)
    assert infos[released]["time"] - t_catch == pytest.approx(release_delay, abs=env.unwrapped.dt + 1e-9)
    for obs_k, _, _, _, info_k in records[released:]:
        assert info_k["ball_pos"][2] < 0.0  # parked under the floor
        assert obs_k[S["ball_visible"]][0] == 0.0
        np.testing.assert_array_equal(obs_k[S["ball_pos"]], 0.0)
    # second catch: success, the end, the second reward
    obs, reward, terminated, truncated, info = records[-1]
    assert info["is_success"] and terminated and not truncated and reward == 1.0
    assert info["balls_caught"] == 2 and info["holding"] == 1
    np.testing.assert_array_equal(obs[S["balls_caught"]], [1.0, 1.0])
    assert sum(r[1] for r in records) == 2.0


def test_one_catch_is_not_a_success():
    env = gym.make(ENV_ID)
    for seed in range(12):
        records = play_scripted(env, seed, skip_second=True)
        info = records[-1][4]
        if info["balls_caught"] == 1:
            break
    else:
        pytest.fail("the scripted catcher never caught the first ball in 12 throws")
    _obs, _reward, terminated, _truncated, info = records[-1]
    assert terminated and info["missed"] and not info["is_success"]
    assert info["time"] > records[0][4]["flight_time"]  # it ended on the second ball's miss


def test_the_first_miss_ends_the_episode():
    env = gym.make(ENV_ID)
    records = play_scripted(env, 1, skip_first=True)
    _obs, _reward, terminated, _truncated, info = records[-1]
    assert terminated and info["missed"] and info["balls_caught"] == 0 and not info["is_success"]
    assert info["time"] < records[0][4]["release2_time"] + records[0][4]["flight2_time"]


def test_deterministic_and_first_ball_is_the_ladders():
    a, b = gym.make(ENV_ID), gym.make(ENV_ID)
    rec_a, rec_b = play_scripted(a, 7), play_scripted(b, 7)
    assert len(rec_a) == len(rec_b)
    for (oa, ra, ta, _, ia), (ob, rb, tb, _, ib) in zip(rec_a, rec_b):
        np.testing.assert_array_equal(oa, ob)
        assert (ra, ta) == (rb, tb)
        np.testing.assert_array_equal(ia["ball2_pos"], ib["ball2_pos"])
    _, ladder = gym.make("EyeCatch-v0").reset(seed=7)
    first = rec_a[0][4]
    for key in ("release_pos", "release_vel", "arrival_pos", "gaze_dir"):
        np.testing.assert_array_equal(first[key], ladder[key])
    assert first["flight_time"] == ladder["flight_time"]
    # a reset after a full episode restores the scene: same episode again
    rec_c = play_scripted(a, 7)
    for (oa, *_), (oc, *_) in zip(rec_a, rec_c):
        np.testing.assert_array_equal(oa, oc)
