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
* the lateral position std of a **moving image** grows with its speed on the retina (retinal slip):
  ``sigma_q * max(1, slip / knee)``, ``knee`` = 2.5 deg/s, the image speed up to which foveal acuity
  is unchanged by motion (Westheimer & McKee 1975); beyond it the growth in proportion to the slip is
  our modelling choice (a constant smear time of 6.7 ms), in line with dynamic visual acuity falling
  steeply with target speed when the eye does not stabilise the image (Ludvigh & Miller 1958; Brown
  1972: "position and velocity errors [of pursuit] are the main determinants of DVA"). So a pursued
  ball is localised to ~1 arcmin and one sweeping past a still eye at 50 deg/s to ~20 arcmin. Not
  in the Eyecatch paper (static 20/20 acuity at any speed: ``position_slip_knee_deg_s=inf``,
  ``EyeCatchPaper-v0``); added before the first release so that where the eye looks decides the catch
  (``docs/reproductions/gaze_default.md``);
* everything is divided by the acuity factor ``alpha(theta) = E2 / (E2 + theta)`` (``theta`` the
  eccentricity from the line of sight, ``E2`` = 2 deg: acuity halves 2 deg from the fovea, the
  standard cortical-magnification form, e.g. Levi, Klein & Aitsebaomo 1985);
* nothing is seen beyond the field of view (+-60 deg, Eom et al. 2019) or during a saccade;
* opt-in human peripheral vision (vision/periphery.py; all off by default): a human-shaped field of view, a
  position law faster than the acuity law, crowding, and depth noise that grows away from the
  vergence distance (:mod:`visuomotor_gym.vision.periphery`).

One ``noise_scale`` multiplies every standard deviation (Eyecatch section 5 uses x10 for poor
vision). All randomness comes from the ``numpy.random.Generator`` the caller passes in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from visuomotor_gym.core import args
from visuomotor_gym.core.args import Flag, Num
from visuomotor_gym.vision import periphery

ARCMIN = math.pi / (180.0 * 60.0)
DEG = math.pi / 180.0
_ANGLE_BOUNDS = {"bounds": (0.0, 180.0), "low_open": True}  # field metadata of the human field's extents


# What each VisionParams field accepts (visuomotor_gym.core.args.check_fields; a field not listed here
# gets the check its default's type implies: a finite number, a real boolean). The upper bounds are
# modelling choices far beyond any sourced value (10 deg of lateral std at the fovea; the noise scale
# 1000 x the env's own 1000 x multiplier); position_slip_knee_deg_s = inf is the paper's static acuity.
VISION_RULES = {
    "retinal_position_std_arcmin": Num(0.0, 600.0),
    "retinal_velocity_weber": Num(0.0, 10.0),
    "retinal_velocity_floor_deg_s": Num(0.0, 100.0),
    "depth_std_fraction": Num(0.0, 10.0),
    "depth_rate_std_fraction": Num(0.0, 10.0),
    "fovea_e2_deg": Num(0.0, 180.0, low_open=True),
    "field_of_view_deg": Num(0.0, 180.0, low_open=True),
    "position_slip_knee_deg_s": Num(0.0, 1000.0, low_open=True, inf_ok=True),
    "noise_scale": Num(0.0, 1e6),
    "foveated": Flag(),
}


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
    # Moving-target localisation: lateral position std x max(1, retinal slip / knee). The knee: foveal
    # Landolt-C and vernier thresholds are unchanged by image motion up to 2.5 deg/s (Westheimer &
    # McKee 1975, JOSA 65:847). Growth in proportion to the slip above it: modelling choice (a fixed
    # smear time of 1 arcmin / 2.5 deg/s = 6.7 ms; swept 1-10 deg/s in docs/reproductions/gaze_default.md).
    # inf: static 20/20 acuity at any retinal speed, the Eyecatch paper's model (EyeCatchPaper-v0).
    position_slip_knee_deg_s: float = 2.5
    noise_scale: float = 1.0  # multiplies every standard deviation (x10: Eyecatch "poor vision")
    foveated: bool = True  # False: foveal acuity everywhere, no field-of-view limit (FullView)
    # --- Human peripheral vision (vision/periphery.py), each off by default. Metadata
    # "bounds": the allowed range [low, high] ("low_open": low itself excluded), "optional": None allowed
    # (the mechanism off); "choices": the allowed strings.
    # Field of view: "cone" (half-angle field_of_view_deg, all round) or "human": 60 deg up, 75 down,
    # 100 to each side (Spector 1990, Clinical Methods ch. 116), elliptical between the meridians.
    field_shape: str = field(default="cone", metadata={"choices": periphery.FIELD_SHAPES})
    field_up_deg: float = field(default=60.0, metadata=_ANGLE_BOUNDS)  # Spector 1990
    field_down_deg: float = field(default=75.0, metadata=_ANGLE_BOUNDS)  # Spector 1990
    field_side_deg: float = field(default=100.0, metadata=_ANGLE_BOUNDS)  # Spector 1990
    # Lateral position std x (1 + theta / E2_pos) instead of / alpha(theta): position judgements degrade
    # faster with eccentricity than resolution (Levi, Klein & Aitsebaomo 1985); 0.6-0.8 deg often quoted,
    # unconfirmed (modelling choice, to confirm). None: off (the acuity law, E2 = fovea_e2_deg).
    position_e2_deg: float | None = field(
        default=None, metadata={"bounds": (0.0, 90.0), "low_open": True, "optional": True})
    # Crowding: flankers of the same kind (another object) within crowding_bouma x eccentricity pool
    # with the target (Bouma 1970: b ~ 0.5; Parkes et al. 2001: compulsory averaging).
    crowding: bool = False
    crowding_bouma: float = field(default=0.5, metadata={"bounds": (0.0, 2.0), "low_open": True})  # Bouma
    # Targets this close to the fovea are never crowded: the foveola's radius (1-1.2 deg across), where
    # b * theta < 0.25 deg, near foveal crowding's few arcmin (Levi, Klein & Aitsebaomo 1985):
    # modelling choice.
    crowding_fovea_deg: float = field(default=0.5, metadata={"bounds": (0.0, 90.0)})
    # Depth and depth-rate std x (1 + eta / eta_2), eta = interocular |1/d - 1/d_fix| the disparity
    # pedestal from the vergence distance (Blakemore 1970: stereo thresholds rise with the pedestal);
    # eta_2 (arcmin): modelling choice, to confirm. None: off (depth noise independent of vergence).
    depth_pedestal_arcmin: float | None = field(
        default=None, metadata={"bounds": (0.0, 600.0), "low_open": True, "optional": True})
    # Interocular distance for the pedestal: mean adult interpupillary distance ~63 mm (Dodgson 2004).
    interocular_m: float = field(default=0.063, metadata={"bounds": (0.0, 0.2), "low_open": True})
    # Positional disarray (periphery.DisarrayField): the share of the lateral position variance the
    # periphery adds to the fovea's that is fixed in retinal coordinates for the episode (Hess & Field
    # 1993), the rest drawn every step; 0: off. The share is a modelling choice (swept); disarray_length: the field's
    # correlation length in units of eccentricity, one crowding zone (Bouma 1970's 0.5; modelling choice).
    position_disarray: float = field(default=0.0, metadata={"bounds": (0.0, 1.0)})
    disarray_length: float = field(default=0.5, metadata={"bounds": (0.0, 4.0), "low_open": True})
    # Set by __post_init__: whether any of the mechanisms above acts (always False without foveation).
    periphery_on: ClassVar[bool] = False

    def __post_init__(self) -> None:
        # Every field, those added later included: VISION_RULES, else the field's metadata (bounds,
        # optional, choices), else the check its default's type implies (visuomotor_gym.core.args).
        args.check_fields(self, VISION_RULES)
        # Whether any peripheral mechanism acts (the retina then bypasses its compiled kernel).
        object.__setattr__(self, "periphery_on", self.foveated and (
            self.field_shape == "human" or self.position_e2_deg is not None or self.crowding
            or self.depth_pedestal_arcmin is not None or self.position_disarray > 0.0))

    def scaled(self, factor: float) -> VisionParams:
        """A copy with ``noise_scale`` multiplied by ``factor``."""
        return replace(self, noise_scale=self.noise_scale * factor)


#: The human periphery, one eye for every family: the four mechanisms of docs/reproductions/gaze_default.md
#: (``"all four"``) -- the human field (Spector 1990), the position law with E2 = 0.7 deg (modelling choice,
#: swept 0.35-1.4), crowding with Bouma's b = 0.5 (Bouma 1970; Parkes et al. 2001) and the depth pedestal of
#: 10 arcmin (modelling choice, swept 10 / 60 / off) -- and the positional disarray (Hess & Field 1993) with
#: the share 0.8 of the added lateral variance fixed in retinal coordinates (modelling choice, swept
#: 0 / 0.5 / 0.8 / 1.0 in gaze_default.md (g)). The fields of :class:`VisionParams` they set.
HUMAN_PERIPHERY = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0,
                   "position_disarray": 0.8}


def human_periphery(base: VisionParams | None = None, **overrides) -> VisionParams:
    """``base`` (default: the default :class:`VisionParams`) with :data:`HUMAN_PERIPHERY` switched on,
    then ``overrides`` (any :class:`VisionParams` field, e.g. ``depth_pedestal_arcmin=None`` to leave the
    depth law off)."""
    return replace(base if base is not None else VisionParams(), **{**HUMAN_PERIPHERY, **overrides})


def acuity(eccentricity_rad: float, params: VisionParams) -> float:
    """Acuity factor alpha(theta) in (0, 1]: 1 at the fovea, E2/(E2+theta) away from it."""
    if not params.foveated:
        return 1.0
    e2 = params.fovea_e2_deg * DEG
    return e2 / (e2 + eccentricity_rad)


def slip_factor(retinal_speed: float, params: VisionParams) -> float:
    """Growth of the lateral position std with retinal slip (rad/s): max(1, slip / knee); 1 without foveation."""
    if not params.foveated:
        return 1.0
    knee = params.position_slip_knee_deg_s * DEG
    return max(1.0, abs(retinal_speed) / knee)


def line_of_sight_rotation(direction: np.ndarray) -> np.ndarray:
    """Rotation exp([w] theta) taking the visual axis (1, 0, 0) onto the unit vector ``direction``.

    Rodrigues' formula with w = x_hat cross u, theta = angle(x_hat, u) (Eyecatch Eq. 3).
    """
    return np.array(_los_rows(float(direction[0]), float(direction[1]), float(direction[2])))


def _los_rows(ux: float, uy: float, uz: float):
    """Rows of :func:`line_of_sight_rotation` as tuples of floats (the per-step path)."""
    c = ux
    if c < -1.0 + 1e-12:  # exactly behind: any half-turn about an axis perpendicular to x
        return ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0))
    # k = (1,0,0) x u = (0, -uz, uy); R = I + [k] + [k]^2 / (1 + c)
    f = 1.0 / (1.0 + c)
    return (
        (c, -uy, -uz),
        (uy, 1.0 - f * uy * uy, -f * uy * uz),
        (uz, -f * uy * uz, 1.0 - f * uz * uz),
    )


def eccentricity(position_eye: np.ndarray) -> float:
    """Angle (rad) between the visual axis and the line of sight to ``position_eye``."""
    d = math.sqrt(float(position_eye @ position_eye))
    if d <= 0.0:
        return 0.0
    return math.acos(max(-1.0, min(1.0, float(position_eye[0]) / d)))


def is_in_field_of_view(position_eye: np.ndarray, params: VisionParams) -> bool:
    """Whether a point (eye frame) lies inside the field of view (always, without foveation): the cone
    of half-angle ``field_of_view_deg`` or, with ``field_shape="human"``, the human field
    (:func:`visuomotor_gym.vision.periphery.in_field`)."""
    if not params.foveated:
        return True
    if params.field_shape == "human":
        return periphery.in_field(*(float(c) for c in position_eye), params)
    return eccentricity(position_eye) <= params.field_of_view_deg * DEG


def standard_deviations(distance: float, eccentricity_rad: float, retinal_speed: float, params: VisionParams,
                        fixation: float | None = None):
    """The diagonal of Sigma (Eyecatch Eq. 2) along the line of sight: (depth, lateral, lateral) x2.

    ``retinal_speed`` is the speed (rad/s) of the image on the retina: the line-of-sight angular
    velocity minus the eye's own angular velocity, so pursuit that stabilises the image sharpens the
    velocity estimate. With the peripheral mechanisms of :mod:`visuomotor_gym.vision.periphery`: the
    lateral position std follows the position law (``position_e2_deg``) and the depth stds grow with
    the disparity pedestal from the vergence distance ``fixation`` (m; ``depth_pedestal_arcmin``).
    """
    return np.array(_sigmas(distance, eccentricity_rad, retinal_speed, params, fixation))


#: How long an agent's memory of a target's samples is taken to last when it sizes the positional
#: disarray's share of a sample's error (:func:`disarray_looks`): modelling choice (one second, about
#: the span over which the baselines' filters weigh old samples).
DISARRAY_HORIZON_S = 1.0


def disarray_looks(eccentricity_rad: float, retinal_speed: float, params: VisionParams, dt: float,
                   horizon_s: float = DISARRAY_HORIZON_S) -> float:
    """How many of an observer's successive samples (every ``dt`` s) of one target read the same place
    of the positional-disarray field (:class:`~visuomotor_gym.vision.periphery.DisarrayField`): the
    field decorrelates over ``disarray_length x (theta + theta_0)`` of retinal travel, covered at the
    image's retinal speed (rad/s), so ``1 + l (theta + theta_0) / (speed dt)`` looks, at most
    ``horizon_s / dt`` (a still image); 1 without the disarray."""
    if params.position_disarray <= 0.0 or not params.foveated:
        return 1.0
    span = params.disarray_length * (eccentricity_rad + periphery.position_e2_deg(params) * DEG)
    most = max(1.0, horizon_s / dt)
    speed = abs(retinal_speed)
    return most if speed * most * dt <= span else min(most, 1.0 + span / (speed * dt))


def believed_sigmas(distance, eccentricity_rad, retinal_speed, params, fixation=None, dt=None):
    """The stds an observer that knows its eye should give one sample when it fuses a stream of them
    every ``dt`` s: :func:`standard_deviations`, with the lateral ones multiplied by ``sqrt(1 + w (k -
    1))`` under the positional disarray (``w`` its share of the lateral variance at this eccentricity,
    ``k`` = :func:`disarray_looks`): a filter that takes ``k`` looks as independent then ends with the
    fixed part's variance unreduced. Without the disarray (or ``dt``) exactly :func:`standard_deviations`."""
    sig = _sigmas(distance, eccentricity_rad, retinal_speed, params, fixation)
    if dt is None or params.position_disarray <= 0.0 or not params.foveated:
        return sig
    w = periphery.disarray_weight(eccentricity_rad, params)
    g = math.sqrt(1.0 + w * (disarray_looks(eccentricity_rad, retinal_speed, params, dt) - 1.0))
    return (sig[0], sig[1] * g, sig[2] * g, sig[3], sig[4], sig[5])


def _sigmas(distance, eccentricity_rad, retinal_speed, params, fixation=None):
    """``standard_deviations`` as a tuple of floats (the per-step path)."""
    k = distance * params.noise_scale / acuity(eccentricity_rad, params)
    lateral = k * params.retinal_position_std_arcmin * ARCMIN * slip_factor(retinal_speed, params)
    lateral_rate = k * (
        params.retinal_velocity_weber * abs(retinal_speed) + params.retinal_velocity_floor_deg_s * DEG
    )
    if params.periphery_on:  # the periphery laws (off by default: the arithmetic above, unchanged)
        if params.position_e2_deg is not None:
            lateral = (distance * params.noise_scale * periphery.position_factor(eccentricity_rad, params)
                       * params.retinal_position_std_arcmin * ARCMIN * slip_factor(retinal_speed, params))
        g = periphery.depth_factor(distance, fixation, params)
        return (k * params.depth_std_fraction * g, lateral, lateral, k * params.depth_rate_std_fraction * g,
                lateral_rate, lateral_rate)
    return (k * params.depth_std_fraction, lateral, lateral, k * params.depth_rate_std_fraction, lateral_rate,
            lateral_rate)


def covariance(position_eye: np.ndarray, retinal_speed: float, params: VisionParams,
               fixation: float | None = None, dt: float | None = None) -> np.ndarray:
    """The 6x6 observation covariance A Sigma^2 A^T in the eye frame (Eyecatch Eq. 1-3); ``fixation``
    (m): the vergence distance, for the depth law of ``depth_pedestal_arcmin``; ``dt`` (s): the
    observer's sampling period, to size the positional disarray as :func:`believed_sigmas` does."""
    position_eye = np.asarray(position_eye, dtype=float)
    d = math.sqrt(float(position_eye @ position_eye))
    sig = np.array(believed_sigmas(d, eccentricity(position_eye), retinal_speed, params, fixation, dt))
    rot = line_of_sight_rotation(position_eye / d) if d > 0 else np.eye(3)
    a = np.zeros((6, 6))
    a[:3, :3] = rot
    a[3:, 3:] = rot
    return a @ np.diag(sig**2) @ a.T


def perceive(position_eye, velocity_eye, retinal_speed: float, params: VisionParams, rng: np.random.Generator,
             fixation: float | None = None):
    """One look at a point: ``(position, velocity, visible)`` in the eye frame, as float lists.

    Outside the field of view nothing is drawn and zeros are returned with ``visible=False``
    (saccadic suppression is the caller's business: it knows when the eye moved). ``fixation`` (m):
    the eye's vergence distance, for the depth law of ``depth_pedestal_arcmin``.
    """
    x, y, z = position_eye
    d = math.sqrt(x * x + y * y + z * z)
    if d <= 0.0:
        return list(position_eye), list(velocity_eye), True
    ecc = math.acos(max(-1.0, min(1.0, x / d)))
    if params.foveated and (ecc > periphery.human_field_limit(y / d, z / d, params)
                            if params.field_shape == "human" else ecc > params.field_of_view_deg * DEG):
        return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False
    pos, vel = _draw_at(x, y, z, d, ecc, velocity_eye, retinal_speed, params, rng, fixation)
    return pos, vel, True


def _draw_at(x, y, z, d, ecc, velocity_eye, retinal_speed, params, rng, fixation=None, fixed=None):
    """True state + A Sigma eps with eps ~ N(0, I6) (Eyecatch Eq. 1-3) for a point at distance ``d`` > 0
    and eccentricity ``ecc`` (rad); float lists in and out. ``fixed``: the positional-disarray field's
    two lateral values at the point's retinal place (:class:`~visuomotor_gym.vision.periphery.DisarrayField`):
    the lateral position components of eps are then ``sqrt(w) fixed + sqrt(1 - w) eps`` with ``w = s (1 -
    1 / f**2)``, ``s = params.position_disarray`` and ``f`` the position law's growth at ``ecc``
    (:func:`~visuomotor_gym.vision.periphery.position_factor`): a share ``s`` of the variance the periphery
    adds to the fovea's is fixed in place (the same unit variance; the same six draws from ``rng``)."""
    s0, s1, s2, s3, s4, s5 = _sigmas(d, ecc, retinal_speed, params, fixation)
    e0, e1, e2, e3, e4, e5 = rng.standard_normal(6).tolist()
    if fixed is not None:
        w = periphery.disarray_weight(ecc, params)
        a, c = math.sqrt(w), math.sqrt(1.0 - w)
        e1, e2 = a * fixed[0] + c * e1, a * fixed[1] + c * e2
    n0, n1, n2, n3, n4, n5 = s0 * e0, s1 * e1, s2 * e2, s3 * e3, s4 * e4, s5 * e5
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = _los_rows(x / d, y / d, z / d)
    vx, vy, vz = velocity_eye
    return (
        [x + r00 * n0 + r01 * n1 + r02 * n2, y + r10 * n0 + r11 * n1 + r12 * n2, z + r20 * n0 + r21 * n1 + r22 * n2],
        [vx + r00 * n3 + r01 * n4 + r02 * n5, vy + r10 * n3 + r11 * n4 + r12 * n5, vz + r20 * n3 + r21 * n4 + r22 * n5],
    )
