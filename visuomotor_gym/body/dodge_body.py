"""The walker with a heading-and-speed action (ObstacleDodge): a subclass of
:class:`~visuomotor_gym.body.walker_body.WalkerBody` whose action block ``locomotion`` replaces the
footstep block; ObstacleWalk's body is unchanged.

The scripted gait (:mod:`visuomotor_gym.body.walker`) keeps the pelvis facing the path (+x): it has no
turning step. Its footstep action still steers: the lateral offset of each footstep moves the body
sideways by that much per step. A heading is therefore realised as a *direction of travel* (the body
walks obliquely, facing ahead), the footstep ``(v T cos h, v T sin h)`` for heading ``h`` and speed ``v``
(T = 0.5 s per step), with the gait's limits: step length 0.25-0.95 m, lateral offset +-0.3 m and feet
never closer than 0.06 m, so a stride moves at most 0.36 m sideways and the direction of travel saturates
near 18 deg at 1.3 m/s (measured in tests/test_obstacle_dodge.py; modelling
choice: a crab-walking abstraction of turning; steering in Fajen & Warren 2003 is the direction of
locomotion). As with footsteps, the command is read at each mid-stance for the next step of that foot:
it shows in the pelvis's path ~0.5-1 s later.

Action block ``locomotion`` (2 values in [-1, 1], modelling choice): heading (direction of travel from
the path's +x, + = left), linear onto [-30, 30] deg; speed, piecewise linear onto [0.5, 1.9] m/s with 0 =
1.3 m/s, the nominal gait ([-1, 0] onto [0.5, 1.3], [0, 1] onto [1.3, 1.9]). 0.5 and 1.9 m/s are what the
gait's step lengths allow at its fixed 0.5 s per step (``GaitParams.step_range_m`` 0.25-0.95 m): humans
slow right down when a pedestrian cuts in (Olivier et al. 2012 report speed as well as course
adaptations), so the body offers the gait's whole range; it cannot stop (the gait's cadence is fixed).
In the first definition of v0 the floor was 0.7 m/s (a modelling choice with no source; the sweep is in
docs/reproductions/dodge.md). Toe clearance stays at the gait's nominal 5 cm (the floor is flat).
"""

from __future__ import annotations

import math

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import WalkerBody

HEADING_RANGE_DEG = 30.0
# The gait's speeds at 0.5 s per step: step lengths 0.25-0.95 m (GaitParams.step_range_m).
SPEED_RANGE_M_S = (0.5, 1.9)
NOMINAL_SPEED_M_S = 1.3  # the gait's nominal 0.65 m step per 0.5 s: the action's 0


class DodgeBody(WalkerBody):
    """:class:`WalkerBody` with the ``locomotion`` (heading, speed) action block."""

    action_structure = {"locomotion": 2}  # noqa: RUF012 (a body replaces it, never mutates it)
    n_action = 2

    def footstep_from_locomotion(self, a0: float, a1: float) -> tuple[float, float, float]:
        """(length, lateral, clearance) in metres for a locomotion action in [-1, 1]^2 (unclipped: the
        gait clips length and lateral to its ranges)."""
        heading = a0 * HEADING_RANGE_DEG * math.pi / 180.0
        lo, hi = SPEED_RANGE_M_S
        speed = NOMINAL_SPEED_M_S + a1 * ((NOMINAL_SPEED_M_S - lo) if a1 < 0.0 else (hi - NOMINAL_SPEED_M_S))
        step = speed * self.p.step_s
        return step * math.cos(heading), step * math.sin(heading), self.p.nominal_clearance_m

    @staticmethod
    def action_from_locomotion(heading_rad: float, speed: float) -> list[float]:
        """The inverse map (for agents), clipped to [-1, 1]."""
        lo, hi = SPEED_RANGE_M_S
        h = heading_rad / (HEADING_RANGE_DEG * math.pi / 180.0)
        dv = speed - NOMINAL_SPEED_M_S
        s = dv / ((NOMINAL_SPEED_M_S - lo) if dv < 0.0 else (hi - NOMINAL_SPEED_M_S))
        return [min(max(h, -1.0), 1.0), min(max(s, -1.0), 1.0)]

    def command(self, data, a, al: list, dt: float) -> None:
        self.gait.set_next_footstep(*self.footstep_from_locomotion(al[0], al[1]))
        self.gait.advance(data, dt)


__all__ = ["HEADING_RANGE_DEG", "NOMINAL_SPEED_M_S", "SPEED_RANGE_M_S", "DodgeBody", "GaitParams"]
