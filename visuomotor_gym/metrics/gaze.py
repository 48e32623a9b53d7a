"""Per-episode gaze measures on an :class:`~visuomotor_gym.bench.trace.EpisodeTrace`.

Conventions (see ``EpisodeTrace``): row ``k`` is the state after the k-th control step, ``t[k]`` its
time; the ball is released at ``t = 0``. A saccade flagged in ``saccade_onset[k]`` started at the
start of step ``k``, i.e. at ``t[k] - dt``. Every measure returns NaN when it is undefined for the
episode (e.g. no saccade at all), never raises on a well-formed trace.

The oculomotor plant already enforces the main sequence, the 800 deg/s and 100 deg/s limits and the
200 ms refractory period, so these measures look at *when* and *where* the agent moves its eyes and
head (the strategy), not at saccade kinematics.
"""

from __future__ import annotations

import numpy as np

from visuomotor_gym.geometry import angles_deg

FOVEA_DEG = 5.0  # "ball on the fovea": within 5 deg of the line of sight (our choice)
DEAD_ZONE_DEG = 20.0  # head dead zone, Eyecatch Sec. 4.2 Eq. 17 (0.349 rad) [Leigh & Zee 1999]
DEAD_ZONE_TOLERANCE_DEG = 5.0  # allowance above the dead zone before a row is non-compliant (our choice)


# --- geometry ------------------------------------------------------------------------------------
angle_deg = angles_deg  # row-wise angle (deg): visuomotor_gym.geometry.angles_deg


# --- saccade timing ------------------------------------------------------------------------------
def saccade_onset_times(trace) -> np.ndarray:
    """Onset times (s since release) of every saccade: ``t[k] - dt`` for each flagged row ``k``."""
    onset = np.asarray(trace.saccade_onset, dtype=bool)
    return np.asarray(trace.t, dtype=float)[onset] - float(trace.dt)


def first_saccade_latency(trace) -> float:
    """Time from the release (t = 0) to the first saccade onset (s); NaN without a saccade.

    Eyecatch Sec. 4.1: the initial saccade waits until the ball's position estimate is significant
    [Carpenter & Williams 1995], so a human-like first saccade is not immediate.
    """
    onsets = saccade_onset_times(trace)
    return float(onsets[0]) if onsets.size else float("nan")


def saccade_intervals(trace) -> np.ndarray:
    """Intervals (s) between consecutive saccade onsets over the whole episode (may be empty)."""
    return np.diff(saccade_onset_times(trace))


def ball_apex_time(trace) -> float:
    """Time (s) of the ball's highest point in the trace (for bounce throws too: the max of z)."""
    z = np.asarray(trace.ball_pos, dtype=float)[:, 2]
    if not np.isfinite(z).any():
        return float("nan")
    return float(np.asarray(trace.t, dtype=float)[int(np.nanargmax(z))])


CATCHUP_LANDING_DEG = 10.0  # a catch-up saccade lands with the ball within 10 deg of the line of sight
# (modelling choice: twice the 5 deg foveal window; the Eyecatch baseline lands 90 % of its saccades within
# 12 deg, a random eye 10 % within 22 deg)


def saccade_landing_rows(trace) -> np.ndarray:
    """For each saccade onset row ``k``, the first row ``j >= k`` with no saccade in flight at its end (the
    row where the saccade has landed; the last row when it is still flying at the episode's end)."""
    onsets = np.flatnonzero(np.asarray(trace.saccade_onset, dtype=bool))
    flying = np.asarray(trace.in_saccade, dtype=bool)
    out = []
    for k in onsets.tolist():
        j = k
        while j < flying.size - 1 and flying[j]:
            j += 1
        out.append(j)
    return np.asarray(out, dtype=int)


def ball_directed_onsets(trace, landing_deg: float = CATCHUP_LANDING_DEG) -> np.ndarray:
    """Onset times (s) of the saccades that landed on the ball: the ball within ``landing_deg`` of the line
    of sight at the landing row (:func:`saccade_landing_rows`)."""
    onsets = saccade_onset_times(trace)
    if onsets.size == 0:
        return onsets
    ecc = ball_eccentricity_deg(trace)[saccade_landing_rows(trace)]
    return onsets[np.nan_to_num(ecc, nan=np.inf) <= landing_deg]


def catchup_saccade_interval(trace) -> float:
    """Mean interval (s) between consecutive *ball-directed* saccade onsets during catch-up: intervals that
    start at or before the ball apex, between saccades that landed with the ball within
    ``CATCHUP_LANDING_DEG`` of the line of sight (:func:`ball_directed_onsets`). NaN with fewer than one
    such interval.

    Eyecatch Sec. 4.1 and Fig. 4: catch-up saccades come about every 200 ms before the apex, after which
    pursuit takes over (Fig. 3). Only saccades that land on the ball count: the plant refuses onsets closer
    than 200 ms, so an eye saccading at random reached the human interval for free when every saccade
    counted (realism version 1).
    """
    onsets = ball_directed_onsets(trace)
    apex = ball_apex_time(trace)
    if onsets.size < 2 or not np.isfinite(apex):
        return float("nan")
    intervals = np.diff(onsets)
    catchup = intervals[onsets[:-1] <= apex + 1e-9]
    return float(catchup.mean()) if catchup.size else float("nan")


# --- where the eye points ------------------------------------------------------------------------
def ball_eccentricity_deg(trace) -> np.ndarray:
    """Per-row angle (deg) between the line of sight and the direction from the eye to the ball centre."""
    to_ball = np.asarray(trace.ball_pos, dtype=float) - np.asarray(trace.eye_pos, dtype=float)
    return angle_deg(trace.gaze_dir, to_ball)


def _saccade_free(trace) -> np.ndarray:
    """Rows with no saccade in flight: none started in the step, none still running at its end."""
    return ~(np.asarray(trace.in_saccade, dtype=bool) | np.asarray(trace.saccade_onset, dtype=bool))


def pursuit_share_after_apex(trace, fovea_deg: float = FOVEA_DEG) -> float:
    """Fraction of the rows after the ball apex (to the catch or episode end) that are pursuit: no saccade
    in flight during the step and the ball within ``fovea_deg`` of the line of sight.

    Eyecatch Sec. 1, Fig. 3: smooth pursuit is "especially prominent after the ball has passed the apex".
    NaN when no row follows the apex.
    """
    apex = ball_apex_time(trace)
    t = np.asarray(trace.t, dtype=float)
    after = t > apex + 1e-9
    if not np.isfinite(apex) or not after.any():
        return float("nan")
    pursuing = _saccade_free(trace) & (ball_eccentricity_deg(trace) <= fovea_deg)
    return float(pursuing[after].mean())


FOVEATION_START_S = 0.25  # the human first saccade has landed: 180-200 ms saccade latency
# (../shared/REFERENCES.md: "saccade latency 180-200 ms") plus a ~30-50 ms main-sequence duration


def ball_foveation(trace, fovea_deg: float = FOVEA_DEG,
                   start_s: float = FOVEATION_START_S) -> float:
    """Fraction of rows from ``start_s`` (0.25 s after the release, the same for every agent) to the
    catch/end with the ball within ``fovea_deg`` of the line of sight; rows in a saccade count as not
    foveating when the ball is off-axis.

    The window is fixed, not tied to the agent's own first saccade: an agent whose first saccade comes
    late, or whose pursuit loses the ball, scores lower (counting from its own landing rewarded a late
    first saccade). 0.25 s is when a human's first saccade (180-200 ms latency) has landed. NaN when
    no row falls in the window. Eyecatch Sec. 1 ("keep your eyes on the ball"), Sec. 3.1 (acuity falls
    with eccentricity).
    """
    t = np.asarray(trace.t, dtype=float)
    window = t >= start_s - 1e-9
    if not window.any():
        return float("nan")
    return float((ball_eccentricity_deg(trace)[window] <= fovea_deg).mean())


# --- head ----------------------------------------------------------------------------------------
def eye_in_head_eccentricity_deg(trace) -> np.ndarray:
    """Per-row gaze-in-head eccentricity (deg): angle(line of sight, head forward axis)."""
    return angle_deg(trace.gaze_dir, trace.head_dir)


def head_contribution(
    trace, dead_zone_deg: float = DEAD_ZONE_DEG, tolerance_deg: float = DEAD_ZONE_TOLERANCE_DEG
) -> float:
    """Dead-zone compliance where the law asks the head to move.

    Eyecatch Sec. 4.2, Eq. 17-18: the head's saccade takes up the part of a gaze shift beyond a 20 deg
    dead zone, ``max(0, theta - 20 deg)`` [Leigh & Zee 1999], and the head pursues with the eye, so once
    the head has caught up (~400 ms head saccades) the line of sight stays within ~20 deg of the head's
    forward axis.

    Definition: the *demand rows* are those where the line of sight is more than ``dead_zone_deg +
    tolerance_deg`` (25 deg) from the head's forward axis after reset, i.e. where the law says the head
    must have turned. The value is the fraction of demand rows whose gaze-in-head eccentricity,
    ``angle(gaze_dir, head_dir)``, is at most 25 deg. An agent that leaves the head still while its eye
    follows the ball far off-axis (the eye pinned at its range limit) scores 0, one whose head takes up
    the excess scores 1. It does not penalise a head that does more than the law. NaN when there are no
    demand rows (the gaze never left the dead zone: the law asks nothing of the head). The 5 deg
    tolerance is our choice: the dead zone is a population summary, not a sharp limit.
    """
    limit = dead_zone_deg + tolerance_deg
    head0 = np.asarray(trace.head_dir, dtype=float)[0]
    demand = angle_deg(trace.gaze_dir, head0[None, :]) > limit
    if not demand.any():
        return float("nan")
    return float(np.mean(eye_in_head_eccentricity_deg(trace)[demand] <= limit))
