"""One JSON-ready summary of a set of episodes: what the evaluator writes for an (agent, env) pair.

The dispatcher: each family's record (:class:`visuomotor_gym.family.Family`) names its summariser and
its miss distance; the shared scaffolding lives in the leaf :mod:`visuomotor_gym.metrics.common`
(re-exported here), which no family module's import reaches back from.
"""

from __future__ import annotations

from collections.abc import Sequence

from visuomotor_gym.families import default_family, family_for
from visuomotor_gym.family import Family
from visuomotor_gym.metrics.common import (  # noqa: F401 (re-exported: the names' old home)
    episode_success,
    goal_summary,
    latency_summary,
    to_json_safe,
)


def _record(trace) -> Family:
    """The family record of a trace's env id; the default family's (catch) for an id this version
    does not register (an old results file), as before the records."""
    try:
        return family_for(str(getattr(trace, "env_id", "")))
    except ValueError:
        return default_family()


def summarize(traces: Sequence) -> dict:
    """Every benchmark number for a set of episodes, as plain JSON-serialisable Python (None = undefined),
    from the summariser of the episodes' family (the first trace's env id).

    Keys (every family):

    * ``episodes``, ``diverged`` (count; physics divergences count as failures);
    * ``success`` (count), ``success_rate``, ``success_rate_ci95``: the family-neutral count and rate
      of episodes that met the task's goal (:func:`episode_success`; for catching, every ball caught)
      with its Wilson 95 % interval, so a leaderboard can rank tasks that do not catch anything;
    * ``caught`` (count), ``catch_rate``, ``catch_rate_ci95`` ([low, high], Wilson 95 %): the catches;
      on every other family the same successes again -- deprecated aliases of ``success`` and
      ``success_rate``, kept so older results files and their readers still work;
    * ``gaze_realism``: ``{"score", "components": {name: {"value", "score", "episodes"}}}`` against the
      family's human reference table;
    * ``latency_ms``: ``{"p50", "p95", "max"}`` policy compute time per step;
    * ``reaction_times_s``: ``{"first_saccade": {"mean", "median"}, "hand_onset": {"mean", "median"}}``;
    * ``miss_distance_m``: ``{"mean", "median"}`` of the family's miss distance
      (:func:`episode_miss_distance`) over the failed episodes (diverged ones excluded);
    * ``time_to_catch_s``: ``{"mean", "median"}`` time to success over the successful episodes;
    * ``hand_path`` (single-ball catch ids only): the hand's transport to the interception point against
      Faraway's reach model (:func:`~visuomotor_gym.metrics.catch_handpath.catch_hand_path`), reported
      beside ``gaze_realism`` and not part of its score.

    Diverged episodes end on a physics reset, so their last state is not the agent's doing: they are
    left out of the behavioural measures (realism, reaction times, miss distance) but count in the
    success rate and latency.
    """
    traces = list(traces)
    record = _record(traces[0]) if traces else default_family()
    return to_json_safe(record.summarise(traces))


def episode_miss_distance(trace) -> float:
    """The miss distance of one episode in its family's terms: the ball's closest approach to the catch
    site, the hand's closest approach to the object, or the distance (stones) left to the goal. (The
    summaries average it over the failed episodes only.)"""
    return _record(trace).episode_miss_distance(trace)
