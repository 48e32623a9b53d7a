"""The lookahead agent's memory of the stones: each stone's centre fused over time on the stones' plane.

The agent knows that the stones' tops lie level with the slab it starts on (``STONE_PLANE_Z``; part of
the task's description). Every visual sample of a stone's centre is turned into a point of that plane:
the perceived direction from the eye (its distance is discarded: depth noise is 5 % of the distance at
the fovea and ~20x that 40 deg away, Eyecatch Eq. 2) is followed down to the plane. Its direction error
is the vision model's lateral standard deviation (Eyecatch Eq. 1-3, evaluated at the plane's distance
and the sample's eccentricity) over the *perceived* distance (a point whose depth noise brought it near
the eye has a direction that much less certain), which on the plane becomes ``sigma_lat`` across the
line of sight and ``sigma_lat / sin(depression)`` along it. Each stone's plane points are fused in
information form (a static Kalman filter, as the iwao agent's corners). A perceived point whose distance
came out negative (depth noise larger than the distance) lies behind the eye on the same line: its
direction is turned round. Samples are placed in the path frame (x along the slab from the start, y
left) with the agent's proprioception (eye pose in the pelvis frame, odometry).
"""

from __future__ import annotations

import math

from visuomotor_gym.baselines.crowding import crowd_std

from visuomotor_gym.tasks.stepping_stones import STONE_TOP_Z
from visuomotor_gym.vision.foveation import VisionParams, believed_sigmas

EyePose = tuple  # (eye position (3), eye axes as rows of a 3x3, columns = axes) in the path frame

STONE_PLANE_Z = STONE_TOP_Z
MIN_STD_M = 1e-4  # a floor for the noiseless oracle rung (its information would be infinite)
MIN_DEPRESSION = 0.02  # rad: a direction this close to the horizon says little about where on the plane
# With the depth law (VisionParams.depth_pedestal_arcmin), a sample perceived nearer than this share of
# the distance to the plane along its direction is dropped (modelling choice; see StoneMemory.add).
NEAR_GATE = 0.5


class _Stone:
    __slots__ = ("info", "n", "vec")

    def __init__(self) -> None:
        self.info = [0.0, 0.0, 0.0]  # xx, xy, yy
        self.vec = [0.0, 0.0]
        self.n = 0


class StoneMemory:
    """Fused centre of every stone seen so far, by course index."""

    def __init__(self, vision: VisionParams) -> None:
        self.vision = vision
        self.stones: dict[int, _Stone] = {}

    def reset(self) -> None:
        self.stones = {}

    @staticmethod
    def eye_pose(eye_pos, rot_rows, odo) -> EyePose:
        """The eye's pose in the path frame from its pose in the pelvis frame and the odometry."""
        ox, oy, yaw, pz = odo
        c, s = math.cos(yaw), math.sin(yaw)
        pos = (ox + c * eye_pos[0] - s * eye_pos[1], oy + s * eye_pos[0] + c * eye_pos[1], pz + eye_pos[2])
        rows = ((c * rot_rows[0][0] - s * rot_rows[1][0], c * rot_rows[0][1] - s * rot_rows[1][1],
                 c * rot_rows[0][2] - s * rot_rows[1][2]),
                (s * rot_rows[0][0] + c * rot_rows[1][0], s * rot_rows[0][1] + c * rot_rows[1][1],
                 s * rot_rows[0][2] + c * rot_rows[1][2]),
                tuple(rot_rows[2]))
        return pos, rows

    @staticmethod
    def _in_eye(pose: EyePose, px: float, py: float, pz: float) -> tuple[float, float, float]:
        (ex, ey, ez), ((a00, a01, a02), (a10, a11, a12), (a20, a21, a22)) = pose
        dx, dy, dz = px - ex, py - ey, pz - ez
        n = math.sqrt(dx * dx + dy * dy + dz * dz) or 1.0
        return ((a00 * dx + a10 * dy + a20 * dz) / n, (a01 * dx + a11 * dy + a21 * dz) / n,
                (a02 * dx + a12 * dy + a22 * dz) / n)

    def retinal_slip(self, px: float, py: float, pose: EyePose, prev: EyePose | None, dt: float) -> float:
        """Speed (rad/s) of the image of the still point (px, py) on the stones' plane over the last
        control step, from the eye's own poses (the point's image moves as the eye translates and turns)."""
        if prev is None:
            return 0.0
        a = self._in_eye(pose, px, py, STONE_PLANE_Z)
        b = self._in_eye(prev, px, py, STONE_PLANE_Z)
        dot = max(-1.0, min(1.0, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]))
        return math.acos(dot) / dt

    def add(self, index: int, p_eye, eye_pos, rot_rows, odo, prev: EyePose | None = None, dt: float = 0.02,
            crowded: bool = False) -> None:
        """One sample of stone ``index``: ``p_eye`` in the eye frame, ``eye_pos`` and ``rot_rows`` (3x3,
        columns = eye axes) in the pelvis frame, ``odo`` = (x, y, yaw, pelvis height) of the pelvis;
        ``prev`` the eye's pose (:meth:`eye_pose`) one control step ``dt`` earlier, for the retinal slip
        that blurs a moving image (the lateral std grows above a knee: ``foveation.slip_factor``).
        ``crowded``: the sample may be pooled with a neighbour's (``baselines.crowding``): its std is at
        least the crowding zone's spread (``crowding.crowd_std`` at the plane's distance)."""
        ex, ey, ez = p_eye
        d = math.sqrt(ex * ex + ey * ey + ez * ez)
        if d <= 1e-9:
            return
        ecc = math.acos(max(-1.0, min(1.0, ex / d)))
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rot_rows
        lx, ly, lz = r00 * ex + r01 * ey + r02 * ez, r10 * ex + r11 * ey + r12 * ez, r20 * ex + r21 * ey + r22 * ez
        if lz > 0.0:  # behind the eye: the same line of sight, turned round
            lx, ly, lz = -lx, -ly, -lz
        dep = -lz / d  # sine of the depression of the line of sight
        if dep < MIN_DEPRESSION:
            return
        ox, oy, yaw, pz = odo
        c, s = math.cos(yaw), math.sin(yaw)
        eye_h = pz + eye_pos[2] - STONE_PLANE_Z  # the eye's height over the plane
        t = eye_h / dep  # distance along the line of sight to the plane
        if self.vision.depth_pedestal_arcmin is not None and d < NEAR_GATE * t:
            # With the depth law the depth noise can bring a point far nearer the eye than the plane, and
            # the lateral noise then bends its direction by degrees: its eccentricity, and the std the
            # model gives it, are not to be trusted (modelling choice: such samples are dropped).
            return
        hx, hy = (c * lx - s * ly) / d, (s * lx + c * ly) / d  # horizontal part of the unit line of sight
        exw, eyw = ox + c * eye_pos[0] - s * eye_pos[1], oy + s * eye_pos[0] + c * eye_pos[1]
        px, py = exw + t * hx, eyw + t * hy
        # The lateral noise is a distance at the true range (~t): seen from the eye at the perceived range
        # d it is an angle s_lat / d, which is t s_lat / d across the line of sight on the plane.
        est = self.estimate(index)
        qx, qy = est[0] if est is not None else (px, py)
        pose = self.eye_pose(eye_pos, rot_rows, odo)
        slip = self.retinal_slip(qx, qy, pose, prev, dt)
        if self.vision.periphery_on and est is not None:
            # With the human periphery a far-peripheral sample can be bent by many degrees (the position
            # law, slip, a near depth), landing near the line of sight: its noise is then modelled at the
            # larger of its perceived eccentricity and that of the stone's current estimate (modelling
            # choice; without it one such sample, taken for a foveal one, can move the estimate by metres).
            u = self._in_eye(pose, qx, qy, STONE_PLANE_Z)
            ecc = max(ecc, math.acos(max(-1.0, min(1.0, u[0]))))
        # dt: the positional disarray, if the eye has it, sized for a stream of looks (no effect without)
        s_lat = max(believed_sigmas(t, ecc, slip, self.vision, None, dt)[1] * t / d, MIN_STD_M)
        if crowded:
            s_lat = max(s_lat, crowd_std(t, ecc, self.vision))
        h = math.hypot(hx, hy)
        if h <= 1e-9:  # straight down: isotropic
            a_info = c_info = 1.0 / (s_lat * s_lat)
            ux, uy = 1.0, 0.0
        else:
            ux, uy = hx / h, hy / h
            a_info = (dep / s_lat) ** 2  # along the horizontal line of sight
            c_info = 1.0 / (s_lat * s_lat)  # across it
        stone = self.stones.get(index)
        if stone is None:
            stone = self.stones[index] = _Stone()
        ixx = a_info * ux * ux + c_info * uy * uy
        ixy = (a_info - c_info) * ux * uy
        iyy = a_info * uy * uy + c_info * ux * ux
        I, v = stone.info, stone.vec  # noqa: E741 (the information matrix)
        I[0] += ixx
        I[1] += ixy
        I[2] += iyy
        v[0] += ixx * px + ixy * py
        v[1] += ixy * px + iyy * py
        stone.n += 1

    def estimate(self, index: int):
        """((x, y), std of x, std of y) of stone ``index`` once seen, else None."""
        stone = self.stones.get(index)
        if stone is None or stone.n == 0:
            return None
        xx, xy, yy = stone.info
        det = xx * yy - xy * xy
        if det <= 0.0:
            return None
        cxx, cxy, cyy = yy / det, -xy / det, xx / det
        vx, vy = stone.vec
        return (cxx * vx + cxy * vy, cxy * vx + cyy * vy), math.sqrt(cxx), math.sqrt(cyy)
