"""The catch family's summary of a set of episodes (its :class:`~visuomotor_gym.family.Family` summariser)."""

from __future__ import annotations

from collections.abc import Sequence

from visuomotor_gym.metrics.catch_handpath import catch_hand_path, measures_hand_path
from visuomotor_gym.metrics.common import episode_success, latency_summary
from visuomotor_gym.metrics.outcome import miss_distance, reaction_times, time_to_catch
from visuomotor_gym.metrics.realism import gaze_realism
from visuomotor_gym.metrics.stats import mean_median, wilson_interval


def catch_summary(traces: Sequence) -> dict:
    """Every benchmark number for a set of catch episodes (keys: :func:`visuomotor_gym.metrics.summarize`).

    Diverged episodes end on a physics reset, so their last state is not the agent's doing: they are
    left out of the behavioural measures (realism, reaction times, miss distance) but count in the
    catch rate and latency. ``hand_path`` (single-ball ids only) is reported beside ``gaze_realism``,
    not in its score (:mod:`visuomotor_gym.metrics.catch_handpath`).
    """
    traces = list(traces)
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
        "success": succeeded,
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
    if traces and measures_hand_path(traces[0]):  # beside gaze_realism, not in its score
        out["hand_path"] = catch_hand_path(valid)
    return out
