"""SteppingStones-v0: no leak of the stones' true positions, every rung from the registry on the same
course, the course sampler and its argument check, falls, the lookahead baseline against its gaze-blind
twin, stepping-target realism.
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
from visuomotor_gym.envs.stones import STONES_LAYOUT, SteppingStonesEnv
from visuomotor_gym.registration import ENV_SPECS, FAMILIES
from visuomotor_gym.tasks.stepping_stones import K_SLOTS, STONE_TOP_Z, CourseDistribution, sample_course

STONES_IDS = FAMILIES["stones"]


def test_the_five_rungs_are_registered_in_the_stones_family():
    assert set(STONES_IDS) == {"SteppingStonesOracle-v0", "SteppingStonesFullView-v0", "SteppingStones-v0",
                               "SteppingStonesDelayed-v0", "SteppingStonesPoorVision-v0"}
    assert all(s.max_episode_steps == 1000 for s in ENV_SPECS if s.family == "stones")


@pytest.mark.parametrize("env_id", STONES_IDS)
def test_every_rung_runs_from_the_registry_on_the_same_course(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=7)
    assert obs.shape == (STONES_LAYOUT.size,) and env.observation_space.contains(obs)
    _, ref_info = SteppingStonesEnv().reset(seed=7)
    np.testing.assert_array_equal(info["stones"], ref_info["stones"])  # same course on every rung
    for _ in range(5):
        obs, *_ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and np.isfinite(obs).all()


def test_layout_and_action_blocks():
    env = SteppingStonesEnv()
    assert env.observation_structure == STONES_LAYOUT.structure
    assert env.action_structure == {"footstep": 4, "gaze": 2, "fixation": 1, "head": 2}


def test_bad_course_and_agent_input_give_clear_errors():
    with pytest.raises(ValueError, match="n_stones"):
        SteppingStonesEnv(course_distribution={"n_stones": 40})
    agent = make_agent("lookahead", "SteppingStones-v0", 9)
    with pytest.raises(ValueError, match="observation of size"):
        agent.predict(np.zeros(5))


def _look_up(n):
    a = np.zeros((n, 9), np.float32)
    a[:, 5] = 0.5  # gaze up (elevation, 30 deg a step until the eye's range)
    a[:, 8] = 1.0  # head up (neck pitch +40 deg)
    return a


def _move_stones(env):
    """Change the true course after reset (every stone 20 cm left, 10 cm on): what a leak would reveal."""
    task = env.task
    for i, (x, y) in enumerate(task.course.stones.tolist()):
        x, y = x + 0.1, y + 0.2
        env.data.mocap_pos[task.mocap[i]][:2] = (x, y)
        task.targets[i].place(x, y, STONE_TOP_Z)
        task.course.stones[i] = (x, y)


@pytest.mark.parametrize("vision", ["foveated", "oracle"])
def test_no_observation_leak_of_the_stones_true_positions(vision):
    """Looking up at the sky, the foveated walker's observations do not depend on where the stones are (the
    same episode with a moved course gives identical observations, before the first stone is reached).
    The human field reaches 75 deg below the fixation point, so the stones are out of it only once eye and
    head are up (SETTLE steps). The oracle rung (true centres) is the positive control: there the same
    change shows."""
    settle = 15  # 0.3 s: the eye's two saccades and the head's 40 deg at <= 300 deg/s
    actions = _look_up(60)
    a, b = SteppingStonesEnv(vision=vision), SteppingStonesEnv(vision=vision)
    a.reset(seed=5)
    b.reset(seed=5)
    _move_stones(b)
    differ = False
    for i, act in enumerate(actions):
        oa, *_ = a.step(act)
        ob, *_ = b.step(act)
        if i >= settle:
            differ |= not np.array_equal(oa, ob)
    if vision == "foveated":
        assert not differ
        assert not any(oa[STONES_LAYOUT.slices[f"stone_{k}"]][4] for k in range(K_SLOTS))
    else:
        assert differ


def _steppable(course, dist, w_lo, w_hi, max_turn_deg):
    """Brute force over a 0.1 deg grid of headings: a foothold sequence exists with each foot's centre
    on its stone's centre, each step's width (across its own heading) in [w_lo, w_hi] on the foot's side
    and each heading within ``max_turn_deg`` of the one before (the last slab foot: heading 0)."""
    grid = np.radians(np.arange(-120.0, 120.0, 0.1))
    ok = np.abs(grid) < 1e-9  # headings the previous foothold can have
    reach = round(max_turn_deg / 0.1)
    prev = np.array([dist.start_foot_x_m, dist.start_foot_y_m])
    for k, st in enumerate(course.stones):
        d = st - prev
        width = (-d[0] * np.sin(grid) + d[1] * np.cos(grid)) * (1.0 if k % 2 == 0 else -1.0)
        fwd = d[0] * np.cos(grid) + d[1] * np.sin(grid)
        spread = np.convolve(ok.astype(float), np.ones(2 * reach + 1), mode="same") > 0
        ok = spread & (width >= w_lo - 1e-9) & (width <= w_hi + 1e-9) & (fwd >= 0.25) & (fwd <= 0.95)
        if not ok.any():
            return False
        prev = st
    return True


@pytest.mark.slow
def test_course_sampler_follows_allsteps_turns_beyond_20_deg_and_every_course_is_steppable():
    dist = CourseDistribution()
    turns, in_range, widest = [], [], []
    for seed in range(200):
        course = sample_course(np.random.default_rng(seed), dist, (-0.3, 0.3), (0.12, 0.06), 45.0)
        st = course.stones
        assert len(st) == dist.n_stones
        prev = np.vstack([[dist.start_foot_x_m, dist.start_foot_y_m], st[:-1]])
        spacing = np.linalg.norm(st - prev, axis=1)
        in_range += ((spacing >= 0.65 - 1e-9) & (spacing <= 0.85 + 1e-9)).tolist()
        assert np.all(np.abs(course.headings) <= math.radians(dist.max_heading_deg) + 1e-9)
        turns += np.abs(np.diff(np.concatenate([[0.0], course.headings]))).tolist()
        widest.append(np.degrees(np.abs(course.headings).max()))
        assert np.all(np.diff(st[:, 0]) > 0.3)  # the path always leads away from the slab
        gaps = np.linalg.norm(st[:, None] - st[None], axis=2) + 9.0 * np.eye(len(st))
        assert gaps.min() > 0.5  # stones never overlap (radius 0.25)
        assert _steppable(course, dist, 0.06 + dist.lateral_slack_m, 0.42 - dist.lateral_slack_m, 45.0 - dist.turn_slack_deg)
    assert np.mean(in_range) > 0.98  # ALLSTEPS' 0.65-0.85 m spacing
    turns = np.degrees(turns)
    assert np.mean(turns <= 30.0 + 1e-6) > 0.98 and turns.max() > 25.0  # ALLSTEPS: +-30 deg, and used
    widest = np.array(widest)
    # The path's direction drifts well beyond the +-20 deg the first (non-turning) walker was held to.
    assert np.mean(widest > 20.0) > 0.9 and np.mean(widest > 40.0) > 0.5 and widest.max() > 55.0


def test_a_foot_over_the_gap_ends_the_episode_and_scores_minus_one():
    env = SteppingStonesEnv()
    env.reset(seed=0)
    a = np.zeros(9, np.float32)
    a[0] = 1.0  # 0.95 m steps: off the slab and past the stones
    for _ in range(1000):
        _, r, term, _, info = env.step(a)
        if term:
            break
    assert info["fell"] and term and not info["is_success"] and not info["finished"]
    assert info["reward_terms"]["fall"] == -1.0 and r == pytest.approx(-1.0)
    assert env.task.landings[-1][1] == -2  # the last landing found no support


def _successes(agent, seeds, env_id="SteppingStones-v0"):
    env = gym.make(env_id)
    policy = make_agent(agent, env_id, 9)
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


def test_the_oracle_lookahead_crosses_and_success_lands_on_the_last_stone():
    env = gym.make("SteppingStonesOracle-v0")
    policy = make_agent("lookahead", "SteppingStonesOracle-v0", 9)
    obs, info = env.reset(seed=1)
    while True:
        obs, r, term, trunc, info = env.step(policy.predict(obs)[0])
        if term or trunc:
            break
    task = env.unwrapped.task
    assert info["is_success"] and info["finished"] and r == pytest.approx(1.0)
    assert task.landings[-1][1] == len(task.course.stones) - 1 and info["stones_landed"] >= 10


def test_lookahead_turns_the_walker_along_a_curving_course():
    """A course whose path turns beyond +-40 deg: the oracle lookahead crosses it, the pelvis turning with
    the path (its yaw follows the stones' headings) and every foot landing on a stone."""
    env = gym.make("SteppingStonesOracle-v0")
    policy = make_agent("lookahead", "SteppingStonesOracle-v0", 9)
    for seed in range(20):
        obs, info = env.reset(seed=seed)
        if np.abs(env.unwrapped.course.headings).max() > math.radians(45.0):
            break
    headings = env.unwrapped.course.headings
    yaws = []
    while True:
        obs, _, term, trunc, info = env.step(policy.predict(obs)[0])
        yaws.append(float(env.unwrapped.data.qpos[3]))
        if term or trunc:
            break
    assert info["is_success"]
    yaws = np.array(yaws)
    assert np.abs(yaws).max() > math.radians(35.0)  # the walker turned, well beyond +-20 deg
    assert np.sign(yaws[np.argmax(np.abs(yaws))]) == np.sign(headings[np.argmax(np.abs(headings))])


@pytest.mark.slow
def test_lookahead_crosses_more_courses_than_its_gaze_blind_twin():
    # Development seeds (outside the pinned 0-199). Under the human periphery with the disarray lookahead
    # crosses 97.5 % of the pinned courses: 10 of these 12 (300 and 302 not); neither held twin crosses one.
    seeds = range(300, 312)
    looking = _successes("lookahead", seeds)
    blind, generic = _successes("lookahead:gaze_blind=true", seeds), _successes("gaze_blind:lookahead", seeds)
    assert looking >= 9 and blind <= 3 and generic <= 3, (looking, blind, generic)


def test_stones_realism_measures_on_a_synthetic_trace():
    from visuomotor_gym.metrics.stones_realism import episode_measures, stones_gaze_realism

    dt = 0.02
    t = np.arange(0, 6.0, dt)
    stones = np.array([[2.0 + 0.75 * k, 0.0] for k in range(8)])
    # A foot lands on stone k at 2.0 + 0.5 k s; next_stone moves on 0.1 s later. Gaze is on stone n + 1
    # (two steps ahead of the stance foot) and switches with next_stone.
    landing = 2.0 + 0.5 * np.arange(8)
    n = np.array([(ti >= landing + 0.1 - 1e-9).sum() for ti in t])
    eye = np.stack([1.3 * t, 0 * t, 1.6 + 0 * t], axis=1)
    target = np.concatenate([stones[np.minimum(n + 1, 7)], np.full((len(t), 1), STONE_TOP_Z)], axis=1)
    gaze = (target - eye) / np.linalg.norm(target - eye, axis=1, keepdims=True)
    onset = np.r_[False, np.diff(n) > 0]  # a saccade when the gaze switches to the next stone
    trace = SimpleNamespace(eye_pos=eye, gaze_dir=gaze, stones=stones, stone_radius=0.25, next_stone=n, t=t, dt=dt,
                            diverged=False, saccade_onset=onset, in_saccade=onset.copy())
    m = episode_measures(trace)
    assert m["fixation_steps_ahead"] == 2.0
    assert m["fixation_lead_s"] == pytest.approx(0.9, abs=0.03)  # onset 0.9 s before each landing
    assert m["stone_fixation_share"] > 0.9
    assert m["fixation_duration_s"] == pytest.approx(0.48)  # 25 rows between switches, 1 of them in flight
    score = stones_gaze_realism([trace])
    for name in ("stone_fixation_share", "fixation_steps_ahead", "fixation_lead_s", "fixation_duration_s"):
        assert score["components"][name]["score"] > 0.7, name
    assert score["score"] > 0.6  # 8 saccades in 6 s (1.3/s): a little below the human rate
    late = SimpleNamespace(**{**trace.__dict__, "gaze_dir": (np.concatenate(
        [stones[np.minimum(n, 7)], np.full((len(t), 1), STONE_TOP_Z)], axis=1) - eye)})
    late.gaze_dir = late.gaze_dir / np.linalg.norm(late.gaze_dir, axis=1, keepdims=True)
    m2 = episode_measures(late)  # gaze one step later: on the stone the swinging foot lands on
    assert m2["fixation_steps_ahead"] == 1.0
    assert stones_gaze_realism([late])["components"]["fixation_steps_ahead"]["score"] < 0.9


def test_summary_routes_stones_traces_to_the_stones_realism():
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.metrics.summary import summarize

    env = gym.make("SteppingStones-v0")
    trace = run_episode(env, make_agent("lookahead", "SteppingStones-v0", 9), 2, "SteppingStones-v0", "lookahead")
    out = summarize([trace])
    assert set(out["gaze_realism"]["components"]) == {"saccade_rate_hz", "fixation_duration_s", "stone_fixation_share",
                                                      "fixation_steps_ahead", "fixation_lead_s"}
    assert out["episodes"] == 1 and out["success_rate"] in (0.0, 1.0)
