# ObstaclePool.near writes max as the builtin's comparison, on purpose.
"""The obstacle scene of the walker families: the pool of obstacle boxes and where each one stands.

Scene state, not the gait's: the walker scene (``envs_assets/walker.xml``) carries
``WALKER_OBSTACLE_POOL`` pre-allocated mocap bodies, each with one box geom (``WALKER_OBSTACLES``);
a task places, resizes and parks them per episode (ObstacleWalk's course) and asks which are near the
walker (:meth:`ObstaclePool.near`, the cheap test before contact checks,
:mod:`visuomotor_gym.tasks.walk_contacts`). Parked obstacles sit under the floor, behind the start,
where nothing touches them.
"""

from __future__ import annotations

import math

import mujoco

from visuomotor_gym.body import walker_names as wn


class ObstaclePool:
    """The scene's pre-allocated obstacle boxes: placed, resized and parked per episode.

    Each obstacle is a mocap body with one box geom. Resizing writes the geom's half-sizes and the
    bounding volumes MuJoCo's collision broad- and mid-phase read (``geom_rbound``, ``geom_aabb``, the
    body's BVH box), so the model is compiled once and obstacles stay real contact geometry.
    """

    PARK_Z = -5.0  # metres: parked obstacles sit under the floor, 40 m behind the start

    def __init__(self, model: mujoco.MjModel) -> None:
        m = model
        self.geoms = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in wn.WALKER_OBSTACLES]
        self.bodies = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in wn.WALKER_OBSTACLES]
        if min(self.geoms + self.bodies) < 0:
            raise ValueError(f"the model lacks the obstacle pool ({wn.WALKER_OBSTACLES[0]}..): is it envs_assets/{wn.WALKER_SCENE}?")
        self.mocap = [int(m.body_mocapid[b]) for b in self.bodies]
        self.bvh = [int(m.body_bvhadr[b]) for b in self.bodies]
        self._park = [m.body_pos[b].copy() for b in self.bodies]
        self.index_of_geom = {g: i for i, g in enumerate(self.geoms)}
        self.boxes: list[tuple[float, float, float, float, float] | None] = [None] * len(self.geoms)

    def __len__(self) -> int:
        return len(self.geoms)

    def park_all(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        for i in range(len(self.geoms)):
            self.park(model, data, i)

    def park(self, model: mujoco.MjModel, data: mujoco.MjData, i: int) -> None:
        """Move obstacle ``i`` out of the way (under the floor, behind the start) and mark it unused."""
        data.mocap_pos[self.mocap[i]] = self._park[i]
        data.mocap_quat[self.mocap[i]] = (1.0, 0.0, 0.0, 0.0)
        self.boxes[i] = None

    def place(self, model: mujoco.MjModel, data: mujoco.MjData, i: int, x: float, y: float,
              length: float, width: float, height: float, yaw: float = 0.0, rgba=None) -> None:
        """Stand obstacle ``i`` on the floor: footprint centre (x, y), ``length`` along its x axis (the
        walking direction when ``yaw`` is the path heading), ``width`` across, ``height`` up (metres)."""
        if min(length, width, height) <= 0.0:
            raise ValueError(f"obstacle sizes must be positive, got {(length, width, height)}")
        g = self.geoms[i]
        half = (0.5 * length, 0.5 * width, 0.5 * height)
        model.geom_size[g] = half
        model.geom_rbound[g] = math.sqrt(half[0] ** 2 + half[1] ** 2 + half[2] ** 2)
        model.geom_aabb[g] = (0.0, 0.0, 0.0, *half)
        if self.bvh[i] >= 0:
            model.bvh_aabb[self.bvh[i]] = (0.0, 0.0, 0.0, *half)
        if rgba is not None:
            model.geom_rgba[g] = rgba
        data.mocap_pos[self.mocap[i]] = (x, y, half[2])
        data.mocap_quat[self.mocap[i]] = (math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw))
        # World-aligned footprint bounds, for the cheap "is anything near" test.
        c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
        ex, ey = c * half[0] + s * half[1], s * half[0] + c * half[1]
        self.boxes[i] = (x - ex, x + ex, y - ey, y + ey, height)

    def near(self, x: float, y: float, radius: float) -> bool:
        """Whether any placed obstacle's footprint comes within ``radius`` of (x, y)."""
        r2 = radius * radius
        # A box more than ``reach`` away along x cannot pass the test below (dx > radius (1 + 1e-9)
        # makes the rounded dx * dx exceed the rounded radius * radius), so skipping it changes no answer.
        reach = radius * (1.0 + 1e-9) if radius > 1e-100 else math.inf
        for box in self.boxes:
            if box is not None:
                x0, x1 = box[0], box[1]
                if x0 - x > reach or x - x1 > reach:
                    continue
                # dx = max(x0 - x, 0.0, x - x1) and dy alike, as conditional expressions (the same
                # comparisons as the builtin's, in the same order).
                dx = x0 - x
                if dx < 0.0:
                    dx = 0.0
                t = x - x1
                if t > dx:
                    dx = t
                dy = box[2] - y
                if dy < 0.0:
                    dy = 0.0
                t = y - box[3]
                if t > dy:
                    dy = t
                if dx * dx + dy * dy <= r2:
                    return True
        return False


__all__ = ["ObstaclePool"]
