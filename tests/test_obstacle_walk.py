"""ObstacleWalk-v0: no leak of the obstacles' true state, every rung from the registry on the same course,
the course sampler, trips and footholds, the iwao baseline against its gaze-blind twin, walking realism.
The family-independent checks (API checkers, docstring tables, determinism, pickling, bad input,
reward terms, memory) run for every rung in tests/test_families.py."""

from __future__ import annotations

import math
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.envs.walk import WALK_LAYOUT, WALKWAY_DEFINITION, WINDING_LAYOUT, ObstacleWalkEnv
from visuomotor_gym.registration import ENV_SPECS, FAMILIES
from visuomotor_gym.tasks.obstacle_walk import (
    BAR,
    K_SLOTS,
    N_POINTS,
    CourseDistribution,
    ObstacleWalkTask,
    sample_course,
    top_points,
)

WALK_IDS = FAMILIES["walk"]
# The first definition (the straight walkway's bars, boxes and mats, the 20 deg cone): what most tests here
# check; the default (the winding walkway, the human periphery) is tested in tests/test_walk_winding.py.
W = WALKWAY_DEFINITION
W_VISION = WALKWAY_DEFINITION["vision_params"]


def test_the_five_rungs_are_registered_in_the_walk_family():
    assert set(WALK_IDS) == {"ObstacleWalkOracle-v0", "ObstacleWalkFullView-v0", "ObstacleWalk-v0",
                             "ObstacleWalkDelayed-v0", "ObstacleWalkPoorVision-v0"}
    assert all(s.max_episode_steps == 2000 for s in ENV_SPECS if s.family == "walk")


@pytest.mark.parametrize("env_id", WALK_IDS)
def test_every_rung_runs_from_the_registry_on_the_same_course(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=7)
    assert obs.shape == (WINDING_LAYOUT.size,) and env.observation_space.contains(obs)
    ref = ObstacleWalkEnv()  # the default: the winding walkway
    _, ref_info = ref.reset(seed=7)
    np.testing.assert_array_equal(info["obstacles"], ref_info["obstacles"])  # same course on every rung
    for _ in range(5):
        obs, _r, _term, _trunc, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and np.isfinite(obs).all()


def test_layout_and_action_blocks():
    env = ObstacleWalkEnv(**W)
    assert env.observation_structure == WALK_LAYOUT.structure
    assert env.action_structure == {"footstep": 3, "gaze": 2, "fixation": 1, "head": 2}
    env = ObstacleWalkEnv()  # the default: the winding walkway's turning walker
    assert env.observation_structure == WINDING_LAYOUT.structure
    assert env.action_structure == {"footstep": 4, "gaze": 2, "fixation": 1, "head": 2}


def _look_up(n):
    a = np.zeros((n, 8), np.float32)
    a[:, 4] = 0.5  # gaze up (elevation, 30 deg a step until the eye's range)
    a[:, 7] = 1.0  # head up (neck pitch +40 deg)
    return a


def _move_obstacles(env):
    """Change the true course after reset (other places, heights): what a leak would reveal."""
    task = env.task
    for i, (x, y, depth, width, height, _kind) in enumerate(task.course.obstacles.tolist()):
        x, height = x + 0.7, min(height + 0.1, 0.4)
        task.pool.place(env.model, env.data, i, x, y, depth, width, height)
        for t, point in zip(task.targets[N_POINTS * i: N_POINTS * (i + 1)], top_points(x, y, depth, width, height)):
            t.place(*point)
        task.course.obstacles[i, [0, 4]] = (x, height)


@pytest.mark.parametrize("vision", ["foveated", "oracle"])
def test_no_observation_leak_of_the_obstacles_true_state(vision):
    """Looking up at the sky, the foveated walker's observations do not depend on where the obstacles
    are or how high (the same episode with a moved course gives identical observations). The oracle rung
    (true corners) is the positive control: there the same change shows."""
    actions = _look_up(40)
    a, b = ObstacleWalkEnv(vision=vision, **W), ObstacleWalkEnv(vision=vision, **W)
    a.reset(seed=5)
    b.reset(seed=5)
    _move_obstacles(b)
    differ = False
    for act in actions:
        oa, *_ = a.step(act)
        ob, *_ = b.step(act)
        differ |= not np.array_equal(oa, ob)
    if vision == "foveated":
        assert not differ
        seen = [oa[WALK_LAYOUT.slices[f"obstacle_{k}"]][1 + 3 * N_POINTS:] for k in range(K_SLOTS)]
        assert not np.any(seen)
    else:
        assert differ


def test_course_sampler_follows_its_distribution():
    dist = CourseDistribution()
    for seed in range(50):
        course = sample_course(np.random.default_rng(seed), dist, 16)
        ob = course.obstacles
        assert 15.0 <= course.length <= 20.0 and len(ob) >= 3
        near, far = ob[:, 0] - ob[:, 2] / 2, ob[:, 0] + ob[:, 2] / 2
        assert near[0] >= 3.0 and far[-1] <= course.length - dist.finish_clear_m
        assert np.all(near[1:] - far[:-1] >= 1.6 - 1e-9)
        tall = ob[:, 5] != 2
        assert np.all((ob[tall, 4] >= 0.05) & (ob[tall, 4] <= 0.30)) and np.all(ob[~tall, 4] == 0.01)


def test_bars_span_the_walkway_and_everything_else_lies_inside_it():
    dist = CourseDistribution()
    half = 0.5 * dist.walkway_width_m
    n_bars = 0
    for seed in range(50):
        ob = sample_course(np.random.default_rng(seed), dist, 16).obstacles
        bars = ob[:, 5] == BAR
        n_bars += int(bars.sum())
        np.testing.assert_array_equal(ob[bars, 3], dist.walkway_width_m)
        np.testing.assert_array_equal(ob[bars, 1], 0.0)
        assert np.all(np.abs(ob[:, 1]) + 0.5 * ob[:, 3] <= half + 1e-12)
    assert n_bars > 20
    with pytest.raises(ValueError, match="walkway_width_m"):
        ObstacleWalkEnv(vision_params=W_VISION, course_distribution={"walkway_width_m": 0.0}).reset(seed=0)


def test_the_eye_sees_four_points_of_each_top_face():
    """On the oracle rung the slot's four points are the true corners and edge midpoints (eye frame)."""
    env = ObstacleWalkEnv(vision="oracle", **W)
    obs, info = env.reset(seed=3)
    block = obs[WALK_LAYOUT.slices["obstacle_0"]]
    x, y, depth, width, height, _ = info["obstacles"][0]
    truth = np.array(top_points(x, y, depth, width, height))
    assert block[0] == 0.0 and np.all(block[1 + 3 * N_POINTS:] == 1.0)
    seen_world = np.asarray(block[1:1 + 3 * N_POINTS], float).reshape(N_POINTS, 3) @ env.eye.rot.T + env.eye.pos
    np.testing.assert_allclose(seen_world, truth, atol=1e-4)
    # The near-edge and far-edge midpoints lie on the centre line of a bar that spans the walkway.
    assert truth[2, 1] == truth[3, 1] == y


def _walk_sideways(env, lateral):
    a = np.zeros(8, np.float32)
    a[1] = lateral  # the lateral offset block: every step this far beside the nominal step width
    a[2] = 1.0  # high toe clearance
    for _ in range(1000):
        _obs, r, term, trunc, info = env.step(a)
        if term or trunc:
            return r, term, info
    raise AssertionError("the episode did not end")


def test_leaving_the_walkway_ends_the_episode_as_a_failure():
    env = ObstacleWalkEnv(vision_params=W_VISION, course_distribution={"first_m": (8.0, 8.0)})  # nothing to trip on for 8 m
    env.reset(seed=0)
    _r, term, info = _walk_sideways(env, 1.0)
    assert term and info["off_path"] and not info["is_success"] and not info["tripped"]
    assert info["reward_terms"]["off_path"] == -1.0
    feet_y = env.gait.feet_world(env.data)[:, 1]
    assert np.abs(feet_y).max() > 0.5 * env.course_distribution.walkway_width_m
    # Drifting sideways is fine inside a walkway wide enough for it.
    wide = ObstacleWalkEnv(vision_params=W_VISION, course_distribution={"first_m": (8.0, 8.0), "walkway_width_m": 40.0})
    wide.reset(seed=0)
    a = np.zeros(8, np.float32)
    a[1], a[2] = 1.0, 1.0
    for _ in range(150):
        *_, term, _trunc, info = wide.step(a)
    assert not info["off_path"] and not term


def test_the_task_checks_every_landed_foothold_once():
    env = ObstacleWalkEnv(**W)
    env.reset(seed=0)
    task: ObstacleWalkTask = env.task
    for _ in range(100):
        env.step(np.zeros(8, np.float32))
    g = env.gait
    assert task._next_check == (g.tick - g.T_ds) // g.T + 1  # footholds 0 .. k flat by now


def test_a_trip_ends_the_episode_and_scores_nothing():
    env = ObstacleWalkEnv(**W)
    env.reset(seed=0)
    a = np.zeros(8, np.float32)
    a[0], a[2] = 0.1, -1.0  # 0.65 m steps, 2 cm clearance: walks into the first bar
    for _ in range(1000):
        _obs, r, term, _trunc, info = env.step(a)
        if term:
            break
    assert info["tripped"] and term and not info["is_success"]
    assert info["reward_terms"]["trip"] == -1.0 and r == pytest.approx(-1.0)


def _successes(agent, seeds):
    env = gym.make("ObstacleWalk-v0")  # the default: the winding walkway, 9 actions
    policy = make_agent(agent, "ObstacleWalk-v0", int(env.action_space.shape[0]))
    wins = 0
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        policy.reset()
        while True:
            obs, _, term, trunc, info = env.step(policy.predict(obs)[0])
            if term or trunc:
                break
        wins += bool(info["is_success"])
    return wins


@pytest.mark.slow
def test_iwao_crosses_more_courses_than_its_gaze_blind_twin():
    seeds = range(100, 108)
    looking, blind = _successes("iwao", seeds), _successes("iwao:gaze_blind=true", seeds)
    assert looking >= 7 and blind <= 5 and looking - blind >= 3, (looking, blind)


def test_walk_realism_measures_on_a_synthetic_trace():
    from visuomotor_gym.metrics.walk_realism import episode_measures, walk_gaze_realism

    t = np.arange(0, 6.0, 0.02)
    pelvis = np.stack([1.3 * t, 0 * t, 0.9 + 0 * t], axis=1)
    eye = pelvis + [0.1, 0.0, 0.7]
    obstacle = np.array([[5.0, 0.0, 0.05, 1.0, 0.2, 0.0]])
    # Gaze on the obstacle's top during the first 20 % of its approach, then on the floor 1.5 m ahead.
    target = np.where((pelvis[:, 0] < 0.4)[:, None], [5.0, 0.0, 0.2], eye * [1, 1, 0] + [1.5, 0.0, 0.0])
    gaze = (target - eye) / np.linalg.norm(target - eye, axis=1, keepdims=True)
    onset = np.zeros(len(t), bool)
    onset[np.argmax(pelvis[:, 0] >= 0.4)] = True  # the saccade from the obstacle to the floor
    trace = SimpleNamespace(eye_pos=eye, gaze_dir=gaze, pelvis_pos=pelvis, obstacles=obstacle, diverged=False, t=t,
                            dt=0.02, saccade_onset=onset, in_saccade=onset.copy())
    m = episode_measures(trace)
    # Approach: pelvis x in [0, 4.375). Fixated (gaze point held): x < 0.4. The travel gaze (1.5 m ahead on the
    # floor) also sweeps over it for 0.25 m, but that is a travel fixation (the gaze point moves at 1.3 m/s).
    assert m["obstacle_fixation_share"] == pytest.approx(0.4 / 4.375, abs=0.01)
    assert m["fixation_while_crossing"] == 0.0
    assert m["travel_fixation_distance_m"] == pytest.approx(1.5, abs=0.01)
    assert 45.0 < m["gaze_below_horizon_deg"] < 50.0  # arctan(1.6 / 1.5) = 46.8 deg
    assert m["path_fixation_share"] == 1.0 and m["saccade_rate_hz"] == pytest.approx(1 / t[-1])
    assert math.isnan(m["fixation_duration_s"])  # one saccade: no fixation between two
    score = walk_gaze_realism([trace])
    comps = score["components"]
    # looked away while crossing (in range), capped by the score of the obstacle share it is measured on
    assert comps["fixation_while_crossing"]["score"] == comps["obstacle_fixation_share"]["score"] > 0.9
    # where it looked is human-like, but one saccade in 6 s is not: the moves group decides the score
    assert score["components"]["fixation_duration_s"]["score"] == 0.0 and score["score"] < 0.1
