"""Per-episode hand measures: tangential speed, submovement onsets, eye-hand synchrony, peak speed.

The hand is the catch site (``EpisodeTrace.hand_pos``). Its speed is taken per control step,
``v_k = |hand_pos[k] - hand_pos[k-1]| / dt`` for the interval ``(t[k-1], t[k]]``; no agent internals are
used, so every agent is measured the same way.
"""

from __future__ import annotations

import numpy as np

from visuomotor_gym.metrics.gaze import saccade_onset_times

SUBMOVEMENT_MIN_RISE_M_S = 0.05  # a speed minimum counts as an onset only if the speed then rises this much
SYNC_WINDOW_S = 0.06  # hand onset "with" a saccade: within +-60 ms of its onset (our choice)
HAND_ONSET_SPEED_M_S = 0.1  # behavioural hand reaction: first step faster than this


def hand_speed(trace) -> np.ndarray:
    """Hand tangential speed per step (m/s); entry ``i`` covers ``(t[i], t[i+1]]`` (length ``T - 1``)."""
    p = np.asarray(trace.hand_pos, dtype=float)
    return np.linalg.norm(np.diff(p, axis=0), axis=1) / float(trace.dt)


def _submovement_onset_indices(speed: np.ndarray, min_rise: float) -> np.ndarray:
    """Indices of speed local minima followed by a rise of at least ``min_rise`` before the next minimum."""
    v = np.where(np.isfinite(speed), speed, np.nan)
    n = v.size
    if n < 2:
        return np.zeros(0, dtype=int)
    # local minimum: not above the previous sample (the left edge counts) and strictly below the next
    left = np.r_[True, v[1:-1] <= v[:-2]] if n > 2 else np.array([True])
    is_min = np.zeros(n, dtype=bool)
    is_min[: n - 1] = left[: n - 1] & (v[:-1] < v[1:])
    minima = np.flatnonzero(is_min)
    onsets = []
    for j, i in enumerate(minima):
        stop = minima[j + 1] if j + 1 < minima.size else n
        peak = np.nanmax(v[i + 1 : stop + 1]) if stop > i else np.nan
        if np.isfinite(peak) and peak - v[i] >= min_rise:
            onsets.append(i)
    return np.asarray(onsets, dtype=int)


def hand_submovement_onsets(trace, min_rise_m_s: float = SUBMOVEMENT_MIN_RISE_M_S) -> np.ndarray:
    """Onset times (s) of hand submovements, detected from the tangential speed alone.

    A submovement (Eyecatch Sec. 4, Eq. 15-16: superposed minimum-jerk speed bells) shows up as a local
    minimum of the hand speed followed by acceleration. Minima whose following rise is below
    ``min_rise_m_s`` (0.05 m/s: tremor, servo ripple, a hand at rest) are ignored. The onset time is the
    end of the minimum-speed step, ``t[i+1]``, i.e. the instant the speed starts to rise (exact to one
    control step for a submovement starting from rest).

    Exact (to one step) for submovements that do not overlap in time. When a submovement starts before
    the previous one has ended, the speed minimum lies between the new onset and the end of the previous
    submovement, so the onset is reported late by up to the overlap; heavily blended ones (e.g. Eyecatch's
    ~400 ms submovements every 200 ms, Sec. 4.3) may show no minimum at all and merge. Separating those
    needs a least-squares decomposition (Eyecatch Sec. 4, Fig. 6; Rohrer & Hogan 2003), which is not
    unique.
    """
    idx = _submovement_onset_indices(hand_speed(trace), float(min_rise_m_s))
    return np.asarray(trace.t, dtype=float)[idx + 1]


def saccade_hand_synchrony(trace, window_s: float = SYNC_WINDOW_S) -> float:
    """Fraction of hand submovement onsets within ``window_s`` (+-60 ms) of some saccade onset.

    Eyecatch Sec. 1 and Fig. 4: hand submovement start times are "well synchronized" with catch-up
    saccades. NaN without any hand submovement; 0 when there are submovements but no saccades.
    Chance level is not 0: with saccades every 200 ms a +-60 ms window covers 60 % of the time.
    """
    hand = hand_submovement_onsets(trace)
    if hand.size == 0:
        return float("nan")
    sacc = saccade_onset_times(trace)
    if sacc.size == 0:
        return 0.0
    nearest = np.min(np.abs(hand[:, None] - sacc[None, :]), axis=1)
    return float(np.mean(nearest <= window_s + 1e-9))


def hand_peak_speed(trace) -> float:
    """Largest hand tangential speed over the episode (m/s); Eyecatch Sec. 4.3: humans stay <= 2 m/s."""
    v = hand_speed(trace)
    v = v[np.isfinite(v)]
    return float(v.max()) if v.size else float("nan")


def hand_onset_time(trace, threshold_m_s: float = HAND_ONSET_SPEED_M_S) -> float:
    """Hand reaction time: end ``t[i+1]`` of the first step faster than ``threshold_m_s`` (NaN if never)."""
    fast = np.flatnonzero(hand_speed(trace) > threshold_m_s)
    return float(np.asarray(trace.t, dtype=float)[fast[0] + 1]) if fast.size else float("nan")
