"""The iwao planner's fallback when no foothold is clear (PlannerParams.fallback_sigmas): hand-built cases
on the planner alone (no physics: the planner is pure geometry over its estimates)."""

from __future__ import annotations

import numpy as np
import pytest
from visuomotor_gym.baselines.iwao.agent import FOOTHOLDS_FALLBACK_SIGMAS, IwaoAgent, IwaoParams
from visuomotor_gym.baselines.iwao.perception import ObstacleEstimate
from visuomotor_gym.baselines.iwao.planner import HALF_WIDTH_M, HEEL_M, TOE_M, FootstepPlanner, PlannerParams

# The last three latched footholds (u, v, side): the right foot (side 1) stands at u = 1.30, the left
# swings next from u = 0.65.
FOOTHOLDS = [(0.0, 0.06, 1), (0.65, 0.06, 0), (1.30, -0.06, 1)]


def _wall(sd: float) -> list[ObstacleEstimate]:
    """Flat patches 1.40-2.60 m along the path side by side across the walkway, each 0.14 m wide with
    0.24 m free between neighbours, one of them on the nominal foothold (v = 0.06): the 9 cm foot fits
    between two of them clear of the estimates grown by the 4 cm lateral margin (v in 0.215-0.285), but
    not once they are grown by 1 or 2 stds of ``sd`` = 5 cm as well."""
    ys = 0.06 + 0.38 * np.arange(-2, 2)
    return [ObstacleEstimate(i, 1.40, 2.60, y - 0.07, y + 0.07, 0.01, sd, sd, sd) for i, y in enumerate(ys)]


def _on_a_patch(length: float, lateral: float, planner: FootstepPlanner, obstacles) -> bool:
    u = FOOTHOLDS[-1][0] + length
    v = float(planner._next_v(FOOTHOLDS[-1][1], np.array([lateral]), 0)[0])
    return any(u + TOE_M > o.x0 and u - HEEL_M < o.x1 and v + HALF_WIDTH_M > o.y0 and v - HALF_WIDTH_M < o.y1
               for o in obstacles)


def test_without_fallback_a_closed_step_is_the_blind_nominal_one():
    planner, obstacles = FootstepPlanner(), _wall(0.05)
    length, lateral, _ = planner.plan(FOOTHOLDS, obstacles)
    assert (length, lateral) == pytest.approx((planner.g.nominal_step_m, 0.0))
    assert _on_a_patch(length, lateral, planner, obstacles)  # the step the prepared flip's missteps took


def test_the_fallback_steps_clear_of_the_estimates_when_2_stds_close_every_foothold():
    planner, obstacles = FootstepPlanner(params=PlannerParams(fallback_sigmas=(1.0, 0.0))), _wall(0.05)
    length, lateral, _ = planner.plan(FOOTHOLDS, obstacles)
    assert not _on_a_patch(length, lateral, planner, obstacles)
    # With precise estimates (sd 1 mm) the 2-std plan is clear already: the fallback is not used.
    precise = _wall(0.001)
    assert FootstepPlanner(params=PlannerParams(fallback_sigmas=(1.0, 0.0))).plan(FOOTHOLDS, precise) \
        == FootstepPlanner().plan(FOOTHOLDS, precise)


def test_iwao_uses_the_fallback_only_with_the_footholds_gaze():
    assert FOOTHOLDS_FALLBACK_SIGMAS == (1.0, 0.0)
    assert IwaoAgent(IwaoParams(gaze_mode="footholds")).planner.p.fallback_sigmas == FOOTHOLDS_FALLBACK_SIGMAS
    assert IwaoAgent(IwaoParams()).planner.p.fallback_sigmas == ()
