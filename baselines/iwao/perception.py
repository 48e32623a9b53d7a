"""The iwao agent's memory of the obstacles: each seen point of their top faces (two corners and the
midpoints of the near and far edges: ``tasks.obstacle_walk.TOP_POINTS``) fused over time in the path frame.

A point is a still point, so every visual sample is one more measurement of the same point: the
agent adds its information ``C^-1`` (the inverse of the vision model's covariance, Eyecatch Eq. 1-3,
along and across the line of sight) to that corner's running sum (a static Kalman filter in
information form). Samples are placed in the *path frame* (x along the path from the start, y left,
z up) with the agent's own proprioception: the eye pose in the pelvis frame and the odometry block.
The covariance is evaluated at the perceived point (the agent does not know the truth). Nothing is
assumed about the obstacles except that they are boxes whose corners span the footprint, and that an
obstacle whose corners were not seen may span the walkway (its edges are painted and known).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from visuomotor_gym.baselines.crowding import crowd_std

from visuomotor_gym.tasks.obstacle_walk import N_POINTS, CourseDistribution
from visuomotor_gym.vision import periphery
from visuomotor_gym.vision.foveation import VisionParams, _sigmas

MIN_STD_M = 1e-4  # a floor for the noiseless oracle rung (its information would be infinite)
# With positional disarray in the vision model (VisionParams.position_disarray: a share of the periphery's
# excess lateral error is fixed in retinal coordinates, Hess & Field 1993) successive looks at a point
# from one retinal place share that error; the memory counts so many looks per retinal place (modelling
# choice: the 50 Hz looks of one 0.3 s fixation, during which a point off the fovea keeps its place), so
# the fixed part of a sample's variance is weighted as if shared by that many samples. Rough course,
# human_periphery(position_disarray=0.8), iwao, seeds 0-39: 35/40 with 15, 33/40 with 30, 27/40 without;
# foveation.believed_sigmas (k from the predicted slip, up to 1 s of looks) instead: 33/40 (seeds 40-79:
# 32/40 against 36/40 with 15).
DISARRAY_LOOKS = 15


def eye_motion(prev, now, dt: float):
    """(eye velocity, gaze angular velocity) in the path frame between two eye poses ``(eye position,
    gaze direction)`` (path frame) ``dt`` seconds apart: the same finite differences as the env's
    retinal slip (``core.eye.Eye.retinal_speed``)."""
    (p0, g0), (p1, g1) = prev, now
    v = ((p1[0] - p0[0]) / dt, (p1[1] - p0[1]) / dt, (p1[2] - p0[2]) / dt)
    w = ((g0[1] * g1[2] - g0[2] * g1[1]) / dt, (g0[2] * g1[0] - g0[0] * g1[2]) / dt,
         (g0[0] * g1[1] - g0[1] * g1[0]) / dt)
    return v, w


def still_point_slip(u, d: float, v, w) -> float:
    """Speed (rad/s) of the image of a still point at distance ``d`` along the unit line of sight ``u``
    for an eye moving at ``v`` whose gaze turns at ``w``: the line of sight's angular velocity
    ``u x (-v) / d`` minus ``w``, across the line of sight."""
    ux, uy, uz = u
    ax, ay, az = -v[0], -v[1], -v[2]
    sx = (uy * az - uz * ay) / d - w[0]
    sy = (uz * ax - ux * az) / d - w[1]
    sz = (ux * ay - uy * ax) / d - w[2]
    along = sx * ux + sy * uy + sz * uz
    sx, sy, sz = sx - along * ux, sy - along * uy, sz - along * uz
    return math.sqrt(sx * sx + sy * sy + sz * sz)


class Corner:
    """Information-form estimate of one still point."""

    __slots__ = ("_dirty", "_est", "info", "n", "vec")

    def __init__(self, height_prior: tuple[float, float] | None = None) -> None:
        self.info = [0.0] * 6  # xx, xy, xz, yy, yz, zz
        self.vec = [0.0, 0.0, 0.0]
        if height_prior is not None:  # information on z alone: the point's height above the floor
            mean, sd = height_prior
            self.info[5] = 1.0 / (sd * sd)
            self.vec[2] = mean / (sd * sd)
        self.n = 0
        self._est = None
        self._dirty = True

    def add(self, z: tuple[float, float, float], u: tuple[float, float, float], s_depth: float, s_lat: float) -> None:
        """A sample ``z`` with std ``s_depth`` along the unit line of sight ``u`` and ``s_lat`` across it."""
        a = 1.0 / (s_lat * s_lat)
        b = 1.0 / (s_depth * s_depth) - a
        ux, uy, uz = u
        I = self.info  # noqa: E741 (the information matrix)
        I[0] += a + b * ux * ux
        I[1] += b * ux * uy
        I[2] += b * ux * uz
        I[3] += a + b * uy * uy
        I[4] += b * uy * uz
        I[5] += a + b * uz * uz
        uz_dot = ux * z[0] + uy * z[1] + uz * z[2]
        v = self.vec
        v[0] += a * z[0] + b * ux * uz_dot
        v[1] += a * z[1] + b * uy * uz_dot
        v[2] += a * z[2] + b * uz * uz_dot
        self.n += 1
        self._dirty = True

    def prior(self):
        """The estimate to linearise the next sample at (refreshed every 4 samples), None before 2."""
        if self.n < 2:
            return None
        if self._est is None or (self._dirty and self.n % 4 == 0):
            self.estimate()
        return self._est[0]

    def _matrix(self) -> np.ndarray:
        xx, xy, xz, yy, yz, zz = self.info
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])

    def estimate(self) -> tuple[np.ndarray, np.ndarray]:
        """(position, standard deviations along x, y, z) of the fused estimate."""
        if self._dirty:
            cov = np.linalg.inv(self._matrix())
            self._est = (cov @ np.array(self.vec), np.sqrt(np.maximum(np.diag(cov), 0.0)))
            self._dirty = False
        return self._est


@dataclass
class ObstacleEstimate:
    """A box from its two fused corners (path frame): footprint, height and their uncertainties."""

    index: int
    x0: float
    x1: float
    y0: float
    y1: float
    height: float
    sx: float  # std of the x extents
    sy: float
    sz: float


NEAR_LEFT, FAR_RIGHT, NEAR_MID, FAR_MID = range(N_POINTS)  # the order of tasks.obstacle_walk.TOP_POINTS


def _fused(estimates: list, axis: int) -> tuple[float, float]:
    """Inverse-variance mean and std along ``axis`` of ``(position, stds)`` estimates of one coordinate."""
    w = [1.0 / max(float(s[axis]), 1e-6) ** 2 for _, s in estimates]
    total = sum(w)
    return sum(wi * float(p[axis]) for wi, (p, _) in zip(w, estimates)) / total, math.sqrt(1.0 / total)


class ObstacleMemory:
    """Fused points of every obstacle seen so far, by course index. ``walkway_half_width_m``: the
    lateral extent assumed for a side whose corner was not seen (the obstacle may span the walkway)."""

    def __init__(self, vision: VisionParams,
                 walkway_half_width_m: float = 0.5 * CourseDistribution().walkway_width_m,
                 height_prior: tuple[float, float] | None = None, gate: float | None = None) -> None:
        self.vision = vision
        self.walkway_half_width_m = walkway_half_width_m
        # (mean, std) in metres of a point's height above the floor before any sample, or None: no prior.
        # A top face on the floor is placed by the angle of its line of sight below the horizon, given
        # the eye's height (Ooi, Wu & He 2001, Nature 414:197); see IwaoParams.height_prior_m.
        self.height_prior = height_prior
        self.gate = gate  # outlier gate of add (in stds), or None: every sample fused (iwao v0)
        self.corners: dict[int, tuple[Corner, ...]] = {}

    def reset(self) -> None:
        self.corners = {}

    def add(self, index: int, which: int, p_eye, eye_pos, rot_rows, odo, motion=None, vergence=None,
            crowded: bool = False) -> None:
        """One sample of point ``which`` (``TOP_POINTS`` order: 0 near-left, 1 far-right, 2 near-edge
        midpoint, 3 far-edge midpoint) of obstacle ``index``: ``p_eye`` in
        the eye frame, ``eye_pos`` and ``rot_rows`` (3x3, columns = eye axes) in the pelvis frame,
        ``odo`` = (x, y, yaw, pelvis height) placing the pelvis frame in the path frame. ``motion`` =
        (eye velocity, gaze angular velocity), path frame, over the control step that ended with this
        sample (the agent's efference copy and proprioception: :func:`eye_motion`): the retinal slip of
        a still point, which widens the lateral noise above the knee (``VisionParams``
        ``position_slip_knee_deg_s``, Westheimer & McKee 1975), is predicted from it; None: no slip.
        ``vergence``: the eye's vergence distance (m, proprioception) for the depth law of
        ``VisionParams.depth_pedestal_arcmin`` (no effect without it). ``crowded``: the sample may be
        pooled with another obstacle's (``baselines.crowding``): both stds are at least
        ``crowding.crowd_std`` (the spread of the crowding zone)."""
        ex, ey, ez = p_eye
        d = math.sqrt(ex * ex + ey * ey + ez * ez)
        if d <= 0.0:
            return
        ecc = math.acos(max(-1.0, min(1.0, ex / d)))
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rot_rows
        bx = eye_pos[0] + r00 * ex + r01 * ey + r02 * ez
        by = eye_pos[1] + r10 * ex + r11 * ey + r12 * ez
        bz = eye_pos[2] + r20 * ex + r21 * ey + r22 * ez
        lx, ly, lz = bx - eye_pos[0], by - eye_pos[1], bz - eye_pos[2]
        ox, oy, yaw, pz = odo
        c, s = math.cos(yaw), math.sin(yaw)
        z = (ox + c * bx - s * by, oy + s * bx + c * by, pz + bz)
        u = ((c * lx - s * ly) / d, (s * lx + c * ly) / d, lz / d)
        points = self.corners.get(index)
        if points is None:
            points = self.corners[index] = tuple(Corner(self.height_prior) for _ in range(N_POINTS))
        corner = points[which]
        eye_w = (z[0] - d * u[0], z[1] - d * u[1], z[2] - d * u[2])  # the eye, path frame
        # The noise is spread along and across the *true* line of sight at the *true* distance, which the
        # agent does not know. The perceived point is no guide when the depth noise is as large as the
        # distance (~40 deg off the fovea): it may come out next to the eye or behind it, its direction
        # then wrong by a lot. So, as an extended Kalman filter linearises at its prior, the line of sight
        # and the distance are those of the point's current estimate; before there is one, of the point
        # where the perceived ray meets the plane 0.15 m above the floor (mid-range of the obstacles).
        prior = corner.prior()
        if prior is not None:
            # (As Python floats: the same values as the estimate's numpy ones, and the arithmetic below,
            # down to the information sums, stays in plain floats, which are faster than numpy scalars.)
            px, py, pz = prior.tolist()
            lx, ly, lz = px - eye_w[0], py - eye_w[1], pz - eye_w[2]
            d_ref = math.sqrt(lx * lx + ly * ly + lz * lz)
            u = (lx / d_ref, ly / d_ref, lz / d_ref)
        else:
            if u[2] >= -0.02 or u[0] <= 0.0:  # an obstacle's top lies ahead and below the eye
                return
            d_ref = (eye_w[2] - 0.15) / -u[2]
            if d < 0.3 * d_ref:  # too near to trust its direction
                return
        d_ref = min(max(d_ref, 0.3), 30.0)
        slip = 0.0 if motion is None else still_point_slip(u, d_ref, *motion)
        s_depth, s_lat = _sigmas(d_ref, ecc, slip, self.vision, vergence)[:2]
        if self.vision.position_disarray > 0.0 and self.vision.foveated:
            # the fixed part w of the lateral variance counts DISARRAY_LOOKS times (see DISARRAY_LOOKS)
            s_lat *= math.sqrt(1.0 + (DISARRAY_LOOKS - 1) * periphery.disarray_weight(ecc, self.vision))
        if crowded:
            s_depth, s_lat = max(s_depth, crowd_std(d_ref, ecc, self.vision)), max(s_lat, crowd_std(d_ref, ecc, self.vision))
        if self.gate is not None and prior is not None and corner.n >= 3:
            # Robust fusion: a sample whose line of sight misses the point's estimate by more than ``gate``
            # times sqrt(its lateral variance + the estimate's variance summed over x, y, z) is an outlier
            # (a crowded percept pooled with a flanker the agent could not flag: Bouma 1970) and is not
            # fused. (The estimate's variance along the line of sight counts too: a lenient gate while
            # the point is placed only along one line, modelling choice.)
            px, py, pz = prior.tolist()
            rx, ry, rz = px - z[0], py - z[1], pz - z[2]
            along = rx * u[0] + ry * u[1] + rz * u[2]
            miss2 = rx * rx + ry * ry + rz * rz - along * along
            est_sd = corner.estimate()[1]
            var = s_lat * s_lat + float(est_sd[0] ** 2 + est_sd[1] ** 2 + est_sd[2] ** 2)
            if miss2 > self.gate * self.gate * var:
                return
        corner.add(z, u, max(s_depth, MIN_STD_M), max(s_lat, MIN_STD_M))

    def obstacle(self, index: int) -> ObstacleEstimate | None:
        """The box of obstacle ``index`` once its near and its far edge were seen (each at a corner or at
        its midpoint), else None. A side whose corner was not seen extends to the walkway's edge."""
        points = self.corners.get(index)
        if points is None:
            return None
        est = [pt.estimate() if pt.n else None for pt in points]
        near = [e for e in (est[NEAR_LEFT], est[NEAR_MID]) if e is not None]
        far = [e for e in (est[FAR_RIGHT], est[FAR_MID]) if e is not None]
        if not near or not far:
            return None
        x0, s_x0 = _fused(near, 0)
        x1, s_x1 = _fused(far, 0)
        height, s_z = _fused(near + far, 2)
        half = self.walkway_half_width_m
        y1, s_y1 = (float(est[NEAR_LEFT][0][1]), float(est[NEAR_LEFT][1][1])) if est[NEAR_LEFT] else (half, 0.0)
        y0, s_y0 = (float(est[FAR_RIGHT][0][1]), float(est[FAR_RIGHT][1][1])) if est[FAR_RIGHT] else (-half, 0.0)
        return ObstacleEstimate(index, min(x0, x1), max(x0, x1), min(y0, y1), max(y0, y1), max(height, 0.0),
                                max(s_x0, s_x1), max(s_y0, s_y1), s_z)

    def known(self) -> list[ObstacleEstimate]:
        out = []
        for i in sorted(self.corners):
            est = self.obstacle(i)
            if est is not None:
                out.append(est)
        return out
