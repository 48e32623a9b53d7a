"""Encoding agent intentions as the catch env's ``control="hand"`` action (the inverse of the env's
action mapping), shared by the scripted and model-based agents."""

from __future__ import annotations

import math

import numpy as np

from visuomotor_gym.body.seated import HAND_WORKSPACE
from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.core.head import neck_range_deg
from visuomotor_gym.oculomotor.plant import OculomotorParams

NECK_RANGE_DEG = neck_range_deg()  # yaw, pitch (degrees), read from envs_assets/common/head_eye.xml
_FIX = OculomotorParams().fixation_range_m
_LOG_FIX = (math.log(_FIX[0]), math.log(_FIX[1]))


def eye_head_action(gaze, fixation_m: float | None, head, gaze_range_rad: float) -> np.ndarray:
    """The gaze (2), fixation (1) and head (2) blocks every body shares, as the env maps them back: gaze change
    (retinal azimuth, elevation; rad) over the gaze action range, fixation distance log-mapped onto the plant's
    range (None keeps the neutral 0), neck (yaw, pitch; rad) onto [-1, 1] of each joint's range."""
    a = np.zeros(5, dtype=np.float32)
    a[0] = np.clip(gaze[0] / gaze_range_rad, -1.0, 1.0)
    a[1] = np.clip(gaze[1] / gaze_range_rad, -1.0, 1.0)
    if fixation_m is not None:
        lo_f, hi_f = _LOG_FIX
        a[2] = np.clip(2.0 * (math.log(max(fixation_m, 1e-3)) - lo_f) / (hi_f - lo_f) - 1.0, -1.0, 1.0)
    for k in range(2):
        lo_h, hi_h = NECK_RANGE_DEG[k]
        h = math.degrees(float(head[k]))
        a[3 + k] = np.clip(h / hi_h if h >= 0 else -h / lo_h, -1.0, 1.0)
    return a


def hand_target_action(hand_target_world) -> np.ndarray:
    """The hand-target block (3 values in [-1, 1]) of a ``control="hand"`` action for a world point
    (clipped to the hand workspace)."""
    lo, hi = HAND_WORKSPACE[:, 0], HAND_WORKSPACE[:, 1]
    return np.clip(2.0 * (np.asarray(hand_target_world) - SEAT_ORIGIN - lo) / (hi - lo) - 1.0, -1.0, 1.0)


def hand_action(
    hand_target_world,
    grasp_closed: bool,
    gaze=(0.0, 0.0),
    head=(0.0, 0.0),
    fixation_m: float | None = None,
    gaze_range_rad: float = math.radians(60.0),
) -> np.ndarray:
    """The 9-dim action: hand target (world point), grasp, gaze change (retinal azimuth, elevation,
    rad), fixation distance (m; None keeps the action's neutral value) and neck (yaw, pitch, rad)."""
    a = np.zeros(9, dtype=np.float32)
    a[:3] = hand_target_action(hand_target_world)
    a[3] = 1.0 if grasp_closed else -1.0
    a[4:9] = eye_head_action(gaze, fixation_m, head, gaze_range_rad)
    return a
