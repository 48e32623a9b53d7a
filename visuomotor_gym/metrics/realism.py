"""The gaze-realism score: per-episode measures scored against a human reference table, combined so
that a still eye and a random eye cannot pass.

The catch family's table is data (``human_reference.json``, loaded by :func:`load_reference`); the other
families keep theirs beside their measures (``walk_realism``, ``stones_realism``, ``dodge_realism``,
``reach_realism``). Every entry has a value, an accepted human range, a tolerance, a unit, a source and a
**group** (:data:`GROUPS`).

How a set of episodes is scored (:func:`score_components`, used by every family):

* a component's ``value`` is the mean (or, for the reach family, the median) of its per-episode measure
  over the episodes that define it, and ``episodes`` says how many did;
* its ``score`` is :func:`score_component` of that value (1 inside the human range, a Gaussian fall-off
  outside) times its **coverage**, the share of the scored episodes that define it. A component that no
  episode defines scores **0**, not "left out": an eye that never saccades has no human saccade pattern,
  an eye that never lands on a stone has no human look-ahead. (Before version 2 undefined components were
  dropped from the mean, so a still eye was never penalised for not moving.) Coverage stops a handful of
  stray episodes from scoring for the rest;
* a component measured only on the rows or episodes where the eye was on a target (the look-ahead of the
  rows whose gaze is on a stone, the latency of the pedestrians that were fixated) names that target's
  share as its ``given``, and its score is capped by the score of the share: a look-ahead measured on the
  few fixations that landed on a stone by chance says nothing about an eye that rarely looks at stones (a
  random eye's chance hits land ~2 steps ahead as often as not, because any line of sight 30-50 deg down
  lands there);
* components are grouped: ``"moves"`` (when the eye moves: saccade rate, fixation durations, saccade
  latencies and timing locked to the task), ``"where"`` (where it lands: share of fixation time on the task's
  targets, look-ahead, foveation of the ball or the object), for the reach family ``"hand"`` (the
  hand path) and, for the walk family, ``"layout"`` (where the line of sight sits relative to the
  walkway: on the travel path, how far ahead, how far below the horizon, which one posture of a still
  eye satisfies as well as a moving one; kept as a group of its own so that it cannot bank points for
  ``"where"``, which there counts only fixations that hold a target). A group's score is the mean of its
  components' scores;
* the realism **score is the smallest group score**. Each group is necessary: a human eye both moves like
  a human eye and looks where humans look. The two cheap ways to imitate one group fail the other: a
  still or body-locked eye (held twin, best static posture) can sit where humans look most of the time
  (a pitch of 40 deg down lands 1.9 m ahead, on the travel path) but makes no saccades, so its
  ``moves`` group is ~0 (where a body-locked eye does saccade at a human rate, re-centring as a walker's
  pelvis turns on the stepping stones, its fixations sweep past the targets and its ``where`` group
  fails); a random eye saccades at a human-like rate but its fixations fall on the task's targets only
  by chance, so its ``where`` group is low. A mean over all components (the score before
  version 2) let either of them bank the other group's points: a still eye scored 0.97-1.0 on three
  families. The minimum, not a product or a geometric mean, because a product punishes a human-like
  agent twice for one weak group and a geometric mean of two groups still gives sqrt(0.25) = 0.5 to an
  eye that is perfect in one group and poor in the other (modelling choice).

Components the plant or a controller guarantees are not scored: the catch family's hand peak speed (the
hand controller caps its reference at 2 m/s, ``control.hand``) is gone from the table, and the catch-up
saccade interval (the plant refuses onsets closer than 200 ms) counts only saccades that land on the
ball (:func:`visuomotor_gym.metrics.gaze.catchup_saccade_interval`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from importlib import resources

import numpy as np

from visuomotor_gym.metrics import gaze, hand

#: The realism definition: 2 = this module's rule (undefined scores 0, the smallest group score); results
#: written with the mean of the defined components (version 1) carry no ``version``.
REALISM_VERSION = 2
REFERENCE_FILE = "human_reference.json"
REQUIRED_FIELDS = ("value", "low", "high", "unit", "source", "notes", "group")
#: The component groups (each reference entry names one); the score is the smallest group score.
GROUPS = ("moves", "where", "hand", "layout")

#: component name -> per-episode measure (trace -> float, NaN when undefined)
COMPONENT_MEASURES: dict[str, Callable] = {
    "first_saccade_latency_s": gaze.first_saccade_latency,
    "catchup_saccade_interval_s": gaze.catchup_saccade_interval,
    "pursuit_share_after_apex": gaze.pursuit_share_after_apex,
    "ball_foveation": gaze.ball_foveation,
    "head_contribution": gaze.head_contribution,
    "saccade_hand_synchrony": hand.saccade_hand_synchrony,
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


def score_components(per_episode: Sequence[Mapping[str, float]], reference: Mapping,
                     reduce: str = "mean") -> dict:
    """Score a set of episodes from their per-episode measures (the rule of every family).

    ``per_episode`` holds one ``{component: value (NaN where undefined)}`` per scored episode, ``reference``
    the family's table (every entry with a ``group`` of :data:`GROUPS`), ``reduce`` how the defined values
    combine (``"mean"`` or ``"median"``). Returns ``{"score", "components": {name: {"value", "score",
    "episodes"}}}``: ``value`` the reduced value (NaN when no episode defines it), ``score``
    :func:`score_component` times the coverage (defined episodes / scored episodes; 0 when undefined),
    ``episodes`` the defining episodes, capped by the score of the component an entry names as ``given``;
    ``score`` the smallest group mean (NaN without episodes).
    """
    if reduce not in ("mean", "median"):
        raise ValueError(f"reduce must be 'mean' or 'median', got {reduce!r}")
    rows = list(per_episode)
    n = len(rows)
    components: dict[str, dict] = {}
    groups: dict[str, list[float]] = {}
    for name, entry in reference.items():
        group = entry.get("group")
        if group not in GROUPS:
            raise ValueError(f"reference entry {name!r} needs a group in {GROUPS}, got {group!r}")
        values = np.array([float(r[name]) for r in rows], dtype=float)
        ok = values[np.isfinite(values)]
        if ok.size:
            value = float(np.mean(ok)) if reduce == "mean" else float(np.median(ok))
            score = score_component(name, value, reference) * ok.size / n
        else:
            value, score = float("nan"), 0.0
        components[name] = {"value": value, "score": score if n else float("nan"), "episodes": int(ok.size)}
    for name, entry in reference.items():  # capped by the share it is measured on (module docstring)
        given = entry.get("given")
        if given is not None:
            if given not in components or reference[given].get("given") is not None:
                raise ValueError(f"reference entry {name!r}: 'given' must name an unconditional component of the "
                                 f"table, got {given!r}")
            if n:
                components[name]["score"] = min(components[name]["score"], components[given]["score"])
    for name, entry in reference.items():
        groups.setdefault(entry["group"], []).append(components[name]["score"])
    total = min(float(np.mean(v)) for v in groups.values()) if n and groups else float("nan")
    return {"score": total, "components": components, "version": REALISM_VERSION}


def group_scores(result: Mapping, reference: Mapping) -> dict[str, float]:
    """The mean component score of each group of a :func:`score_components` result (for reports)."""
    out: dict[str, list[float]] = {}
    for name, c in result["components"].items():
        out.setdefault(reference[name]["group"], []).append(float(c["score"]))
    return {g: float(np.mean(v)) for g, v in out.items()}


def gaze_realism(traces: Sequence, reference: Mapping | None = None) -> dict:
    """Gaze-realism score of a set of catch episodes (:func:`score_components` of the table's measures).

    Returns ``{"score": float in [0, 1] (NaN without episodes), "components": {name: {"value": mean over
    the episodes where it is defined, "score": score_component(value) x coverage (0 when undefined),
    "episodes": how many episodes defined it}}}``; the score is the smallest group mean.
    """
    reference = load_reference() if reference is None else reference
    unknown = set(reference) - set(COMPONENT_MEASURES)
    if unknown:
        raise KeyError(f"reference components without a measure: {sorted(unknown)}")
    traces = list(traces)
    columns = {name: component_values(traces, name) for name in reference}
    rows = [{name: columns[name][i] for name in reference} for i in range(len(traces))]
    return score_components(rows, reference)
