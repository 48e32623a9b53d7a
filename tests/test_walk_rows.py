"""ObstacleWalk's opt-in rows-with-gaps course (``CourseDistribution(layout="rows")``, preset ``"rows"``) and
the iwao planner's corridor through rows (``PlannerParams.rows``): geometry of the drawn courses, hand-built
corridor cases (the planner alone: pure geometry over its estimates) and one real-physics crossing by the
planner with true footprints."""

from __future__ import annotations

import numpy as np
import pytest
from visuomotor_gym.baselines.iwao.agent import IwaoAgent, _registered_layout
from visuomotor_gym.baselines.iwao.perception import ObstacleEstimate
from visuomotor_gym.baselines.iwao.planner import HALF_WIDTH_M, FootstepPlanner, PlannerParams

from visuomotor_gym.static_gaze import registered_kwargs
from visuomotor_gym.tasks.obstacle_walk import (
    COURSE_PRESETS,
    MAT,
    ROWS_COURSE,
    CourseDistribution,
    sample_course,
)


@pytest.mark.parametrize("seed", range(12))
def test_every_row_spans_the_walkway_with_one_gap_of_the_drawn_width(seed):
    d = ROWS_COURSE
    half = 0.5 * d.walkway_width_m
    course = sample_course(np.random.default_rng(seed), d, 16)
    obs = course.obstacles
    assert len(obs) >= 6 and len(obs) % 2 == 0  # at least three rows of two patches
    assert np.all(obs[:, 5] == MAT) and np.allclose(obs[:, 4], d.mat_height_m)
    near = []
    for right, left in zip(obs[0::2], obs[1::2]):
        assert right[0] == left[0] and right[2] == left[2]  # one row: same centre x, same depth
        assert d.row_depth_m[0] <= right[2] <= d.row_depth_m[1]
        lo, hi = right[1] + 0.5 * right[3], left[1] - 0.5 * left[3]  # the gap's edges
        assert right[1] - 0.5 * right[3] == pytest.approx(-half) and left[1] + 0.5 * left[3] == pytest.approx(half)
        assert d.row_gap_m[0] <= hi - lo <= d.row_gap_m[1]
        assert d.row_gap_lateral_m[0] <= 0.5 * (lo + hi) <= d.row_gap_lateral_m[1]
        near.append(right[0] - 0.5 * right[2])
        assert right[0] + 0.5 * right[2] <= course.length - d.finish_clear_m
    steps = np.diff(near)
    assert np.all(steps >= d.row_step_m[0] - 1e-9) and np.all(steps <= d.row_step_m[1] + 1e-9)


def test_the_rows_preset_is_opt_in_and_keeps_labelled_slots():
    assert COURSE_PRESETS["rows"] is ROWS_COURSE and ROWS_COURSE.rough  # labelled slots, a sight range
    assert not CourseDistribution().rough
    with pytest.raises(ValueError, match="row_gap_m"):
        CourseDistribution(layout="rows", row_gap_m=(0.0, 0.3))
    with pytest.raises(ValueError, match="layout"):
        CourseDistribution(layout="lanes")


def _row(x0: float, x1: float, lo: float, hi: float, sd: float = 0.01) -> list[ObstacleEstimate]:
    """A row of two flat patches across the walkway with a gap from ``lo`` to ``hi`` (path frame)."""
    return [ObstacleEstimate(0, x0, x1, -0.75, lo, 0.01, sd, sd, sd),
            ObstacleEstimate(1, x0, x1, hi, 0.75, 0.01, sd, sd, sd)]


def test_the_row_corridor_runs_through_the_gap_nearest_the_pelvis():
    planner = FootstepPlanner(params=PlannerParams(rows=True))
    row = _row(2.0, 2.6, 0.25, 0.60)
    arr, gap = planner._zones(row, 0.0)
    # The feet's centres are free from 0.25 + 0.045 + 0.04 (lateral margin) to 0.60 - 0.085: an interval of
    # 0.18 m, narrower than twice the 0.14 m kept from its ends, so the corridor is its middle.
    assert planner.row_corridor(1.0, -0.2, arr, gap) == pytest.approx(0.5 * (0.25 + 0.60), abs=1e-9)
    # A gap at the walkway's edge (one patch from -0.35 to the left edge): the free interval runs from the
    # feet's limit inside the walkway, -(0.75 - 0.05 - 0.045), to -0.35 - 0.085; 0.22 m wide: its middle.
    edge = _row(2.0, 2.6, -0.75, -0.35)
    lim = 0.75 - 0.05 - HALF_WIDTH_M
    assert planner.row_corridor(1.0, 0.0, *planner._zones(edge, 0.0)) == pytest.approx(0.5 * (-lim - 0.435), abs=1e-9)


def test_the_row_corridor_turns_to_the_next_row_once_the_last_foothold_has_entered_a_row():
    planner = FootstepPlanner(params=PlannerParams(rows=True))
    rows = _row(2.0, 2.6, -0.50, -0.15) + _row(3.8, 4.4, 0.30, 0.65)
    arr, gap = planner._zones(rows, 0.0)
    assert planner.row_corridor(1.2, 0.0, arr, gap) == pytest.approx(-0.325, abs=1e-9)
    assert planner.row_corridor(2.1, -0.3, arr, gap) == pytest.approx(0.475, abs=1e-9)
    assert planner.row_corridor(4.6, 0.4, arr, gap) == 0.0  # no row ahead: the centre line


def test_iwao_gets_the_row_corridor_only_on_the_rows_course():
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "rows"}):
        assert _registered_layout("ObstacleWalk-v0") == "rows"
        agent = IwaoAgent.for_env("ObstacleWalk-v0")
        assert agent.params.gaze_mode == "footholds" and agent.planner.p.rows
    assert not IwaoAgent.for_env("ObstacleWalk-v0").planner.p.rows
    assert _registered_layout("SteppingStones-v0") is None


@pytest.mark.parametrize("seed", [1000, 1009])
def test_the_planner_with_true_footprints_crosses_the_rows(seed):
    """ObstacleWalkOracle-v0 on the rows course (real MuJoCo physics). Seed 1009 (of 1000-1011 the one)
    missteps without the rows corridor: beside the first obstacle across the centre line, released only
    past its far end, the corridor turned to the next gap too late for the gait's lateral reach."""
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    with registered_kwargs("ObstacleWalkOracle-v0", {"course_distribution": "rows"}):
        env = gym.make("ObstacleWalkOracle-v0")
        policy = make_agent("iwao", "ObstacleWalkOracle-v0", int(env.action_space.shape[0]), seed=seed)
        trace = run_episode(env, policy, seed=seed, env_id="ObstacleWalkOracle-v0", agent="iwao")
        env.close()
    assert trace.success, trace.task
