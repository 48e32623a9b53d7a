"""Foveated vision noise model of Yeo et al., *Eyecatch* (SIGGRAPH 2012), section 3.1.

The eye perceives a point's position and velocity in the **eye frame** (origin at the centre of the
globe, x along the visual axis, z up in the reference position) as a Gaussian around the truth:

    [p; p_dot] ~ N([p_true; p_dot_true], A Sigma^2 A^T)                      (Eyecatch Eq. 1)
    Sigma = diag(sx, sy, sz, sx_dot, sy_dot, sz_dot) / alpha(theta)            (Eyecatch Eq. 2)
    A     = blockdiag(exp([w] theta), exp([w] theta))                          (Eyecatch Eq. 3)

``exp([w] theta)`` is the rotation that carries the visual axis onto the line of sight to the
point, so the diagonal of Sigma is expressed along the line of sight (x: depth) and across it
(y, z: lateral). The standard deviations (Eyecatch Table 1, whose values were lost from our copy of
the paper; the defaults below follow the text):

* lateral position: ``d * sigma_q`` with ``sigma_q`` = 1 arcmin, the resolution of 20/20 vision,
  converted with the small-angle approximation (``d`` = distance eye to point);
* lateral velocity: ``d * (weber * |retinal speed| + floor)``, Weber fraction 5 % (McKee 1981), plus
  a small floor so a perfectly pursued target is not known exactly;
* depth and depth-rate: "much worse" than lateral and proportional to depth (vergence), here
  ``depth_std_fraction * d`` and ``depth_rate_std_fraction * d`` (per second);
* everything is divided by the acuity factor ``alpha(theta) = E2 / (E2 + theta)`` (``theta`` the
  eccentricity from the line of sight, ``E2`` = 2 deg: acuity halves 2 deg from the fovea, the
  standard cortical-magnification form, e.g. Levi, Klein & Aitsebaomo 1985);
* nothing is seen beyond the field of view (+-60 deg, Eom et al. 2019) or during a saccade.

One ``noise_scale`` multiplies every standard deviation (Eyecatch section 5 uses x10 for poor
vision). All randomness comes from the ``numpy.random.Generator`` the caller passes in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

ARCMIN = math.pi / (180.0 * 60.0)
DEG = math.pi / 180.0


@dataclass(frozen=True)
class VisionParams:
    """Constants of the vision model. Angles in the names' units; distances in metres."""

    retinal_position_std_arcmin: float = 1.0  # 20/20 vision resolves 1 arcmin (Eyecatch Table 1)
    retinal_velocity_weber: float = 0.05  # Weber fraction of retinal speed (McKee 1981)
    retinal_velocity_floor_deg_s: float = 0.2  # velocity noise of a perfectly stabilised image
    depth_std_fraction: float = 0.05  # depth std = 5 % of depth at the fovea
    depth_rate_std_fraction: float = 0.1  # depth-rate std (m/s) = 0.1/s * depth at the fovea
    fovea_e2_deg: float = 2.0  # alpha(theta) = E2 / (E2 + theta)
    field_of_view_deg: float = 60.0  # half-angle; nothing is seen beyond it (Eom et al. 2019)
    noise_scale: float = 1.0  # multiplies every standard deviation (x10: Eyecatch "poor vision")
    foveated: bool = True  # False: foveal acuity everywhere, no field-of-view limit (FullView)

    def __post_init__(self) -> None:
        for name in (
            "retinal_position_std_arcmin",
            "retinal_velocity_weber",
            "retinal_velocity_floor_deg_s",
            "depth_std_fraction",
            "depth_rate_std_fraction",
            "noise_scale",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"VisionParams.{name} must be finite and >= 0, got {value!r}")
        if not (math.isfinite(self.fovea_e2_deg) and self.fovea_e2_deg > 0.0):
            raise ValueError(f"VisionParams.fovea_e2_deg must be > 0, got {self.fovea_e2_deg!r}")
        if not (0.0 < self.field_of_view_deg <= 180.0):
            raise ValueError(
                f"VisionParams.field_of_view_deg must be in (0, 180], got {self.field_of_view_deg!r}"
            )

    def scaled(self, factor: float) -> VisionParams:
        """A copy with ``noise_scale`` multiplied by ``factor``."""
        return replace(self, noise_scale=self.noise_scale * factor)


def acuity(eccentricity_rad: float, params: VisionParams) -> float:
    """Acuity factor alpha(theta) in (0, 1]: 1 at the fovea, E2/(E2+theta) away from it."""
    if not params.foveated:
        return 1.0
    e2 = params.fovea_e2_deg * DEG
    return e2 / (e2 + eccentricity_rad)


def line_of_sight_rotation(direction: np.ndarray) -> np.ndarray:
    """Rotation exp([w] theta) taking the visual axis (1, 0, 0) onto the unit vector ``direction``.

    Rodrigues' formula with w = x_hat cross u, theta = angle(x_hat, u) (Eyecatch Eq. 3).
    """
    ux, uy, uz = float(direction[0]), float(direction[1]), float(direction[2])
    c = ux
    if c < -1.0 + 1e-12:  # exactly behind: any half-turn about an axis perpendicular to x
        return np.diag([-1.0, -1.0, 1.0])
    # k = (1,0,0) x u = (0, -uz, uy); R = I + [k] + [k]^2 / (1 + c)
    f = 1.0 / (1.0 + c)
    return np.array(
        [
            [c, -uy, -uz],
            [uy, 1.0 - f * uy * uy, -f * uy * uz],
            [uz, -f * uy * uz, 1.0 - f * uz * uz],
        ]
    )


def eccentricity(position_eye: np.ndarray) -> float:
    """Angle (rad) between the visual axis and the line of sight to ``position_eye``."""
    d = math.sqrt(float(position_eye @ position_eye))
    if d <= 0.0:
        return 0.0
    return math.acos(max(-1.0, min(1.0, float(position_eye[0]) / d)))


def is_in_field_of_view(position_eye: np.ndarray, params: VisionParams) -> bool:
    """Whether a point (eye frame) lies inside the field of view (always, without foveation)."""
    if not params.foveated:
        return True
    return eccentricity(position_eye) <= params.field_of_view_deg * DEG


def standard_deviations(distance: float, eccentricity_rad: float, retinal_speed: float, params: VisionParams):
    """The diagonal of Sigma (Eyecatch Eq. 2) along the line of sight: (depth, lateral, lateral) x2.

    ``retinal_speed`` is the speed (rad/s) of the image on the retina: the line-of-sight angular
    velocity minus the eye's own angular velocity, so pursuit that stabilises the image sharpens the
    velocity estimate.
    """
    k = distance * params.noise_scale / acuity(eccentricity_rad, params)
    lateral = k * params.retinal_position_std_arcmin * ARCMIN
    lateral_rate = k * (
        params.retinal_velocity_weber * abs(retinal_speed) + params.retinal_velocity_floor_deg_s * DEG
    )
    return np.array(
        [k * params.depth_std_fraction, lateral, lateral, k * params.depth_rate_std_fraction, lateral_rate, lateral_rate]
    )


def covariance(position_eye: np.ndarray, retinal_speed: float, params: VisionParams) -> np.ndarray:
    """The 6x6 observation covariance A Sigma^2 A^T in the eye frame (Eyecatch Eq. 1-3)."""
    position_eye = np.asarray(position_eye, dtype=float)
    d = math.sqrt(float(position_eye @ position_eye))
    sig = standard_deviations(d, eccentricity(position_eye), retinal_speed, params)
    rot = line_of_sight_rotation(position_eye / d) if d > 0 else np.eye(3)
    a = np.zeros((6, 6))
    a[:3, :3] = rot
    a[3:, 3:] = rot
    return a @ np.diag(sig**2) @ a.T


def sample(
    position_eye: np.ndarray,
    velocity_eye: np.ndarray,
    retinal_speed: float,
    params: VisionParams,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Draw one perceived (position, velocity) in the eye frame, ignoring the field of view."""
    d = math.sqrt(float(position_eye @ position_eye))
    if d <= 0.0:
        return position_eye.copy(), velocity_eye.copy()
    ecc = math.acos(max(-1.0, min(1.0, float(position_eye[0]) / d)))
    return _draw(position_eye, velocity_eye, d, ecc, retinal_speed, params, rng)


def perceive(
    position_eye: np.ndarray,
    velocity_eye: np.ndarray,
    retinal_speed: float,
    params: VisionParams,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, bool]:
    """One look at a point: ``(position, velocity, visible)`` in the eye frame.

    Outside the field of view nothing is drawn and zeros are returned with ``visible=False``
    (saccadic suppression is the caller's business: it knows when the eye moved).
    """
    d = math.sqrt(float(position_eye @ position_eye))
    ecc = math.acos(max(-1.0, min(1.0, float(position_eye[0]) / d))) if d > 0.0 else 0.0
    if params.foveated and ecc > params.field_of_view_deg * DEG:
        return np.zeros(3), np.zeros(3), False
    if d <= 0.0:
        return position_eye.copy(), velocity_eye.copy(), True
    pos, vel = _draw(position_eye, velocity_eye, d, ecc, retinal_speed, params, rng)
    return pos, vel, True


def _draw(position_eye, velocity_eye, d, ecc, retinal_speed, params, rng):
    """Noise A Sigma eps, eps ~ N(0, I6) (Eyecatch Eq. 1-3), added to the true state."""
    sig = standard_deviations(d, ecc, retinal_speed, params)
    rot = line_of_sight_rotation(position_eye / d)
    eps = (rng.standard_normal(6) * sig).reshape(2, 3) @ rot.T  # rows: R (Sigma eps)_pos, R (Sigma eps)_vel
    return position_eye + eps[0], velocity_eye + eps[1]
