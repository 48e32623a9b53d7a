"""The real belief update between plans: one Kalman filter per object, plus Eom's compact covariance.

Each tracked object has two pieces of belief:

* the **mean** (and the estimator's own full covariance) comes from the Eyecatch filter
  (:class:`visuomotor_gym.baselines.eyecatch.BallKalmanFilter`, Yeo et al. 2012 Eq. 4-14): it fuses every
  real eye-frame sample (position *and* velocity) weighted by the environment's foveated covariance
  A Sigma^2 A^T. This is Eom Eq. 3 with the real observation, i.e. "the actual simulation" of Eom
  section 6, with the vision model of our environment;
* the **compact covariance** ``sigma = (sp, sv, spv)`` of Eom section 4.3 is what the planner reasons
  with. Eom Eq. 4 does not depend on the observation, only on where the eye looked, so it is propagated
  every control step with the planner's own model (:func:`.belief.covariance_step`, process noise
  ``Q = alpha I`` per 20 ms step): observed with the actual gaze when the eye produced a sample, predicted
  only when it did not (saccadic suppression, outside the field of view). When the object is first seen
  it starts from a vague prior (``prior``, 1 m^2 and 1 (m/s)^2 by default; Eom give none) updated with
  that first observation, or, with ``prior=None``, from the compact projection of the filter's covariance.
"""

from __future__ import annotations

import math

import numpy as np
from visuomotor_gym.baselines.eyecatch import BallKalmanFilter, EyecatchAgent, KalmanParams

from visuomotor_gym.vision import foveation
from visuomotor_gym.vision.foveation import VisionParams

from .belief import ObservationNoise, compact_from_covariance, covariance_step, observation_variance


class ObjectBelief:
    """Belief about one object: Kalman mean (real update) + compact covariance (Eom's model)."""

    def __init__(self, dt: float, kalman: KalmanParams, prior: tuple[float, float, float] | None = None):
        self.dt = float(dt)
        self.prior = prior  # compact covariance before the first observation (None: from the filter)
        self.filter = BallKalmanFilter(dt, kalman)
        self.sigma: np.ndarray | None = None
        self.prev_gaze: np.ndarray | None = None

    @property
    def tracked(self) -> bool:
        return self.filter.initialised

    def predict(self) -> None:
        if self.filter.initialised:
            self.filter.predict()

    def fuse(self, z: np.ndarray, rot: np.ndarray, eye: np.ndarray, eye_turn: np.ndarray,
             vision: VisionParams) -> None:
        """Fuse one eye-frame sample ``z`` = (position, velocity) taken with eye axes ``rot`` at ``eye``.

        The noise covariance is evaluated as the Eyecatch agent does (conservatively: the larger of the
        prior's and the sample's distance and retinal speed, the prior's direction), see
        ``EyecatchAgent._fuse``; a prior behind the eye restarts the filter.
        """
        f = self.filter
        if f.initialised and float(rot[:, 0] @ (f.x[:3] - eye)) <= 0.0:
            f.reset()
        pos, vel = z[:3], z[3:]
        if f.initialised:
            sample_dist = math.sqrt(float(pos @ pos))
            prior = rot.T @ (f.x[:3] - eye)
            prior_dist = math.sqrt(float(prior @ prior))
            # Unlike the single-ball heuristic we also keep the larger eccentricity: an object first seen
            # in the periphery (the second ball) has a poor prior whose direction may sit near the fovea,
            # and a foveal noise level would lock that wrong estimate in.
            direction = prior if prior[0] / max(prior_dist, 1e-9) <= pos[0] / max(sample_dist, 1e-9) else pos
            pos = direction * (max(prior_dist, sample_dist) / max(math.sqrt(float(direction @ direction)), 1e-9))
            vel = rot.T @ f.x[3:]
        speed = max(EyecatchAgent._retinal_speed(pos, vel, eye_turn), EyecatchAgent._retinal_speed(pos, z[3:], eye_turn))
        # self.dt: the positional disarray, if the eye has it, sized for a stream of looks (none without)
        f.update(z, foveation.covariance(pos, speed, vision, dt=self.dt), rot, eye)

    def update_sigma(self, seen: bool, gaze_az: float, gaze_el: float, eye: np.ndarray,
                     noise: ObservationNoise, q: float, slip: float = 0.0) -> None:
        """Eom Eq. 4 for one control step with the actual gaze (prediction only when nothing was seen);
        ``slip``: the object's estimated retinal speed (rad/s) during the step."""
        if not self.filter.initialised:
            return
        r = observation_variance(noise, gaze_az, gaze_el, self.filter.x[:3], eye, slip2=slip * slip) if seen else math.inf
        if self.sigma is None:  # first sight: the prior, then this observation
            self.sigma = np.array(self.prior, dtype=float) if self.prior is not None else compact_from_covariance(self.filter.P)
        self.sigma = covariance_step(self.sigma, np.asarray(r), self.dt, q)

    def reset(self) -> None:
        self.filter.reset()
        self.sigma = None
