"""Realism and outcome summary of the push family (PushRecovery; Eom et al. 2019, section 7).

Per episode, from the trace (true scene, scoring only):

* ``gaze_hand_lead_s``: the hand's first contact with a cube minus the start of the last stretch of gaze
  within 5 deg of that cube's face centre up to the contact (since PushRecovery's eleventh pass; before it,
  the first time gaze was there: a look at the cube before the push, broken off, no longer counts). Land,
  Mennie & Rusted 1999: gaze reaches an object ~0.56 s before the hand acts on it; Johansson et al. 2001:
  gaze leads the hand to contact points. Undefined without a contact.
* ``hand_reaction_s``: the hand's movement onset after the push's onset (speed above 0.3 m/s); Maki &
  McIlroy's reviews put the onset of compensatory arm reactions ~100-150 ms after a perturbation
  (REFERENCES.md, marked unconfirmed: the range is our choice).
* ``saccade_after_push_s``: the first saccade after the push's onset.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.metrics.common import goal_summary
from visuomotor_gym.metrics.realism import score_components
from visuomotor_gym.metrics.stats import mean_median

GAZE_ON_BLOCK_DEG = 5.0  # as the reach family's "gaze on the object" (modelling choice)
HAND_ONSET_SPEED_M_S = 0.3  # modelling choice: above the body's sway

PUSH_REFERENCE = {
    "gaze_hand_lead_s": {
        "value": 0.56, "low": 0.1, "high": 0.8, "tolerance": 0.2, "unit": "s", "group": "where",
        "source": "Land, Mennie & Rusted 1999 (REFERENCES.md): gaze reaches an object ~0.56 s before the hand "
                  "acts on it; Johansson et al. 2001: gaze leads the hand to contact points. A push leaves less "
                  "time than a self-paced reach: the 0.1 s low bound is our choice.",
        "notes": "Median over episodes with a hand contact of (first contact) - (start of the last stretch of gaze "
                 "within 5 deg of that cube's face centre up to the contact); negative when the hand arrives first.",
    },
    "hand_reaction_s": {
        "value": 0.15, "low": 0.1, "high": 0.25, "tolerance": 0.1, "unit": "s", "group": "hand",
        "source": "Maki & McIlroy's reviews of change-in-support reactions: arm reactions start ~100-150 ms after "
                  "the perturbation (REFERENCES.md; unconfirmed, range our choice).",
        "notes": "Median of (hand speed first above 0.3 m/s after the push) - (push onset).",
    },
    "saccade_after_push_s": {
        "value": 0.2, "low": 0.1, "high": 0.3, "tolerance": 0.1, "unit": "s", "group": "moves",
        "source": "Saccade latency 180-200 ms (REFERENCES.md, Catching); our choice for a reactive saccade.",
        "notes": "Median of (first saccade onset after the push) - (push onset).",
    },
}


def push_measures(trace) -> dict[str, float]:
    """The per-episode measures (NaN where undefined) of one push-family trace."""
    out = {name: float("nan") for name in PUSH_REFERENCE}
    t = np.asarray(trace.t, dtype=float)
    dt = float(trace.dt)
    hand = np.asarray(trace.hand_pos, dtype=float)
    t_push = float(trace.push_time)
    if hand.shape[0] < 3:
        return out
    speed = np.linalg.norm(np.diff(hand, axis=0), axis=1) / dt
    after = np.flatnonzero((speed > HAND_ONSET_SPEED_M_S) & (t[1:] > t_push))
    if after.size:
        out["hand_reaction_s"] = float(t[after[0] + 1]) - t_push
    onsets = np.flatnonzero(np.asarray(trace.saccade_onset, dtype=bool) & (t > t_push))
    if onsets.size:
        out["saccade_after_push_s"] = float(t[onsets[0]] - dt) - t_push
    contact = np.flatnonzero(np.asarray(trace.hand_on_block, dtype=bool))
    faces = np.asarray(trace.block_faces, dtype=float).reshape(-1, 3)
    if contact.size:
        # the cube of the first contact: the face nearest the hand then
        block = int(np.argmin(np.linalg.norm(faces - hand[contact[0]], axis=1)))
        ecc = angles_deg(np.asarray(trace.gaze_dir, dtype=float), faces[block] - np.asarray(trace.eye_pos, dtype=float))
        on = ecc[: contact[0] + 1] <= GAZE_ON_BLOCK_DEG
        if on.any():
            # the start of the last stretch of gaze on the cube up to the contact (the fixation that guides the
            # hand, Land et al.'s lead); a look at it broken off earlier (a look-ahead fixation, Pelz & Canosa
            # 2001) does not count
            off = np.flatnonzero(~on)
            last_on = int(np.flatnonzero(on)[-1])
            before = off[off < last_on]
            start = int(before[-1]) + 1 if before.size else 0
            out["gaze_hand_lead_s"] = float(t[contact[0]] - t[start])
    return out


def push_realism(traces: Sequence, reference: Mapping | None = None) -> dict:
    """Gaze and reaction realism of a set of push episodes (the rule of every family:
    :func:`~visuomotor_gym.metrics.realism.score_components`)."""
    reference = PUSH_REFERENCE if reference is None else reference
    return score_components([push_measures(tr) for tr in traces], reference, reduce="median")


def hand_miss_distance(tr) -> float:
    """The closest the catch site came to any cube's face centre over the episode (m): a fall's miss."""
    hand = np.asarray(tr.hand_pos, dtype=float)
    faces = np.asarray(tr.block_faces, dtype=float).reshape(-1, 3)
    return float(np.min(np.linalg.norm(hand[:, None, :] - faces[None, :, :], axis=2)))


def push_summary(traces: Sequence) -> dict:
    """:func:`~visuomotor_gym.metrics.common.goal_summary` for push-family traces, plus the hand's
    reaction time after the push as ``reaction_times_s["hand_onset"]``."""
    traces = list(traces)
    out = goal_summary(traces, push_realism, hand_miss_distance)
    valid = [tr for tr in traces if not tr.diverged]
    out["reaction_times_s"]["hand_onset"] = mean_median([push_measures(tr)["hand_reaction_s"] for tr in valid])
    return out
