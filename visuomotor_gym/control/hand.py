"""Cartesian hand control: damped least squares on the torso + arm Jacobian.

``control="hand"`` turns a hand target into setpoints for the 10 torso and arm servos:

* the hand reference moves toward the target at most ``max_speed`` (2 m/s, the peak hand speed
  Eyecatch section 4.3 observed in human catching);
* one damped-least-squares step (Wampler 1986; Buss 2004) maps the remaining error to joint
  setpoints; torso columns are down-weighted so the arm does most of the work, as in the weighted
  pseudo-inverse of Eyecatch section 4.4;
* the null space pulls gently toward a nominal posture so the redundant arm does not drift.

The error is taken between the reference and the hand position *the current setpoints would give*
(linearised: ``x + J (q_set - q)``), so servo lag is neither integrated (no overshoot) nor thrown
away (no drag).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from visuomotor_gym import _native
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Num
from visuomotor_gym.geometry import solve3

# What each HandControlParams field accepts (visuomotor_gym.core.args.check_fields): non-negative, and
# bounded by modelling choices (5x the human hand's 2 m/s, a setpoint step of at most half a turn).
HAND_RULES = {
    "max_speed_m_s": Num(0.0, 10.0),
    "damping": Num(0.0, 1.0),
    "torso_weight": Num(0.0, 10.0),
    "posture_gain": Num(0.0, 1.0),
    "max_joint_step_rad": Num(0.0, 3.15),
}


@dataclass(frozen=True)
class HandControlParams:
    """Gains and limits of the Cartesian hand controller."""

    max_speed_m_s: float = 2.0  # Eyecatch 4.3: human hand speed stays below ~2 m/s
    damping: float = 0.04  # DLS damping lambda (m)
    torso_weight: float = 0.35  # relative weight of torso joints in the weighted pseudo-inverse
    posture_gain: float = 0.1  # null-space pull toward the nominal posture, per control step
    max_joint_step_rad: float = 0.35  # largest setpoint change per control step

    def __post_init__(self) -> None:
        args.check_fields(self, HAND_RULES)


class HandController:
    """Turns a Cartesian hand reference into servo setpoints for the torso and arm joints."""

    def __init__(
        self,
        model: mujoco.MjModel,
        site_id: int,
        dof_ids: np.ndarray,
        qpos_ids: np.ndarray,
        joint_ranges: np.ndarray,
        nominal: np.ndarray,
        n_torso: int,
        params: HandControlParams | None = None,
    ):
        self.model = model
        self.site_id = site_id
        self.dof_ids = dof_ids  # slices or index arrays
        self.qpos_ids = qpos_ids
        self.params = params or HandControlParams()
        margin = 1e-3
        self.lower = joint_ranges[:, 0] + margin
        self.upper = joint_ranges[:, 1] - margin
        self.nominal = np.ascontiguousarray(nominal, dtype=float)
        weights = np.ones(len(joint_ranges))
        weights[:n_torso] = self.params.torso_weight
        self.weights = weights
        self._weights_rows = np.tile(weights, (3, 1))
        self._jacp = np.zeros((3, model.nv))
        self._damping2 = self.params.damping**2  # lambda^2 on the diagonal
        self.reference = np.zeros(3)
        # The compiled element-wise steps (visuomotor_gym._native, _kernels.c: hand_*), when built, and
        # the arrays they fill; the matrix products stay numpy's.
        self._native = _native.enabled()
        n = len(joint_ranges)
        self._native_indices = np.concatenate(  # the order of _kernels.c's HandConsts
            [[n], np.arange(model.nv)[dof_ids], np.arange(model.nq)[qpos_ids]]).astype(np.float64).tobytes()
        self._native_work = (np.empty((3, n)), np.empty((3, n)), np.empty(n), np.empty(n), np.empty(3))

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._native = self._native and _native.enabled()  # unpickled where the extension is missing

    def reset(self, hand_pos: np.ndarray) -> None:
        """Start the hand reference where the hand is."""
        self.reference = np.array(hand_pos, dtype=float)

    def advance_reference(self, target, dt: float) -> np.ndarray:
        """Move the reference toward ``target`` (a 3-vector) by at most ``max_speed * dt``; return it."""
        if self._native:  # this method, compiled (_kernels.c: hand_advance)
            self.reference = _native.kernels.hand_advance(self.reference, target, self.params.max_speed_m_s, dt)
            return self.reference
        tx, ty, tz = target.tolist() if isinstance(target, np.ndarray) else target
        rx, ry, rz = self.reference.tolist()
        dx, dy, dz = tx - rx, ty - ry, tz - rz
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        limit = self.params.max_speed_m_s * dt
        if dist > limit:
            k = limit / dist
            dx, dy, dz = dx * k, dy * k, dz * k
        self.reference = np.array([rx + dx, ry + dy, rz + dz])
        return self.reference

    def setpoints(self, data: mujoco.MjData, setpoint: np.ndarray) -> np.ndarray:
        """New joint setpoints that bring the hand toward ``self.reference``.

        ``data`` must hold current kinematics (``mj_kinematics`` + ``mj_comPos``); ``setpoint`` is
        the servos' current position setpoints.
        """
        p = self.params
        mujoco.mj_jacSite(self.model, data, self._jacp, None, self.site_id)
        if self._native and setpoint.flags.c_contiguous and setpoint.dtype == np.float64:
            return self._setpoints_native(data, setpoint)
        # A contiguous copy, and ndarray.dot rather than @: on these 3x10 shapes numpy's per-call
        # overhead is most of the cost (this runs every control step). The 3-vector and 3x3 steps are
        # scalar arithmetic, the same operations numpy would do element by element.
        jac = np.ascontiguousarray(self._jacp[:, self.dof_ids])
        posture = p.posture_gain * (self.nominal - setpoint)
        # Error of the hand the setpoints would give, minus what the posture step already moves.
        j0, j1, j2 = jac.dot(setpoint - data.qpos[self.qpos_ids] + posture).tolist()
        r0, r1, r2 = self.reference.tolist()
        s0, s1, s2 = data.site_xpos[self.site_id].tolist()
        error = ((r0 - s0) - j0, (r1 - s1) - j1, (r2 - s2) - j2)
        jw = jac * self._weights_rows  # J W (the weights tiled to J's shape: no broadcasting)
        # W (JW)^T (JW (JW)^T + l^2 I)^-1 e; "+ 0.0" off the diagonal as the identity matrix's zeros add
        (a, b, c), (d, e, f), (g, h, i) = jw.dot(jw.T).tolist()
        l2 = self._damping2
        system = ((a + l2, b + 0.0, c + 0.0), (d + 0.0, e + l2, f + 0.0), (g + 0.0, h + 0.0, i + l2))
        dq = self.weights * solve3(system, error).dot(jw) + posture
        values = dq.tolist()
        step = max(max(values), -min(values))
        if step > p.max_joint_step_rad:
            dq *= p.max_joint_step_rad / step
        dq += setpoint
        np.maximum(dq, self.lower, out=dq)
        return np.minimum(dq, self.upper, out=dq)

    def _setpoints_native(self, data: mujoco.MjData, setpoint: np.ndarray) -> np.ndarray:
        """:meth:`setpoints` after ``mj_jacSite``: the same numpy products (jac.dot, jw.dot(jw.T),
        y.dot(jw)) on the same values, the element-wise steps around them compiled."""
        k = _native.kernels
        p = self.params
        jac, jw, posture, x, y = self._native_work
        k.hand_gather(self._native_indices, self._jacp, data.qpos, setpoint, self.nominal, self.weights, p.posture_gain,
                      jac, jw, posture, x)
        k.hand_solve(jw.dot(jw.T), jac.dot(x), self.reference, data.site_xpos, self.site_id, self._damping2, y)
        dq = np.empty(len(posture))
        k.hand_finish(y.dot(jw), self.weights, posture, setpoint, p.max_joint_step_rad, self.lower, self.upper, dq)
        return dq
