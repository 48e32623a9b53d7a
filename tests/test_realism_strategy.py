"""Realism that measures strategy (realism version 2): on every family a still eye and a random eye score <=
0.5 and a human-like eye scores high; the moving-eye measures against hand-computed cases; undefined scores 0.

The traces are synthetic :class:`EpisodeTrace` objects (no simulation) built per family: a *human-like* eye
saccades about 3 times a second onto the task's targets (the obstacles and the walkway ahead, the next
stones, the pedestrians, the object, the ball), a *still* eye keeps one body-locked line of sight and never
saccades (the static twin's strategy; a held gaze is the same for these measures), a *random* eye saccades at
random times (a human-like rate) to random directions. The last test plays a few real episodes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from visuomotor_gym import handpath
from visuomotor_gym.bench.trace import EpisodeTrace
from visuomotor_gym.metrics import gaze as G
from visuomotor_gym.metrics import strategy
from visuomotor_gym.metrics.dodge_realism import DODGE_REFERENCE, dodge_gaze_realism, first_run
from visuomotor_gym.metrics.reach_realism import REACH_REFERENCE, reach_measures, reach_realism
from visuomotor_gym.metrics.realism import (
    GROUPS,
    gaze_realism,
    group_scores,
    load_reference,
    score_component,
    score_components,
)
from visuomotor_gym.metrics.stones_realism import STONES_REFERENCE, stone_fixation_share, stones_gaze_realism
from visuomotor_gym.metrics.walk_realism import (
    WALK_REFERENCE,
    episode_measures,
    path_fixation_share,
    walk_gaze_realism,
)

DT = 0.02
FAMILIES = ("catch", "reach", "walk", "stones", "dodge")
STONE_TOP_Z = -0.005


# --- building blocks -------------------------------------------------------------------------------
def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def direction(az_deg, el_deg):
    az, el = np.radians(az_deg), np.radians(el_deg)
    return np.stack(np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)), axis=-1)


def saccade_rows(t, onsets, rows=2):
    """``saccade_onset`` and ``in_saccade`` for onsets at the given times (s): onset ``s`` flags row
    ``round(s / dt) + 1`` (the saccade starts at the start of that step) and ``rows`` rows are in flight."""
    onset = np.zeros(len(t), dtype=bool)
    flying = np.zeros(len(t), dtype=bool)
    ks = []
    for s in onsets:
        k = round(s / DT) + 1
        if k < len(t):
            onset[k] = True
            flying[k:k + rows] = True
            ks.append(k)
    return onset, flying, ks


def make(env_id, t, gaze, eye, onsets, head=None, success=True, **task) -> EpisodeTrace:
    onset, flying, _ = saccade_rows(t, onsets)
    n = len(t)
    return EpisodeTrace(env_id=env_id, agent="synthetic", seed=0, dt=DT, t=t, gaze_dir=unit(gaze), eye_pos=eye,
                        head_dir=unit(gaze) if head is None else head, in_saccade=flying, saccade_onset=onset,
                        action=np.full((n, 1), np.nan), latency_s=np.full(n, 1e-3), success=success, diverged=False,
                        truncated=False, task=task)


def piecewise(t, onsets):
    """Per row, the index of the fixation in progress: 0 before the first onset, i after onset i."""
    rows = [round(s / DT) + 1 for s in onsets]
    return np.searchsorted(np.asarray(rows), np.arange(len(t)), side="right")


def random_onsets(rng, duration, start=0.02):
    """Onset times at random: gaps uniform in [0.2, 0.45] s (the plant's 200 ms refractory period up; a mean
    of ~3 saccades per second, a human-like rate)."""
    out, s = [], start + rng.uniform(0.0, 0.2)
    while s < duration - 0.05:
        out.append(round(s / DT) * DT)
        s += rng.uniform(0.2, 0.45)
    return out


def random_gaze(rng, t, onsets, el=(-60.0, 20.0)):
    """A line of sight that jumps to a uniformly random direction at every onset (az within +-60 deg)."""
    k = piecewise(t, onsets)
    dirs = direction(rng.uniform(-60.0, 60.0, len(onsets) + 1), rng.uniform(*el, len(onsets) + 1))
    return dirs[k]


# --- catch ------------------------------------------------------------------------------------------
GRAV = np.array([0.0, 0.0, -9.81])
CATCH_EYE = np.array([0.0, 0.0, 1.13])
RELEASE, ARRIVAL, FLIGHT = np.array([5.0, 0.3, 1.5]), np.array([0.35, -0.25, 1.0]), 1.0  # apex at 0.449 s


def min_jerk(t, t0, duration):
    s = np.clip((t - t0) / duration, 0.0, 1.0)
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def catch_trace(kind, seed=0):
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    v0 = (ARRIVAL - RELEASE - 0.5 * GRAV * FLIGHT**2) / FLIGHT
    ball = RELEASE + np.outer(t, v0) + 0.5 * np.outer(t**2, GRAV)
    eye = np.tile(CATCH_EYE, (len(t), 1))
    hand = np.tile([0.2, -0.25, 0.9], (len(t), 1))
    on_release = np.tile(unit(RELEASE - CATCH_EYE), (len(t), 1))
    if kind == "human":  # first saccade at 0.2 s, catch-up at 0.4 s, one more at 0.6; pursuit in between
        onsets = [0.2, 0.4, 0.6]
        gaze = np.where((t < 0.22)[:, None], on_release, unit(ball - eye))
        for s in onsets:  # a hand submovement starts with each saccade (Eyecatch Fig. 4)
            hand = hand + np.outer(min_jerk(t, s, 0.18), [0.05, 0.0, 0.03])
        head = gaze
    elif kind == "still":
        onsets, gaze, head = [], on_release, None
        hand = hand + np.outer(min_jerk(t, 0.3, 0.5), [0.15, 0.0, 0.1])
    else:
        rng = np.random.default_rng(seed)
        onsets = random_onsets(rng, FLIGHT)
        gaze, head = random_gaze(rng, t, onsets), None
        for s in (0.2, 0.4, 0.6):
            hand = hand + np.outer(min_jerk(t, s, 0.18), [0.05, 0.0, 0.03])
    if head is None:
        head = np.tile([1.0, 0.0, 0.0], (len(t), 1))
    return make("EyeCatch-v0", t, gaze, eye, onsets, head=head, ball_pos=ball, ball_vel=np.zeros_like(ball),
                hand_pos=hand, ball_visible=np.ones(len(t), bool), missed=False, release_pos=RELEASE,
                arrival_pos=ARRIVAL, flight_time=FLIGHT)


# --- reach ------------------------------------------------------------------------------------------
REACH_EYE = np.array([0.1, 0.0, 1.13])
HAND_START, OBJECT = np.array([0.32, -0.05, 0.74]), np.array([0.35, -0.55, 0.93])


def reach_trace(kind, seed=0):
    path = np.vstack([np.repeat(HAND_START[None], 16, axis=0), handpath.faraway_path(HAND_START, OBJECT, 30)])
    t = np.round(np.arange(len(path)) * DT, 10)
    eye = np.tile(REACH_EYE, (len(t), 1))
    ahead = np.tile([1.0, 0.0, 0.0], (len(t), 1))
    if kind == "human":  # a saccade to the object at 0.2 s, gaze on it until the hand arrives (Land et al. 1999)
        onsets = [0.2]
        gaze = np.where((t < 0.22)[:, None], ahead, unit(OBJECT - eye))
    elif kind == "still":
        onsets, gaze = [], ahead
    else:
        rng = np.random.default_rng(seed)
        onsets = random_onsets(rng, t[-1])
        gaze = random_gaze(rng, t, onsets)
    return make("ShelfReach-v0", t, gaze, eye, onsets, hand_pos=path, object_pos=OBJECT, target_index=0,
                hand_home=HAND_START, object_visible=np.ones(len(t), bool), panel_hit=False)


# --- walk -------------------------------------------------------------------------------------------
OBSTACLES = np.array([[5.0, 0.0, 0.3, 1.5, 0.2, 0.0], [9.5, 0.0, 0.3, 1.5, 0.2, 0.0]])


def walk_trace(kind, seed=0):
    t = np.round(np.arange(0.0, 9.0, DT), 10)
    pelvis = np.stack([1.3 * t, 0 * t, 0.9 + 0 * t], axis=1)
    eye = pelvis + [0.1, 0.0, 0.7]
    travel = unit(np.tile([1.5, 0.0, -1.6], (len(t), 1)))  # the floor 1.5 m ahead, carried with the body
    if kind == "human":  # a saccade every 0.3 s; every fifth fixation during an approach goes to the obstacle
        onsets = list(np.round(np.arange(0.3, t[-1], 0.3), 10))
        fix = piecewise(t, onsets)
        # between saccades gaze holds the floor point it landed on, 1.9 m ahead (Muller et al. 2023, Fig. 1)
        start = np.searchsorted(fix, fix)  # the first row of each row's fixation
        held = eye[start] * [1, 1, 0] + [1.9, 0.0, 0.0]
        gaze = unit(held - eye)
        for ob in OBSTACLES:
            near = ob[0] - 0.5 * ob[2]
            approach = (pelvis[:, 0] >= near - 5.0) & (pelvis[:, 0] < near - 1.5)
            look = approach & (fix % 5 == 0)
            gaze[look] = unit(np.array([ob[0], ob[1], ob[4]]) - eye[look])
    elif kind == "still":  # body-locked 40 deg down (lands 1.9 m ahead: on the walkway), never a saccade
        onsets, gaze = [], np.tile(direction(0.0, -40.0), (len(t), 1))
    elif kind == "body-locked saccades":  # the floor 1.5 m ahead carried with the body, re-centred every 0.3 s
        onsets, gaze = list(np.round(np.arange(0.3, t[-1], 0.3), 10)), travel
    else:
        rng = np.random.default_rng(seed)
        onsets = random_onsets(rng, t[-1])
        gaze = random_gaze(rng, t, onsets)
    return make("ObstacleWalk-v0", t, gaze, eye, onsets, pelvis_pos=pelvis, feet_pos=np.zeros((len(t), 6)),
                step_phase=np.zeros(len(t)), obstacle_seen=np.ones(len(t), bool), course_length=12.0,
                obstacles=OBSTACLES, tripped=False, misstepped=False, off_path=False, finished=True)


# --- stones -----------------------------------------------------------------------------------------
STONES = np.array([[2.0 + 0.75 * k, 0.0] for k in range(10)])
STEP_S = 0.48


def stones_trace(kind, seed=0):
    t = np.round(np.arange(0.0, 2.0 + STEP_S * 10, DT), 10)
    landing = 2.0 + STEP_S * np.arange(len(STONES))
    n = np.array([(ti >= landing + 0.1 - 1e-9).sum() for ti in t])
    eye = np.stack([2.0 + (0.75 / STEP_S) * (t - 2.0) - 0.75, 0 * t, 1.6 + 0 * t], axis=1)
    if kind == "human":  # gaze on the stone two steps ahead of the stance foot, a saccade when the foot lands
        onsets = [float(t[k] - DT) for k in np.flatnonzero(np.diff(n)) + 1]
        target = np.concatenate([STONES[np.minimum(n + 1, len(STONES) - 1)], np.full((len(t), 1), STONE_TOP_Z)], 1)
        gaze = target - eye
    elif kind == "still":  # body-locked 40 deg down
        onsets, gaze = [], np.tile(direction(0.0, -40.0), (len(t), 1))
    else:
        rng = np.random.default_rng(seed)
        onsets = random_onsets(rng, t[-1])
        gaze = random_gaze(rng, t, onsets)
    return make("SteppingStones-v0", t, gaze, eye, onsets, pelvis_pos=eye - [0, 0, 0.7],
                feet_pos=np.zeros((len(t), 6)), step_phase=np.zeros(len(t)), next_stone=n.astype(float),
                stone_seen=np.ones(len(t), bool), stones=STONES, stone_radius=0.25, fell=False, finished=True)


# --- dodge ------------------------------------------------------------------------------------------
PED_ONSETS = (0.6, 2.4, 4.5, 6.6)


def dodge_trace(kind, seed=0):
    t = np.round(np.arange(0.0, 10.0, DT), 10)
    eye = np.stack([1.3 * t, 0 * t, 1.6 + 0 * t], axis=1)
    crowd = np.zeros((4, 9))
    crowd[:, 0] = PED_ONSETS
    ped = np.full((len(t), 4, 3), np.nan)
    for i, onset in enumerate(PED_ONSETS):
        live = t >= onset - 1e-9
        side = 1.0 if i % 2 else -1.0
        ped[live, i] = np.stack([1.3 * onset + 6.0 - 0.5 * (t[live] - onset), side * (2.0 - 0.3 * (t[live] - onset)),
                                 1.2 + 0 * t[live]], axis=1)
    path = unit(np.tile([3.0, 0.0, -1.6], (len(t), 1)))
    if kind == "human":  # a saccade every 0.3 s; pedestrians 0-2 fixated 0.6 s after they appear, for 0.6 s
        onsets = list(np.round(np.arange(0.3, t[-1], 0.3), 10))
        gaze = path.copy()
        for i, onset in enumerate(PED_ONSETS[:3]):
            look = (t >= onset + 0.6 + 1e-9) & (t < onset + 1.2 + 1e-9)
            gaze[look] = unit(ped[look, i] - eye[look])
    elif kind == "still":
        onsets, gaze = [], np.tile(direction(0.0, -5.0), (len(t), 1))
    else:
        rng = np.random.default_rng(seed)
        onsets = random_onsets(rng, t[-1])
        gaze = random_gaze(rng, t, onsets)
    return make("ObstacleDodge-v0", t, gaze, eye, onsets, pelvis_pos=eye - [0, 0, 0.7],
                feet_pos=np.zeros((len(t), 6)), pedestrian_pos=ped, step_phase=np.zeros(len(t)),
                pedestrian_seen=np.ones(len(t), bool), goal_distance=13.0, pedestrians=crowd, collided=False,
                finished=True, veered=np.zeros(4, bool), min_gap=1.0)


BUILD = {"catch": catch_trace, "reach": reach_trace, "walk": walk_trace, "stones": stones_trace, "dodge": dodge_trace}
REALISM = {"catch": gaze_realism, "reach": reach_realism, "walk": walk_gaze_realism, "stones": stones_gaze_realism,
           "dodge": dodge_gaze_realism}


def realism(family, kind, episodes=3):
    return REALISM[family]([BUILD[family](kind, seed=s) for s in range(episodes)])


# --- every family: human-like high, still and random <= 0.5 -------------------------------------------
@pytest.mark.parametrize("family", FAMILIES)
def test_a_human_like_eye_scores_high(family):
    r = realism(family, "human")
    assert r["score"] >= 0.85, (family, r)


@pytest.mark.parametrize("family", FAMILIES)
def test_a_still_eye_scores_at_most_one_half(family):
    r = realism(family, "still")
    assert r["score"] <= 0.5, (family, r)
    # it never saccades: the components that need a saccade are undefined and score 0, not left out
    undefined = [c for c in r["components"].values() if c["episodes"] == 0]
    assert undefined and all(c["score"] == 0.0 for c in undefined)


@pytest.mark.parametrize("family", FAMILIES)
def test_a_random_eye_scores_at_most_one_half(family):
    r = realism(family, "random", episodes=6)
    assert r["score"] <= 0.5, (family, r)


@pytest.mark.parametrize("family", ("walk", "stones", "dodge"))
def test_the_random_eye_fails_where_it_looks_not_when(family):
    """A random eye saccading at a human rate passes the ``moves`` group: what fails it is where it lands."""
    ref = {"walk": WALK_REFERENCE, "stones": STONES_REFERENCE, "dodge": DODGE_REFERENCE}[family]
    r = realism(family, "random", episodes=6)
    scores = {g: np.mean([c["score"] for n, c in r["components"].items() if ref[n]["group"] == g]) for g in
              ("moves", "where")}
    assert scores["moves"] > 0.7 and scores["where"] <= 0.5, scores


# --- the rule: coverage, undefined -> 0, the smallest group ------------------------------------------------
REF = {
    "a": {"value": 1.0, "low": 0.0, "high": 2.0, "tolerance": 1.0, "unit": "-", "group": "moves"},
    "b": {"value": 1.0, "low": 0.0, "high": 2.0, "tolerance": 1.0, "unit": "-", "group": "where"},
    "c": {"value": 1.0, "low": 0.0, "high": 2.0, "tolerance": 1.0, "unit": "-", "group": "where"},
}


def test_an_undefined_component_scores_zero_and_coverage_scales_the_rest():
    rows = [{"a": 1.0, "b": 1.0, "c": float("nan")}, {"a": 3.0, "b": float("nan"), "c": float("nan")}]
    r = score_components(rows, REF)
    a, b, c = (r["components"][k] for k in "abc")
    assert a == {"value": 2.0, "score": 1.0, "episodes": 2}
    assert b == {"value": 1.0, "score": 0.5, "episodes": 1}  # in range, defined in 1 of 2 episodes
    assert math.isnan(c["value"]) and c["score"] == 0.0 and c["episodes"] == 0
    assert r["score"] == pytest.approx(min(1.0, (0.5 + 0.0) / 2))  # the smaller group mean


def test_the_score_is_the_smallest_group_mean():
    rows = [{"a": 4.0, "b": 1.0, "c": 1.0}]  # a two tolerances out: exp(-2)
    r = score_components(rows, REF)
    assert r["score"] == pytest.approx(math.exp(-2.0))
    assert score_components([{"a": 1.0, "b": 1.0, "c": 4.0}], REF)["score"] == pytest.approx((1 + math.exp(-2)) / 2)
    assert math.isnan(score_components([], REF)["score"])
    r = score_components([{"a": 1.0, "b": 1.0, "c": 1.0}] * 3, REF, reduce="median")
    assert r["score"] == 1.0


def test_the_rule_refuses_bad_input():
    with pytest.raises(ValueError, match="group"):
        score_components([{"a": 1.0}], {"a": {**REF["a"], "group": "posture"}})
    with pytest.raises(ValueError, match="reduce"):
        score_components([{"a": 1.0}], {"a": REF["a"]}, reduce="max")


def test_every_table_names_a_group_and_a_source_for_every_component():
    tables = {"catch": load_reference(), "reach": REACH_REFERENCE, "walk": WALK_REFERENCE,
              "stones": STONES_REFERENCE, "dodge": DODGE_REFERENCE}
    for family, table in tables.items():
        assert {e["group"] for e in table.values()} >= {"moves", "where"}, family
        for name, entry in table.items():
            assert entry["group"] in GROUPS and entry["source"].strip() and entry["unit"].strip(), (family, name)
            assert entry["low"] <= entry["value"] <= entry["high"] and entry["tolerance"] > 0, (family, name)
    # what the plant or a controller guarantees is not scored
    assert "hand_peak_speed_m_s" not in tables["catch"]


# --- the moving-eye measures against hand-computed cases ---------------------------------------------------
def _bare(t, onsets, gaze=None):
    n = len(t)
    return make("ObstacleWalk-v0", t, np.tile([1.0, 0.0, 0.0], (n, 1)) if gaze is None else gaze,
                np.zeros((n, 3)), onsets)


def test_saccade_rate_counts_onsets_per_second():
    t = np.round(np.arange(0.0, 2.0 + 1e-9, DT), 10)  # 2 s
    assert strategy.saccade_rate(_bare(t, [0.3, 0.6, 0.9])) == pytest.approx(1.5)
    assert strategy.saccade_rate(_bare(t, [])) == 0.0
    assert math.isnan(strategy.saccade_rate(_bare(t[:10], [])))  # 0.18 s: too short for a rate


def test_fixation_durations_are_the_runs_between_saccades():
    t = np.round(np.arange(0.0, 2.0 + 1e-9, DT), 10)
    tr = _bare(t, [0.3, 0.6, 1.0])  # rows 16-17, 31-32, 51-52 in flight
    # runs bounded by saccades: rows 18-30 (13 rows) and 33-50 (18 rows); before row 16 and after row 52: cut
    assert strategy.fixation_durations(tr) == pytest.approx([13 * DT, 18 * DT])
    assert strategy.fixation_duration(tr) == pytest.approx(15.5 * DT)
    assert math.isnan(strategy.fixation_duration(_bare(t, [0.3])))  # one saccade: no bounded fixation


def test_fixation_share_counts_resting_rows_on_target():
    t = np.round(np.arange(0.0, 1.0 + 1e-9, DT), 10)  # 51 rows
    tr = _bare(t, [0.3])  # rows 16, 17 in flight: 49 resting rows
    on = np.zeros(len(t), bool)
    on[:16] = True  # 16 resting rows on target before the saccade
    assert strategy.fixation_share(tr, on) == pytest.approx(16 / 49)
    rows = np.zeros(len(t), bool)
    rows[10:20] = True  # resting rows 10-15 and 18-19: 6 of 8 on target
    assert strategy.fixation_share(tr, on, rows) == pytest.approx(6 / 8)
    assert math.isnan(strategy.fixation_share(tr, on, np.zeros(len(t), bool)))


def test_path_fixation_share_on_the_walkway_ahead():
    human = walk_trace("still")  # 40 deg down: 1.9 m ahead, on the walkway
    assert path_fixation_share(human) == 1.0
    t = human.t
    level = make("ObstacleWalk-v0", t, np.tile([1.0, 0.0, 0.0], (len(t), 1)), human.eye_pos, [],
                 **human.task)
    assert path_fixation_share(level) == 0.0  # never meets the floor
    aside = make("ObstacleWalk-v0", t, np.tile(direction(60.0, -40.0), (len(t), 1)), human.eye_pos, [],
                 **human.task)  # 1.9 m out at 60 deg: 1.65 m to the side, off the 1.5 m walkway
    assert path_fixation_share(aside) == 0.0


def test_ground_fixation_share_counts_held_floor_points_only():
    from visuomotor_gym.metrics.walk_realism import ground_fixation_share

    human, carried = walk_trace("human"), walk_trace("body-locked saccades")
    resting = ~(human.in_saccade | human.saccade_onset)
    # the human eye's floor point jumps only while a saccade is in flight; a look at an obstacle's top (0.2 m
    # high, eye at 1.6 m) moves its floor point at 1.3 * 0.2 / 1.4 = 0.19 m/s, under 0.5: every resting row
    # holds but the first row of the trace (no speed yet)
    assert ground_fixation_share(human) == pytest.approx(1 - 1 / resting.sum())
    assert ground_fixation_share(carried) == 0.0  # the floor point moves at 1.3 m/s, past 0.5 m/s
    assert ground_fixation_share(walk_trace("still")) == 0.0


def test_a_body_locked_eye_that_saccades_fails_where_it_looks_on_the_walkway():
    """A line of sight carried with the body and re-centred at a human rate (the winding walkway's best static
    twin re-centres as the pelvis turns) passes ``moves`` and ``layout``; holding no point, it fails ``where``."""
    r = score_components([episode_measures(walk_trace("body-locked saccades"))], WALK_REFERENCE)
    groups = group_scores(r, WALK_REFERENCE)
    assert groups["moves"] > 0.9 and groups["layout"] > 0.9 and groups["where"] <= 0.2, groups
    assert r["score"] <= 0.5


def test_stone_fixation_share_counts_upcoming_stones_only():
    tr = stones_trace("human")
    # gaze on stone min(n + 1, 9): upcoming while n <= 9; after the last landing (n = 10) stone 9 is behind
    resting = ~(tr.in_saccade | tr.saccade_onset)
    assert stone_fixation_share(tr) == pytest.approx(np.mean(tr.next_stone[resting] <= 9))
    assert 0.9 < stone_fixation_share(tr) < 1.0
    behind = make("SteppingStones-v0", tr.t, np.concatenate(
        [STONES[np.maximum(tr.next_stone.astype(int) - 1, 0)], np.full((len(tr.t), 1), STONE_TOP_Z)], 1) - tr.eye_pos,
        tr.eye_pos, [], **tr.task)  # gaze on the stone already stepped on (under the stance foot)
    # upcoming only before the first landing (n = 0: the stance "stone" is stone 0, not yet stepped on)
    assert stone_fixation_share(behind) == pytest.approx(np.mean(tr.next_stone == 0))


def test_reach_object_fixation_share_and_first_saccade_latency():
    m = reach_measures(reach_trace("human"))
    assert m["first_saccade_latency_s"] == pytest.approx(0.2)
    assert m["object_fixation_share"] == 1.0  # from the landing to the hand's arrival, all resting rows on it
    assert math.isnan(reach_measures(reach_trace("still"))["object_fixation_share"])  # never got there


def test_catchup_interval_counts_only_saccades_that_land_on_the_ball():
    human = catch_trace("human")
    assert G.ball_directed_onsets(human) == pytest.approx([0.2, 0.4, 0.6])
    assert G.catchup_saccade_interval(human) == pytest.approx(0.2)
    # the same onsets, but the eye lands 20 deg off the ball: the plant's 200 ms no longer scores
    off = make("EyeCatch-v0", human.t, direction(20.0, 0.0)[None].repeat(len(human.t), 0), human.eye_pos,
               [0.2, 0.4, 0.6], **human.task)
    assert G.ball_directed_onsets(off).size == 0
    assert math.isnan(G.catchup_saccade_interval(off))
    assert gaze_realism([off])["components"]["catchup_saccade_interval_s"]["score"] == 0.0


def test_score_component_still_scores_the_range():
    assert score_component("ball_foveation", 0.8) == 1.0
    assert score_component("ball_foveation", 0.4) == pytest.approx(math.exp(-0.5))


# --- a small real check --------------------------------------------------------------------------------
def test_lookahead_scores_high_and_its_held_twin_low_on_real_episodes():
    from visuomotor_gym.bench.evaluate import make_env, run_chunk

    env = make_env("SteppingStones-v0")
    try:
        looking = run_chunk("lookahead", "SteppingStones-v0", [0, 1, 2], env=env)
        held = run_chunk("gaze_blind:lookahead", "SteppingStones-v0", [0, 1, 2], env=env)
    finally:
        env.close()
    full, blind = stones_gaze_realism(looking), stones_gaze_realism(held)
    assert full["score"] >= 0.85, full
    assert blind["score"] <= 0.5, blind
    held = blind["components"]["fixation_duration_s"]  # the held eye never saccades: undefined, scored 0
    assert held["episodes"] == 0 and held["score"] == 0.0


def test_dodge_first_run_is_the_start_of_the_first_long_enough_run():
    """A fixation starts at the first step of the first run of at least FIXATION_MIN_S on the pedestrian."""
    assert first_run([False, True, True, False, True, True, True], 3) == 4
    assert first_run([True, True, True], 3) == 0
    assert first_run([True, True, False, True], 3) is None
    assert first_run([], 1) is None
