"""The gaze-realism score: per-episode measures scored against the human reference table.

The table is data (``human_reference.json``, loaded by :func:`load_reference`), with a value, an accepted
human range, a unit and a source for every component. A component's value is the mean of its
per-episode measure over the episodes where it is defined; its score is 1 inside the human range and
falls off as a Gaussian outside (:func:`score_component`). The realism score is the mean of the available
component scores (DESIGN.md section 4).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from importlib import resources

import numpy as np

from visuomotor_gym.metrics import gaze, hand
from visuomotor_gym.metrics.stats import nan_mean

REFERENCE_FILE = "human_reference.json"
REQUIRED_FIELDS = ("value", "low", "high", "unit", "source", "notes")

#: component name -> per-episode measure (trace -> float, NaN when undefined)
COMPONENT_MEASURES: dict[str, Callable] = {
    "first_saccade_latency_s": gaze.first_saccade_latency,
    "catchup_saccade_interval_s": gaze.catchup_saccade_interval,
    "pursuit_share_after_apex": gaze.pursuit_share_after_apex,
    "ball_foveation": gaze.ball_foveation,
    "head_contribution": gaze.head_contribution,
    "saccade_hand_synchrony": hand.saccade_hand_synchrony,
    "hand_peak_speed_m_s": hand.hand_peak_speed,
}


def load_reference() -> dict[str, dict]:
    """The human reference table: ``{component name: {"value", "low", "high", "tolerance", "unit",
    "source", "notes"}}``, read from the packaged ``human_reference.json``."""
    text = resources.files("visuomotor_gym.metrics").joinpath(REFERENCE_FILE).read_text(encoding="utf-8")
    return json.loads(text)["components"]


def _tolerance(entry: Mapping) -> float:
    tol = entry.get("tolerance")
    if tol is None:
        tol = float(entry["high"]) - float(entry["low"])
    tol = float(tol)
    if not tol > 0:
        raise ValueError(f"reference entry needs a positive tolerance or a non-empty range: {dict(entry)}")
    return tol


def score_component(name: str, value: float, reference: Mapping | None = None) -> float:
    """Score in [0, 1] of one component value against its human range.

    1 inside ``[low, high]``; outside, ``exp(-d^2 / (2 w^2))`` with ``d`` the distance to the nearer bound
    and ``w`` the entry's ``tolerance`` (the range width when the entry has none): 0.61 at one tolerance
    outside, 0.14 at two, 0.01 at three. NaN (the component is excluded) when ``value`` is NaN.
    ``reference`` is the table of :func:`load_reference` (loaded when None).
    """
    reference = load_reference() if reference is None else reference
    if name not in reference:
        raise KeyError(f"no human reference for component {name!r}; known: {sorted(reference)}")
    value = float(value)
    if not math.isfinite(value):
        return float("nan")
    entry = reference[name]
    low, high = float(entry["low"]), float(entry["high"])
    d = max(low - value, value - high, 0.0)
    return math.exp(-0.5 * (d / _tolerance(entry)) ** 2)


def component_values(traces: Sequence, name: str) -> np.ndarray:
    """The per-episode values of one component (NaN where undefined)."""
    measure = COMPONENT_MEASURES[name]
    return np.array([measure(tr) for tr in traces], dtype=float)


def gaze_realism(traces: Sequence, reference: Mapping | None = None) -> dict:
    """Gaze-realism score of a set of episodes.

    Returns ``{"score": float in [0, 1] (NaN if no component is defined), "components": {name: {"value":
    mean over the episodes where it is defined, "score": score_component(value), "episodes": how many
    episodes defined it}}}``; the score is the mean of the non-NaN component scores.
    """
    reference = load_reference() if reference is None else reference
    unknown = set(reference) - set(COMPONENT_MEASURES)
    if unknown:
        raise KeyError(f"reference components without a measure: {sorted(unknown)}")
    components = {}
    for name in reference:
        values = component_values(traces, name)
        value = nan_mean(values)
        components[name] = {
            "value": value,
            "score": score_component(name, value, reference),
            "episodes": int(np.isfinite(values).sum()),
        }
    return {"score": nan_mean([c["score"] for c in components.values()]), "components": components}
