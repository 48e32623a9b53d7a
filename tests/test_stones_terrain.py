"""SteppingStones' "rough" course (the default): reproducible, the same path as the default
course, hazards placed by the documented rule (a hand-computed case), hazards never hold a foot, no
observation leak of unseen hazards or stones (counterfactual scenes; slot ids advance only on landings),
the lookahead agent's periphery adaptations gated on its vision model, and the static-gaze search on env
keyword arguments."""

from __future__ import annotations

import json
import math
from dataclasses import asdict

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent, match_vision
from visuomotor_gym.envs.stones import STONES_LAYOUT, SteppingStonesEnv
from visuomotor_gym.envs.walk import WALK_VISION
from visuomotor_gym.tasks.stepping_stones import (
    COURSE_PRESETS,
    K_SLOTS,
    ROUGH_SCENE,
    STONE_TOP_Z,
    STONES_SCENE,
    CourseDistribution,
    course_preset,
    sample_hazards,
)
from visuomotor_gym.vision.foveation import VisionParams

ALL_FOUR = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0}


def test_rough_preset_is_the_default_reproducible_and_keeps_the_allsteps_path():
    """One seed, one scenario: the same seed gives the same stones and hazards ("rough" is the default
    course); the path stones are the "allsteps" course's (the hazards are drawn after them), another seed
    gives another course."""
    a, b, plain = SteppingStonesEnv(course_distribution="rough"), SteppingStonesEnv(), \
        SteppingStonesEnv(course_distribution="allsteps")
    a.reset(seed=11)
    b.reset(seed=11)
    plain.reset(seed=11)
    np.testing.assert_array_equal(a.course.stones, b.course.stones)
    np.testing.assert_array_equal(a.course.hazards, b.course.hazards)
    np.testing.assert_array_equal(a.course.stones, plain.course.stones)
    assert len(a.course.hazards) > 0 and len(plain.course.hazards) == 0
    a.reset(seed=12)
    assert not np.array_equal(a.course.stones, b.course.stones)
    assert a.scene == ROUGH_SCENE and plain.scene == STONES_SCENE
    assert a.task.radius == pytest.approx(COURSE_PRESETS["rough"]["stone_radius_m"]) and plain.task.radius == 0.25


def test_every_hazard_keeps_its_distance_and_clearance():
    dist = course_preset("rough")
    env = SteppingStonesEnv(course_distribution="rough")
    for seed in range(5):
        env.reset(seed=seed)
        c, r_s = env.course, dist.stone_radius_m
        assert np.bincount(c.hazard_of, minlength=len(c.stones)).max() <= dist.hazards_per_stone
        for (hx, hy), i in zip(c.hazards, c.hazard_of):
            own = math.hypot(hx - c.stones[i][0], hy - c.stones[i][1])
            assert dist.hazard_distance_m[0] - 1e-9 <= own <= dist.hazard_distance_m[1] + 1e-9
            assert np.min(np.hypot(*(c.stones - (hx, hy)).T)) >= r_s + dist.hazard_radius_m + dist.hazard_clearance_m
            assert hx - dist.hazard_radius_m > 2.3  # beyond the slab
        gaps = np.hypot(*(c.hazards[:, None, :] - c.hazards[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(gaps, np.inf)
        assert gaps.min() >= 2 * dist.hazard_radius_m + dist.hazard_clearance_m


class _Draws:
    """A generator stand-in that returns queued uniform draws (the hand-computed case)."""

    def __init__(self, values):
        self.values = list(values)

    def uniform(self, low, high):
        v = self.values.pop(0)
        assert low <= v <= high
        return v


def test_hazard_placement_by_hand():
    """Stones at (3, 0) and (3.7, 0), radius 0.15; hazards of radius 0.12, clearance 0.05, one per stone.
    Stone 0: angle 0, distance 0.4 -> (3.4, 0): 0.3 m from stone 1's centre < 0.15 + 0.12 + 0.05 = 0.32,
    redrawn; angle pi/2, distance 0.35 -> (3, 0.35): 0.35 >= 0.32 from stone 0, kept. Stone 1: angle
    pi/2, distance 0.35 -> (3.7, 0.35): 0.7 m from the first hazard (>= 0.29), kept. A hazard whose rim
    reaches the slab's far edge (x - 0.12 <= 2.3) is redrawn: stone 2 at (2.5, 0.8), angle pi,
    distance 0.33 -> (2.17, 0.8) refused, angle 0 -> (2.83, 0.8) kept."""
    dist = CourseDistribution(stone_radius_m=0.15, hazards_per_stone=1, hazard_radius_m=0.12,
                              hazard_distance_m=(0.32, 0.45), hazard_clearance_m=0.05)
    stones = np.array([[3.0, 0.0], [3.7, 0.0], [2.5, 0.8]])
    rng = _Draws([0.0, 0.4, math.pi / 2, 0.35, math.pi / 2, 0.35, math.pi - 1e-12, 0.33, 0.0, 0.33])
    hazards, owner = sample_hazards(rng, dist, stones)
    np.testing.assert_allclose(hazards, [[3.0, 0.35], [3.7, 0.35], [2.83, 0.8]], atol=1e-9)
    assert owner.tolist() == [0, 1, 2] and rng.values == []


def test_hazards_never_hold_a_foot_and_are_drawn_beside_their_stones():
    env = SteppingStonesEnv(course_distribution="rough")
    env.reset(seed=3)
    task, m = env.task, env.model
    assert all(int(m.geom_contype[g]) == 0 and int(m.geom_conaffinity[g]) == 0 for g in task.hazard_geoms)
    assert not set(task.hazard_geoms) & set(task.support_of_geom)
    for k, (x, y) in enumerate(env.course.hazards.tolist()):
        np.testing.assert_allclose(env.data.mocap_pos[task.hazard_mocap[k]][:2], (x, y))
        assert m.geom_size[task.hazard_geoms[k], 0] == pytest.approx(0.12)
    for g in task.geoms:
        assert m.geom_size[g, 0] == pytest.approx(0.15)


def test_bad_presets_and_hazard_counts_are_refused():
    with pytest.raises(ValueError, match="not a preset; allowed: \\['allsteps', 'rough'\\]"):
        SteppingStonesEnv(course_distribution="rocky")
    with pytest.raises(ValueError, match="hazards_per_stone \\* n_stones must be <= 32"):
        CourseDistribution(n_stones=14, hazards_per_stone=3)
    with pytest.raises(ValueError, match="stone_radius_m"):
        CourseDistribution(stone_radius_m=0.01)
    with pytest.raises(ValueError, match="hazard_distance_m"):
        CourseDistribution(hazard_distance_m=(0.5, 0.3))


def _look_up(n):
    a = np.zeros((n, 9), np.float32)
    a[:, 5] = 0.5  # gaze up
    a[:, 8] = 1.0  # head up
    return a


def _move_hazards(env, beyond: int):
    """Move every hazard of the stones from index ``beyond`` on (not in any slot yet) 25 cm sideways."""
    task = env.task
    for k, (i, (x, y)) in enumerate(zip(task.course.hazard_of.tolist(), task.course.hazards.tolist())):
        if i >= beyond:
            env.data.mocap_pos[task.hazard_mocap[k]][:2] = (x, y + 0.25)
            task.hazard_targets[k].position[:] = (x, y + 0.25, STONE_TOP_Z)  # (place() would show it)
            task.course.hazards[k] = (x, y + 0.25)


@pytest.mark.parametrize("vision_params", [{}, ALL_FOUR])
def test_no_leak_of_unseen_hazards(vision_params):
    """The hazards of stones beyond the slots are never sampled: moving them leaves every observation of
    a lookahead walk identical, while the slots' stones are still ahead (crowding on or off)."""
    envs = [SteppingStonesEnv(course_distribution="rough", vision_params=vision_params) for _ in range(2)]
    agent = make_agent("lookahead", "SteppingStones-v0", 9)
    match_vision(agent, envs[0].vision_params)
    oa, _ = envs[0].reset(seed=4)
    ob, _ = envs[1].reset(seed=4)
    _move_hazards(envs[1], beyond=K_SLOTS + 2)
    agent.reset()
    for _ in range(60):  # 1.2 s: the walker is still on the slab (next_stone 0, slots 0-3)
        np.testing.assert_array_equal(oa, ob)
        act, _ = agent.predict(oa)
        oa, *_ = envs[0].step(act)
        ob, *_ = envs[1].step(act)
    assert envs[0].task.next_stone == 0
    np.testing.assert_array_equal(oa, ob)


def test_seen_hazards_crowd_the_stone_but_never_move_the_slot_ids():
    """Positive control: with crowding, moving the hazards of the slots' stones changes what is perceived
    of them (looking down the path), but the slot ids (course indices) stay those of the same stones."""
    kw = {"course_distribution": "rough", "vision_params": ALL_FOUR}
    a, b = SteppingStonesEnv(**kw), SteppingStonesEnv(**kw)
    a.reset(seed=4)
    b.reset(seed=4)
    _move_hazards(b, beyond=0)
    acts = np.zeros((40, 9), np.float32)
    acts[:, 5] = -0.2  # gaze down toward the stones ahead
    differ = False
    ids = [STONES_LAYOUT.slices[f"stone_{k}"].start for k in range(K_SLOTS)]
    for act in acts:
        oa, *_ = a.step(act)
        ob, *_ = b.step(act)
        differ |= not np.array_equal(oa, ob)
        assert oa[ids].tolist() == ob[ids].tolist() == [float(k) for k in range(K_SLOTS)]
    assert differ


def test_slot_ids_advance_only_when_a_foot_lands():
    """Over a rough crossing, the first slot's id is always one past the last stone a foot has landed on
    (0 before any): passing stones, seen or not, moves no slot."""
    env = SteppingStonesEnv(course_distribution="rough", vision_params=ALL_FOUR)
    agent = make_agent("lookahead", "SteppingStones-v0", 9)
    match_vision(agent, env.vision_params)
    obs, _ = env.reset(seed=2)
    agent.reset()
    slot0 = STONES_LAYOUT.slices["stone_0"].start
    changes = 0
    landed_before = 0
    for _ in range(600):
        before = obs[slot0]
        act, _ = agent.predict(obs)
        obs, _, term, trunc, _ = env.step(act)
        if term or trunc:
            break
        if obs[slot0] != before:
            changes += 1
        # the observation was taken before this step's landings were checked: the landings up to the last step
        assert obs[slot0] == landed_before
        landed_before = max([s + 1 for _, s, _ in env.task.landings if s >= 0], default=0)
    assert changes >= 5


def test_lookahead_adapts_only_when_its_vision_model_has_the_periphery():
    """Default vision: fixation action 0, gaze on the stone after the swinging foot's (the original agent:
    the golden digests). Depth law: the fixation action asks for vergence at the gaze target's distance
    (1.5-6 m on the stones, never the action 0's 1.4 m); crowding: gaze on the first unplanned stone and
    peripheral samples flagged."""
    from visuomotor_gym.baselines.lookahead.agent import _LOG_FIX, beyond_fovea, fixation_action

    lo, hi = _LOG_FIX
    assert fixation_action(math.exp(0.5 * (lo + hi))) == pytest.approx(0.0)
    assert beyond_fovea([[1.0, 0.0, 0.0], [1.0, math.tan(math.radians(0.4)), 0.0],
                         [1.0, 0.0, math.tan(math.radians(0.6))]], math.radians(0.5)) == {2}
    for fields in ({}, ALL_FOUR):  # {}: the walk family's 20 deg cone, the first definition's eye
        env = SteppingStonesEnv(course_distribution="rough", vision_params=VisionParams(**{**asdict(WALK_VISION), **fields}))
        agent = make_agent("lookahead", "SteppingStones-v0", 9)
        match_vision(agent, env.vision_params)
        obs, _ = env.reset(seed=0)
        agent.reset()
        for _ in range(120):
            act, _ = agent.predict(obs)
            if fields:
                assert 1.5 <= math.exp(lo + (act[6] + 1.0) * 0.5 * (hi - lo)) <= 6.0
            else:
                assert act[6] == 0.0
            obs, *_ = env.step(act)
        gazed = {t for _, t in agent.log}
        if fields:  # the first unplanned stone: one past the swinging foot's by 2.4 s
            assert agent.planned_stone + 1 in gazed
        assert env.task.next_stone >= 1


def test_static_gaze_search_takes_env_kwargs(tmp_path):
    """``--env-kwargs`` reaches the env (the rough course, the human periphery) and the agent's vision
    model, is recorded, and bad values are refused before any episode."""
    from visuomotor_gym.static_gaze import _Scorer, main, registered_kwargs

    kwargs = {"course_distribution": "rough", "vision_params": {"field_shape": "human", "crowding": True}}
    out = tmp_path / "s.json"
    assert main(["search", "--env", "SteppingStones-v0", "--agent", "lookahead", "--out", str(out), "--quiet",
                 "--postures", "0,-35,0,-15", "--coarse-episodes", "1", "--final-episodes", "1",
                 "--env-kwargs", json.dumps(kwargs)]) == 0
    record = json.loads(out.read_text())
    assert record["env_kwargs"] == kwargs and len(record["postures"]) == 1
    with registered_kwargs("SteppingStones-v0", kwargs):
        scorer = _Scorer("SteppingStones-v0", "lookahead", 100000)
        try:
            assert scorer.env.unwrapped.course_distribution.hazards_per_stone == 2
            assert scorer.env.unwrapped.vision_params.crowding
            agent = make_agent("lookahead", "SteppingStones-v0", 9)
            assert agent.vision == scorer.env.unwrapped.vision_params  # the agent models the env's eye
        finally:
            scorer.close()
    assert not gym.spec("SteppingStones-v0").kwargs  # restored
    with pytest.raises(SystemExit, match="JSON object"):
        main(["search", "--env", "SteppingStones-v0", "--agent", "lookahead", "--out", str(out),
              "--env-kwargs", "[1, 2]"])
    with pytest.raises(ValueError, match="not a preset"):
        main(["search", "--env", "SteppingStones-v0", "--agent", "lookahead", "--out", str(out), "--quiet",
              "--postures", "0,-35", "--env-kwargs", '{"course_distribution": "rocky"}'])


def test_rough_crossing_needs_the_moving_eye():
    """With the human periphery on the rough course, lookahead crosses where its held twin falls (a few
    seeds; the measured rates are in docs/reproductions/data/terrain/)."""
    kw = {"course_distribution": "rough", "vision_params": ALL_FOUR}
    wins = {}
    for spec in ("lookahead", "gaze_blind:lookahead"):
        env = gym.make("SteppingStones-v0", **kw)
        policy = make_agent(spec, "SteppingStones-v0", 9)
        match_vision(policy, env.unwrapped.vision_params)
        from visuomotor_gym.bench.trace import run_episode

        wins[spec] = sum(run_episode(env, policy, seed=s, env_id="SteppingStones-v0", agent=spec).success
                         for s in range(3))
        env.close()
    assert wins["lookahead"] == 3 and wins["gaze_blind:lookahead"] == 0


def test_belief_mpc_plane_variance_knows_crowding():
    """With crowding in the vision model a sample beyond the 0.5 deg fovea has at least the crowding zone's
    variance on the plane: std c = 0.5 * b * theta * d across the line of sight, c / sin(depression) along
    it, r = c^2 (1 + 1 / dep^2) / 2 (hand-computed at d = 2 m, theta = 10 deg, dep = 0.6); inside the
    fovea and without crowding the vision model's own."""
    from dataclasses import replace

    from visuomotor_gym.baselines.belief_mpc.stone_belief import plane_variance

    from visuomotor_gym.vision.foveation import VisionParams

    plain = VisionParams(field_shape="human")
    crowd = replace(plain, crowding=True)
    th = math.radians(10.0)
    c = 0.5 * 0.5 * th * 2.0
    expected = 0.5 * c * c * (1.0 + 1.0 / 0.36)
    r_plain = float(plane_variance(2.0, th, 0.0, 0.6, plain, limit=math.radians(90)))
    r_crowd = float(plane_variance(2.0, th, 0.0, 0.6, crowd, limit=math.radians(90)))
    assert r_plain < expected and r_crowd == pytest.approx(expected)
    fov = math.radians(0.4)
    assert float(plane_variance(2.0, fov, 0.0, 0.6, crowd, limit=math.radians(90))) == \
        float(plane_variance(2.0, fov, 0.0, 0.6, plain, limit=math.radians(90)))
