"""Hand-path realism of the catch family: the hand's transport to the interception point against
Faraway, Reed & Wang's (2007) reach model, reported **beside** the catch family's gaze realism.

Which part of a catch is compared with ``faraway_path``
-------------------------------------------------------
Faraway et al. (2007) model a point-to-point reach to a resting object: one movement from a start to an end,
one speed peak (the Beta(1.63, 1.75) profile). A catch is not that: the hand leaves its rest position towards
an interception point that the catcher's estimate keeps revising while the ball flies (Eyecatch sec. 4.3:
overlapping ~400 ms submovements, one per ~200 ms visuomotor update), and once there it waits or
follows the ball in small corrections until the ball arrives. So the compared segment
(:func:`catch_reach_segment`) is the hand's **transport**:

* it starts at the hand's movement onset (the first step faster than ``HAND_ONSET_SPEED_M_S``, as
  :func:`visuomotor_gym.metrics.hand.hand_onset_time` and the reach family);
* it is headed for the interception point actually used: the catch site's position at the catch (the
  last step of a caught episode) or, when the ball was not caught, at the ball's closest approach to the
  catch site (the miss);
* it ends at the hand's **arrival** there: once the catch site stays within ``ARRIVAL_RADIUS_M`` of that
  point until the catch / closest approach, the first step no faster than ``HAND_ONSET_SPEED_M_S`` (the
  movement's offset, the onset rule reversed), or the catch / closest approach if the hand never slows
  down. The dwell after arrival (waiting, millimetre corrections) is left out because it is not part of a
  reach: kept, it adds almost nothing spatially but pushes the relative time of the peak speed towards 0.
  The radius keeps a pause between two submovements far from the interception point from ending the
  transport early; the speed rule keeps the slow final approach of a reach inside it.

``faraway_path`` is drawn between the segment's own ends (its first and last catch-site positions), so
the distance measures what the transport did on its way; every revision of the interception point, every
detour and return, adds to it. A catcher who predicted the interception point at the start and made one
human-like reach to it would score like a human reach; a catcher who chased its estimate would not. This
is the point of the measure, and also its limit: Faraway et al. measured reaches, not catches, so applying its
numbers to catching is our **modelling choice** (no human hand-path data for catching are in
``REFERENCES.md``; only the hand's peak speed, Eyecatch sec. 4.3, is a catching number, and it is reported
unscored because the hand controller caps the hand at 2 m/s, so every agent met it).

Per episode (:func:`catch_hand_path_measures`, NaN where undefined): the distance to Faraway's path
(max at equal relative arc length, scaled to the paper's 56.7 cm median reach), the curvature index (0 =
straight, 1 = Faraway's mean curvature), the peak catch-site speed in the segment and its relative time,
the transport's length (start to end), and the gaze-hand lead: the hand's arrival minus the first time,
before the catch / closest approach, that the line of sight came within ``GAZE_ON_TARGET_DEG`` of the
interception point. That is the reach family's definition with the object replaced by where the hand
goes (gaze leads the hand to where it will act: Land et al. 1999, Johansson et al. 2001, for reaching);
positive = the eye was there first. It is undefined for a catcher that only tracks the ball, so
``gaze_ahead_share`` (1 when the gaze reached the interception point before the hand did, else 0) says
in how many transports it happened. Nothing is measured when the hand never moves, when the trace has no
finite hand or ball path, for two-ball ids (an episode holds two catches and its trace records only the
first ball), or when the transport is shorter than ``MIN_REACH_M`` or than 2 control steps.

Per set (:func:`catch_hand_path`): medians over the episodes that define each component (as the reach
family: only medians over many reaches separate straight from human-like paths), scored with
:func:`visuomotor_gym.metrics.realism.score_component` against :data:`CATCH_HANDPATH_REFERENCE`; the
block's score is the mean of the scored components (the gaze-hand lead has no human number for catching
and is reported unscored). The block is *not* folded into the catch family's ``gaze_realism`` score,
which stays what it was. :func:`path_verdict` names the medians in words: ``"human-like"``,
``"straight-line-like"``, ``"more curved than human"``, ``"unlike a single reach"`` or ``"between
human-like and unlike a single reach"``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from visuomotor_gym import handpath
from visuomotor_gym.envs.catch import FAMILY
from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.metrics.reach_realism import REACH_REFERENCE
from visuomotor_gym.metrics.realism import score_component

HAND_ONSET_SPEED_M_S = 0.1  # as metrics.hand.HAND_ONSET_SPEED_M_S and the reach family
MIN_REACH_M = 0.05  # shorter transports are not reaches (modelling choice, as metrics.reach_realism)
# The hand is near the interception point when it stays this close to it: half the 6 cm catch volume
# (EyeCatch-v0's catch_radius), so the ball can be caught from there; it has arrived when it then slows
# below HAND_ONSET_SPEED_M_S. Modelling choice.
ARRIVAL_RADIUS_M = 0.03
GAZE_ON_TARGET_DEG = 5.0  # "on the interception point": as metrics.reach_realism.GAZE_ON_OBJECT_DEG (our choice)

# Verdict thresholds (path_verdict), on the medians over episodes:
# Faraway et al. (2007), Table 2: the chosen model's median error against human reaches.
HUMAN_LIKE_MAX_CM = 8.0
# Faraway et al. (2007), Table 2: the straight minimum-jerk (Flash-Hogan) model's median error against human
# reaches. A median distance to the chosen model above it is farther from the model than the rejected
# straight-line model was from humans: not one reach. (It is *not* the distance of a straight path to
# faraway_path, which is only ~6 cm at 56.7 cm: docs/reproductions/faraway.md.)
UNLIKE_REACH_MIN_CM = 12.6
# The interquartile range of the curvature index of synthetic human reaches (docs/reproductions/faraway.md,
# REACH_REFERENCE["curvature_index"]); a straight path has 0.
HUMAN_CURVATURE_LOW = REACH_REFERENCE["curvature_index"]["low"]
HUMAN_CURVATURE_HIGH = REACH_REFERENCE["curvature_index"]["high"]

_APPLIED = (" Applied to the transport of a catch: modelling choice (Faraway et al. 2007 measured reaches "
            "to resting objects; there is no human hand-path number for catching in REFERENCES.md).")


def _reference() -> dict[str, dict]:
    ref = {
        name: {**REACH_REFERENCE[name], "source": REACH_REFERENCE[name]["source"] + _APPLIED}
        for name in ("faraway_distance_cm", "curvature_index", "peak_speed_time")
    }
    ref["faraway_distance_cm"]["notes"] = (
        "Median over catches of the max distance of the transport (movement onset to arrival at the "
        "interception point) to faraway_path between its ends, at equal relative arc length, scaled to a "
        "56.7 cm reach. A straight transport also scores ~6 cm: read it with curvature_index.")
    ref["curvature_index"]["notes"] = "Median over catches of handpath.HandPathRealism.curvature_index of the transport."
    ref["peak_speed_time"]["notes"] = "Median over catches of the relative time of the peak speed within the transport."
    ref["hand_peak_speed_m_s"] = {
        "value": None, "low": None, "high": None, "tolerance": None, "unit": "m/s", "scored": False,
        "source": "Eyecatch sec. 4.3: humans keep the hand below ~2 m/s. Not scored: the hand controller caps its "
                  "reference at 2 m/s (control.hand.HandParams.max_speed_m_s), so every agent met the bound.",
        "notes": "Median over catches of the peak catch-site speed within the transport (20 ms differences).",
    }
    ref["gaze_hand_lead_s"] = {
        "value": None, "low": None, "high": None, "tolerance": None, "unit": "s", "scored": False,
        "source": "None for catching: not scored. (Land, Mennie & Rusted 1999 measured ~0.56 s for reaching to "
                  "resting objects; catchers track the ball, REFERENCES.md, so that number does not transfer.) "
                  "The definition is a modelling choice.",
        "notes": "Median, over the episodes in which gaze came within 5 deg of the interception point before the "
                 "catch / closest approach, of (hand arrival) - (first such time); negative: the hand was there "
                 "before the eye. Undefined when gaze never went there (an agent that only tracks the ball).",
    }
    ref["gaze_ahead_share"] = {
        "value": None, "low": None, "high": None, "tolerance": None, "unit": "fraction of episodes",
        "scored": False, "reduce": "mean",
        "source": "None for catching: not scored (modelling choice).",
        "notes": "Share of the measured transports in which gaze came within 5 deg of the interception point "
                 "before the hand arrived there (gaze_hand_lead_s > 0).",
    }
    ref["transport_length_m"] = {
        "value": None, "low": None, "high": None, "tolerance": None, "unit": "m", "scored": False,
        "source": "Descriptive, not scored.",
        "notes": "Median distance from the transport's start to its end: faraway_distance_cm is scaled by "
                 "0.567 m over it.",
    }
    return ref


#: The catch family's hand-path reference: value, range, tolerance, unit, source per component
#: (``"scored": False``: reported, not scored).
CATCH_HANDPATH_REFERENCE: dict[str, dict] = _reference()


def _nan() -> float:
    return float("nan")


def measures_hand_path(trace) -> bool:
    """Whether the catch hand path is measured for this trace's env: single-ball catch ids (a two-ball
    episode holds two catches, and its trace records only the first ball's path)."""
    env_id = str(getattr(trace, "env_id", "")).removeprefix("visuomotor_gym:")
    for spec in FAMILY.env_entries():  # the catch family's ids
        if spec.id == env_id:
            return int(spec.kwargs.get("n_balls", 1)) == 1
    return False


def catch_reach_segment(trace) -> tuple[int, int, int] | None:
    """Rows ``(onset, arrival, end)`` of the hand's transport in a single-ball catch trace (see the module
    docstring; ``end`` is the catch or the ball's closest approach, the catch site's position there the
    interception point), or None when there is none (the hand never moves, arrives in fewer than 2 steps, or the
    trace lacks a finite hand or ball path)."""
    try:
        hand = np.asarray(trace.hand_pos, dtype=float)
        ball = np.asarray(trace.ball_pos, dtype=float)
        dt = float(trace.dt)
    except AttributeError:
        return None
    if (hand.ndim != 2 or hand.shape[1:] != (3,) or hand.shape[0] < 3 or ball.shape != hand.shape
            or not np.all(np.isfinite(hand)) or not np.all(np.isfinite(ball)) or not dt > 0):
        return None
    speed = np.linalg.norm(np.diff(hand, axis=0), axis=1) / dt  # entry i covers (t[i], t[i+1]]
    moving = np.flatnonzero(speed > HAND_ONSET_SPEED_M_S)
    if moving.size == 0:
        return None
    onset = int(moving[0])
    end = hand.shape[0] - 1 if bool(trace.success) else int(np.argmin(np.linalg.norm(ball - hand, axis=1)))
    if end <= onset:
        return None
    away = np.flatnonzero(np.linalg.norm(hand[onset : end + 1] - hand[end], axis=1) > ARRIVAL_RADIUS_M)
    near = onset + (int(away[-1]) + 1 if away.size else 0)  # from here on, within the radius
    slow = np.flatnonzero(speed[near:end] <= HAND_ONSET_SPEED_M_S)  # the movement's offset, once near
    arrival = near + int(slow[0]) if slow.size else end
    if arrival - onset < 2:
        return None
    return onset, arrival, end


def catch_hand_path_measures(trace) -> dict[str, float]:
    """The per-episode measures (NaN where undefined) of one catch-family trace: the keys of
    :data:`CATCH_HANDPATH_REFERENCE`."""
    out = {name: _nan() for name in CATCH_HANDPATH_REFERENCE}
    if not measures_hand_path(trace):
        return out
    seg = catch_reach_segment(trace)
    if seg is None:
        return out
    onset, arrival, end = seg
    hand = np.asarray(trace.hand_pos, dtype=float)
    path = hand[onset : arrival + 1]
    if float(np.linalg.norm(path[-1] - path[0])) < MIN_REACH_M:
        return out
    r = handpath.hand_path_realism(path, float(trace.dt))
    out["faraway_distance_cm"] = 100.0 * r.faraway_max_at_median_reach
    out["curvature_index"] = r.curvature_index
    out["hand_peak_speed_m_s"] = r.peak_speed
    out["peak_speed_time"] = r.peak_time
    out["transport_length_m"] = r.reach_length
    try:
        t = np.asarray(trace.t, dtype=float)
        gaze = np.asarray(trace.gaze_dir, dtype=float)
        eye = np.asarray(trace.eye_pos, dtype=float)
    except AttributeError:
        return out
    ecc = angles_deg(gaze[: end + 1], hand[end] - eye[: end + 1])
    on = np.flatnonzero(ecc <= GAZE_ON_TARGET_DEG)
    if on.size:
        out["gaze_hand_lead_s"] = float(t[arrival]) - float(t[on[0]])
    out["gaze_ahead_share"] = float(on.size > 0 and on[0] < arrival)
    return out


def path_verdict(distance_cm: float, curvature_index: float) -> str | None:
    """The hand paths of a set of catches (or reaches) in words, from the medians of
    ``faraway_distance_cm`` and ``curvature_index``; None when either is undefined.

    In order: ``"unlike a single reach"`` above ``UNLIKE_REACH_MIN_CM`` (12.6 cm); ``"straight-line-like"``
    below the human curvature range (0.48); ``"more curved than human"`` above it (1.40); ``"human-like"``
    at most ``HUMAN_LIKE_MAX_CM`` (8.0 cm); otherwise ``"between human-like and unlike a single reach"``.
    Sources of the thresholds: see the module constants (the combination is our modelling choice)."""
    d, k = float(distance_cm), float(curvature_index)
    if not (math.isfinite(d) and math.isfinite(k)):
        return None
    if d > UNLIKE_REACH_MIN_CM:
        return "unlike a single reach"
    if k < HUMAN_CURVATURE_LOW:
        return "straight-line-like"
    if k > HUMAN_CURVATURE_HIGH:
        return "more curved than human"
    if d <= HUMAN_LIKE_MAX_CM:
        return "human-like"
    return "between human-like and unlike a single reach"


def catch_hand_path(traces: Sequence, reference: Mapping | None = None) -> dict:
    """Hand-path realism of a set of catch episodes: ``{"score", "verdict", "episodes", "components":
    {name: {"value" (median over the episodes that define it), "score" (None for unscored components),
    "episodes"}}}``. ``episodes`` counts the episodes with a measurable transport; with none, every
    value, the score and the verdict are NaN / None."""
    reference = CATCH_HANDPATH_REFERENCE if reference is None else reference
    per_episode = [catch_hand_path_measures(tr) for tr in traces]
    components = {}
    for name, entry in reference.items():
        values = np.array([m[name] for m in per_episode], dtype=float)
        ok = values[np.isfinite(values)]
        if not ok.size:
            value = _nan()
        else:
            value = float(np.mean(ok)) if entry.get("reduce") == "mean" else float(np.median(ok))
        score = score_component(name, value, reference) if entry.get("scored", True) else _nan()
        components[name] = {"value": value, "score": score, "episodes": int(ok.size)}
    scores = [c["score"] for c in components.values() if math.isfinite(c["score"])]
    measured = sum(math.isfinite(m["faraway_distance_cm"]) for m in per_episode)
    return {
        "score": float(np.mean(scores)) if scores else _nan(),
        "verdict": path_verdict(components["faraway_distance_cm"]["value"], components["curvature_index"]["value"]),
        "episodes": int(measured),
        "components": components,
    }
