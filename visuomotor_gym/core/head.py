"""The head: a 2-DOF neck (Donders' law: yaw, then pitch; Eyecatch section 4.2) driven by
integrated-velocity servos toward a commanded posture at a limited speed.

The neck's joints, ranges and servos come from the shared head+eye fragment
(``envs_assets/common/head_eye.xml``), the one source of the neck limits: :func:`neck_range_deg`
reads them from it for code that has no compiled model (action encoders, planners).
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET

import mujoco
import numpy as np

from visuomotor_gym.assets import asset_path
from visuomotor_gym.body import names
from visuomotor_gym.core.observation import Block
from visuomotor_gym.oculomotor.plant import DEG, OculomotorParams

HEAD_BLOCKS = (
    Block("head_qpos", 2, "rad", "neck yaw and pitch"),
    Block("head_qvel", 2, "rad/s", "neck yaw and pitch velocities"),
)
HEAD_ACTION_STRUCTURE = {"head": 2}
HEAD_FRAGMENT = "common/head_eye.xml"


@functools.cache
def neck_range_deg() -> tuple[tuple[float, float], ...]:
    """(yaw, pitch) joint ranges in degrees, read from the head+eye fragment's neck joints."""
    root = ET.parse(asset_path(HEAD_FRAGMENT)).getroot()
    joints = {j.get("name"): j for j in root.iter("joint")}
    out = []
    for name in names.NECK_JOINTS:
        lo, hi = (float(x) for x in joints[name].get("range").split())
        out.append((lo, hi))
    return tuple(out)


class Head:
    """The neck of a model that holds the head+eye fragment.

    The head action (one value per neck joint in [-1, 1]) maps 0 to straight ahead and +-1 to the
    joint's range ends; the servo is driven toward that posture at <= ``head_max_deg_s``.
    """

    def __init__(self, model: mujoco.MjModel, params: OculomotorParams) -> None:
        m = model
        neck_j = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names.NECK_JOINTS]
        qpos = [int(m.jnt_qposadr[j]) for j in neck_j]
        dofs = [int(m.jnt_dofadr[j]) for j in neck_j]
        self._qpos = slice(qpos[0], qpos[1] + 1) if qpos[1] == qpos[0] + 1 else np.array(qpos)
        self._dof = slice(dofs[0], dofs[1] + 1) if dofs[1] == dofs[0] + 1 else np.array(dofs)
        self.range = m.jnt_range[neck_j].copy()  # radians (compiled)
        self._range_list = self.range.tolist()
        self._act = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in names.NECK_ACTUATORS]
        self._actadr = [int(m.actuator_actadr[a]) for a in self._act]
        self._vmax = params.head_max_deg_s * DEG
        self.body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.HEAD)

    def reset(self, data: mujoco.MjData) -> None:
        """Straight ahead, servo setpoints equal to it."""
        data.qpos[self._qpos] = 0.0
        data.act[self._actadr] = 0.0

    def command(self, data: mujoco.MjData, yaw: float, pitch: float, dt: float) -> None:
        """Velocity-limited position servo toward the posture of the head action (yaw, pitch)."""
        vmax = self._vmax
        act, ctrl = data.act, data.ctrl
        for k, h in enumerate((yaw, pitch)):
            lo_h, hi_h = self._range_list[k]
            v = ((h * hi_h if h >= 0 else -h * lo_h) - act[self._actadr[k]]) / dt
            ctrl[self._act[k]] = min(max(v, -vmax), vmax)

    def observe(self, values: list, data: mujoco.MjData) -> None:
        """Append the :data:`HEAD_BLOCKS`."""
        values += data.qpos[self._qpos].tolist()
        values += data.qvel[self._dof].tolist()

    def info(self, data: mujoco.MjData) -> dict:
        return {
            "head_qpos": data.qpos[self._qpos].copy(),
            "head_dir": data.xmat[self.body, 0::3].copy(),  # the head's forward axis, world
        }
