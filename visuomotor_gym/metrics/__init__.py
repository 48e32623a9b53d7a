"""Benchmark metrics computed from episode traces (success with a Wilson interval, gaze realism against a sourced human table, latency, outcome measures).

Everything here is pure numpy on :class:`visuomotor_gym.bench.trace.EpisodeTrace` objects (any object
with the same attributes works), so the evaluator, plots and tests share one definition of each number.

* :func:`summarize` -- every benchmark number for a set of episodes, JSON-ready;
* :func:`wilson_interval` -- the catch rate's confidence interval;
* :func:`gaze_realism`, :func:`score_component`, :func:`load_reference` -- the realism score against the
  human reference table ``human_reference.json`` (value, range, unit, source and group per component);
  :func:`score_components` -- the rule every family's realism follows (an undefined component scores 0,
  the score is the weakest group's mean); :mod:`~visuomotor_gym.metrics.strategy` -- the moving-eye
  measures (saccade rate, fixation durations, share of fixation time on targets);
* per-episode measures (NaN when undefined): :func:`first_saccade_latency`, :func:`saccade_intervals`,
  :func:`catchup_saccade_interval`, :func:`ball_apex_time`, :func:`pursuit_share_after_apex`,
  :func:`ball_foveation`, :func:`head_contribution`, :func:`hand_submovement_onsets`,
  :func:`saccade_hand_synchrony`, :func:`hand_peak_speed`, :func:`reaction_times`, :func:`miss_distance`;
* :func:`latency_summary` -- policy compute time per step (ms).
"""

from visuomotor_gym.metrics.gaze import (
    ball_apex_time,
    ball_eccentricity_deg,
    ball_foveation,
    catchup_saccade_interval,
    eye_in_head_eccentricity_deg,
    first_saccade_latency,
    head_contribution,
    pursuit_share_after_apex,
    saccade_intervals,
    saccade_onset_times,
)
from visuomotor_gym.metrics.hand import (
    hand_onset_time,
    hand_peak_speed,
    hand_speed,
    hand_submovement_onsets,
    saccade_hand_synchrony,
)
from visuomotor_gym.metrics.outcome import miss_distance, reaction_times, time_to_catch
from visuomotor_gym.metrics.realism import (
    COMPONENT_MEASURES,
    component_values,
    gaze_realism,
    load_reference,
    score_component,
    score_components,
)
from visuomotor_gym.metrics.stats import wilson_interval
from visuomotor_gym.metrics.summary import latency_summary, summarize, to_json_safe

__all__ = [
    "COMPONENT_MEASURES",
    "ball_apex_time",
    "ball_eccentricity_deg",
    "ball_foveation",
    "catchup_saccade_interval",
    "component_values",
    "eye_in_head_eccentricity_deg",
    "first_saccade_latency",
    "gaze_realism",
    "hand_onset_time",
    "hand_peak_speed",
    "hand_speed",
    "hand_submovement_onsets",
    "head_contribution",
    "latency_summary",
    "load_reference",
    "miss_distance",
    "pursuit_share_after_apex",
    "reaction_times",
    "saccade_hand_synchrony",
    "saccade_intervals",
    "saccade_onset_times",
    "score_component",
    "score_components",
    "summarize",
    "time_to_catch",
    "to_json_safe",
    "wilson_interval",
]
