"""One JSON-ready summary of a set of episodes: what the evaluator writes for an (agent, env) pair."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from visuomotor_gym.metrics.outcome import miss_distance, reaction_times, time_to_catch
from visuomotor_gym.metrics.realism import gaze_realism
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


def _family(trace) -> str | None:
    """The registered family of a trace's env id (None when unknown or absent)."""
    from visuomotor_gym.registration import family_of

    try:
        return family_of(str(getattr(trace, "env_id", "")))
    except ValueError:
        return None


def summarize(traces: Sequence) -> dict:
    """Every benchmark number for a set of episodes, as plain JSON-serialisable Python (None = undefined).

    Keys:

    * ``episodes``, ``caught`` (count), ``catch_rate``, ``catch_rate_ci95`` ([low, high], Wilson 95 %),
      ``diverged`` (count; physics divergences count as not caught);
    * ``success_rate``, ``success_rate_ci95``: the family-neutral rate of episodes that met the task's
      goal (:func:`episode_success`; for catching it is the catch rate) with its Wilson 95 % interval,
      so a leaderboard can rank tasks that do not catch anything;
    * ``gaze_realism``: ``{"score", "components": {name: {"value", "score", "episodes"}}}``
      (:func:`~visuomotor_gym.metrics.realism.gaze_realism`);
    * ``latency_ms``: ``{"p50", "p95", "max"}`` policy compute time per step;
    * ``reaction_times_s``: ``{"first_saccade": {"mean", "median"}, "hand_onset": {"mean", "median"}}``;
    * ``miss_distance_m``: ``{"mean", "median"}`` closest ball-to-catch-site distance over the episodes
      that were not caught (diverged ones excluded);
    * ``time_to_catch_s``: ``{"mean", "median"}`` over caught episodes;
    * ``hand_path`` (single-ball catch ids only): the hand's transport to the interception point against
      Faraway's reach model, ``{"score", "verdict", "episodes", "components"}``
      (:func:`~visuomotor_gym.metrics.catch_handpath.catch_hand_path`), reported beside ``gaze_realism``
      and not part of its score.

    Diverged episodes end on a physics reset, so their last state is not the agent's doing: they are
    left out of the behavioural measures (realism, reaction times, miss distance) but count in the
    catch rate and latency.
    """
    traces = list(traces)
    family = _family(traces[0]) if traces else None
    if family in _FAMILY_SUMMARIES:  # a family with its own realism table and outcome measures
        return to_json_safe(_FAMILY_SUMMARIES[family](traces))
    n = len(traces)
    caught = sum(bool(tr.caught) for tr in traces)
    diverged = sum(bool(tr.diverged) for tr in traces)
    valid = [tr for tr in traces if not tr.diverged]
    failed = [tr for tr in valid if not tr.caught]
    rts = [reaction_times(tr) for tr in valid]
    low, high = wilson_interval(caught, n)
    succeeded = sum(episode_success(tr) for tr in traces)
    s_low, s_high = wilson_interval(succeeded, n)
    out = {
        "episodes": n,
        "caught": caught,
        "catch_rate": caught / n if n else float("nan"),
        "catch_rate_ci95": [low, high],
        "success_rate": succeeded / n if n else float("nan"),
        "success_rate_ci95": [s_low, s_high],
        "diverged": diverged,
        "gaze_realism": gaze_realism(valid),
        "latency_ms": latency_summary(traces),
        "reaction_times_s": {
            "first_saccade": mean_median([r["first_saccade_s"] for r in rts]),
            "hand_onset": mean_median([r["hand_onset_s"] for r in rts]),
        },
        "miss_distance_m": mean_median([miss_distance(tr) for tr in failed]),
        "time_to_catch_s": mean_median([time_to_catch(tr) for tr in valid if tr.caught]),
    }
    if family == "catch":  # beside gaze_realism, not in its score (metrics.catch_handpath)
        from visuomotor_gym.metrics.catch_handpath import catch_hand_path, measures_hand_path

        if measures_hand_path(traces[0]):
            out["hand_path"] = catch_hand_path(valid)
    return to_json_safe(out)


def goal_summary(traces: Sequence, realism, distance_left) -> dict:
    """:func:`summarize` for a family whose goal is not a catch (walk, stones, dodge): the same keys,
    ``caught`` and ``catch_rate`` counting successes; ``gaze_realism`` from the family's ``realism(valid
    traces)``; ``time_to_catch_s`` the time to the goal of the successful episodes and
    ``miss_distance_m`` ``distance_left(trace)`` of the failed ones (diverged episodes left out of the
    behavioural measures, as for catching)."""
    from visuomotor_gym.metrics.gaze import first_saccade_latency

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


def _family_summary(module: str, function: str):
    def run(traces):
        import importlib

        return getattr(importlib.import_module(f"visuomotor_gym.metrics.{module}"), function)(traces)

    return run


# Each non-catch family's miss distance of one failed episode (the catch family's is metrics.outcome's).
_FAMILY_MISS_DISTANCE = {
    "reach": _family_summary("reach_realism", "closest_distance"),
    "walk": _family_summary("walk_realism", "distance_left"),
    "stones": _family_summary("stones_realism", "distance_left"),
    "dodge": _family_summary("dodge_realism", "distance_left"),
}


def episode_miss_distance(trace) -> float:
    """The miss distance of one episode in its family's terms: the ball's closest approach to the catch
    site, the hand's closest approach to the object, or the distance (stones) left to the goal. (The
    summaries average it over the failed episodes only.)"""
    family = _family(trace)
    if family in _FAMILY_MISS_DISTANCE:
        return float(_FAMILY_MISS_DISTANCE[family](trace))
    return float(miss_distance(trace))


# The families with their own summary (realism table and outcome measures); catch is summarize() itself.
_FAMILY_SUMMARIES = {
    "reach": _family_summary("reach_realism", "reach_summary"),
    "walk": _family_summary("walk_realism", "walk_summary"),
    "stones": _family_summary("stones_realism", "stones_summary"),
    "dodge": _family_summary("dodge_realism", "dodge_summary"),
}
