"""The scaffolding every family's summary is built from: latency, JSON safety, success, the goal summary.

A leaf of the metrics: it imports no family's module (no ``*_realism``, no registration), so each
family's summariser imports it and the dispatcher (:mod:`visuomotor_gym.metrics.summary`) imports the
families, with no cycle between them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from visuomotor_gym.metrics.gaze import first_saccade_latency
from visuomotor_gym.metrics.stats import mean_median, wilson_interval


def latency_summary(traces: Sequence) -> dict[str, float]:
    """Policy compute time per step over all steps of all episodes, in milliseconds: ``{"p50", "p95",
    "max"}`` (NaN when no step was timed). Real time at 50 Hz needs p95 below the 20 ms control period."""
    parts = [np.asarray(tr.latency_s, dtype=float).ravel() for tr in traces]
    lat = np.concatenate(parts) if parts else np.zeros(0)
    lat = lat[np.isfinite(lat)] * 1e3
    if lat.size == 0:
        return {"p50": float("nan"), "p95": float("nan"), "max": float("nan")}
    p50, p95 = np.percentile(lat, [50.0, 95.0])
    return {"p50": float(p50), "p95": float(p95), "max": float(lat.max())}


def to_json_safe(obj):
    """Plain Python for ``json.dumps(..., allow_nan=False)``: NaN/inf -> None, numpy -> float/int/list."""
    if isinstance(obj, Mapping):
        return {str(k): to_json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [to_json_safe(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


def episode_success(trace) -> bool:
    """Whether an episode met its task's goal, for any task family.

    An :class:`~visuomotor_gym.bench.trace.EpisodeTrace` carries ``success`` (``info["is_success"]``;
    for catching, every ball caught), so for the catch family ``success_rate == catch_rate``; a
    trace-like object without it succeeds when ``caught``.
    """
    success = getattr(trace, "success", None)
    return bool(trace.caught if success is None else success)


def goal_summary(traces: Sequence, realism: Callable[[Sequence], dict],
                 distance_left: Callable[[object], float]) -> dict:
    """The summary of a family whose goal is not a catch (reach, walk, stones, dodge): the keys of the
    catch summary, ``caught`` and ``catch_rate`` counting successes; ``gaze_realism`` from the family's
    ``realism(valid traces)``; ``time_to_catch_s`` the time to the goal of the successful episodes and
    ``miss_distance_m`` ``distance_left(trace)`` of the failed ones (diverged episodes left out of the
    behavioural measures, as for catching); ``reaction_times_s["hand_onset"]`` undefined (a family with
    a hand sets it)."""
    traces = list(traces)
    n = len(traces)
    succeeded = sum(bool(tr.success) for tr in traces)
    valid = [tr for tr in traces if not tr.diverged]
    low, high = wilson_interval(succeeded, n)
    return {
        "episodes": n,
        "caught": succeeded,
        "catch_rate": succeeded / n if n else float("nan"),
        "catch_rate_ci95": [low, high],
        "success": succeeded,
        "success_rate": succeeded / n if n else float("nan"),
        "success_rate_ci95": [low, high],
        "diverged": sum(bool(tr.diverged) for tr in traces),
        "gaze_realism": realism(valid),
        "latency_ms": latency_summary(traces),
        "reaction_times_s": {
            "first_saccade": mean_median([first_saccade_latency(tr) for tr in valid]),
            "hand_onset": mean_median([float("nan")]),
        },
        "miss_distance_m": mean_median([distance_left(tr) for tr in valid if not tr.success]),
        "time_to_catch_s": mean_median([float(tr.t[-1]) for tr in valid if tr.success]),
    }
