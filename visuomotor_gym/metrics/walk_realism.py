"""Walking gaze realism (ObstacleWalk family): per-episode measures of when the eye moved and where it
looked, scored against human walking data with :func:`visuomotor_gym.metrics.realism.score_components`
(each component 1 inside the human range with a Gaussian fall-off outside, times the share of episodes
that define it, 0 when none does; the score is the smallest of the ``moves``, ``where`` and ``layout``
group means, so a still eye and a random eye both fail: see :mod:`visuomotor_gym.metrics.realism`).

Measures (from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace` of an ObstacleWalk env: ``eye_pos``,
``gaze_dir``, ``pelvis_pos``, ``in_saccade``, ``saccade_onset`` per step; the course ``obstacles`` per
episode):

``moves`` (:mod:`visuomotor_gym.metrics.strategy`):

* ``saccade_rate_hz``: saccade onsets per second;
* ``fixation_duration_s``: the median saccade-free run between two saccades;

``where``:

* ``obstacle_fixation_share``: the share of each obstacle's *approach* (from when it is
  ``APPROACH_START_M`` ahead of the pelvis until the pelvis is ``CROSSING_M`` before its near edge)
  during which gaze *fixates* it: the line of sight meets the plane of its top within ``ON_OBSTACLE_M``
  of its footprint and the point where it meets it moves slower than ``STABLE_GAZE_M_S``, averaged over
  the obstacles of the episode. Patla & Vickers (1997) tell obstacle fixations from *travel fixations*,
  "gaze stable and travelling at the speed of whole body": a line of sight carried with the body sweeps
  over an obstacle at walking speed and is a travel fixation, not an obstacle fixation. (Counting the
  sweep let a line of sight held 20 deg down score the human 20 %: 0.085 of the approach on 30 courses,
  against 0.008 with the stability condition);
* ``fixation_while_crossing``: the same share while stepping over or around it (pelvis from
  ``CROSSING_M`` before its near edge to ``CROSSING_M`` past its far edge), over the obstacles that were
  fixated during their approach: "planning in the steps before" means looking at it and then away.
  (Counted over every obstacle, an eye that never looked at one scored 1 here for free);
* ``ground_fixation_share``: of the resting rows whose gaze lands on the walkway ahead (below), the share
  in which the point where the line of sight meets the floor *holds* (moves slower than
  ``STABLE_GAZE_M_S``): walkers looking at the nearby ground saccade to a location and hold gaze on it
  while the body moves on (Muller et al. 2023, Fig. 1; Matthis, Yates & Hayhoe 2018). A line of sight
  kept at one posture in the body frame, or held in direction by the vestibulo-ocular reflex, sweeps
  the floor at walking speed and holds nothing.

``layout`` (where the line of sight sits; one posture of a still eye can satisfy all three, so they form
a group of their own and cannot bank points for ``where``):

* ``path_fixation_share``: the share of the resting rows (no saccade in flight) whose gaze lands on the
  walkway ahead: on an obstacle, or on the floor between ``PATH_NEAR_M`` and ``PATH_FAR_M`` ahead of the
  eye and within ``PATH_HALF_WIDTH_M`` of the walkway's centre line;
* ``travel_fixation_distance_m`` (the look-ahead): the median horizontal distance from the eye to where
  gaze meets the floor, over the steps whose gaze is on the floor ahead and on no obstacle;
* ``gaze_below_horizon_deg``: the median angle of the line of sight below the horizontal.

Window sizes and tolerances are modelling choices (stated with each constant).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from visuomotor_gym.metrics import strategy
from visuomotor_gym.metrics.common import goal_summary
from visuomotor_gym.metrics.realism import score_components
from visuomotor_gym.metrics.stats import nan_mean

APPROACH_START_M = 5.0  # modelling choice: the approach phase starts ~4 s (3 steps + the view) ahead at 1.3 m/s
CROSSING_M = 0.6  # modelling choice: about one step (0.65 m) before and after the obstacle
# Modelling choice: a fixation within ~2-4 deg of the obstacle's edge at 1.5-3 m (the accuracy of the
# eye trackers of the walking studies is ~1 deg; fixation areas are drawn around the obstacle).
ON_OBSTACLE_M = 0.10
# The walkway ahead (path_fixation_share): Patla & Vickers 1997 classify walking fixations as obstacle
# fixations, travel fixations 1-2 m ahead of the feet and fixations in the 4-6 m region, all on the travel
# path; 0.5-6 m ahead of the eye covers them (modelling choice). Half-width: the 1.5 m walkway
# (tasks.obstacle_walk.CourseDistribution.walkway_width_m) plus 0.25 m for the eye-tracker-like slack.
PATH_NEAR_M, PATH_FAR_M = 0.5, 6.0
# Modelling choice: a fixation of the obstacle holds its gaze point; a travel fixation's gaze point moves at
# the walking speed (~1.3 m/s). 0.5 m/s between two control steps separates them with room for the gaze
# drift of a real fixation.
STABLE_GAZE_M_S = 0.5
PATH_HALF_WIDTH_M = 1.0

WALK_REFERENCE: dict[str, dict] = {
    "saccade_rate_hz": strategy.SACCADE_RATE_REFERENCE,
    "fixation_duration_s": strategy.FIXATION_DURATION_REFERENCE,
    "obstacle_fixation_share": {
        "value": 0.2, "low": 0.1, "high": 0.3, "tolerance": 0.05, "unit": "fraction of the approach",
        "group": "where",
        "source": "Patla & Vickers 1997, NeuroReport 8:3661: obstacles were fixated ~20 % of the approach time "
                  "(REFERENCES.md [V]); the 0.1-0.3 range around it and the 0.05 tolerance (an eye that never "
                  "lands on an obstacle scores exp(-2) = 0.14) are our modelling choice",
        "notes": "Mean over the obstacles the pelvis reached; a fixation holds its gaze point (slower than 0.5 "
                 "m/s), a line of sight sweeping over the obstacle with the body is a travel fixation.",
    },
    "fixation_while_crossing": {
        "value": 0.0, "low": 0.0, "high": 0.05, "tolerance": 0.1, "unit": "fraction of the crossing",
        "group": "where", "given": "obstacle_fixation_share",
        "source": "Patla & Vickers 1997: obstacles were not fixated while being stepped over, the planning was "
                  "done in the steps before (REFERENCES.md [V]); the 5 % allowance is our modelling choice",
        "notes": "Pelvis within one step of the obstacle; over the obstacles fixated during their approach "
                 "(undefined, scoring 0, when the eye never looked at one).",
    },
    "ground_fixation_share": {
        "value": 0.6, "low": 0.3, "high": 1.0, "tolerance": 0.1, "unit": "fraction of the time on the walkway",
        "group": "where",
        "source": "Muller et al. 2023, eLife 12:e82410, Fig. 1: walkers looking at the nearby ground make saccades "
                  "to new locations followed by fixations in which gaze is held stable at a location in the "
                  "world while the body moves forward (REFERENCES.md [V]); Matthis, Yates & Hayhoe 2018 on rough "
                  "terrain. Patla & Vickers 2003 report travel fixations (gaze carried with the body) > 50 % of "
                  "the time on a flat laboratory walkway, so the lower bound 0.3 admits them; the range and the "
                  "tolerance (a line of sight that holds no ground point scores exp(-4.5) = 0.01) are our "
                  "modelling choice",
        "notes": "Resting rows with gaze on the walkway ahead (as path_fixation_share); a row holds when the "
                 "point where the line of sight meets the floor moves slower than 0.5 m/s.",
    },
    "path_fixation_share": {
        "value": 0.9, "low": 0.8, "high": 1.0, "tolerance": 0.2, "unit": "fraction of the fixation time",
        "group": "layout",
        "source": "Patla & Vickers 1997: the fixations of walkers approaching an obstacle are obstacle "
                  "fixations, travel fixations 1-2 m ahead and fixations 4-6 m ahead, all on the travel path; "
                  "Patla & Vickers 2003, Exp Brain Res 148:133: travel fixations alone take > 50 % of the time "
                  "(REFERENCES.md [V]). No paper gives the share of fixations off the path: the 0.8-1.0 range "
                  "and the tolerance are our modelling choice",
        "notes": "Resting rows (no saccade in flight) with gaze on an obstacle or on the walkway floor 0.5-6 m "
                 "ahead of the eye.",
    },
    "travel_fixation_distance_m": {
        "value": 1.5, "low": 1.0, "high": 2.0, "tolerance": 0.5, "unit": "m", "group": "layout", "given": "path_fixation_share",
        "source": "Patla & Vickers 1997: travel fixations 1-2 m ahead of the feet (REFERENCES.md [V])",
        "notes": "The look-ahead: median horizontal eye-to-gaze-point distance while gaze is on the floor and "
                 "on no obstacle.",
    },
    "gaze_below_horizon_deg": {
        "value": 45.0, "low": 30.0, "high": 60.0, "tolerance": 10.0, "unit": "deg", "group": "layout",
        "source": "Muller et al. 2023, eLife 12:e82410: gaze 30-60 deg from the vertical on rocky ground "
                  "(REFERENCES.md [V]); consistent with Iwao et al.'s arctan(h/l) (Sec. 4.2.1), 47 deg for "
                  "h = 1.6, l = 1.5 m",
        "notes": "Median over the episode's steps.",
    },
}


def _gaze_hits(eye: np.ndarray, gaze: np.ndarray, z: float) -> np.ndarray:
    """(T, 2) x, y where each line of sight meets the plane at height ``z`` (NaN when it does not descend to it)."""
    dz = gaze[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (z - eye[:, 2]) / dz
    s = np.where((dz < -1e-6) & (s > 0), s, np.nan)
    return eye[:, :2] + s[:, None] * gaze[:, :2]


def _holds(points: np.ndarray, dt: float) -> np.ndarray:
    """(T,) rows whose point (``_gaze_hits``) moved slower than ``STABLE_GAZE_M_S`` since the previous row
    (False on the first row and where the point is undefined)."""
    speed = np.r_[np.inf, np.linalg.norm(np.diff(points, axis=0), axis=1) / dt]
    return np.nan_to_num(speed, nan=np.inf) <= STABLE_GAZE_M_S


def _frame(trace):
    """(obstacles, to_path) of a trace: on the winding walkway (the trace's ``path``) the obstacles in path
    coordinates (s along the centre line, n across it) and a map of (T, 2) world points into them; else the
    obstacles as recorded and None (the straight walkway's x and y are its path coordinates)."""
    path = trace.task.get("path") if isinstance(getattr(trace, "task", None), dict) else None
    if path is None:
        return np.asarray(trace.obstacles, dtype=float).reshape(-1, 6), None
    path = np.asarray(path, dtype=float)
    ds = float(np.hypot(*(path[1, :2] - path[0, :2])))
    tx, ty = np.cos(path[:, 2]), np.sin(path[:, 2])

    def to_path(points: np.ndarray) -> np.ndarray:
        pts = np.asarray(points, dtype=float)[:, :2]
        out = np.full(pts.shape, np.nan)
        ok = np.all(np.isfinite(pts), axis=1)
        for k in np.flatnonzero(ok).tolist():
            dx, dy = pts[k, 0] - path[:, 0], pts[k, 1] - path[:, 1]
            i = int(np.argmin(dx * dx + dy * dy))
            out[k] = (i * ds + tx[i] * dx[i] + ty[i] * dy[i], -ty[i] * dx[i] + tx[i] * dy[i])
        return out

    return np.asarray(trace.obstacles_path, dtype=float).reshape(-1, 6), to_path


def _on(points: np.ndarray, ob: np.ndarray, tol: float) -> np.ndarray:
    x, y, depth, width = ob[0], ob[1], ob[2], ob[3]
    inside_x = np.abs(points[:, 0] - x) <= 0.5 * depth + tol
    inside_y = np.abs(points[:, 1] - y) <= 0.5 * width + tol
    return inside_x & inside_y


def obstacle_shares(trace) -> tuple[float, float]:
    """(mean approach fixation share over the obstacles approached, mean crossing fixation share over the
    obstacles crossed that had been fixated during their approach); a row fixates an obstacle when gaze
    is on it and its gaze point moves slower than ``STABLE_GAZE_M_S``."""
    obstacles, to_path = _frame(trace)
    eye, gaze, pelvis = np.asarray(trace.eye_pos), np.asarray(trace.gaze_dir), np.asarray(trace.pelvis_pos)
    approach, crossing = [], []
    dt = float(trace.dt)
    px = pelvis[:, 0] if to_path is None else to_path(pelvis)[:, 0]
    for ob in obstacles:
        near, far = ob[0] - 0.5 * ob[2], ob[0] + 0.5 * ob[2]
        hits = _gaze_hits(eye, gaze, ob[4])
        holds = _holds(hits, dt)
        if to_path is not None:
            hits = to_path(hits)
        on = _on(hits, ob, ON_OBSTACLE_M) & holds
        a = (px >= near - APPROACH_START_M) & (px < near - CROSSING_M)
        c = (px >= near - CROSSING_M) & (px <= far + CROSSING_M)
        looked = False
        if a.sum() >= 10:  # at least 0.2 s of approach
            approach.append(float(on[a].mean()))
            looked = bool(on[a].any())
        if c.sum() >= 10 and looked:
            crossing.append(float(on[c].mean()))
    return nan_mean(approach), nan_mean(crossing)


def on_walkway(trace) -> np.ndarray:
    """(T,) rows whose gaze lands on an obstacle or on the walkway floor ``PATH_NEAR_M``-``PATH_FAR_M``
    ahead of the eye (within ``PATH_HALF_WIDTH_M`` of the centre line y = 0)."""
    obstacles, to_path = _frame(trace)
    eye, gaze = np.asarray(trace.eye_pos, dtype=float), np.asarray(trace.gaze_dir, dtype=float)
    ground = _gaze_hits(eye, gaze, 0.0)
    if to_path is None:
        ahead = ground[:, 0] - eye[:, 0]
    else:  # along the winding walkway's centre line
        ground = to_path(ground)
        ahead = ground[:, 0] - to_path(eye)[:, 0]
    with np.errstate(invalid="ignore"):
        out = (ahead >= PATH_NEAR_M) & (ahead <= PATH_FAR_M) & (np.abs(ground[:, 1]) <= PATH_HALF_WIDTH_M)
    for ob in obstacles:
        hits = _gaze_hits(eye, gaze, ob[4])
        out |= _on(hits if to_path is None else to_path(hits), ob, ON_OBSTACLE_M)
    return out


def path_fixation_share(trace, walkway: np.ndarray | None = None) -> float:
    """Share of the resting rows whose gaze is on the walkway ahead (:func:`on_walkway`, or ``walkway``
    when the caller has it)."""
    return strategy.fixation_share(trace, on_walkway(trace) if walkway is None else walkway)


def ground_fixation_share(trace, walkway: np.ndarray | None = None) -> float:
    """Share of the resting rows with gaze on the walkway ahead (:func:`on_walkway`, or ``walkway`` when the
    caller has it) whose floor point holds (moves slower than ``STABLE_GAZE_M_S`` since the previous row)."""
    eye, gaze = np.asarray(trace.eye_pos, dtype=float), np.asarray(trace.gaze_dir, dtype=float)
    holds = _holds(_gaze_hits(eye, gaze, 0.0), float(trace.dt))
    return strategy.fixation_share(trace, holds, rows=on_walkway(trace) if walkway is None else walkway)


def travel_fixation_distance(trace) -> float:
    obstacles, to_path = _frame(trace)
    eye, gaze = np.asarray(trace.eye_pos), np.asarray(trace.gaze_dir)
    ground = _gaze_hits(eye, gaze, 0.0)
    if to_path is None:
        free = np.isfinite(ground[:, 0]) & (ground[:, 0] > eye[:, 0])
    else:
        with np.errstate(invalid="ignore"):
            free = np.isfinite(ground[:, 0]) & (to_path(ground)[:, 0] > to_path(eye)[:, 0])
    for ob in obstacles:
        hits = _gaze_hits(eye, gaze, ob[4])
        free &= ~_on(hits if to_path is None else to_path(hits), ob, ON_OBSTACLE_M)
    if free.sum() < 10:
        return float("nan")
    return float(np.median(np.hypot(*(ground[free] - eye[free, :2]).T)))


def gaze_below_horizon(trace) -> float:
    gaze = np.asarray(trace.gaze_dir)
    return float(np.median(np.degrees(-np.arcsin(np.clip(gaze[:, 2], -1.0, 1.0)))))


def episode_measures(trace) -> dict[str, float]:
    share, crossing = obstacle_shares(trace)
    walkway = on_walkway(trace)  # once: on the winding walkway it maps every row into path coordinates
    return {
        "saccade_rate_hz": strategy.saccade_rate(trace),
        "fixation_duration_s": strategy.fixation_duration(trace),
        "obstacle_fixation_share": share,
        "fixation_while_crossing": crossing,
        "ground_fixation_share": ground_fixation_share(trace, walkway),
        "path_fixation_share": path_fixation_share(trace, walkway),
        "travel_fixation_distance_m": travel_fixation_distance(trace),
        "gaze_below_horizon_deg": gaze_below_horizon(trace),
    }


def walk_gaze_realism(traces: Sequence, reference: dict | None = None) -> dict:
    """``{"score", "components": {name: {"value", "score", "episodes"}}}`` like
    :func:`~visuomotor_gym.metrics.realism.gaze_realism`, for walking episodes (diverged ones left out)."""
    reference = WALK_REFERENCE if reference is None else reference
    rows = [episode_measures(tr) for tr in traces if not getattr(tr, "diverged", False)]
    return score_components(rows, reference)


def distance_left(tr) -> float:
    """How far from the goal an episode ended: the distance (m) left to the finish line (its ``miss_distance_m``)."""
    _, to_path = _frame(tr)
    end = np.asarray(tr.pelvis_pos)[-1:]
    along = float(end[0, 0]) if to_path is None else float(to_path(end)[0, 0])
    return max(float(tr.course_length) - along, 0.0)


def walk_summary(traces: Sequence) -> dict:
    """:func:`~visuomotor_gym.metrics.common.goal_summary` for walk-family traces: the same keys (``caught``
    and ``catch_rate`` count successes, equal to ``success_rate``), ``gaze_realism`` from
    :func:`walk_gaze_realism`; ``time_to_catch_s`` is the time to the finish line of the successful
    walks, ``miss_distance_m`` the distance left to the finish in the failed ones, ``hand_onset`` NaN
    (no hand). Diverged episodes are left out of the behavioural measures, as for catching."""
    return goal_summary(traces, walk_gaze_realism, distance_left)
