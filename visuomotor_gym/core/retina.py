"""The retina: what the eye perceives of the scene's visual targets.

A :class:`VisualTarget` is anything visible (a ball, an obstacle, a stepping stone, a pedestrian, a
shelf object) with a world position and velocity. :meth:`Retina.sample` turns each target into one
visual sample per control step through the foveated noise model of
:mod:`visuomotor_gym.vision.foveation` (Eyecatch Eq. 1-3), with saccadic suppression, the field of
view and the visual-delay line. The sample is ``(position, velocity, visible)`` in the eye frame at
sampling time (lists of floats; zeros when not visible).
"""

from __future__ import annotations

import math
from collections import deque

import mujoco
import numpy as np

from visuomotor_gym import _native
from visuomotor_gym.vision import foveation, periphery
from visuomotor_gym.vision.foveation import VisionParams

VISION_MODES = ("foveated", "full_view", "oracle")


def nothing() -> tuple[list, list, bool]:
    """The sample of a target that is not seen."""
    return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False


def periphery_constants(params: VisionParams) -> bytes:
    """The constants of the compiled periphery (``_kernels.c``: ``PeripheryConsts``, in its order):
    each angle in radians computed as :mod:`visuomotor_gym.vision.periphery` and
    :func:`visuomotor_gym.vision.foveation._sigmas` compute it, so both paths use the same doubles."""
    deg, p = periphery.DEG, params
    return np.array([
        1.0 if p.foveated else 0.0, 1.0 if p.field_shape == "human" else 0.0, p.field_of_view_deg * foveation.DEG,
        p.field_side_deg * deg, p.field_up_deg * deg, p.field_down_deg * deg,
        1.0 if p.crowding else 0.0, p.crowding_fovea_deg * deg, p.crowding_bouma,
        0.0 if p.position_e2_deg is None else 1.0, periphery.position_e2_deg(p) * deg,
        p.fovea_e2_deg * foveation.DEG, p.noise_scale, p.retinal_position_std_arcmin, foveation.ARCMIN,
        p.position_slip_knee_deg_s * foveation.DEG, p.retinal_velocity_weber,
        p.retinal_velocity_floor_deg_s * foveation.DEG, p.depth_std_fraction, p.depth_rate_std_fraction,
        0.0 if p.depth_pedestal_arcmin is None else 1.0,
        0.0 if p.depth_pedestal_arcmin is None else p.depth_pedestal_arcmin * periphery.ARCMIN,
        p.interocular_m, p.position_disarray, 1.0 if p.angular_on else 0.0,
    ], dtype=np.float64).tobytes()


class VisualTarget:
    """Something the eye can see. Subclasses give its world position and velocity as arrays
    (:meth:`state`) and say when the scene hides it (``hidden``: behind its thrower, out of play, not
    yet placed); the retina decides the rest (field of view, saccades, noise, delay).

    For crowding (``VisionParams.crowding``, :func:`visuomotor_gym.vision.periphery.crowding_groups`):
    ``kind`` -- only targets of the same kind crowd one another; ``group`` -- the object the target is a
    point of (None: the target is an object of its own, named ``name``); points of one object do not
    crowd one another."""

    name: str = "target"
    hidden: bool = False
    kind: str = "target"
    group: str | None = None

    def state(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class FreeBodyTarget(VisualTarget):
    """A target on a free joint: position and velocity are its qpos/qvel (world)."""

    def __init__(self, name: str, qpos_adr: int, dof_adr: int) -> None:
        self.name = name
        self.qpos_adr = int(qpos_adr)
        self.dof_adr = int(dof_adr)

    def state(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        q, v = self.qpos_adr, self.dof_adr
        return data.qpos[q : q + 3], data.qvel[v : v + 3]


class PointTarget(VisualTarget):
    """A still point of the scene (a corner of an obstacle's top face, a stone's centre): its world
    position is whatever the task last wrote into ``position`` (a length-3 array), its velocity zero.
    ``hidden`` (a plain attribute here) hides it, e.g. while its object is parked out of the scene."""

    _ZERO = np.zeros(3)

    def __init__(self, name: str, group: str | None = None) -> None:
        self.name = name
        self.group = group  # the object this is a point of (crowding); None: a point object of its own
        self.position = np.zeros(3)
        self.hidden = True

    def place(self, x: float, y: float, z: float) -> None:
        """Put the point at (x, y, z) (world) and show it."""
        self.position[:] = (x, y, z)
        self.hidden = False

    def state(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        return self.position, self._ZERO


class Retina:
    """Visual samples of targets.

    Parameters
    ----------
    mode : str
        ``"foveated"`` (noise grows with eccentricity, nothing outside the field of view or during a
        saccade), ``"full_view"`` (foveal noise everywhere; ``params.foveated`` must be False) or
        ``"oracle"`` (the true state, noiseless).
    params : VisionParams
    delay_steps : int
        Visual latency in control steps: a sample reaches the observation this many steps later
        (nothing is seen before the first one arrives).
    dt : float
        Control period (s), for retinal slip.
    """

    def __init__(self, mode: str, params: VisionParams, delay_steps: int, dt: float) -> None:
        if mode not in VISION_MODES:
            raise ValueError(f"vision={mode!r} is not one of {list(VISION_MODES)}")
        self.mode = mode
        self.params = params
        self.delay_steps = int(delay_steps)
        self.dt = float(dt)
        # Slightly wider than the field (1e-9 rad): foveation.perceive makes the exact decision.
        self._cos_fov = math.cos(min(params.field_of_view_deg * foveation.DEG + 1e-9, math.pi))
        # The compiled _see_all (visuomotor_gym._native, _kernels.c: retina_see_all), when built; its
        # constants in the order of its VisionConsts struct.
        # With the periphery's mechanisms (params.periphery_on) the compiled _see_all_periphery
        # (_kernels.c: retina_see_periphery) and its constants (periphery_constants).
        self._native = _native.enabled()
        deg = foveation.DEG
        self._native_constants = np.array([
            1.0 if params.foveated else 0.0, self._cos_fov, params.field_of_view_deg * deg, params.noise_scale,
            params.retinal_position_std_arcmin, foveation.ARCMIN, params.retinal_velocity_weber,
            params.retinal_velocity_floor_deg_s * deg, params.depth_std_fraction, params.depth_rate_std_fraction,
            params.fovea_e2_deg * deg, params.position_slip_knee_deg_s * deg,
        ], dtype=np.float64).tobytes()
        self._periphery_constants = periphery_constants(params)
        self.reset()

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self.__dict__.setdefault("_disarray", None)  # pickled before the positional disarray existed
        self.__dict__.setdefault("last_samples", None)
        self._native = self._native and _native.enabled()  # unpickled where the extension is missing
        if "_periphery_constants" not in state:  # pickled before the compiled periphery existed
            self._periphery_constants = periphery_constants(self.params)

    def reset(self) -> None:
        self._delay: deque = deque(maxlen=self.delay_steps + 1)
        self._disarray = None
        self.last_samples = None

    def draw_field(self, rng: np.random.Generator) -> None:
        """Draw this episode's positional-disarray field from ``rng``
        (:class:`~visuomotor_gym.vision.periphery.DisarrayField`): only on a foveated eye with
        ``params.position_disarray`` > 0; otherwise nothing is drawn (the env's random stream is
        untouched). The env calls it once per reset, after the task has drawn its scenario."""
        if self.mode == "foveated" and self.params.foveated and self.params.position_disarray > 0.0:
            self._disarray = periphery.DisarrayField(self.params, rng)

    def sample(self, data: mujoco.MjData, targets, eye, saccading: bool, rng: np.random.Generator) -> list:
        """One sample per target (in order), after the visual-delay line."""
        if self.mode == "oracle":
            samples = [self._see(data, t, eye, saccading, rng) for t in targets]
        elif self.params.foveated and saccading:  # saccadic suppression: nothing of any target
            samples = [nothing() for _ in targets]
        else:
            samples = self._see_all(data, targets, eye, rng)
        self.last_samples = samples  # this step's samples before the delay line (a task's percept of its time)
        if self.delay_steps:
            self._delay.append(samples)
            if len(self._delay) <= self.delay_steps:  # nothing has reached the brain yet
                return [nothing() for _ in targets]
            return self._delay[0]
        return samples

    def _see_all(self, data, targets, eye, rng) -> list:
        """:meth:`_see` of every target (not the oracle, no saccade in flight), with the eye's pose read
        once: the same arithmetic in the same order, without a call and its look-ups per target (a
        walker's course hands the retina a dozen targets every step)."""
        if self.params.periphery_on:
            return self._see_all_periphery(data, targets, eye, rng)
        if self._native:  # this method, compiled
            return _native.kernels.retina_see_all(targets, data, eye.pos_list + eye.prev_pos + eye.prev_gaze
                                                  + eye.rot_flat, self.dt, self._native_constants, rng)
        vp = self.params
        foveated = vp.foveated
        cos_fov = self._cos_fov
        ex, ey, ez = eye.pos_list
        rot = eye.rot_flat
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = rot
        dt = self.dt
        perceive = foveation.perceive
        out = []
        for target in targets:
            if target.hidden:
                out.append(nothing())
                continue
            pos, vel = target.state(data)
            bx, by, bz = pos.tolist()
            rx, ry, rz = bx - ex, by - ey, bz - ez
            # R^T (p - r) (rotate_t, Eyecatch Eq. 6-7)
            px = r0 * rx + r3 * ry + r6 * rz
            if foveated and px < cos_fov * math.sqrt(rx * rx + ry * ry + rz * rz):
                out.append(nothing())  # outside the field of view (before the costlier retinal slip)
                continue
            pos_eye = [px, r1 * rx + r4 * ry + r7 * rz, r2 * rx + r5 * ry + r8 * rz]
            vx, vy, vz = vel.tolist()
            vel_eye = [r0 * vx + r3 * vy + r6 * vz, r1 * vx + r4 * vy + r7 * vz, r2 * vx + r5 * vy + r8 * vz]
            retinal_speed = eye.retinal_speed(rx, ry, rz, vx, vy, vz, dt)
            out.append(perceive(pos_eye, vel_eye, retinal_speed, vp, rng))
        return out

    def _see_all_periphery(self, data, targets, eye, rng) -> list:
        """:meth:`_see_all` with the human periphery of :mod:`visuomotor_gym.vision.periphery`: the field
        of view of ``params.field_shape``; crowding, each crowded target seen at the mean position and
        velocity (eye frame) of its group (:func:`~visuomotor_gym.vision.periphery.crowding_groups`: each
        flanking object once), with the noise of a look at that mean (its distance and eccentricity; the
        target's own retinal slip); the position law and the depth law (the eye's
        vergence distance ``eye.fixation``) inside :func:`~visuomotor_gym.vision.foveation.perceive`.
        One ``rng.standard_normal(6)`` per seen target, in target order, as without them."""
        if self._native:  # this method, compiled
            return _native.kernels.retina_see_periphery(targets, data, eye.pos_list + eye.prev_pos + eye.prev_gaze
                                                        + eye.rot_flat, self.dt, self._periphery_constants, rng,
                                                        eye.fixation, self._disarray)
        vp = self.params
        ex, ey, ez = eye.pos_list
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = eye.rot_flat
        dt = self.dt
        seen = []  # (target index, position, velocity (eye frame), retinal speed, distance)
        for i, target in enumerate(targets):
            if target.hidden:
                continue
            pos, vel = target.state(data)
            bx, by, bz = pos.tolist()
            rx, ry, rz = bx - ex, by - ey, bz - ez
            pos_eye = [r0 * rx + r3 * ry + r6 * rz, r1 * rx + r4 * ry + r7 * rz, r2 * rx + r5 * ry + r8 * rz]
            if not periphery.in_field(*pos_eye, vp):
                continue
            vx, vy, vz = vel.tolist()
            vel_eye = [r0 * vx + r3 * vy + r6 * vz, r1 * vx + r4 * vy + r7 * vz, r2 * vx + r5 * vy + r8 * vz]
            d = math.sqrt(pos_eye[0] ** 2 + pos_eye[1] ** 2 + pos_eye[2] ** 2)
            seen.append((i, pos_eye, vel_eye, eye.retinal_speed(rx, ry, rz, vx, vy, vz, dt), d))
        if vp.crowding and len(seen) > 1:
            dirs = [[c / d for c in p] if d > 0.0 else [1.0, 0.0, 0.0] for _, p, _, _, d in seen]
            eccs = [math.acos(max(-1.0, min(1.0, u[0]))) for u in dirs]
            kinds = [targets[i].kind for i, *_ in seen]
            objects = [targets[i].name if targets[i].group is None else targets[i].group for i, *_ in seen]
            groups = periphery.crowding_groups(dirs, eccs, kinds, objects, vp)
            positions = [p for _, p, _, _, _ in seen]
            velocities = [v for _, _, v, _, _ in seen]
            seen = [(i, periphery.pooled(positions, g), periphery.pooled(velocities, g), slip, d)
                    for (i, _, _, slip, d), g in zip(seen, groups)]
        out = [nothing() for _ in targets]
        draw = foveation._draw_at
        fixation = eye.fixation
        # A look at each (pooled) point, as foveation.perceive draws it once it is known to be seen (a
        # pooled point may lie just outside the field that holds its target: still seen): its distance and
        # eccentricity, then the disarray field at every point's place in one go (when the eye has it).
        looks = []
        for _, (x, y, z), _, _, _ in seen:
            d = math.sqrt(x * x + y * y + z * z)
            looks.append((d, math.acos(max(-1.0, min(1.0, x / d))) if d > 0.0 else 0.0))
        fixed = None
        if self._disarray is not None and seen:
            fixed = self._disarray.values([e for _, e in looks], [math.atan2(p[2], p[1]) for _, p, *_ in seen]).T.tolist()
        for k, (i, (x, y, z), vel_eye, slip, _) in enumerate(seen):
            d, ecc = looks[k]
            if d <= 0.0:
                out[i] = ([x, y, z], list(vel_eye), True)
                continue
            p, v = draw(x, y, z, d, ecc, vel_eye, slip, vp, rng, fixation, None if fixed is None else fixed[k])
            out[i] = (p, v, True)
        return out

    def _see(self, data, target: VisualTarget, eye, saccading: bool, rng) -> tuple[list, list, bool]:
        """One target's sample (see :meth:`sample`)."""
        if target.hidden:
            return nothing()
        if self.mode == "oracle":
            pos_eye, vel_eye = eye.to_eye(*target.state(data))
            return pos_eye.tolist(), vel_eye.tolist(), True
        if self.params.foveated and saccading:  # saccadic suppression
            return nothing()
        return self._see_all(data, (target,), eye, rng)[0]
