"""Kalman filter of the ball state, Yeo et al., *Eyecatch* (SIGGRAPH 2012), section 3.2.

State ``x = (p, p_dot)`` in the world frame; the internal model knows gravity (McIntyre et al.
2001):

    x_{k+1} = F x_k + b,   F = [[I, I dt], [0, I]],   b = [g dt^2 / 2; g dt]           (Eq. 4-5)

(Eq. 5 prints ``b = [0; g dt]``; without the ``g dt^2 / 2`` position term the internal model drifts
2 mm per 20 ms step away from a real ballistic flight, which a filter without process noise turns
into overconfident, biased estimates. We keep the exact term.)

The eye observes the ball in the eye frame (orientation ``R``, position ``r``):

    z_k = H_k x_k + h_k + v_k,   H_k = blockdiag(R^T, R^T),   h_k = [-R^T r; 0]          (Eq. 6-7)

with ``v_k ~ N(0, A Sigma^2 A^T)`` from the vision model (Eq. 1-3). Predict / update are Eq. 8-14;
there is no process noise in the paper (the brain trusts its gravity model). When the Mahalanobis
measure of the innovation ``y^T S^-1 y`` is abnormal (a bounce), the prior covariance is reset to a
large value before the update (the adaptive reset at the end of section 3.2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

GRAVITY = np.array([0.0, 0.0, -9.81])


@dataclass(frozen=True)
class KalmanParams:
    """Constants of the filter."""

    initial_position_var_m2: float = 100.0  # P_0|0: "sufficiently large" (Eyecatch 3.2)
    initial_velocity_var_m2_s2: float = 100.0
    reset_mahalanobis: float = 40.0  # y^T S^-1 y above this resets P: the chi^2 (6 dof) tail beyond 40
    # has p = 4.6e-7, about one false reset in 40,000 throws of 50 samples (the paper gives no value:
    # our choice of p). The one threshold of the Eyecatch agent (EyecatchParams.reset_mahalanobis); on
    # 200 EyeCatchBounce-v0 throws it catches 43 % against 38.5 % with 100
    reset_after_abnormal_samples: float = 2  # the reset needs this many abnormal innovations in a
    # row; a single one is an outlier and its sample is dropped (standard innovation gating). A bounce
    # changes every later innovation, so it still resets, one sample (20 ms) later. Modelling choice:
    # with x10 noise single outliers reset the filter several times a throw. 200 throws: the revised
    # agent catches 57.0 % of EyeCatchBounce-v0 (43.0 % before the revision) and, with 1 instead of 2,
    # 51.5 % of EyeCatchPaperPoorVision-v0 against 53.0 % (docs/reproductions/eyecatch.md)
    reset_when_position_std_below_m: float = 0.25  # only a confident filter resets (Eyecatch 3.2:
    # the failure the reset cures is "especially when the error covariance is small")
    process_noise_acc_m_s2: float = 0.5  # white acceleration noise. The paper has none; without it
    # the filter grows overconfident (state errors ~4 sigma per axis in EyeCatchFullView-v0); with
    # 0.5 m/s^2 the normalised estimation error is chi-square consistent (median 4.1 for 6 dof).
    measurement_floor_m: float = 1e-3  # keeps S invertible and the reset sane with noiseless vision


class BallKalmanFilter:
    """The filter of Eq. 4-14 with the adaptive reset. ``x`` and ``P`` are public."""

    def __init__(self, dt: float, params: KalmanParams | None = None):
        self.dt = float(dt)
        self.params = params or KalmanParams()
        self.F = np.eye(6)
        self.F[:3, 3:] = np.eye(3) * self.dt
        self.b = np.concatenate([0.5 * GRAVITY * self.dt**2, GRAVITY * self.dt])
        q = self.params.process_noise_acc_m_s2**2
        dt = self.dt
        # Discrete white-noise-acceleration covariance (zero by default).
        self.Q = q * np.block(
            [[np.eye(3) * dt**4 / 4, np.eye(3) * dt**3 / 2], [np.eye(3) * dt**3 / 2, np.eye(3) * dt**2]]
        )
        self.reset()

    def reset(self) -> None:
        """No prior knowledge: x = 0, P large (Eyecatch 3.2)."""
        self.x = np.zeros(6)
        self.P = self._initial_covariance()
        self.initialised = False  # no measurement yet
        self.resets = 0
        self.rejected = 0
        self.abnormal_run = 0
        self.last_mahalanobis = float("nan")
        self.last_S = None

    def _initial_covariance(self) -> np.ndarray:
        p = self.params
        return np.diag([p.initial_position_var_m2] * 3 + [p.initial_velocity_var_m2_s2] * 3)

    def predict(self) -> None:
        """Eq. 8-9."""
        self.x = self.F @ self.x + self.b
        self.P = self.F @ self.P @ self.F.T + self.Q

    @staticmethod
    def observation_model(rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """H_k and h_k of Eq. 7 for an eye at ``pos`` with axes ``rot`` (columns, world frame)."""
        H = np.zeros((6, 6))
        H[:3, :3] = rot.T
        H[3:, 3:] = rot.T
        h = np.concatenate([-rot.T @ pos, np.zeros(3)])
        return H, h

    def update(self, z: np.ndarray, R_meas: np.ndarray, rot: np.ndarray, pos: np.ndarray) -> float:
        """Eq. 10-14 with the adaptive reset; returns the Mahalanobis measure of the innovation."""
        H, h = self.observation_model(rot, pos)
        R_meas = R_meas + np.eye(6) * self.params.measurement_floor_m**2
        y = z - H @ self.x - h  # Eq. 10
        S = H @ self.P @ H.T + R_meas  # Eq. 11
        maha = float(y @ np.linalg.solve(S, y))
        confident = float(np.trace(self.P[:3, :3])) < 3.0 * self.params.reset_when_position_std_below_m**2
        abnormal = self.initialised and confident and maha > self.params.reset_mahalanobis
        self.abnormal_run = self.abnormal_run + 1 if abnormal else 0
        if abnormal and self.abnormal_run < self.params.reset_after_abnormal_samples:
            self.rejected += 1  # one abnormal sample: an outlier, not (yet) a change of course
            self.last_mahalanobis = maha
            return maha
        if abnormal:
            # Abnormal innovation: forget the prior covariance (the ball changed its course).
            self.P = self._initial_covariance()
            self.resets += 1
            self.abnormal_run = 0
            S = H @ self.P @ H.T + R_meas
        self.x, self.P = self.correct(self.x, self.P, y, S, H)
        self.initialised = True
        self.last_mahalanobis = maha
        self.last_S = S
        return maha

    @staticmethod
    def correct(x, P, y, S, H):
        """Eq. 12-14: the posterior of (x, P) given innovation ``y`` with covariance ``S``."""
        K = np.linalg.solve(S.T, (P @ H.T).T).T  # Eq. 12: P H^T S^-1
        x = x + K @ y  # Eq. 13
        P = (np.eye(len(x)) - K @ H) @ P  # Eq. 14
        return x, 0.5 * (P + P.T)

    def extrapolate(self, horizon_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Mean position and velocity ``horizon_s`` ahead under the internal model (exact)."""
        p, v = self.x[:3], self.x[3:]
        return p + v * horizon_s + 0.5 * GRAVITY * horizon_s**2, v + GRAVITY * horizon_s

    def trajectory(self, times: np.ndarray) -> np.ndarray:
        """Mean positions at ``times`` (s from now), shape (len(times), 3)."""
        t = np.asarray(times, dtype=float)[:, None]
        return self.x[:3] + self.x[3:] * t + 0.5 * GRAVITY * t * t


class RetinalBiasFilter(BallKalmanFilter):
    """:class:`BallKalmanFilter` with a **retinal-bias state** for an eye with the positional disarray
    (``vision/periphery.py``, mechanism 5): the augmented state ``(p, p_dot, g)`` adds ``g``, the two
    unit-variance values of the disarray field (:class:`~visuomotor_gym.vision.periphery.DisarrayField`)
    at the ball's retinal place. A sample's lateral position error is ``s sqrt(w) g`` (fixed in retinal
    place) plus white noise of std ``s sqrt(1 - w)`` (``s`` the lateral std, ``w`` the disarray's share):
    the caller passes ``bias=(rho, M)`` to :meth:`update`, ``M`` (6 x 2) the map of ``g`` into the sample
    (eye frame) and ``rho`` the field's correlation between the last fused sample's retinal place and
    this one's (1: the same place, 0: independent, as after a saccade); between samples
    ``g <- rho g + sqrt(1 - rho^2) xi``, ``xi ~ N(0, I)`` (the field's prior). So a bias that stays with
    the ball's retinal place is not read as motion or depth, and a saccade that moves the ball to
    another place re-draws it.

    ``x`` and ``P`` are the ball's part (views of the augmented ``xa``, ``Pa``): every reader of the
    6-D filter reads them unchanged. Assigning ``x`` sets the ball's mean; assigning ``P`` starts a new
    prior (the bias forgotten: mean 0, covariance I, uncorrelated with the ball).
    """

    BIAS_DIM = 2

    @property
    def x(self) -> np.ndarray:
        return self.xa[:6]

    @x.setter
    def x(self, value) -> None:
        if not hasattr(self, "xa"):
            self.xa = np.zeros(6 + self.BIAS_DIM)
        self.xa[:6] = value

    @property
    def P(self) -> np.ndarray:
        return self.Pa[:6, :6]

    @P.setter
    def P(self, value) -> None:
        if not hasattr(self, "Pa"):
            self.Pa = np.eye(6 + self.BIAS_DIM)
        self.Pa[:6, :6] = value
        self.Pa[:6, 6:] = 0.0
        self.Pa[6:, :6] = 0.0
        self.Pa[6:, 6:] = np.eye(self.BIAS_DIM)
        self.xa[6:] = 0.0

    def predict(self) -> None:
        """Eq. 8-9 on the ball's part; the bias is a property of the retinal place, unchanged."""
        self.xa[:6] = self.F @ self.xa[:6] + self.b
        Pa = self.Pa
        Pa[:6, :6] = self.F @ Pa[:6, :6] @ self.F.T + self.Q
        Pa[:6, 6:] = self.F @ Pa[:6, 6:]
        Pa[6:, :6] = Pa[:6, 6:].T

    def update(self, z: np.ndarray, R_meas: np.ndarray, rot: np.ndarray, pos: np.ndarray,
               bias: tuple[float, np.ndarray] | None = None) -> float:
        """Eq. 10-14 on the augmented state, with the adaptive reset. ``bias=(rho, M)``: see the class
        docstring; None: the sample carries no bias (``M = 0``) and the place is unchanged."""
        rho, M = (1.0, np.zeros((6, self.BIAS_DIM))) if bias is None else (float(bias[0]), np.asarray(bias[1]))
        if not 0.0 <= rho <= 1.0:
            raise ValueError(f"bias correlation rho must be in [0, 1], got {rho!r}")
        if rho < 1.0:  # the ball moved to another retinal place: g <- rho g + sqrt(1 - rho^2) xi
            self.xa[6:] *= rho
            self.Pa[:, 6:] *= rho
            self.Pa[6:, :] *= rho
            self.Pa[6:, 6:] += np.eye(self.BIAS_DIM) * (1.0 - rho * rho)
        H6, h = self.observation_model(rot, pos)
        H = np.hstack([H6, M])
        R_meas = R_meas + np.eye(6) * self.params.measurement_floor_m**2
        y = z - H @ self.xa - h  # Eq. 10
        S = H @ self.Pa @ H.T + R_meas  # Eq. 11
        maha = float(y @ np.linalg.solve(S, y))
        confident = float(np.trace(self.Pa[:3, :3])) < 3.0 * self.params.reset_when_position_std_below_m**2
        abnormal = self.initialised and confident and maha > self.params.reset_mahalanobis
        self.abnormal_run = self.abnormal_run + 1 if abnormal else 0
        if abnormal and self.abnormal_run < self.params.reset_after_abnormal_samples:
            self.rejected += 1
            self.last_mahalanobis = maha
            return maha
        if abnormal:
            self.P = self._initial_covariance()  # the bias forgotten too
            self.resets += 1
            self.abnormal_run = 0
            S = H @ self.Pa @ H.T + R_meas
        self.xa, self.Pa = self.correct(self.xa, self.Pa, y, S, H)
        self.initialised = True
        self.last_mahalanobis = maha
        self.last_S = S
        return maha
