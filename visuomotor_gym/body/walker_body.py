"""The walker as a :class:`~visuomotor_gym.core.parts.Body`: the footstep action block, proprioception
and the pelvis frame over the scripted gait of :mod:`visuomotor_gym.body.walker`.

Action block ``footstep`` (3 values in [-1, 1], mapped linearly onto the gait's ranges of
:class:`~visuomotor_gym.body.walker.GaitParams`): step length (0.25-0.95 m), lateral offset from the
nominal step width (-0.3-0.3 m, + = left) and toe clearance (0.02-0.45 m). The command is handed to
the gait every control step and *read at each mid-stance* for the next step of the foot in stance
(:meth:`WalkerGait.set_next_footstep`); an action of 0 asks for a 0.60 m step, straight, with 0.235 m
clearance (the middle of each range; modelling choice: linear maps, as the other bodies' actions).

:class:`TurningWalkerBody` (SteppingStones) has a fourth footstep value, the **turn** of the new
foothold's heading from the previous one's, linear onto +-45 deg (``GaitParams.max_turn_deg``; 0 =
straight on), on :class:`~visuomotor_gym.body.walker.TurningGait`, and one more observation block,
``foothold_headings``. ObstacleWalk and ObstacleDodge keep :class:`WalkerBody`.

Observations are expressed in the pelvis frame (:class:`~visuomotor_gym.core.frames.RootFrame`:
origin at the pelvis, x along its heading, z up).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.walker import DEG, GaitParams, TurningGait, WalkerGait
from visuomotor_gym.core.frames import RootFrame
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Body

N_FOOTHOLDS_OBSERVED = 3  # the last three latched footholds (modelling choice: the landed one and the two planned)

WALKER_BLOCKS = (
    Block("gait_phase", 3, "0..1, 0..1, s",
          "step phase (0 at a heel strike), stride phase (0 at a left heel strike), time until the next "
          "mid-stance, when the footstep action is read"),
    Block("pelvis", 4, "m, m/s",
          "pelvis height above the floor; pelvis velocity (forward, left, up) in the pelvis frame"),
    Block("feet_pos", 6, "m", "left and right sole centres, pelvis frame"),
    Block("footholds", 3 * N_FOOTHOLDS_OBSERVED, "m, m, 0/1",
          "the last three latched footholds, oldest first: (x, y) in the pelvis frame and the foot "
          "(0 left, 1 right); the newest is where the next footstep's length and offset count from"),
    Block("leg_qpos", 10, "rad", "left then right leg joints: hip roll, hip pitch, knee, ankle pitch, ankle roll"),
)


class WalkerBody(Body):
    """Footstep actions, proprioception and events of the walker (``envs_assets/walker.xml``)."""

    observation_blocks = WALKER_BLOCKS
    trace_step_fields = ("pelvis_pos", "feet_pos")
    action_structure = {"footstep": 3}  # noqa: RUF012 (a body replaces it, never mutates it)
    n_action = 3
    gait_class = WalkerGait

    def __init__(self, model: mujoco.MjModel, params: GaitParams | None = None) -> None:
        self.model = model
        self.gait = self.gait_class(model, params)
        self.p = self.gait.p
        self.frame = RootFrame(self.gait.pelvis_body)
        (l0, l1), (a0, a1), (c0, c1) = self.p.step_range_m, self.p.lateral_range_m, self.p.clearance_range_m
        self._maps = ((0.5 * (l0 + l1), 0.5 * (l1 - l0)), (0.5 * (a0 + a1), 0.5 * (a1 - a0)),
                      (0.5 * (c0 + c1), 0.5 * (c1 - c0)))
        leg = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in wn.WALKER_LEG_JOINTS[0] + wn.WALKER_LEG_JOINTS[1]]
        self._leg_qpos = [int(model.jnt_qposadr[j]) for j in leg]
        self._root_dof = [int(model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)])
                          for n in wn.WALKER_ROOT_JOINTS[:3]]
        # The same indices as slices where they are evenly spaced (a slice reads faster than a list).
        self._leg_qpos_at = _as_slice(self._leg_qpos)
        self._root_dof_at = _as_slice(self._root_dof)
        self._soles_at = _as_slice(self.gait.sole_sites)
        self.start_xy = (0.0, 0.0)
        self.start_yaw = 0.0

    def footstep_from_action(self, a0: float, a1: float, a2: float) -> tuple[float, float, float]:
        """(length, lateral, clearance) in metres for a footstep action in [-1, 1]^3."""
        (lc, lh), (ac, ah), (cc, ch) = self._maps
        return lc + a0 * lh, ac + a1 * ah, cc + a2 * ch

    @staticmethod
    def action_from_footstep(length: float, lateral: float, clearance: float, p: GaitParams | None = None):
        """The inverse of :meth:`footstep_from_action` (for agents), clipped to [-1, 1]."""
        p = p or GaitParams()
        out = []
        for value, (lo, hi) in ((length, p.step_range_m), (lateral, p.lateral_range_m),
                                (clearance, p.clearance_range_m)):
            out.append(min(max((2.0 * value - lo - hi) / (hi - lo), -1.0), 1.0))
        return out

    # --- episode ------------------------------------------------------------------------------
    def reset_pose(self, data: mujoco.MjData) -> None:
        """Walking at the nominal speed, left heel striking at the path's start."""
        x, y = self.start_xy
        self.gait.reset(self.model, data, x, y, self.start_yaw)

    def start(self, data: mujoco.MjData) -> None:
        self.frame.update(data)

    # --- control ------------------------------------------------------------------------------
    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None:
        self.gait.set_next_footstep(*self.footstep_from_action(al[0], al[1], al[2]))
        self.gait.advance(data, dt)

    # --- state --------------------------------------------------------------------------------
    def observe(self, values: list, data: mujoco.MjData) -> None:
        """Append the :data:`WALKER_BLOCKS` (``frame`` must be current: the env updates it before the
        observation, since it moves with the pelvis).

        Written out in scalar Python (the gait's ``step_phase``, ``stride_phase``, ``next_latch_time
        - time``, ``foothold_world`` and the frame's ``to_local``, inline): the same operations in the
        same order, so the same values."""
        d, g, f = data, self.gait, self.frame
        tick, T, ts = g.tick, g.T, g.timestep
        values += ((tick % T) / T, (tick % (2 * T)) / (2 * T), g.next_latch_tick * ts - tick * ts)
        vx, vy, vz = d.qvel[self._root_dof_at].tolist()
        c, s = f._cos, f._sin
        ox, oy, oz = f.origin_list
        values += (oz, c * vx + s * vy, -s * vx + c * vy, vz)
        for x, y, z in d.site_xpos[self._soles_at].tolist():
            dx, dy = x - ox, y - oy
            values += (c * dx + s * dy, -s * dx + c * dy, z - oz)
        n = (g.next_latch_tick - g.T_mid) // T + 2  # g.next_footstep_index
        gu, gv, (gx, gy), gc, gs = g.u, g.v, g.origin, g.path_cos, g.path_sin
        for j in range(n - N_FOOTHOLDS_OBSERVED, n):
            u, v = gu[j], gv[j]
            dx, dy = gx + gc * u - gs * v - ox, gy + gs * u + gc * v - oy
            values += (c * dx + s * dy, -s * dx + c * dy, float(j % 2))
        values += d.qpos[self._leg_qpos_at].tolist()

    def info(self, data: mujoco.MjData) -> dict:
        g = self.gait
        tick, T = g.tick, g.T
        return {
            "pelvis_pos": data.xpos[g.pelvis_body].copy(),
            "feet_pos": data.site_xpos[self._soles_at].copy(),
            "step_phase": (tick % T) / T,
            "stride_phase": (tick % (2 * T)) / (2 * T),
        }


TURNING_WALKER_BLOCKS = (
    *WALKER_BLOCKS,
    Block("foothold_headings", N_FOOTHOLDS_OBSERVED, "rad",
          "heading of each of the three footholds of the footholds block (the direction its foot points "
          "when flat on it and the frame of the next footstep), relative to the pelvis heading, + = left"),
)


class TurningWalkerBody(WalkerBody):
    """The walker on :class:`~visuomotor_gym.body.walker.TurningGait` (SteppingStones): the footstep
    block has a fourth value, the **turn** of the footstep's heading from the previous foothold's,
    linear onto +-``GaitParams.max_turn_deg`` (0 = straight on), and the observation a
    ``foothold_headings`` block after the walker's blocks. The first three footstep values are those of
    :class:`WalkerBody`, counted in the new heading's frame."""

    observation_blocks = TURNING_WALKER_BLOCKS
    action_structure = {"footstep": 4}  # noqa: RUF012  (as WalkerBody's: a class-level description)
    n_action = 4
    gait_class = TurningGait

    def __init__(self, model: mujoco.MjModel, params: GaitParams | None = None) -> None:
        super().__init__(model, params)
        self._turn = self.p.max_turn_deg * DEG
        self._yaw_qpos = self.gait.qpos_index[3]

    @staticmethod
    def action_from_turn(turn: float, p: GaitParams | None = None) -> float:
        """The turn action in [-1, 1] for a heading change ``turn`` (rad)."""
        p = p or GaitParams()
        return min(max(turn / (p.max_turn_deg * DEG), -1.0), 1.0)

    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None:
        self.gait.set_next_footstep(*self.footstep_from_action(al[0], al[1], al[2]), turn=al[3] * self._turn)
        self.gait.advance(data, dt)

    def observe(self, values: list, data: mujoco.MjData) -> None:
        super().observe(values, data)
        g = self.gait
        n = (g.next_latch_tick - g.T_mid) // g.T + 2
        yaw = float(data.qpos[self._yaw_qpos])
        for j in range(n - N_FOOTHOLDS_OBSERVED, n):
            values.append(math.remainder(g.yaw + g.h[j] - yaw, 2.0 * math.pi))


def _as_slice(indices: list[int]):
    """``indices`` as a slice when they are evenly spaced and ascending (a slice reads faster than a
    list of indices, and selects the same rows), else the list itself."""
    if len(indices) >= 2 and indices[1] > indices[0]:
        step = indices[1] - indices[0]
        if indices == list(range(indices[0], indices[-1] + 1, step)):
            return slice(indices[0], indices[-1] + 1, step)
    elif len(indices) == 1:
        return slice(indices[0], indices[0] + 1)
    return indices
