"""The iwao agent's footstep planner: at each footstep read (mid-stance), choose the next foothold of the
swinging foot from the obstacles it has perceived (:mod:`.perception`), stepping over what is low and
short enough and around what is not (mats, long boxes).

A grid search over (length, lateral offset) with one step of look-ahead: a candidate foothold must keep
its foot out of every obstacle's *keep-out zone* (the footprint grown by the estimate's uncertainty and
by gaps that the swing needs in front of the toe and behind the heel, growing with the obstacle's height)
and leave at least one such foothold for the other foot next; among those, the cheapest in deviation from
the nominal step and from the lateral corridor (the path's centre line, or beside an obstacle that has to
be walked around, inside the walkway's edges). The toe clearance of the swing is the highest obstacle under it plus a margin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.tasks.obstacle_walk import CourseDistribution

# Foot box around the foothold (envs_assets/common/walker_body.xml: heel 6 cm behind the ankle, toe 20 cm
# ahead, 9 cm wide).
HEEL_M, TOE_M, HALF_WIDTH_M = 0.06, 0.20, 0.045


@dataclass(frozen=True)
class PlannerParams:
    """Margins of the planner (metres). All modelling choices, tuned on ``ObstacleWalkOracle-v0`` so the
    oracle trips on none of 200 courses (docs/reproductions/iwao.md)."""

    # Free gap between the foot box and an obstacle, plus so much per metre of obstacle height: in front
    # of the toe (the stance shin leans forward over it at push-off) and behind the heel (the landing).
    gap_front_m: float = 0.06
    gap_front_per_height: float = 0.8
    gap_back_m: float = 0.04
    gap_back_per_height: float = 0.5
    lateral_margin_m: float = 0.04
    sigmas: float = 2.0  # obstacle extents grown by this many estimate standard deviations
    clearance_margin_m: float = 0.06  # toe clearance above the highest obstacle under the swing
    tall_m: float = 0.15  # over an obstacle taller than this ...
    max_stride_over_tall_m: float = 0.90  # ... no step longer than this
    max_step_over_m: float = 0.85  # a keep-out zone longer than this is walked around
    corridor_margin_m: float = 0.08  # the feet pass this far beside an obstacle walked around
    look_ahead_m: float = 3.5  # obstacles this far ahead of the last foothold shape the corridor
    corridor_release_m: float = 0.15  # ... until the last foothold is this far past their far end
    # The walkway's half width (the env's CourseDistribution.walkway_width_m / 2: its edges are painted on
    # the floor and known, like the path's direction); a foothold keeps its foot box this far inside.
    walkway_half_width_m: float = 0.5 * CourseDistribution().walkway_width_m
    edge_margin_m: float = 0.05
    w_length: float = 1.0
    w_corridor: float = 2.0
    w_lateral: float = 0.3
    # When no foothold is clear: the extents grown by these fewer estimate stds instead of ``sigmas``, in
    # turn, before the nominal step is taken blind (empty: no relaxation, iwao v0 and the walkway's golden
    # digests). On dense hazards the 2-std zones of several uncertain neighbours close every foothold of a
    # step although the best estimates leave room (modelling choice: a walker who must step somewhere
    # steps where the hazards are least likely to be; IwaoAgent sets (1, 0) with gaze_mode="footholds").
    fallback_sigmas: tuple[float, ...] = ()


class FootstepPlanner:
    def __init__(self, gait: GaitParams | None = None, params: PlannerParams | None = None) -> None:
        self.g = gait or GaitParams()
        self.p = params or PlannerParams()
        g = self.g
        self.lengths = np.arange(0.30, g.step_range_m[1] + 1e-9, 0.05)
        self.laterals = np.arange(g.lateral_range_m[0], g.lateral_range_m[1] + 1e-9, 0.05)
        self.lengths2 = np.arange(0.35, g.step_range_m[1] + 1e-9, 0.1)
        self.laterals2 = np.arange(-0.3, 0.3 + 1e-9, 0.1)
        # The candidates' grid and the parts of the costs that do not depend on the footholds (the same
        # operations as in the formulas of ``plan``, done once).
        self._L, self._A = np.meshgrid(self.lengths, self.laterals, indexing="ij")
        self._cost_length = self.p.w_length * np.abs(self._L - g.nominal_step_m)
        self._cost_lateral = self.p.w_lateral * np.abs(self._A)
        self._cost_length2 = np.abs(g.nominal_step_m - self.lengths2) * self.p.w_length
        # Inside the walkway: a foothold's lateral position at most this far from the centre line, and a
        # corridor (the pelvis's lateral target) at most ``_corridor_limit`` (its outer foot inside then).
        self._v_limit = self.p.walkway_half_width_m - self.p.edge_margin_m - HALF_WIDTH_M
        self._corridor_limit = self._v_limit - 0.5 * g.step_width_m

    def _next_v(self, v_prev, lateral, side: int):
        """Lateral position of a foothold of ``side`` (0 left) from the previous one (the gait's rule)."""
        sign = 1.0 if side == 0 else -1.0
        return v_prev + sign * np.maximum(self.g.step_width_m + sign * lateral, self.g.min_step_width_m)

    def _zones(self, obstacles, sigmas: float | None = None):
        """(x0, x1, y0, y1, height) of every keep-out zone as arrays (before the foot box is added), the
        extents grown by ``sigmas`` estimate stds (default ``PlannerParams.sigmas``)."""
        p = self.p
        k = p.sigmas if sigmas is None else sigmas
        arr = np.array([(o.x0 - k * o.sx, o.x1 + k * o.sx, o.y0 - k * o.sy - p.lateral_margin_m,
                         o.y1 + k * o.sy + p.lateral_margin_m, o.height + k * o.sz)
                        for o in obstacles], dtype=float).reshape(-1, 5)
        front = p.gap_front_m + p.gap_front_per_height * arr[:, 4]  # obstacle ahead of the foot
        back = p.gap_back_m + p.gap_back_per_height * arr[:, 4]  # obstacle behind the foot
        return arr, (front, back)

    def _clear(self, u, v, arr, gap):
        """Boolean array: foothold (u, v) (any broadcastable shape) keeps out of every zone."""
        if len(arr) == 0:
            return np.ones(np.broadcast(u, v).shape, dtype=bool)
        u = u[..., None]
        v = v[..., None]
        front, back = gap
        x_hit = (u + TOE_M + front > arr[:, 0]) & (u - HEEL_M - back < arr[:, 1])
        y_hit = (v + HALF_WIDTH_M > arr[:, 2]) & (v - HALF_WIDTH_M < arr[:, 3])
        return ~np.any(x_hit & y_hit, axis=-1)

    def _stride_ok(self, u_prev, u, length, arr):
        """No long stride over a tall obstacle (the stance leg's knee reaches over it at push-off)."""
        p = self.p
        if len(arr) == 0:
            return np.ones(np.broadcast(u_prev, u, length).shape, dtype=bool)
        tall = arr[:, 4] > p.tall_m
        over = tall & (arr[:, 0] > np.asarray(u_prev)[..., None]) & (arr[:, 1] < np.asarray(u)[..., None])
        return ~(np.any(over, axis=-1) & (length > p.max_stride_over_tall_m))

    def corridor(self, u_last: float, y_now: float, obstacles, arr, gap) -> float:
        """The pelvis's lateral target: 0 (the path's centre line) unless an obstacle ahead is too long
        to step over; then beside it, on the side nearer the pelvis's lateral position ``y_now``."""
        p = self.p
        for _o, zone, gf, gb in zip(obstacles, arr.tolist(), gap[0].tolist(), gap[1].tolist()):
            if zone[1] < u_last - p.corridor_release_m or zone[0] > u_last + p.look_ahead_m:
                continue
            if (zone[1] - zone[0]) + TOE_M + HEEL_M + gf + gb <= p.max_step_over_m:
                continue
            half = HALF_WIDTH_M + 0.5 * self.g.step_width_m + p.corridor_margin_m
            left, right = zone[3] + half, zone[2] - half
            if right < 0.0 < left:  # the centre line runs into it: pass on the nearer side inside the walkway
                sides = [c for c in (left, right) if abs(c) <= self._corridor_limit]
                if not sides:
                    continue  # no room beside it: stepped over (the footholds' own tests decide how)
                return float(min(sides, key=lambda c: abs(c - y_now)))
        return 0.0

    def plan(self, footholds, obstacles) -> tuple[float, float, float]:
        """(length, lateral, clearance) of the next footstep. ``footholds``: the last three latched ones
        as (u, v, side) in the path frame, oldest first (the new foothold's foot swings from the oldest);
        ``obstacles``: :class:`~.perception.ObstacleEstimate` list.

        The candidates (length i, lateral j) form a separable grid: a candidate's u depends on i only
        (``u1``), its v on j only (``v1``), and so do the next foothold's on (i, k) and (j, l). The keep-out
        and stride tests (:meth:`_clear`, :meth:`_stride_ok`) are made on those small arrays, with the
        same comparisons on the same values, and combined per zone by a product of 0/1 matrices (a zone
        blocks a foothold when both its x and its y test hit); the costs are the same operations on the
        same values as the plain broadcast over (i, j[, k, l], zone), so the same footstep."""
        g, p = self.g, self.p
        (u_a, v_a, _), (u_b, v_b, side_b) = footholds[-2], footholds[-1]
        u_from, v_from = u_a, v_a  # the new foothold's foot swings from the one before the last
        side = 1 - int(side_b)
        L, A = self._L, self._A
        u1 = u_b + self.lengths  # U[i, j] = u1[i]
        v1 = self._next_v(v_b, self.laterals, side)  # V[i, j] = v1[j]
        for sigmas in (None, *p.fallback_sigmas):  # PlannerParams.fallback_sigmas: fewer stds when nothing is clear
            arr, gap = self._zones(obstacles, sigmas)
            y_goal = self.corridor(u_b, 0.5 * (v_a + v_b), obstacles, arr, gap)
            ok = self._ok_first(u_b, u1, v1, arr, gap) & (np.abs(v1) <= self._v_limit)[None, :]
            # One step of look-ahead: the other foot must find a clear foothold after this one.
            best2 = self._best_next(u1, v1, arr, gap, side, y_goal)
            cost = (self._cost_length + p.w_corridor * np.abs(0.5 * (v1 + v_b) - y_goal) + self._cost_lateral + best2)
            cost = np.where(ok & np.isfinite(best2), cost, np.inf)
            if np.isfinite(cost).any():
                break
        if not np.isfinite(cost).any():  # nothing is clear: the footholds that are clear now, else nominal
            cost = np.where(ok, self._cost_length, np.inf)
            if not np.isfinite(cost).any():
                cost = np.abs(L - g.nominal_step_m) + np.abs(A)
        i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
        length, lateral = float(L[i, j]), float(A[i, j])
        u_to, v_to = float(u1[i]), float(v1[j])
        return length, lateral, self.clearance(u_from, v_from, u_to, v_to, arr)

    def _ok_first(self, u_b: float, u1, v1, arr, gap) -> np.ndarray:
        """(i, j) array: candidate (u1[i], v1[j]) clear of every zone (:meth:`_clear`) and no long stride
        from ``u_b`` over a tall one (:meth:`_stride_ok`)."""
        if len(arr) == 0:
            return np.ones((len(u1), len(v1)), dtype=bool)
        p = self.p
        front, back = gap
        x_hit = (u1[:, None] + TOE_M + front > arr[:, 0]) & (u1[:, None] - HEEL_M - back < arr[:, 1])  # (i, zone)
        y_hit = (v1[:, None] + HALF_WIDTH_M > arr[:, 2]) & (v1[:, None] - HALF_WIDTH_M < arr[:, 3])  # (j, zone)
        clear = (x_hit.astype(float) @ y_hit.astype(float).T) == 0.0  # counts of zones hit by both (exact)
        tall = arr[:, 4] > p.tall_m
        over = tall & (arr[:, 0] > np.asarray(u_b)[..., None]) & (arr[:, 1] < u1[:, None])  # (i, zone)
        stride = ~(over.any(axis=-1) & (self.lengths > p.max_stride_over_tall_m))  # (i,)
        return clear & stride[:, None]

    def _best_next(self, u1, v1, arr, gap, side: int, y_goal: float) -> np.ndarray:
        """(i, j) array: for each candidate foothold (u1[i], v1[j]) the cost of the cheapest clear foothold
        of the other foot after it (length k, lateral l of ``lengths2``, ``laterals2``), inf when there
        is none: ``|nominal - L2| w_length + w_corridor |(v + v2) / 2 - y_goal|`` where clear."""
        g, p = self.g, self.p
        l2 = self.lengths2
        u2 = u1[:, None] + l2  # (i, k): U2[i, j, k, l]
        v2 = self._next_v(v1[:, None], self.laterals2, 1 - side)  # (j, l): V2[i, j, k, l]
        (ni, nk), (nj, nl) = u2.shape, v2.shape
        if len(arr) == 0:
            ok2 = np.ones((ni, nj, nk, nl), dtype=bool)
        else:
            front, back = gap
            x_hit = (u2[..., None] + TOE_M + front > arr[:, 0]) & (u2[..., None] - HEEL_M - back < arr[:, 1])
            y_hit = (v2[..., None] + HALF_WIDTH_M > arr[:, 2]) & (v2[..., None] - HALF_WIDTH_M < arr[:, 3])
            hits = x_hit.reshape(ni * nk, -1).astype(float) @ y_hit.reshape(nj * nl, -1).astype(float).T
            clear = (hits == 0.0).reshape(ni, nk, nj, nl).transpose(0, 2, 1, 3)
            # _stride_ok(U, U2, L2): no long stride over a tall zone between the two footholds.
            tall = arr[:, 4] > p.tall_m
            over = tall & (arr[:, 0] > u1[:, None, None]) & (arr[:, 1] < u2[..., None])  # (i, k, zone)
            stride = ~(over.any(axis=-1) & (l2 > p.max_stride_over_tall_m))  # (i, k)
            ok2 = clear & stride[:, None, :, None]
        ok2 = ok2 & (np.abs(v2) <= self._v_limit)[None, :, None, :]  # inside the walkway
        corridor = p.w_corridor * np.abs(0.5 * (v1[:, None] + v2) - y_goal)  # (j, l)
        if math.inf * p.w_length == math.inf:
            # Where not clear, |inf| w_length + corridor is inf (or NaN with a NaN corridor, which, like
            # inf, the caller treats as no foothold): the clear entries' costs are (j, k, l) sums.
            cost2 = np.where(ok2, self._cost_length2[None, :, None] + corridor[:, None, :], np.inf)
        else:
            cost2 = np.where(ok2, g.nominal_step_m - l2[:, None], np.inf)
            cost2 = np.abs(cost2) * p.w_length + corridor[None, :, None, :]
        return cost2.reshape(ni, nj, -1).min(axis=-1)

    def clearance(self, u0: float, v0: float, u1: float, v1: float, arr) -> float:
        """Toe clearance of a swing from (u0, v0) to (u1, v1): the highest zone under it plus a margin."""
        g, p = self.g, self.p
        lo, hi = min(v0, v1) - HALF_WIDTH_M, max(v0, v1) + HALF_WIDTH_M
        c = g.nominal_clearance_m
        for x0, x1, y0, y1, h in arr.tolist():
            if x1 > u0 - HEEL_M and x0 < u1 + TOE_M and y1 > lo and y0 < hi:
                c = max(c, h + p.clearance_margin_m)
        return float(min(c, g.clearance_range_m[1]))
