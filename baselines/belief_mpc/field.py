"""The belief-MPC planners' model of their eye's field of view and position law, from the env's ``VisionParams``.

The planners predict what a fixation schedule will let them see: a candidate ``j`` is seen while the
eye fixates ``f`` when ``j``'s line of sight lies inside the field around ``f``'s. With the default
``field_shape="cone"`` that is ``theta <= field_of_view_deg`` (the arithmetic the planners always
used, bit for bit); with ``field_shape="human"`` (``visuomotor_gym.vision.periphery``: 60 deg up,
75 deg down, 100 deg to each side, Spector 1990) the limit depends on the direction of ``j`` around
``f``: it is evaluated in a predicted eye frame whose x axis is the line of sight to ``f`` and whose y
axis is horizontal (no torsion; the planners do not predict the head's roll: modelling choice), so
"up" is toward the world's up. The position law (``position_e2_deg``, Levi, Klein & Aitsebaomo 1985)
replaces the acuity E2 of the lateral (on-plane) position std when it is set.
"""

from __future__ import annotations

import numpy as np

from visuomotor_gym.vision import periphery
from visuomotor_gym.vision.foveation import DEG, VisionParams


def field_limit(gaze, target, vision: VisionParams):
    """The eccentricity limit (rad) of the field around the unit line of sight ``gaze`` in the direction
    of the unit vector ``target`` (path frame, z up; both ``(..., 3)``, broadcast). For the cone, the
    scalar ``field_of_view_deg`` in rad; for the human field, an array: the quadrant's ellipse of
    ``periphery.human_field_limit`` in the horizontal-y eye frame (module docstring)."""
    if vision.field_shape != "human":
        return vision.field_of_view_deg * DEG
    g = np.asarray(gaze, dtype=float)
    u = np.asarray(target, dtype=float)
    g, u = np.broadcast_arrays(g, u)
    # eye y (left) = z_up x g, normalised; straight up or down: the path frame's y
    left = np.stack([-g[..., 1], g[..., 0], np.zeros(g.shape[:-1])], axis=-1)
    n = np.linalg.norm(left, axis=-1, keepdims=True)
    left = np.where(n > 1e-9, left / np.maximum(n, 1e-12), np.array([0.0, 1.0, 0.0]))
    up = np.cross(g, left)
    uy = np.sum(u * left, axis=-1)
    uz = np.sum(u * up, axis=-1)
    return field_limit_eye(uy, uz, vision)


def field_limit_eye(uy, uz, vision: VisionParams):
    """``periphery.human_field_limit`` vectorised: the limit (rad) in the direction with eye-frame lateral
    and vertical components ``uy``, ``uz`` (the side limit on the visual axis itself)."""
    uy = np.asarray(uy, dtype=float)
    uz = np.asarray(uz, dtype=float)
    s = vision.field_side_deg * DEG
    v = np.where(uz >= 0.0, vision.field_up_deg, vision.field_down_deg) * DEG
    rho2 = uy * uy + uz * uz
    safe = np.where(rho2 > 0.0, rho2, 1.0)
    den = np.where(rho2 > 0.0, (uy * uy / safe) / (s * s) + (uz * uz / safe) / (v * v), 1.0 / (s * s))
    return 1.0 / np.sqrt(den)


def position_e2_rad(vision: VisionParams) -> float:
    """E2 (rad) of the lateral position std: ``position_e2_deg`` when the position law is on, else the
    acuity law's ``fovea_e2_deg`` (``periphery.position_factor``)."""
    return periphery.position_e2_deg(vision) * DEG


__all__ = ["field_limit", "field_limit_eye", "position_e2_rad"]
