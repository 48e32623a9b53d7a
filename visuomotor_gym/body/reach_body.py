"""The seated body for reaching: :class:`~visuomotor_gym.body.seated.SeatedBody` with a home posture
in front of the belly and, optionally, a Bézier hand action (``hand_action="bezier"``).

The catch family's body is unchanged: this subclass only sets another reset posture and, in the Bézier
mode, another way of producing the hand reference that the same damped-least-squares controller
follows (:mod:`visuomotor_gym.control.hand`).

Bézier hand action (Faraway, Reed & Wang 2007)
---------------------------------------------------------
The body's action blocks are ``hand_target`` (3, the reach's end point, mapped onto the hand workspace as
in ``control="hand"``), ``bezier_y1`` and ``bezier_y2`` (3 each: the two interior control points' offsets
from the start-end axis points at 1/3 and 2/3, per metre of reach, in the body frame (lateral right,
forward, up) of :func:`visuomotor_gym.handpath.body_frame`; -1..1 maps onto -0.5..0.5), ``reach_duration``
(1: -1..1 onto 0.2..2.0 s), ``reach_start`` (1: > 0 starts a reach when none is in progress) and
``grasp``. A reach starts at the hand reference and ends at ``hand_target``; the two offsets and the
duration are latched at its start, the end point follows ``hand_target`` while it runs (on-line
correction). At relative time tau the reference sits at relative arc length F(tau) of the curve, F the
Beta(1.63, 1.75) CDF (Faraway et al. 2007, Sec. 4; :func:`visuomotor_gym.handpath.faraway_path`'s default
timing). Zero offsets give a straight reach; ``bezier_y1 = FARAWAY_Y1 / 0.5`` and ``bezier_y2 = FARAWAY_Y2 /
0.5`` give Faraway's mean path. Between reaches the reference holds the last reach's end.
"""

from __future__ import annotations

import mujoco
import numpy as np

from visuomotor_gym import handpath
from visuomotor_gym.body import names
from visuomotor_gym.body.seated import SeatedBody
from visuomotor_gym.control.hand import HandControlParams
from visuomotor_gym.core.observation import Block
from visuomotor_gym.oculomotor.plant import DEG

HAND_ACTIONS = ("target", "bezier")
# Reset posture of the reaching body (degrees): the catch site rests ~0.32 m in front of the pelvis at
# belly height near the midline, (0.32, -0.05, 0.74) m in the world: the seated analogue of Faraway et al.'s
# "small home shelf in front of the subject" (Sec. 2). Modelling choice (joint values picked so that the
# hand starts clear of the towers and every target is reached by Faraway's path without touching them).
HOME_POSTURE_DEG = {
    "shoulder_flex": 20.0,
    "shoulder_abd": 10.0,
    "shoulder_rot": 30.0,
    "elbow": 100.0,
    "forearm_rot": 0.0,
    "wrist_flex": 0.0,
    "wrist_dev": 0.0,
}
# Bézier action ranges (modelling choice): offsets up to half the reach length (Faraway's means are
# <= 0.15 of it), durations 0.2-2 s (Faraway et al.'s reaches, sampled at 25 Hz, last about a second).
BEZIER_OFFSET_RANGE = 0.5
REACH_DURATION_RANGE_S = (0.2, 2.0)
_ARC_SAMPLES = 65  # samples of the curve for its arc-length table (chord error < 0.1 mm on these reaches)
_U = np.linspace(0.0, 1.0, _ARC_SAMPLES)
_BASIS = handpath.bernstein(3, _U)  # (65, 4)

REACH_PROGRESS_BLOCK = Block("reach_progress", 1, "0..1",
                             "relative time of the Bézier reach in progress (0 when none; hand_action='bezier' only)")


def bezier_point(p0: np.ndarray, p3: np.ndarray, y1, y2, tau: float,
                 alpha: float = handpath.FARAWAY_ALPHA, beta: float = handpath.FARAWAY_BETA) -> np.ndarray:
    """The point of the reach p0 -> p3 with distance-scaled axis offsets ``y1``, ``y2`` (body frame) at
    relative time ``tau``: relative arc length ``Beta CDF(tau)`` along the cubic Bézier. A reach shorter
    than 1 mm is the end point."""
    p0 = np.asarray(p0, dtype=float)
    p3 = np.asarray(p3, dtype=float)
    if float(np.linalg.norm(p3 - p0)) < 1e-3:
        return p3.copy()
    ctrl = handpath.faraway_control_points(p0, p3, y1=tuple(y1), y2=tuple(y2))
    pts = _BASIS @ ctrl
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    s = float(handpath.beta_progress(min(max(tau, 0.0), 1.0), alpha, beta))
    u = float(np.interp(s * cum[-1], cum, _U))
    return (handpath.bernstein(3, u) @ ctrl)[0]


class ReachSeatedBody(SeatedBody):
    """The seated body with the reaching home posture and the ``hand_action`` option."""

    def __init__(self, model: mujoco.MjModel, control: str, hand_params: HandControlParams, dt: float,
                 hand_action: str = "target") -> None:
        super().__init__(model, control, hand_params, dt)
        if hand_action not in HAND_ACTIONS:
            raise ValueError(f"hand_action={hand_action!r} is not one of {list(HAND_ACTIONS)}")
        if hand_action == "bezier" and control != "hand":
            raise ValueError("hand_action='bezier' needs control='hand' (it produces a Cartesian hand reference)")
        self.hand_action = hand_action
        self.ready = np.array([0.0, 0.0, 0.0] + [HOME_POSTURE_DEG[n] * DEG for n in names.ARM_JOINTS])
        self.hand.nominal = self.ready  # the controller's null-space posture
        if hand_action == "bezier":
            self.action_structure = {"hand_target": 3, "bezier_y1": 3, "bezier_y2": 3, "reach_duration": 1,
                                     "reach_start": 1, "grasp": 1}
            self.n_action = sum(self.action_structure.values())
            self.observation_blocks = (*self.observation_blocks, REACH_PROGRESS_BLOCK)
        self._reset_reach()

    def _reset_reach(self) -> None:
        self.reach = None  # (p0, y1, y2, duration) of the reach in progress
        self.reach_elapsed = 0.0
        self.reach_end = None  # the commanded end point (world) of the last or current reach
        self.reach_tau = 0.0

    def start(self, data: mujoco.MjData) -> None:
        super().start(data)
        self._reset_reach()
        self.reach_end = self.hand.reference.copy()

    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None:
        if self.hand_action != "bezier":
            super().command(data, a, al, dt)
            return
        d = data
        setpoint = d.act[self._actadr]
        (lx, ly, lz), (hx, hy, hz) = self._ws_lo_half
        end = np.array((lx + (al[0] + 1.0) * hx, ly + (al[1] + 1.0) * hy, lz + (al[2] + 1.0) * hz))
        if self.reach is None and al[10] > 0.0 and float(np.linalg.norm(end - self.hand.reference)) >= 1e-3:
            lo, hi = REACH_DURATION_RANGE_S
            duration = lo + (al[9] + 1.0) * 0.5 * (hi - lo)
            self.reach = (self.hand.reference.copy(), BEZIER_OFFSET_RANGE * a[3:6], BEZIER_OFFSET_RANGE * a[6:9],
                          duration)
            self.reach_elapsed = 0.0
        if self.reach is not None:
            p0, y1, y2, duration = self.reach
            self.reach_elapsed += dt
            self.reach_tau = min(self.reach_elapsed / duration, 1.0)
            self.reach_end = end
            point = bezier_point(p0, end, y1, y2, self.reach_tau)
            if self.reach_tau >= 1.0:
                self.reach = None
        else:
            self.reach_tau = 0.0
            point = self.reach_end
        self.hand.advance_reference(point, dt)
        new_setpoint = self.hand.setpoints(d, setpoint)
        d.ctrl[self._act] = (new_setpoint - setpoint) / dt
        d.ctrl[self._grasp_act] = (al[self.n_action - 1] + 1.0) * 0.5 * self.grasp_max

    def observe(self, values: list, data: mujoco.MjData) -> None:
        super().observe(values, data)
        if self.hand_action == "bezier":
            values.append(self.reach_tau if self.reach is not None else 0.0)


def home_hand_position(model: mujoco.MjModel) -> np.ndarray:
    """The catch site (world) at the home posture, from a scratch copy of the kinematics."""
    d = mujoco.MjData(model)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names.BODY_JOINTS]
    for j, q in zip(ids, [0.0, 0.0, 0.0] + [HOME_POSTURE_DEG[n] * DEG for n in names.ARM_JOINTS]):
        d.qpos[model.jnt_qposadr[j]] = q
    mujoco.mj_kinematics(model, d)
    return d.site_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, names.CATCH_SITE)].copy()


__all__ = ["BEZIER_OFFSET_RANGE", "HAND_ACTIONS", "HOME_POSTURE_DEG", "REACH_DURATION_RANGE_S",
           "ReachSeatedBody", "bezier_point", "home_hand_position"]
