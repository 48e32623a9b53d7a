"""The belief dynamics of Eom, Han, Shin & Noh (TOG 2019), section 4.3 and Appendix A, in closed form.

Per tracked object ``j`` the belief is ``N(mu_j, Sigma_j)`` over its world position and velocity
``x_j = (p_j, v_j)``. The internal process model knows gravity (Eom Eq. 2, McIntyre et al. 2001)::

    x' = F x + y + delta,   F = [[I, h I], [0, I]],   y = [g h^2 / 2; g h],   delta ~ N(0, Q),  Q = alpha I

(Eom prints ``y = [0; h a]``; we keep the exact ``g h^2 / 2`` position term, as the Eyecatch filter
does, so the mean update is exact for a ballistic ball.) The eye observes the position only
(Eom Eq. 1), ``z = H x + rho``, ``H = [I 0]``, ``rho ~ N(0, r I)``, where ``r`` depends on where the eye
looks.

**Observation noise: the environment's foveated model, not Eom's r.** Eom uses
``r = 1 - exp(-|p_ps - p| / (2 eta))``. We use the noise model the environment actually applies
(``visuomotor_gym.vision.foveation``, Eyecatch Eq. 1-3): every standard deviation is proportional to the
distance ``d`` and divided by the acuity ``alpha(theta) = E2 / (E2 + theta)``. Isotropic (``R = r I``) is
what keeps Eom's covariance compact, so ``r`` is the mean of the three positional variances::

    r = k^2 d^2 (1 + theta_s / E2)^2 + r_floor,   k^2 = s^2 (depth_frac^2 + 2 sigma_q^2) / 3

with ``s`` the vision noise scale, ``depth_frac`` = 5 %, ``sigma_q`` = 1 arcmin and ``E2`` = 2 deg.

**Retinal slip**: the environment's lateral std grows with the image's speed on the retina,
``sigma_q max(1, slip / knee)`` (``VisionParams.position_slip_knee_deg_s`` = 2.5 deg/s, Westheimer &
McKee 1975). The planner keeps the mean of the three variances with the two lateral ones scaled by a
smooth ``1 + slip^2 / knee^2`` (modelling choice: differentiable, equal to the environment's
``max(1, slip/knee)^2`` far above the knee and at most twice it near the knee)::

    r = d^2 (1 + theta_s / E2)^2 (k^2 + k_lat^2 slip^2 / knee^2) + r_floor,   k_lat^2 = 2 s^2 sigma_q^2 / 3

where ``slip`` is the angular speed of the object's direction minus the gaze's own: in the planner the
gaze rate is a control, so the observation noise -- and through it Eom's uncertainty cost -- rewards
pursuit that stabilises the image (and the planner's ``B`` depends on the trajectory). The lateral
share is small at the fovea (1 arcmin against 5 % depth) and grows with slip: ~3 % of ``r`` at
50 deg/s, ~40 % at 200 deg/s (an object crossing a still eye near the hand). The
eccentricity is smoothed for differentiability: ``theta_s = sqrt(|g - u|^2 + eps^2)``, the chord
between the unit gaze ``g`` and the unit direction ``u`` to the believed object (``|g - u| = 2 sin(theta/2)``,
equal to ``theta`` to 1 % below 28 deg). Unlike Eom's saturating ``r``, this one keeps growing away from
the fovea, so the planner's gradient points toward an object however far the eye is from it.

**Compact covariance** (Eom section 4.3): with isotropic ``Sigma_0``, ``Q`` and ``R`` every block of
Sigma stays a multiple of ``I``, ``Sigma = [[sp I, spv I], [spv I, sv I]]``, stored as
``sigma = (sp, sv, spv)``. One step (Appendix A)::

    a = sp + 2 h spv + h^2 sv + q      (prior sp)        s = a + r
    b = spv + h sv                     (prior spv)
    c = sv + q                         (prior sv)
    sp' = a r / s,   spv' = b r / s,   sv' = c - b^2 / s

Sigma' does not depend on the observation (Eom Eq. 4), and under the deterministic mean update of
Eom section 6 the planned mean is ``mu' = F mu + y`` (the expectation over observations). All
derivatives below are closed form (Eom section 7 uses D* for the same purpose) and are checked
against finite differences in ``tests/test_belief_mpc.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from visuomotor_gym.vision.foveation import ARCMIN, DEG, VisionParams

GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass(frozen=True)
class ObservationNoise:
    """Scalar position-noise model ``r(d, theta)`` (see the module docstring); SI units."""

    k2: float  # variance per squared metre of distance, at the fovea
    e2_rad: float  # acuity halves this far from the fovea
    eps_rad: float = 0.2 * DEG  # eccentricity smoothing
    floor_m2: float = 1e-6  # measurement floor (1 mm std), as the Eyecatch filter's
    angular: bool = False  # True: drop the d^2 factor (uncertainty in units of the object's distance)
    k2_slip: float = 0.0  # the lateral share of k2, scaled by slip^2 / knee^2 (module docstring)
    knee_rad_s: float = math.inf  # slip knee (rad/s); inf: no slip term (the paper's static acuity)

    @classmethod
    def from_vision(cls, vision: VisionParams, eps_deg: float = 0.2, angular: bool = False,
                    slip: bool = True) -> ObservationNoise:
        s = vision.noise_scale
        sq = vision.retinal_position_std_arcmin * ARCMIN
        k2 = s * s * (vision.depth_std_fraction**2 + 2.0 * sq * sq) / 3.0
        # The env applies the slip factor only with foveation (slip_factor); FullView has none.
        knee = vision.position_slip_knee_deg_s * DEG if (slip and vision.foveated) else math.inf
        return cls(k2=k2, e2_rad=vision.fovea_e2_deg * DEG if vision.foveated else math.inf,
                   eps_rad=eps_deg * DEG, angular=angular, k2_slip=2.0 * s * s * sq * sq / 3.0,
                   knee_rad_s=knee)

    @property
    def slip_coef(self) -> float:
        """``k_lat^2 / (k^2 knee^2)``: r = k^2 d^2 amp^2 (1 + slip_coef slip^2) + floor."""
        if not math.isfinite(self.knee_rad_s) or self.k2 <= 0.0:
            return 0.0
        return self.k2_slip / (self.k2 * self.knee_rad_s**2)


def gaze_vector(az, el):
    """Unit gaze for world azimuth/elevation (broadcasts): x forward, y left, z up."""
    ce = np.cos(el)
    return np.stack([ce * np.cos(az), ce * np.sin(az), np.sin(el)], axis=-1)


def gaze_vector_derivatives(az, el):
    """(g, dg/daz, dg/del), each (..., 3)."""
    ca, sa, ce, se = np.cos(az), np.sin(az), np.cos(el), np.sin(el)
    g = np.stack([ce * ca, ce * sa, se], axis=-1)
    g_az = np.stack([-ce * sa, ce * ca, np.zeros_like(ce)], axis=-1)
    g_el = np.stack([-se * ca, -se * sa, ce], axis=-1)
    return g, g_az, g_el


def observation_variance(noise: ObservationNoise, gaze_az, gaze_el, pos, eye, with_grad: bool = False,
                         slip2=None):
    """``r`` for objects at world ``pos`` (..., 3) seen from ``eye`` (3,) with gaze (az, el) (...).

    ``slip2``: squared retinal slip (rad/s)^2 (broadcasts with the result; None: a stabilised image).
    With ``with_grad`` also returns ``dr/d(az, el)`` (..., 2) and ``dr/dpos`` (..., 3), and, when
    ``slip2`` is given, ``dr/dslip2`` (...).
    """
    rel = pos - eye
    d2 = np.maximum(np.einsum("...i,...i->...", rel, rel), 1e-12)
    d = np.sqrt(d2)
    ce = np.cos(gaze_el)
    # g . u without building g: u = rel / d
    gu = (ce * np.cos(gaze_az) * rel[..., 0] + ce * np.sin(gaze_az) * rel[..., 1] + np.sin(gaze_el) * rel[..., 2]) / d
    theta = np.sqrt(np.maximum(2.0 - 2.0 * gu, 0.0) + noise.eps_rad**2)
    amp = 1.0 + theta / noise.e2_rad
    scale = 1.0 if noise.angular else d2
    coef = noise.slip_coef
    k2 = noise.k2 if slip2 is None or coef == 0.0 else noise.k2 * (1.0 + coef * np.asarray(slip2))
    r = k2 * scale * amp * amp + noise.floor_m2
    if not with_grad:
        return r
    u = rel / d[..., None]
    g, g_az, g_el = gaze_vector_derivatives(gaze_az, gaze_el)
    dr_dtheta = 2.0 * k2 * scale * amp / noise.e2_rad
    dtheta_dgu = -1.0 / theta
    cgu = dr_dtheta * dtheta_dgu  # dr / d(g.u)
    dr_dgaze = np.stack([cgu * np.sum(g_az * u, axis=-1), cgu * np.sum(g_el * u, axis=-1)], axis=-1)
    # d(g.u)/dpos = (g - (g.u) u) / d ;  d(d^2)/dpos = 2 rel
    dgu_dpos = (g - gu[..., None] * u) / d[..., None]
    dr_dpos = cgu[..., None] * dgu_dpos
    if not noise.angular:
        dr_dpos = dr_dpos + (k2 * amp * amp)[..., None] * 2.0 * rel
    if slip2 is None:
        return r, dr_dgaze, dr_dpos
    dr_dslip2 = np.broadcast_to(noise.k2 * coef * scale * amp * amp, np.shape(r))
    return r, dr_dgaze, dr_dpos, dr_dslip2


def covariance_step(sigma: np.ndarray, r, h: float, q: float, with_grad: bool = False):
    """One compact covariance update (Appendix A). ``sigma`` (..., 3) = (sp, sv, spv); ``r`` (...).

    With ``with_grad`` also returns ``dsigma'/dsigma`` (..., 3, 3) and ``dsigma'/dr`` (..., 3).
    ``r = inf`` (nothing seen) gives the prediction only.
    """
    sp, sv, spv = sigma[..., 0], sigma[..., 1], sigma[..., 2]
    a = sp + 2.0 * h * spv + h * h * sv + q
    b = spv + h * sv
    c = sv + q
    r = np.asarray(r, dtype=float)
    if not with_grad and r.ndim and np.all(np.isfinite(r)):  # the planner's hot path: everything observed
        s = a + r
        out = np.empty(np.broadcast_shapes(sigma.shape, r.shape + (3,)))
        out[..., 0] = a * r / s
        out[..., 1] = c - b * b / s
        out[..., 2] = b * r / s
        return out
    seen = np.isfinite(r)
    r_ = np.where(seen, r, 1.0)
    s = a + r_
    inv_s = 1.0 / s
    out = np.empty(np.broadcast_shapes(sigma.shape, r.shape + (3,)))
    out[..., 0] = np.where(seen, a * r_ * inv_s, a)
    out[..., 1] = np.where(seen, c - b * b * inv_s, c)
    out[..., 2] = np.where(seen, b * r_ * inv_s, b)
    if not with_grad:
        return out
    # Partials of (sp', sv', spv') with respect to the priors (a, c, b) and r.
    inv_s2 = inv_s * inv_s
    d_a = np.stack([r_ * r_ * inv_s2, b * b * inv_s2, -b * r_ * inv_s2], axis=-1)
    d_c = np.stack([np.zeros_like(a), np.ones_like(a), np.zeros_like(a)], axis=-1)
    d_b = np.stack([np.zeros_like(a), -2.0 * b * inv_s, r_ * inv_s], axis=-1)
    d_r = np.stack([a * a * inv_s2, b * b * inv_s2, a * b * inv_s2], axis=-1)
    unseen = ~seen
    if np.any(unseen):
        d_a = np.where(unseen[..., None], np.array([1.0, 0.0, 0.0]), d_a)
        d_b = np.where(unseen[..., None], np.array([0.0, 0.0, 1.0]), d_b)
        d_r = np.where(unseen[..., None], 0.0, d_r)
    # Priors with respect to sigma = (sp, sv, spv): a = (1, h^2, 2h), c = (0, 1, 0), b = (0, h, 1).
    da = np.array([1.0, h * h, 2.0 * h])
    dc = np.array([0.0, 1.0, 0.0])
    db = np.array([0.0, h, 1.0])
    jac = d_a[..., :, None] * da + d_c[..., :, None] * dc + d_b[..., :, None] * db
    return out, jac, d_r


def mean_step(mu: np.ndarray, h: float) -> np.ndarray:
    """Deterministic mean update of Eom section 6: ``mu' = F mu + y`` (the expectation over z)."""
    out = np.array(mu, dtype=float, copy=True)
    out[..., :3] = mu[..., :3] + h * mu[..., 3:] + 0.5 * h * h * GRAVITY
    out[..., 3:] = mu[..., 3:] + h * GRAVITY
    return out


def mean_trajectory(mu: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Positions of the deterministic mean at ``times`` (s ahead), shape (len(times), 3) (exact)."""
    t = np.asarray(times, dtype=float)[:, None]
    return mu[:3] + mu[3:] * t + 0.5 * GRAVITY * t * t


def belief_step(mu, sigma, gaze_az, gaze_el, eye, noise: ObservationNoise, h: float, q: float,
                with_grad: bool = False):
    """The full deterministic belief step of one object: ``(mu', sigma')`` and, with ``with_grad``,
    the Jacobians ``dsigma'/dsigma`` (3, 3), ``dsigma'/d(az, el)`` (3, 2), ``dsigma'/dmu`` (3, 6);
    ``dmu'/dmu = F`` is constant and ``dmu'/dsigma = dmu'/dgaze = 0``.

    The observation noise is evaluated at the prior mean (where the object is believed to be when
    it is looked at).
    """
    mu_bar = mean_step(mu, h)
    if not with_grad:
        r = observation_variance(noise, gaze_az, gaze_el, mu_bar[:3], eye)
        return mu_bar, covariance_step(sigma, r, h, q)
    r, dr_dg, dr_dp = observation_variance(noise, gaze_az, gaze_el, mu_bar[:3], eye, with_grad=True)
    sig, d_sig, d_r = covariance_step(sigma, r, h, q, with_grad=True)
    d_gaze = np.outer(d_r, dr_dg)
    # d r / d mu through mu_bar = F mu + y: dp_bar/dp = I, dp_bar/dv = h I.
    dr_dmu = np.concatenate([dr_dp, h * dr_dp])
    d_mu = np.outer(d_r, dr_dmu)
    return mu_bar, sig, d_sig, d_gaze, d_mu


def compact_from_covariance(P: np.ndarray) -> np.ndarray:
    """The closest compact ``(sp, sv, spv)`` to a full 6x6 covariance (Frobenius: block traces / 3)."""
    return np.array([np.trace(P[:3, :3]) / 3.0, np.trace(P[3:, 3:]) / 3.0, np.trace(P[:3, 3:]) / 3.0])
