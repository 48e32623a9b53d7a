"""Body frames that observations are expressed in.

A *fixed* frame (the seated body's seat: origin at the pelvis joint, axes parallel to the world) or
a *root-body* frame (a walker's pelvis: origin and heading follow the body). Observations of
positions are ``world - origin`` in the frame's axes.
"""

from __future__ import annotations

import math

import numpy as np

# The seated body's frame: the pelvis joint (envs_assets/common/upper_body.xml, body "torso" at
# 0 0 0.5), axes parallel to the world (x toward the thrower, y left, z up). A test checks it
# against the compiled model.
SEAT_ORIGIN = np.array([0.0, 0.0, 0.5])


class FixedFrame:
    """A frame fixed in the world, axes parallel to the world's."""

    fixed = True

    def __init__(self, origin) -> None:
        self.origin = np.array(origin, dtype=float)
        self.origin_list = self.origin.tolist()

    def update(self, data) -> None:  # nothing moves
        return None

    def to_local(self, x: float, y: float, z: float) -> tuple[float, float, float]:
        ox, oy, oz = self.origin_list
        return x - ox, y - oy, z - oz

    @staticmethod
    def axes_local(flat: list) -> list:
        """A row-major 3x3 rotation (world) in the frame's axes: the world's axes, so itself."""
        return flat


class RootFrame:
    """A frame carried by a root body: its origin, and its heading (yaw about world z) only, so
    "down" stays down for a walker whose pelvis pitches and rolls."""

    fixed = False

    def __init__(self, body_id: int) -> None:
        self.body_id = int(body_id)
        self.origin_list = [0.0, 0.0, 0.0]
        self._cos, self._sin = 1.0, 0.0

    def update(self, data) -> None:
        self.origin_list = data.xpos[self.body_id].tolist()
        r = data.xmat[self.body_id]
        yaw = math.atan2(float(r[3]), float(r[0]))
        self._cos, self._sin = math.cos(yaw), math.sin(yaw)

    def to_local(self, x: float, y: float, z: float) -> tuple[float, float, float]:
        ox, oy, oz = self.origin_list
        dx, dy = x - ox, y - oy
        return self._cos * dx + self._sin * dy, -self._sin * dx + self._cos * dy, z - oz

    def axes_local(self, flat: list) -> list:
        """A row-major 3x3 rotation (world) expressed in the frame's axes: Rz(-yaw) @ R."""
        c, s = self._cos, self._sin
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = flat
        return [c * r0 + s * r3, c * r1 + s * r4, c * r2 + s * r5,
                -s * r0 + c * r3, -s * r1 + c * r4, -s * r2 + c * r5, r6, r7, r8]
