"""Pedestrian-avoidance gaze realism (ObstacleDodge family): per-episode measures of when the eye moved
and where it looked, scored against human data with :func:`visuomotor_gym.metrics.realism.score_components`
(each component 1 inside the human range with a Gaussian fall-off outside, times the share of episodes
that define it, 0 when none does; the score is the smaller of the ``moves`` and ``where`` group means:
see :mod:`visuomotor_gym.metrics.realism`).

Measures (from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace` of an ObstacleDodge env: ``eye_pos``,
``gaze_dir``, ``in_saccade``, ``saccade_onset``, ``pedestrian_pos`` per step (parked before the onset);
the crowd ``pedestrians`` per episode):

``moves`` (:mod:`visuomotor_gym.metrics.strategy`): ``saccade_rate_hz`` (onsets per second) and
``fixation_duration_s`` (median saccade-free run between two saccades);

``where``:

* ``pedestrian_fixated_share``: the share of the pedestrians that were fixated at least once while they
  were ahead of the eye (a *fixation*: the line of sight within ``FIXATION_DEG`` of the pedestrian's seen
  point for at least ``FIXATION_MIN_S``), over the pedestrians that appeared at least ``MIN_PRESENT_S``
  before the episode ended;
* ``fixation_latency_s``: the time from a pedestrian's appearance to the start of its first fixation,
  the median over the episode's fixated pedestrians (undefined, scoring 0, when none was fixated).

Thresholds are modelling choices (stated with each constant).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from visuomotor_gym.metrics import strategy
from visuomotor_gym.metrics.common import goal_summary
from visuomotor_gym.metrics.realism import score_components

# Modelling choice: a pedestrian's upper body (~0.5 m wide) subtends ~6-10 deg at 3-5 m; gaze within
# 4 deg of its axis point is on it (eye-tracker accuracy in the VR studies ~1 deg).
FIXATION_DEG = 4.0
FIXATION_MIN_S = 0.1  # modelling choice: the shortest fixation counted (~100 ms, a common eye-tracking floor)
MIN_PRESENT_S = 1.0  # modelling choice: pedestrians that appeared this long before the end are counted

DODGE_REFERENCE: dict[str, dict] = {
    "saccade_rate_hz": strategy.SACCADE_RATE_REFERENCE,
    "fixation_duration_s": strategy.FIXATION_DURATION_REFERENCE,
    "pedestrian_fixated_share": {
        "value": 0.73, "low": 0.59, "high": 0.85, "tolerance": 0.15, "unit": "fraction of the pedestrians",
        "group": "where",
        "source": "Jovancevic, Sullivan & Hayhoe (J Vis 4(8), abstract; REFERENCES.md [V]): pedestrians not on a "
                  "collision course were fixated 73 % of the time, veering ones 59 % (unfixated 41 %); the range "
                  "spans the two, its upper end is our modelling choice",
        "notes": "Share over the pedestrians that appeared >= 1 s before the episode ended.",
    },
    "fixation_latency_s": {
        "value": 0.74, "low": 0.548, "high": 0.74, "tolerance": 0.3, "unit": "s", "group": "where", "given": "pedestrian_fixated_share",
        "source": "Jovancevic, Sullivan & Hayhoe (REFERENCES.md [V]): first fixation 740 ms after a pedestrian "
                  "appeared, 548 ms for one veering onto a collision course",
        "notes": "Per episode the median over the fixated pedestrians, from appearance to the start of the first "
                 "fixation; mean over the episodes that fixated one.",
    },
}


def first_fixations(trace) -> list[int | None]:
    """Per pedestrian of the episode's crowd, the step at which its first fixation starts (the line of sight within
    ``FIXATION_DEG`` of its seen point for at least ``FIXATION_MIN_S`` while it is ahead of the eye, after its
    onset), None when it was never fixated."""
    t = np.asarray(trace.t, dtype=float)
    eye, gaze = np.asarray(trace.eye_pos, dtype=float), np.asarray(trace.gaze_dir, dtype=float)
    ped = np.asarray(trace.pedestrian_pos, dtype=float)  # (T, N, 3), NaN before onset
    crowd = np.asarray(trace.pedestrians, dtype=float).reshape(-1, 9)
    need = max(int(round(FIXATION_MIN_S / float(trace.dt))), 1)
    cos_fix = math.cos(math.radians(FIXATION_DEG))
    starts: list[int | None] = []
    for i in range(crowd.shape[0]):
        d = ped[:, i, :] - eye
        n = np.linalg.norm(d, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            cos = np.einsum("ij,ij->i", d, gaze) / n
        on = np.nan_to_num(cos, nan=-1.0) >= cos_fix
        on &= np.nan_to_num(d[:, 0], nan=-1.0) > 0.0  # ahead of the eye
        on &= t >= crowd[i, 0] - 1e-9  # parked before its onset
        starts.append(first_run(on, need))
    return starts


def first_run(on, need: int) -> int | None:
    """The first step of the first run of at least ``need`` consecutive true values of ``on``, None without one."""
    run = 0
    for k, flag in enumerate(np.asarray(on, dtype=bool).tolist()):
        run = run + 1 if flag else 0
        if run >= need:
            return k - need + 1
    return None


def pedestrian_fixations(trace) -> tuple[float, list[float]]:
    """(share of the counted pedestrians fixated, latencies of the fixated ones) for one episode: the pedestrians
    that appeared at least ``MIN_PRESENT_S`` before the end, fixated as :func:`first_fixations` has it."""
    t = np.asarray(trace.t, dtype=float)
    crowd = np.asarray(trace.pedestrians, dtype=float).reshape(-1, 9)
    counted, fixated, latencies = 0, 0, []
    for onset, start in zip(crowd[:, 0].tolist(), first_fixations(trace)):
        if t[-1] - onset < MIN_PRESENT_S:
            continue
        counted += 1
        if start is not None:
            fixated += 1
            latencies.append(float(t[start] - onset))
    return (fixated / counted if counted else float("nan")), latencies


def episode_measures(trace) -> dict[str, float]:
    share, latencies = pedestrian_fixations(trace)
    return {"saccade_rate_hz": strategy.saccade_rate(trace), "fixation_duration_s": strategy.fixation_duration(trace),
            "pedestrian_fixated_share": share,
            "fixation_latency_s": float(np.median(latencies)) if latencies else float("nan")}


def dodge_gaze_realism(traces: Sequence, reference: dict | None = None) -> dict:
    """``{"score", "components": {name: {"value", "score", "episodes"}}}`` for dodge episodes."""
    reference = DODGE_REFERENCE if reference is None else reference
    rows = [episode_measures(tr) for tr in traces if not getattr(tr, "diverged", False)]
    return score_components(rows, reference)


def distance_left(tr) -> float:
    """How far from the goal an episode ended: the distance (m) left to the goal (its ``miss_distance_m``)."""
    return max(float(tr.goal_distance) - float(np.asarray(tr.pelvis_pos)[-1, 0]), 0.0)


def dodge_summary(traces: Sequence) -> dict:
    """:func:`~visuomotor_gym.metrics.common.goal_summary` for dodge traces: the same keys (``caught`` counts
    successes), ``gaze_realism`` from :func:`dodge_gaze_realism`; ``time_to_catch_s`` is the time to the
    goal of the successful walks, ``miss_distance_m`` the distance left to the goal in the failed ones."""
    return goal_summary(traces, dodge_gaze_realism, distance_left)
