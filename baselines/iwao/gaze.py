"""Iwao et al.'s visuomotor coordination model (Eq. 1-10): head and eye pitch per gait cycle.

Per cycle of length ``T_F`` (here one step, heel strike to heel strike: the cycle of the head's vertical
translation, Iwao et al. Fig. 4), head and eye pitch are Gaussians peaking at ``mu = T_F / 2``::

    theta_H(t) = theta_Hmax exp(-(t - mu)^2 / (2 sigma_H^2))                              (Eq. 1)
    theta_E(t) = theta_Emax exp(-(t - (mu + t_E))^2 / (2 sigma_E^2))                      (Eq. 2)
    theta_G = theta_H + theta_E + theta_B + (theta_Vmax - l / beta)                      (Eq. 5)

with ``theta_G = arctan(h / l)`` the obstacle's angle below the horizontal (section 4.2.1), ``theta_B``
the body's pitch and ``theta_V = theta_Vmax - l / beta`` the view angle at which the obstacle is seen
"indirectly" (20 deg walking, section 4.2.3).

**Eq. 6 against Eq. 7.** Eq. 6 says ``theta_Hmax = alpha theta_Emax``; Eq. 7 writes the eye's
Gaussian as ``alpha theta_Hmax`` (i.e. ``theta_Emax = alpha theta_Hmax``). Eq. 8-10 divide by
``1 + 1/alpha`` for the head and ``1 + alpha`` for the eye, which is what Eq. 6 gives. **We follow
Eq. 6 (and Eq. 8-10):** ``theta_Hmax = alpha X / (1 + alpha)``, ``theta_Emax = X / (1 + alpha)``,
``X = theta_G(mu) - theta_B(mu) - theta_V(mu)``; ``t_E = 0`` as the paper does for Eq. 8.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

DEG = math.pi / 180.0


@dataclass(frozen=True)
class IwaoGazeParams:
    # The view angle while walking (Iwao et al., Sec. 4.2.3: 20 deg walking, 30 deg running).
    view_angle_max_deg: float = 20.0
    # beta in theta_V = theta_Vmax - l / beta (metres per degree). The paper gives no value: modelling
    # choice, the view angle is 0 (the obstacle foveated) from 2 m away and 10 deg at 1 m.
    beta_m_per_deg: float = 0.1
    # alpha, the head/eye ratio ("carefulness"). No value in the paper: modelling choice, the head does a
    # third of the downward gaze shift and the eye two thirds.
    alpha: float = 0.5
    # sigma_H = sigma_E as fractions of the cycle. No value in the paper: modelling choice, T_F / 6 (the
    # Gaussian is ~1 % of its peak at the cycle's ends, so each cycle starts and ends near level).
    sigma_fraction: float = 1.0 / 3.0
    # t_E: the paper neglects the eye's lag for Eq. 8-10; so do we.
    eye_lag_s: float = 0.0
    # theta_B: the walker's trunk does not pitch (torso rigid on the pelvis, which keeps level).
    body_pitch_deg: float = 0.0


def peak_angles(theta_g: float, l: float, p: IwaoGazeParams) -> tuple[float, float]:  # noqa: E741 (Eq. 5's l)
    """(theta_Hmax, theta_Emax) in radians (downward positive) for an obstacle at angle ``theta_g`` and
    horizontal distance ``l`` (m) at the cycle's middle: Eq. 8-10 (Eq. 6's alpha). The view angle is
    kept in [0, theta_Vmax] (beyond ``beta * theta_Vmax`` metres the obstacle is looked at directly)."""
    theta_v = min(max(p.view_angle_max_deg - l / p.beta_m_per_deg, 0.0), p.view_angle_max_deg) * DEG
    x = max(theta_g - p.body_pitch_deg * DEG - theta_v, 0.0)
    return p.alpha * x / (1.0 + p.alpha), x / (1.0 + p.alpha)


def gaussian(t: float, mu: float, sigma: float) -> float:
    return math.exp(-((t - mu) ** 2) / (2.0 * sigma * sigma))


def pitch_at(t: float, cycle_s: float, head_max: float, eye_max: float, p: IwaoGazeParams) -> tuple[float, float]:
    """(theta_H(t), theta_E(t)) in radians, downward positive, ``t`` seconds into the cycle (Eq. 1-2)."""
    mu = 0.5 * cycle_s
    sigma = p.sigma_fraction * cycle_s
    return head_max * gaussian(t, mu, sigma), eye_max * gaussian(t, mu + p.eye_lag_s, sigma)
