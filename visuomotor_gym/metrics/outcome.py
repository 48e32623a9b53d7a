"""Per-episode behavioural outcomes: reaction times, miss distance, time to catch."""

from __future__ import annotations

import numpy as np

from visuomotor_gym.metrics.gaze import first_saccade_latency
from visuomotor_gym.metrics.hand import hand_onset_time


def reaction_times(trace) -> dict[str, float]:
    """Behavioural reaction times (s since release): ``first_saccade_s`` (first saccade onset) and
    ``hand_onset_s`` (first step with hand speed > 0.1 m/s). NaN where the event never happens."""
    return {"first_saccade_s": first_saccade_latency(trace), "hand_onset_s": hand_onset_time(trace)}


def miss_distance(trace) -> float:
    """Closest approach (m) of the ball centre to the catch site over the episode (sampled per step)."""
    gap = np.asarray(trace.ball_pos, dtype=float) - np.asarray(trace.hand_pos, dtype=float)
    d = np.linalg.norm(gap, axis=1)
    d = d[np.isfinite(d)]
    return float(d.min()) if d.size else float("nan")


def time_to_catch(trace) -> float:
    """Time of the catch (s since release), NaN if not caught."""
    return float(trace.t[-1]) if trace.caught else float("nan")
