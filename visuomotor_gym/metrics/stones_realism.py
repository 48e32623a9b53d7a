"""Stepping-stone gaze realism (SteppingStones family): per-episode measures of when the eye moved, which
stone it looked at and when, scored against human data with
:func:`visuomotor_gym.metrics.realism.score_components` (each component 1 inside the human range with a
Gaussian fall-off outside, times the share of episodes that define it, 0 when none does; the score is the
smaller of the ``moves`` and ``where`` group means: see :mod:`visuomotor_gym.metrics.realism`).

Measures (from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace` of a SteppingStones env: ``eye_pos``,
``gaze_dir``, ``in_saccade``, ``saccade_onset``, ``next_stone`` per step; the course ``stones`` and
``stone_radius`` per episode):

``moves`` (:mod:`visuomotor_gym.metrics.strategy`): ``saccade_rate_hz`` (onsets per second) and
``fixation_duration_s`` (median saccade-free run between two saccades);

``where``:

* a step's *fixated stone* is the stone whose top the line of sight meets within ``stone_radius +
  ON_STONE_M`` of its centre (none otherwise);
* ``stone_fixation_share``: the share of the resting rows (no saccade in flight) with gaze on a stone
  not yet stepped on (index >= ``next_stone``): the footholds to come are the task's targets;
* ``fixation_steps_ahead`` (the look-ahead in steps): the median, over the steps with gaze on a stone
  after the first stone was landed on, of the fixated stone's index minus the index of the stone under
  the last landed foot (``next_stone - 1``): how many steps ahead of the stance foot the eye is;
* ``fixation_lead_s`` (the look-ahead in time): for each stone landed on, the time from the onset of
  its last fixation (a run of at least ``MIN_FIXATION_S``) before the landing to the landing (the heel
  strike: ``LANDING_LAG_S`` before ``next_stone`` moves on), the median over the episode's stones
  (robust to the first stones, which a walker starting on the slab may look at for longer).

Window sizes and tolerances are modelling choices (stated with each constant).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from visuomotor_gym.metrics import strategy
from visuomotor_gym.metrics.common import goal_summary
from visuomotor_gym.metrics.realism import score_components

ON_STONE_M = 0.05  # modelling choice: ~1-2 deg at 1.5-3 m, the accuracy of mobile eye trackers (~1 deg)
MIN_FIXATION_S = 0.1  # modelling choice: the usual minimum fixation duration of mobile eye-tracking analyses
# The env moves ``next_stone`` on when the landed foot is flat, at the end of double support (0.1 s after
# the heel strike: GaitParams.double_support_s).
LANDING_LAG_S = 0.1
STONE_PLANE_Z = -0.005  # tasks.stepping_stones.STONE_TOP_Z (the stones' tops)

STONES_REFERENCE: dict[str, dict] = {
    "saccade_rate_hz": strategy.SACCADE_RATE_REFERENCE,
    "fixation_duration_s": strategy.FIXATION_DURATION_REFERENCE,
    "stone_fixation_share": {
        "value": 0.7, "low": 0.4, "high": 1.0, "tolerance": 0.1, "unit": "fraction of the fixation time",
        "group": "where",
        "source": "Patla & Vickers 2003, Exp Brain Res 148:133: walkers stepping on footprints spent > 50 % of the "
                  "time in travel fixations and fixated the targets the rest of it; Bonnen et al. 2021, Exp "
                  "Brain Res: more fixations go to footholds as the terrain gets harder (REFERENCES.md [V]); "
                  "stepping stones with gaps between them are harder than footprints on a floor. No paper gives "
                  "the share for stepping stones: value, range and tolerance are our modelling choice (the 0.1 "
                  "tolerance makes a share of 0.2, what a line of sight held 40 deg down collects as the stones "
                  "pass under it, score exp(-2) = 0.14)",
        "notes": "Resting rows (no saccade in flight) with gaze on a stone not yet stepped on.",
    },
    "fixation_steps_ahead": {
        "value": 2.0, "low": 1.5, "high": 2.5, "tolerance": 0.5, "unit": "steps", "group": "where", "given": "stone_fixation_share",
        "source": "Patla & Vickers 2003, Exp Brain Res 148:133: stepping targets were fixated ~2 steps ahead "
                  "(REFERENCES.md [V]); the 1.5-2.5 range around it is our modelling choice",
        "notes": "Median over the steps with gaze on a stone, after the first stone was landed on.",
    },
    "fixation_lead_s": {
        "value": 0.9, "low": 0.8, "high": 1.0, "tolerance": 0.2, "unit": "s", "group": "where", "given": "stone_fixation_share",
        "source": "Patla & Vickers 2003: stepping targets fixated 0.8-1.0 s before the foot lands on them "
                  "(REFERENCES.md [V])",
        "notes": "Onset of the last fixation (>= 0.1 s) of a stone before its landing, to the heel strike; "
                 "median over the stones landed on, mean over episodes.",
    },
}


def fixated_stones(trace) -> np.ndarray:
    """(T,) index of the stone gaze is on at each step, -1 when on none."""
    eye, gaze = np.asarray(trace.eye_pos, dtype=float), np.asarray(trace.gaze_dir, dtype=float)
    stones = np.asarray(trace.stones, dtype=float).reshape(-1, 2)
    radius = float(trace.stone_radius)
    dz = gaze[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (STONE_PLANE_Z - eye[:, 2]) / dz
    s = np.where((dz < -1e-6) & (s > 0), s, np.nan)
    hit = eye[:, :2] + s[:, None] * gaze[:, :2]
    out = np.full(len(eye), -1, dtype=int)
    if len(stones) == 0:
        return out
    dist = np.linalg.norm(hit[:, None, :] - stones[None, :, :], axis=2)
    dist = np.where(np.isfinite(dist), dist, np.inf)
    best = np.argmin(dist, axis=1)
    on = dist[np.arange(len(eye)), best] <= radius + ON_STONE_M
    out[on] = best[on]
    return out


def steps_ahead(trace) -> float:
    fix = fixated_stones(trace)
    n = np.asarray(trace.next_stone, dtype=float)
    ok = (fix >= 0) & (n >= 1)
    if ok.sum() < 5:
        return float("nan")
    return float(np.median(fix[ok] - (n[ok] - 1)))


def fixation_lead(trace) -> float:
    fix = fixated_stones(trace)
    n = np.asarray(trace.next_stone, dtype=float)
    t = np.asarray(trace.t, dtype=float)
    dt = float(trace.dt)
    min_len = max(1, round(MIN_FIXATION_S / dt))
    leads = []
    for k in range(int(n.max()) if len(n) else 0):
        landed = np.flatnonzero(n > k)
        if len(landed) == 0:
            continue
        t_land = t[landed[0]] - LANDING_LAG_S
        on = (fix == k) & (t <= t_land)
        onset = None
        i = 0
        while i < len(on):  # runs of fixation on stone k before its landing; keep the last long one
            if on[i]:
                j = i
                while j < len(on) and on[j]:
                    j += 1
                if j - i >= min_len:
                    onset = t[i]
                i = j
            else:
                i += 1
        if onset is not None:
            leads.append(t_land - onset)
    return float(np.median(leads)) if leads else float("nan")


def stone_fixation_share(trace) -> float:
    """Share of the resting rows whose gaze is on a stone not yet stepped on (index >= ``next_stone``)."""
    fix = fixated_stones(trace)
    upcoming = (fix >= 0) & (fix >= np.asarray(trace.next_stone, dtype=float))
    return strategy.fixation_share(trace, upcoming)


def episode_measures(trace) -> dict[str, float]:
    return {"saccade_rate_hz": strategy.saccade_rate(trace), "fixation_duration_s": strategy.fixation_duration(trace),
            "stone_fixation_share": stone_fixation_share(trace),
            "fixation_steps_ahead": steps_ahead(trace), "fixation_lead_s": fixation_lead(trace)}


def stones_gaze_realism(traces: Sequence, reference: dict | None = None) -> dict:
    """``{"score", "components": {name: {"value", "score", "episodes"}}}`` for stepping-stone episodes."""
    reference = STONES_REFERENCE if reference is None else reference
    rows = [episode_measures(tr) for tr in traces if not getattr(tr, "diverged", False)]
    return score_components(rows, reference)


def distance_left(tr) -> float:
    """How far from the goal an episode ended: the stones left (count) (its ``miss_distance_m``)."""
    return float(len(np.asarray(tr.stones).reshape(-1, 2)) - np.asarray(tr.next_stone)[-1])


def stones_summary(traces: Sequence) -> dict:
    """:func:`~visuomotor_gym.metrics.common.goal_summary` for stones-family traces: the same keys (``caught``
    and ``catch_rate`` count successes), ``gaze_realism`` from :func:`stones_gaze_realism`;
    ``time_to_catch_s`` is the time to the last stone of the successful crossings, ``miss_distance_m``
    the number of stones left in the failed ones (a count, under the shared key), ``hand_onset`` NaN."""
    return goal_summary(traces, stones_gaze_realism, distance_left)
