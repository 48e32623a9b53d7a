"""Small 3-vector helpers for the per-step hot path.

``numpy.cross`` and ``numpy.linalg.norm`` cost microseconds each on 3-vectors (argument handling
dominates); these scalar versions cost a fraction of that and return the same values.
"""

from __future__ import annotations

import math

import numpy as np


def cross(a, b) -> np.ndarray:
    """Cross product of two 3-vectors."""
    ax, ay, az = a.tolist() if isinstance(a, np.ndarray) else a
    bx, by, bz = b.tolist() if isinstance(b, np.ndarray) else b
    return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])


def norm(a) -> float:
    """Euclidean norm of a 3-vector."""
    x, y, z = a.tolist() if isinstance(a, np.ndarray) else a
    return math.sqrt(x * x + y * y + z * z)


def angle_between(a, b) -> float:
    """Angle (rad) between two vectors, accurate for small and large angles."""
    ax, ay, az = a.tolist() if isinstance(a, np.ndarray) else a
    bx, by, bz = b.tolist() if isinstance(b, np.ndarray) else b
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    return math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz)


def angles_deg(a, b) -> np.ndarray:
    """Row-wise angle (deg) between two arrays of vectors (..., 3), same atan2 form as
    :func:`angle_between` (accurate near 0 and 180 deg); the one vectorised angle helper."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1)))


def unit_from_angles(azimuth: float, elevation: float) -> tuple[float, float, float]:
    """Unit vector for (azimuth about z, then elevation up), x forward, y left, z up, as floats."""
    ce = math.cos(elevation)
    return ce * math.cos(azimuth), ce * math.sin(azimuth), math.sin(elevation)


def rotate(r, x: float, y: float, z: float) -> tuple[float, float, float]:
    """``R @ (x, y, z)`` for a rotation given as its 9 entries, row-major (a list or tuple)."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = r
    return r0 * x + r1 * y + r2 * z, r3 * x + r4 * y + r5 * z, r6 * x + r7 * y + r8 * z


def rotate_t(r, x: float, y: float, z: float) -> tuple[float, float, float]:
    """``R.T @ (x, y, z)`` (into the rotated frame) for ``r`` as in :func:`rotate`."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = r
    return r0 * x + r3 * y + r6 * z, r1 * x + r4 * y + r7 * z, r2 * x + r5 * y + r8 * z


def solve3(m, v) -> np.ndarray:
    """Solve the 3x3 system ``m x = v`` by Cramer's rule (for well-conditioned, e.g. damped, ``m``).
    ``m`` and ``v`` are arrays or nested sequences of floats."""
    (a, b, c), (d, e, f), (g, h, i) = m.tolist() if isinstance(m, np.ndarray) else m
    x, y, z = v.tolist() if isinstance(v, np.ndarray) else v
    ei_fh, fg_di, dh_eg = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * ei_fh + b * fg_di + c * dh_eg
    return np.array(
        [
            (x * ei_fh + b * (f * z - y * i) + c * (y * h - e * z)) / det,
            (a * (y * i - f * z) + x * fg_di + c * (d * z - y * g)) / det,
            (a * (e * z - y * h) + b * (y * g - d * z) + x * dh_eg) / det,
        ]
    )
