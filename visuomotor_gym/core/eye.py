"""The eye as one object: the oculomotor plant, vergence, the vestibulo-ocular reflex (VOR), the
eye-frame pose cache, retinal slip and the gaze overlay drawn into rendered scenes.

Every body carries the same head+eye MJCF fragment (``envs_assets/common/head_eye.xml``); this class
finds its joints by name. :mod:`visuomotor_gym.oculomotor.plant` stays the pure plant (gaze
direction in the world, saccades and pursuit); this class turns that world gaze into eye-in-head
angles for the current head pose (the VOR) and keeps the eye frame that vision samples in.

Scalar maths on lists on purpose: this runs every control step, and numpy's per-call cost dominates
3x3 products.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from visuomotor_gym import _native
from visuomotor_gym.body import names
from visuomotor_gym.core.observation import Block
from visuomotor_gym.geometry import rotate, rotate_t, unit_from_angles
from visuomotor_gym.oculomotor.plant import (
    _ZERO,
    DEG,
    OculomotorParams,
    OculomotorPlant,
    PlantStep,
    angles_from_direction,
    direction_from_angles,
)

GAZE_AGE_CAP_S = 1.0  # the "time since the last saccade onset" observation saturates here (modelling choice)

EYE_BLOCKS = (
    Block("eye_pos", 3, "m", "eye (globe centre) position, body frame"),
    Block("eye_rot", 9, "-", "eye frame axes in the body frame, row-major 3x3 (column 0 = gaze direction)"),
    Block("eye_in_head", 2, "rad", "eye azimuth and elevation relative to the head"),
    Block("fixation", 1, "m", "fixation (vergence) distance"),
    Block("saccade", 2, "0/1, s", "in a saccade now; time since the last saccade onset (capped at 1 s)"),
)
EYE_ACTION_STRUCTURE = {"gaze": 2, "fixation": 1}


class Eye:
    """The cyclopean eye of a body whose model holds the shared head+eye fragment.

    Parameters
    ----------
    model : mujoco.MjModel
    params : OculomotorParams
        Saccade and pursuit limits, eye ranges (Eom et al. 2019 section 4.1), vergence rate.
    gaze_action_range : float
        Requested gaze change (rad) at a gaze action of +-1.
    record : bool
        Keep the plant's 500 Hz gaze trace.
    """

    def __init__(self, model: mujoco.MjModel, params: OculomotorParams, gaze_action_range: float,
                 record: bool = False) -> None:
        m = model

        def jid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)

        self.params = params
        self.gaze_action_range = float(gaze_action_range)
        self.plant = OculomotorPlant(params, record=record)
        self.head_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.HEAD)
        self.offset = m.body_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.EYE)].copy()
        self._offset_list = self.offset.tolist()
        eye_j = [jid(names.EYE_AZIMUTH), jid(names.EYE_ELEVATION)]
        self._qpos_az, self._qpos_el = (int(m.jnt_qposadr[j]) for j in eye_j)
        dofs = [int(m.jnt_dofadr[j]) for j in eye_j]
        self._dof = slice(dofs[0], dofs[1] + 1) if dofs[1] == dofs[0] + 1 else np.array(dofs)
        self._fix_qpos = int(m.jnt_qposadr[jid(names.EYE_FIXATION)])
        self._az_range = (params.eye_azimuth_range_deg[0] * DEG, params.eye_azimuth_range_deg[1] * DEG)
        self._el_range = (params.eye_elevation_range_deg[0] * DEG, params.eye_elevation_range_deg[1] * DEG)
        self._log_fix = (math.log(params.fixation_range_m[0]), math.log(params.fixation_range_m[1]))
        # The compiled command and VOR (visuomotor_gym._native, _kernels.c: eye_command, eye_apply), when built.
        self._native = _native.enabled() and not record
        self._native_constants = (self.gaze_action_range, *self._log_fix, params.vergence_max_diopter_s)
        self._native_ranges = (*self._az_range, *self._el_range)
        self._native_addresses = (self._qpos_az, self._qpos_el, self._fix_qpos, *dofs)
        self._views = None  # (data, its xmat, xpos, qpos, qvel): views of the data last applied to
        self.reset_state()

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_views": None}  # views into an MjData: rebuilt after unpickling

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._native = self._native and _native.enabled()  # unpickled where the extension is missing

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        """Forget the last episode's pose (before the physics is reset)."""
        self.fixation = 1.0
        self.rot_flat = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        self.pos_list = [0.0, 0.0, 0.0]
        self.in_head = (0.0, 0.0)

    def position_now(self, data: mujoco.MjData) -> np.ndarray:
        """The eye's centre (world) from the head's current kinematics."""
        return data.xpos[self.head_body] + data.xmat[self.head_body].reshape(3, 3) @ self.offset

    def look_at(self, data: mujoco.MjData, point, offset=(0.0, 0.0)) -> tuple[np.ndarray, float]:
        """The world gaze direction toward ``point`` turned by ``offset`` (azimuth, elevation; rad),
        and the point's distance from the eye. Needs current head kinematics."""
        eye_pos = self.position_now(data)
        az, el = angles_from_direction(point - eye_pos)
        return direction_from_angles(az + offset[0], el + offset[1]), float(np.linalg.norm(point - eye_pos))

    def reset(self, data: mujoco.MjData, gaze: np.ndarray, fixation: float) -> None:
        """Start the episode looking along ``gaze`` (world unit vector), fixating at ``fixation`` m."""
        self.plant.reset(gaze, time=0.0)
        self.fixation = float(fixation)
        self.apply(data)
        self.end_step()

    # --- control ------------------------------------------------------------------------------
    def command(self, g_az: float, g_el: float, g_fix: float, dt: float, n_substeps: int,
                rng: np.random.Generator) -> PlantStep:
        """Run the plant for one control step toward the requested gaze change (retinal azimuth and
        elevation of the current eye frame, in action units) and move vergence toward the fixation
        action (log-mapped onto the fixation range, rate-limited in diopters)."""
        if self._native:  # this method, compiled, unless a saccade starts
            plant = self.plant
            stepped = _native.kernels.eye_command(self.rot_flat, plant, plant._native_constants, _ZERO,
                                                  self._native_constants, g_az, g_el, g_fix, dt, n_substeps,
                                                  self.fixation)
            if stepped is not None:
                saccading, deferred, self.fixation = stepped
                return PlantStep(False, saccading, deferred)
        u = unit_from_angles(g_az * self.gaze_action_range, g_el * self.gaze_action_range)  # eye frame
        target = rotate(self.rot_flat, *u)  # world, a tuple (the plant takes one as it is)
        plant_step = self.plant.step(target, dt, n_substeps, rng)
        lo, hi = self._log_fix
        fix_target = math.exp(lo + (g_fix + 1.0) * 0.5 * (hi - lo))
        vergence = self.params.vergence_max_diopter_s * dt  # rate limit in diopters
        inv = min(max(1.0 / fix_target, 1.0 / self.fixation - vergence), 1.0 / self.fixation + vergence)
        self.fixation = 1.0 / inv
        return plant_step

    def apply(self, data: mujoco.MjData) -> None:
        """Vestibulo-ocular reflex: turn the world gaze into eye-in-head angles for the current head.

        Clamps to the eye's range (Eom 4.1); if clamped, the plant's gaze becomes what was reached.
        Needs current head kinematics. Sets the eye joints and the cached eye frame (``rot_flat``:
        the rotation's 9 numbers, row-major; ``pos_list``).
        """
        d = data
        if self._native:  # this method, compiled
            views = self._views
            if views is None or views[0] is not d:  # MjData's arrays, read once per data object
                views = self._views = (d, d.xmat, d.xpos, d.qpos, d.qvel)
            _, xmat, xpos, qpos, qvel = views
            flat, self.pos_list, self.in_head, clamped = _native.kernels.eye_apply(
                xmat, xpos, self.head_body, self.plant.gaze, self._offset_list, self._native_ranges, qpos, qvel,
                self._native_addresses, self.fixation)
            self.rot_flat = flat
            if clamped:
                self.plant.constrain(np.array(flat[0::3]))
            return
        h0, h1, h2, h3, h4, h5, h6, h7, h8 = d.xmat[self.head_body].tolist()  # head rotation, row-major
        head = (h0, h1, h2, h3, h4, h5, h6, h7, h8)
        gx, gy, gz = rotate_t(head, *self.plant.gaze.tolist())  # gaze in head coordinates
        az = math.atan2(gy, gx)
        el = math.atan2(gz, math.hypot(gx, gy))
        az_c = min(max(az, self._az_range[0]), self._az_range[1])
        el_c = min(max(el, self._el_range[0]), self._el_range[1])
        ca, sa, ce, se = math.cos(az_c), math.sin(az_c), math.cos(el_c), math.sin(el_c)
        # Eye in head: Rz(azimuth) Ry(-elevation) (Donders/Fick order of the eye joints):
        # [[ca ce, -sa, -ca se], [sa ce, ca, -sa se], [se, 0, ce]]; the eye frame is head_rot @ that.
        e00, e01, e02, e10, e11, e12, e20, e22 = ca * ce, -sa, -ca * se, sa * ce, ca, -sa * se, se, ce
        flat = [
            h0 * e00 + h1 * e10 + h2 * e20, h0 * e01 + h1 * e11, h0 * e02 + h1 * e12 + h2 * e22,
            h3 * e00 + h4 * e10 + h5 * e20, h3 * e01 + h4 * e11, h3 * e02 + h4 * e12 + h5 * e22,
            h6 * e00 + h7 * e10 + h8 * e20, h6 * e01 + h7 * e11, h6 * e02 + h7 * e12 + h8 * e22,
        ]
        self.rot_flat = flat
        if az_c != az or el_c != el:
            self.plant.constrain(np.array(flat[0::3]))
        px, py, pz = d.xpos[self.head_body].tolist()
        ox, oy, oz = rotate(head, *self._offset_list)
        self.pos_list = [px + ox, py + oy, pz + oz]
        self.in_head = (az_c, el_c)
        qpos = d.qpos
        qpos[self._qpos_az] = az_c
        qpos[self._qpos_el] = el_c
        qpos[self._fix_qpos] = self.fixation
        d.qvel[self._dof] = 0.0

    def end_step(self) -> None:
        """Remember this step's eye position and line of sight (retinal slip of the next sample)."""
        self.prev_pos = self.pos_list
        self.prev_gaze = self.rot_flat[0::3]

    # --- geometry -----------------------------------------------------------------------------
    @property
    def rot(self) -> np.ndarray:
        """The eye frame's rotation (columns: visual axis, left, up in the world), as an array."""
        return np.array(self.rot_flat).reshape(3, 3)

    @property
    def pos(self) -> np.ndarray:
        """The eye's centre (world), as an array."""
        return np.array(self.pos_list)

    def to_eye(self, position: np.ndarray, velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A world position and velocity in the current eye frame (Eyecatch Eq. 6-7, no noise)."""
        rot = self.rot
        return (position - self.pos) @ rot, velocity @ rot  # R^T (p - r), R^T v

    def retinal_speed(self, rx: float, ry: float, rz: float, vx: float, vy: float, vz: float,
                      dt: float) -> float:
        """Speed (rad/s) of a point's image on the retina: the line-of-sight angular velocity of the
        point at ``r`` (world, relative to the eye) moving at ``v`` (world), minus the gaze's own
        angular velocity over the last step (pursuit, or the head carrying a clamped eye),
        perpendicular to the line of sight. The one retinal-slip computation of the envs."""
        inv_dt = 1.0 / dt
        ex, ey, ez = self.pos_list
        px, py, pz = self.prev_pos
        ux, uy, uz = vx - (ex - px) / dt, vy - (ey - py) / dt, vz - (ez - pz) / dt
        ax, ay, az = self.prev_gaze
        r0, r3, r6 = self.rot_flat[0::3]  # the line of sight now
        wx, wy, wz = (ay * r6 - az * r3) * inv_dt, (az * r0 - ax * r6) * inv_dt, (ax * r3 - ay * r0) * inv_dt
        dist2 = rx * rx + ry * ry + rz * rz
        sx = (ry * uz - rz * uy) / dist2 - wx
        sy = (rz * ux - rx * uz) / dist2 - wy
        sz = (rx * uy - ry * ux) / dist2 - wz
        along = (sx * rx + sy * ry + sz * rz) / dist2
        sx, sy, sz = sx - along * rx, sy - along * ry, sz - along * rz
        return math.sqrt(sx * sx + sy * sy + sz * sz)

    # --- observation, info, overlay -----------------------------------------------------------
    def observe(self, values: list, frame) -> None:
        """Append the :data:`EYE_BLOCKS` (proprioception: an efference copy of the eye pose)."""
        plant = self.plant
        ex, ey, ez = self.pos_list
        if frame.fixed:  # world axes: the position relative to the origin, the rotation as it is
            ox, oy, oz = frame.origin_list
            values += (ex - ox, ey - oy, ez - oz)
            values += self.rot_flat
        else:
            values += frame.to_local(ex, ey, ez)
            values += frame.axes_local(self.rot_flat)
        values += self.in_head
        values += (
            self.fixation,
            1.0 if plant.saccade is not None else 0.0,
            min(plant.time - plant.last_onset, GAZE_AGE_CAP_S),
        )

    def draw(self, scene: mujoco.MjvScene) -> None:
        """Draw the line of sight, eye to fixation point, into a rendered scene (not the physics)."""
        if scene.ngeom >= scene.maxgeom:
            return
        start = self.pos
        end = start + self.plant.gaze * self.fixation
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), np.zeros(3), np.eye(3).ravel(),
                            np.array([0.1, 0.9, 0.2, 0.6], dtype=np.float32))
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.004, start, end)
        scene.ngeom += 1


__all__ = ["EYE_ACTION_STRUCTURE", "EYE_BLOCKS", "GAZE_AGE_CAP_S", "Eye", "OculomotorParams"]
