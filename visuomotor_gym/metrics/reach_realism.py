"""Hand-path realism of the reach family: a recorded reach against Faraway, Reed & Wang's (2007)
model and the eye-hand timing of human reaching, scored against a sourced human table.

Per episode (:func:`reach_measures`), from the trace only (``hand_pos`` per step, the task's ``object_pos``,
the gaze): the reach is the hand path from its movement onset (first step faster than 0.1 m/s, as
:func:`visuomotor_gym.metrics.hand.hand_onset_time`) to the end of the episode (the success step) or, when
not reached, to the closest approach to the object; then :func:`visuomotor_gym.handpath.hand_path_realism`
gives the distance to Faraway's predicted path (scaled to the paper's 56.7 cm median reach), the curvature
index (0 = straight, 1 = Faraway's mean curvature), peak speed and its relative time; the gaze-hand lead
is the hand's arrival minus the first time gaze comes within ``GAZE_ON_OBJECT_DEG`` of the object, the
object fixation share is the share of the saccade-free rows from then to the hand's arrival with gaze
still on the object, the hand latency is the hand's onset minus the first saccade's onset, and the first
saccade latency is that onset's time.

Per set of episodes (:func:`reach_realism`): each component is the **median** over the episodes that
define it (the reproduction page shows that only medians over many reaches separate straight from
human-like paths: ``docs/reproductions/faraway.md``), scored with
:func:`visuomotor_gym.metrics.realism.score_components` against :data:`REACH_REFERENCE`: times the share
of the episodes that define it (0 when none does), and the score is the smallest of the three group means
(``moves``: the first saccade's latency and the hand's lag behind it; ``where``: gaze on the object
before and during the reach; ``hand``: the path). Before realism version 2 the score was the mean of the
defined components, so an eye that never moved kept the four hand-path points and scored 0.97. The result has
the shape of ``gaze_realism`` (``{"score", "components"}``), so the evaluator's results schema holds it
unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from visuomotor_gym import handpath
from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.metrics import strategy
from visuomotor_gym.metrics.common import goal_summary
from visuomotor_gym.metrics.hand import hand_onset_time
from visuomotor_gym.metrics.realism import score_components
from visuomotor_gym.metrics.stats import mean_median

GAZE_ON_OBJECT_DEG = 5.0  # "on the object": within 5 deg of the line of sight (as metrics.gaze.FOVEA_DEG, our choice)
HAND_ONSET_SPEED_M_S = 0.1  # as metrics.hand.HAND_ONSET_SPEED_M_S
MIN_REACH_M = 0.05  # shorter hand movements are not reaches (modelling choice)

#: The human reference of the reach family: value, accepted range, tolerance (score 0.61 one tolerance
#: outside the range), unit, source. Sources are REFERENCES.md (Reaching) and the reproduction page.
REACH_REFERENCE: dict[str, dict] = {
    "faraway_distance_cm": {
        "value": 6.4, "low": 0.0, "high": 8.0, "tolerance": 2.0, "unit": "cm", "group": "hand",
        "source": "Faraway et al. (2007), Table 2: the chosen model's median maximum error against human "
                  "reaches is 8.0 cm (Flash-Hogan 12.6 cm); 6.4 cm is the median of synthetic human-like "
                  "reaches (docs/reproductions/faraway.md). Range [0, 8.0] and tolerance: our choice.",
        "notes": "Median over reaches of the max distance to faraway_path at equal relative arc length, scaled "
                 "to a 56.7 cm reach. A straight reach also scores ~6 cm: this component alone cannot tell "
                 "straight from human-like (see curvature_index).",
    },
    "curvature_index": {
        "value": 0.92, "low": 0.48, "high": 1.40, "tolerance": 0.4, "unit": "-", "group": "hand",
        "source": "Median and interquartile range of synthetic human-like reaches generated from Faraway "
                  "et al.'s model with its within/between-subject variation (docs/reproductions/faraway.md); "
                  "straight reaches give 0. Tolerance: our choice.",
        "notes": "Median over reaches of handpath.HandPathRealism.curvature_index.",
    },
    "hand_peak_speed_m_s": {
        "value": 1.4, "low": 0.5, "high": 2.0, "tolerance": 0.5, "unit": "m/s", "group": "hand",
        "source": "Upper bound: Eyecatch sec. 4.3 (human hand speed below ~2 m/s). Lower bound 0.5 m/s: our "
                  "choice (a 57 cm reach of ~1 s with Faraway et al.'s Beta(1.63, 1.75) profile peaks at "
                  "~0.9 m/s).",
        "notes": "Median over reaches of the peak catch-site speed (20 ms differences).",
    },
    "peak_speed_time": {
        "value": 0.48, "low": 0.34, "high": 0.58, "tolerance": 0.1, "unit": "relative time", "group": "hand",
        "source": "Faraway et al. (2007), Sec. 4: median relative time of peak speed 0.48; range: "
                  "interquartile range of the synthetic reaches (docs/reproductions/faraway.md).",
        "notes": "Median over reaches of the relative time of the peak speed within the reach.",
    },
    "gaze_hand_lead_s": {
        "value": 0.56, "low": 0.3, "high": 0.8, "tolerance": 0.2, "unit": "s", "group": "where", "given": "object_fixation_share",
        "source": "Land, Mennie & Rusted 1999 (REFERENCES.md, Reaching): gaze reaches an object ~0.56 s before "
                  "the hand acts on it; Johansson et al. 2001: gaze leads the hand. Range: our choice.",
        "notes": "Median over reached episodes of (hand arrival) - (first time gaze is within 5 deg of the object).",
    },
    "hand_after_saccade_s": {
        "value": 0.1, "low": 0.0, "high": 0.25, "tolerance": 0.1, "unit": "s", "group": "moves",
        "source": "Prablanc et al. 1979 (REFERENCES.md, Reaching): the saccade within ~250 ms, the hand ~100 ms "
                  "later. Range: our choice.",
        "notes": "Median of (hand movement onset) - (first saccade onset); undefined (scores 0) without a saccade.",
    },
    "first_saccade_latency_s": {
        "value": 0.2, "low": 0.15, "high": 0.25, "tolerance": 0.05, "unit": "s", "group": "moves",
        "source": "Prablanc et al. 1979 (REFERENCES.md, Reaching): the saccade to the target within ~250 ms; human "
                  "saccade latency 180-200 ms (REFERENCES.md, Catching). The 0.15 s low bound and the tolerance "
                  "are our choice.",
        "notes": "Median onset time of the first saccade; an immediate saccade (~0 s) is not human: the eye must "
                 "first see the object. Undefined (scores 0) without a saccade.",
    },
    "object_fixation_share": {
        "value": 0.9, "low": 0.8, "high": 1.0, "tolerance": 0.2, "unit": "fraction of the fixation time",
        "group": "where",
        "source": "Johansson et al. 2001, J Neurosci: gaze leads the hand to the contact point and never rests on "
                  "the hand; Land, Mennie & Rusted 1999: gaze moves on to the next object only ~0.61 s before the "
                  "action on the current one ends, i.e. after the contact (REFERENCES.md, Reaching). No share is "
                  "reported: value, range and tolerance are our choice.",
        "notes": "Median over episodes of the share of the saccade-free rows, from the first time gaze is within "
                 "5 deg of the object to the hand's arrival (success step, or the closest approach), with gaze "
                 "within 5 deg of the object. Undefined (scores 0) when gaze never reaches the object first.",
    },
}


def _nan() -> float:
    return float("nan")


def reach_measures(trace) -> dict[str, float]:
    """The per-episode measures (NaN where undefined) of one reach-family trace."""
    out = {name: _nan() for name in REACH_REFERENCE}
    hand = np.asarray(trace.hand_pos, dtype=float)
    obj = np.asarray(trace.object_pos, dtype=float).reshape(3)
    t = np.asarray(trace.t, dtype=float)
    dt = float(trace.dt)
    if hand.shape[0] < 3 or not np.all(np.isfinite(hand)):
        return out
    speed = np.linalg.norm(np.diff(hand, axis=0), axis=1) / dt  # entry i covers (t[i], t[i+1]]
    moving = np.flatnonzero(speed > HAND_ONSET_SPEED_M_S)
    onset_row = int(moving[0]) if moving.size else None
    # gaze on the object
    ecc = angles_deg(np.asarray(trace.gaze_dir, dtype=float), obj - np.asarray(trace.eye_pos, dtype=float))
    on = np.flatnonzero(ecc <= GAZE_ON_OBJECT_DEG)
    gaze_on_t = float(t[on[0]]) if on.size else _nan()
    onsets = np.flatnonzero(np.asarray(trace.saccade_onset, dtype=bool))
    first_saccade_t = float(t[onsets[0]] - dt) if onsets.size else _nan()
    out["first_saccade_latency_s"] = first_saccade_t
    arrival_row = hand.shape[0] - 1 if bool(trace.success) else int(np.argmin(np.linalg.norm(hand - obj, axis=1)))
    if on.size and on[0] <= arrival_row:
        rows = np.zeros(hand.shape[0], dtype=bool)
        rows[on[0] : arrival_row + 1] = True
        out["object_fixation_share"] = strategy.fixation_share(trace, ecc <= GAZE_ON_OBJECT_DEG, rows)
    if onset_row is None:
        return out
    hand_onset_t = float(t[onset_row + 1])  # as metrics.hand.hand_onset_time
    out["hand_after_saccade_s"] = hand_onset_t - first_saccade_t
    end_row = hand.shape[0] - 1 if bool(trace.success) else int(np.argmin(np.linalg.norm(hand - obj, axis=1)))
    if end_row - onset_row < 2:
        return out
    path = hand[onset_row : end_row + 1]
    if float(np.linalg.norm(path[-1] - path[0])) < MIN_REACH_M:
        return out
    r = handpath.hand_path_realism(path, dt)
    out["faraway_distance_cm"] = 100.0 * r.faraway_max_at_median_reach
    out["curvature_index"] = r.curvature_index
    out["hand_peak_speed_m_s"] = r.peak_speed
    out["peak_speed_time"] = r.peak_time
    if bool(trace.success):
        out["gaze_hand_lead_s"] = float(t[end_row]) - gaze_on_t
    return out


def reach_realism(traces: Sequence, reference: Mapping | None = None) -> dict:
    """Hand-path and gaze realism of a set of reach episodes: ``{"score", "components": {name: {"value"
    (median over the episodes that define it), "score" (x coverage, 0 when undefined), "episodes"}}}``
    against :data:`REACH_REFERENCE`; the score is the smallest group mean
    (:func:`~visuomotor_gym.metrics.realism.score_components`)."""
    reference = REACH_REFERENCE if reference is None else reference
    return score_components([reach_measures(tr) for tr in traces], reference, reduce="median")


def closest_distance(tr) -> float:
    """The closest the catch site came to the object over the episode (m): a failed reach's miss distance."""
    d = np.linalg.norm(np.asarray(tr.hand_pos, dtype=float) - np.asarray(tr.object_pos, dtype=float).reshape(3), axis=1)
    return float(d.min())


def reach_summary(traces: Sequence) -> dict:
    """:func:`~visuomotor_gym.metrics.common.goal_summary` for reach-family traces (``caught`` and
    ``catch_rate`` count successes, equal to ``success_rate``; ``gaze_realism`` from
    :func:`reach_realism`; the miss distance :func:`closest_distance`) plus one field, the hand's
    reaction time ``reaction_times_s["hand_onset"]``. Diverged episodes are left out of the behavioural
    measures, as for catching."""
    traces = list(traces)
    out = goal_summary(traces, reach_realism, closest_distance)
    valid = [tr for tr in traces if not tr.diverged]
    out["reaction_times_s"]["hand_onset"] = mean_median([hand_onset_time(tr) for tr in valid])
    return out
