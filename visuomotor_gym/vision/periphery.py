"""Human peripheral vision beyond the Eyecatch acuity law: four opt-in mechanisms.

Each is switched on by a :class:`~visuomotor_gym.vision.foveation.VisionParams` field and is off by
default (today's eye, bit for bit); all of them act only on a foveated eye (``foveated=False``, the
FullView rung, sees with the fovea everywhere). The retina (:mod:`visuomotor_gym.core.retina`) applies
them; its compiled path (``_kernels.c``: ``retina_see_periphery``, ``crowding_groups``, ``pooled``) mirrors
the functions here, which stay the reference, bit for bit (``tests/test_native.py``).

1. **Field of view, human shape** (``field_shape="human"``): instead of an all-round cone of half-angle
   ``field_of_view_deg``, the field reaches ``field_up_deg`` = 60 deg above the fixation point,
   ``field_down_deg`` = 75 deg below it and ``field_side_deg`` = 100 deg to either side (Spector 1990,
   *Clinical Methods* 3rd ed., ch. 116 "Visual Fields": the peripheral field "extends 100 degrees
   laterally, 60 degrees medially, 60 degrees upward, and 75 degrees downward"; the cyclopean eye of
   this package sees the union of both eyes' fields, whose lateral limit on each side is one eye's
   temporal 100 deg). Between the meridians the limit is an ellipse in each quadrant (modelling
   choice): a direction at eccentricity ``theta`` and polar angle ``phi`` (from the horizontal
   meridian) is seen when ``theta**2 * (cos(phi)**2 / S**2 + sin(phi)**2 / V**2) <= 1``, ``S`` the side
   limit, ``V`` the upper or lower one. The field is fixed to the eye (perimetry measures it with the
   eye on the fixation point).
2. **Position (localisation) eccentricity law** (``position_e2_deg``): the lateral position std is
   ``sd0 * (1 + theta / E2_pos)`` (times the slip factor) instead of ``sd0 / alpha(theta)``. Position
   judgements (vernier, bisection, localisation) degrade with eccentricity faster than resolution
   (Levi, Klein & Aitsebaomo 1985, Vision Res 25:963); E2_pos around 0.6-0.8 deg is often quoted for
   them, a number we could not confirm in the paper: a parameter, modelling choice to confirm.
   Velocity and depth keep the acuity law.
3. **Crowding** (``crowding``): Bouma's law (Bouma 1970, Nature 226:177): a target at eccentricity
   ``theta`` is crowded by any flanker closer to it (angle between the two lines of sight) than the
   critical spacing ``b * theta``, ``b = crowding_bouma`` = 0.5; crowded targets are seen as the average
   of the group, each flanking object counted once at the mean of its flanking points (compulsory
   averaging, Parkes et al. 2001, Nat Neurosci 4:739). See :func:`crowding_groups` for the exact rule.
4. **Depth precision and the vergence distance** (``depth_pedestal_arcmin``): depth from binocular
   disparity is finest at the fixation (vergence) distance and worsens with the disparity pedestal
   ``eta = I |1/d - 1/d_fix|`` (``I`` the interocular distance): stereo thresholds rise steeply with the
   pedestal (Blakemore 1970, J Physiol 211:599). The depth and depth-rate stds are multiplied by
   ``1 + eta / eta_2``, ``eta_2 = depth_pedestal_arcmin`` the pedestal at which they double (the linear
   form and its constant: modelling choice, to confirm against Blakemore's data).
5. **Positional disarray** (``position_disarray``): a share of the lateral position error that the
   periphery adds to the fovea's is fixed in retinal coordinates for the whole episode instead of drawn
   afresh every step (at eccentricity ``theta`` a share ``s (1 - 1/f(theta)**2)`` of the lateral variance,
   ``f`` the position law's growth; none at the fovea). The periphery's excess position
   uncertainty behaves as an *uncalibrated disarray* of the retinotopic map rather than as sensor noise
   (Hess & Field 1993, Vision Res 33:2663; Michel & Geisler 2011, J Vis 11(1):18: intrinsic position
   uncertainty grows linearly with eccentricity): the same retinal place reports the same wrong position
   each time it is read, so a still eye cannot average it away, while a saccade, pursuit or the target's
   own motion across the retina reads it through other places. Depth keeps its per-step noise (the
   source is about visual direction). Without it, 50 independent looks a second
   at a target 20 deg off the fovea give a still eye a position ~7 times finer than the human threshold
   each look is given (thresholds are measured on single presentations). The fixed part is a smooth,
   unit-variance random field (:class:`DisarrayField`) over retinal log-polar coordinates, one per
   lateral component, drawn from the env's ``np_random`` at each reset;
   its correlation length ``disarray_length`` x the eccentricity is one crowding zone (Bouma's 0.5 theta:
   modelling choice, swept). The share itself is a modelling choice, swept in
   ``docs/reproductions/gaze_default.md``; the per-step marginal std of every sample is unchanged.

Retinal slip (the lateral std grows above 2.5 deg/s, Westheimer & McKee 1975) is kept as it is.
"""

from __future__ import annotations

import math

import numpy as np

DEG = math.pi / 180.0
ARCMIN = DEG / 60.0
FIELD_SHAPES = ("cone", "human")


# --- 1. field of view --------------------------------------------------------------------------
def human_field_limit(uy: float, uz: float, params) -> float:
    """The eccentricity limit (rad) of the human-shaped field in the direction of the eye-frame unit
    vector with lateral and vertical components ``uy``, ``uz`` (``y`` left, ``z`` up): the quadrant's
    ellipse through the side limit ``S`` on the horizontal meridian and the upper (``uz >= 0``) or lower
    limit ``V`` on the vertical one, ``1 / sqrt(cos(phi)**2 / S**2 + sin(phi)**2 / V**2)`` (module
    docstring). On the visual axis itself (``uy = uz = 0``) the side limit."""
    s = params.field_side_deg * DEG
    v = (params.field_up_deg if uz >= 0.0 else params.field_down_deg) * DEG
    rho2 = uy * uy + uz * uz
    if rho2 <= 0.0:
        return s
    return 1.0 / math.sqrt((uy * uy / rho2) / (s * s) + (uz * uz / rho2) / (v * v))


def in_field(x: float, y: float, z: float, params) -> bool:
    """Whether the point (x, y, z) of the eye frame (x along the visual axis) lies in the field of
    view: the cone of half-angle ``field_of_view_deg`` or, with ``field_shape="human"``, the human
    field (:func:`human_field_limit`); always without foveation. The eye's own centre is seen."""
    if not params.foveated:
        return True
    d = math.sqrt(x * x + y * y + z * z)
    if d <= 0.0:
        return True
    ecc = math.acos(max(-1.0, min(1.0, x / d)))
    if params.field_shape == "human":
        return ecc <= human_field_limit(y / d, z / d, params)
    return ecc <= params.field_of_view_deg * DEG


# --- 2. position law ---------------------------------------------------------------------------
def position_e2_deg(params) -> float:
    """E2 (deg) of the lateral position std: ``position_e2_deg`` when the position law is on, else the
    acuity law's ``fovea_e2_deg``."""
    return params.position_e2_deg if params.position_e2_deg is not None else params.fovea_e2_deg


def position_factor(eccentricity_rad: float, params) -> float:
    """Growth of the lateral position std with eccentricity: ``1 + theta / E2_pos`` with
    ``E2_pos = position_e2_deg`` (position judgements, Levi, Klein & Aitsebaomo 1985); without it the
    acuity law ``1 / alpha(theta) = 1 + theta / fovea_e2_deg``; 1 without foveation."""
    if not params.foveated:
        return 1.0
    return 1.0 + eccentricity_rad / (position_e2_deg(params) * DEG)


# --- 4. depth and the vergence distance --------------------------------------------------------
def disparity_pedestal(distance: float, fixation: float, interocular_m: float) -> float:
    """The disparity (rad) of a point at ``distance`` m relative to the fixation (vergence) distance
    ``fixation`` m: ``I |1/d - 1/d_fix|`` (small-angle vergence geometry, points near the median plane)."""
    return interocular_m * abs(1.0 / distance - 1.0 / fixation)


def depth_factor(distance: float, fixation, params) -> float:
    """Growth of the depth (and depth-rate) std with the disparity pedestal: ``1 + eta / eta_2``,
    ``eta`` = :func:`disparity_pedestal`, ``eta_2 = depth_pedestal_arcmin``; 1 when the law is off,
    without foveation or when no fixation distance is given."""
    if params.depth_pedestal_arcmin is None or not params.foveated or fixation is None or distance <= 0.0:
        return 1.0
    eta = disparity_pedestal(distance, fixation, params.interocular_m)
    return 1.0 + eta / (params.depth_pedestal_arcmin * ARCMIN)


# --- 3. crowding -------------------------------------------------------------------------------
def angular_separation(u, v) -> float:
    """Angle (rad) between two unit vectors, ``atan2(|u x v|, u . v)`` (accurate for small angles)."""
    cx = u[1] * v[2] - u[2] * v[1]
    cy = u[2] * v[0] - u[0] * v[2]
    cz = u[0] * v[1] - u[1] * v[0]
    return math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), u[0] * v[0] + u[1] * v[1] + u[2] * v[2])


def crowding_groups(directions, eccentricities, kinds, objects, params) -> list[list[list[int]]]:
    """Who is pooled into whose percept (Bouma 1970; Parkes et al. 2001).

    ``directions``: the unit lines of sight (eye frame) of the targets seen this step (visible, inside
    the field); ``eccentricities`` (rad), ``kinds`` and ``objects`` the same targets' eccentricities,
    kinds and objects. A **neighbour** of target ``i`` is any other seen target of the same kind and of
    another object (points of one object -- the corners of one obstacle -- do not crowd one another)
    whose line of sight makes an angle **strictly less** than the critical spacing
    ``crowding_bouma * theta_i`` with ``i``'s. Returns, for each target ``i``, its group as a list of
    **elements**: ``[i]`` first, then, for each flanking object (in order of first appearance), the
    sorted indices of its points that are neighbours of ``i``. Each element counts once in the average
    (:func:`pooled`): an object seen as four points pulls no harder than one seen as one.
    A target within ``crowding_fovea_deg`` of the fovea is never crowded (there the critical spacing
    ``b theta`` is below the few arcmin of foveal crowding, Levi, Klein & Aitsebaomo 1985 Exp. II).
    The relation is not symmetric: a flanker nearer the fovea than its target may crowd it and not be
    crowded by it. Without ``crowding`` (or foveation) every group is ``[[i]]``.
    """
    n = len(directions)
    groups = [[[i]] for i in range(n)]
    if not (params.crowding and params.foveated):
        return groups
    fovea = params.crowding_fovea_deg * DEG
    for i in range(n):
        theta = eccentricities[i]
        if theta <= fovea:
            continue
        spacing = params.crowding_bouma * theta
        flankers: dict = {}  # object -> its points that are neighbours of i, in index order
        for j in range(n):
            if j != i and kinds[j] == kinds[i] and objects[j] != objects[i] \
                    and angular_separation(directions[i], directions[j]) < spacing:
                flankers.setdefault(objects[j], []).append(j)
        groups[i].extend(flankers.values())
    return groups


def pooled(vectors, group) -> list[float]:
    """Compulsory averaging: the mean over the group's elements (:func:`crowding_groups`) of each
    element's mean of ``vectors[k]`` (3-vectors); a lone target is itself."""
    if len(group) == 1 and len(group[0]) == 1:
        return list(vectors[group[0][0]])
    # The same sums in the same order as sum() over the elements' means (bit for bit), without the
    # per-component generators: this runs for every seen point on every step of a crowded scene.
    sx = sy = sz = 0.0
    for element in group:
        ex = ey = ez = 0.0
        for k in element:
            v = vectors[k]
            ex += v[0]
            ey += v[1]
            ez += v[2]
        n = len(element)
        sx += ex / n
        sy += ey / n
        sz += ez / n
    m = len(group)
    return [sx / m, sy / m, sz / m]


# --- 5. positional disarray --------------------------------------------------------------------
def disarray_weight(eccentricity_rad: float, params) -> float:
    """The share ``w = s (1 - 1/f**2)`` of the lateral position variance at this eccentricity that the
    positional disarray fixes in place (``s = position_disarray``, ``f`` = :func:`position_factor`): ``s``
    of the variance the periphery adds to the fovea's; 0 at the fovea."""
    f = position_factor(eccentricity_rad, params)
    return params.position_disarray * (1.0 - 1.0 / (f * f))


#: Random Fourier features per position component of :class:`DisarrayField` (modelling choice: enough
#: for a near-Gaussian field value, 16 x 2 cosines per seen point and step).
DISARRAY_FEATURES = 16


class DisarrayField:
    """The retinotopic part of the position error (module docstring, 5): two smooth random fields
    ``g_c(u, phi)``, ``c`` = lateral 1, lateral 2, of zero mean and unit variance over retinal
    log-polar coordinates ``u = ln(1 + theta / theta_0)`` (``theta`` the eccentricity, ``theta_0`` the
    position law's E2 -- the acuity law's without it) and ``phi`` the polar angle. Each field is
    ``sqrt(2 / K) sum_k cos(w_k u + m_k phi + b_k)`` (random Fourier features of a squared-exponential
    kernel, Rahimi & Recht 2007): ``w_k ~ N(0, 1 / l**2)``, ``m_k`` the integer nearest to a draw of the
    same law (so the field is periodic in ``phi``), ``b_k ~ U(0, 2 pi)``; ``l = disarray_length``.
    An eccentricity step of ``l theta`` or a polar-angle step of ``l`` radians decorrelates it.
    Draws ``2 K`` normals, ``2 K`` normals and ``2 K`` uniforms from ``rng``, in that order."""

    def __init__(self, params, rng: np.random.Generator, features: int = DISARRAY_FEATURES) -> None:
        scale = 1.0 / params.disarray_length
        self.w = rng.normal(0.0, scale, (2, features, 1))
        self.m = np.rint(rng.normal(0.0, scale, (2, features, 1)))
        self.b = rng.uniform(0.0, 2.0 * math.pi, (2, features, 1))
        self.amplitude = math.sqrt(2.0 / features)
        self.theta_0 = position_e2_deg(params) * DEG

    def values(self, eccentricities, polar_angles) -> np.ndarray:
        """The two fields at each retinal place: an array of shape (2, n) for n places given by
        their eccentricities (rad) and polar angles (rad)."""
        u = np.log1p(np.asarray(eccentricities, dtype=float) / self.theta_0)
        phase = self.w * u + self.m * np.asarray(polar_angles, dtype=float) + self.b
        return self.amplitude * np.cos(phase).sum(axis=1)
