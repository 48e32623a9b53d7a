"""Scripted interception policy for ``EyeCatchOracle-v0`` (the upper bound of the ladder).

It reads the *true* ball state that only the Oracle variant puts in the observation, extrapolates
the ballistic flight to the frontal plane ``x = intercept_x`` in front of the right shoulder, and
holds the hand there, closed (or open, to check that an open hand never catches); the eye follows
the ball (saccades when it is far off the line of sight, pursuit otherwise). It is a check of
the environment (throws are catchable, catch detection works), not a model of human catching; on
the foveated variants its input is noisy and it has no filter, so it is not a leaderboard agent.
"""

from __future__ import annotations

import math

import numpy as np

from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.envs.actions import hand_action
from visuomotor_gym.envs.observation import ObservationLayout
from visuomotor_gym.scenarios.throws import GRAVITY

_S = ObservationLayout().slices


class InterceptOracle:
    """Move the catch site to where the ball will cross ``x = intercept_x`` (world, metres)."""

    def __init__(
        self,
        intercept_x: float = 0.38,
        grasp_closed: bool = True,
        track_with_eye: bool = True,
        gaze_action_range_deg: float = 60.0,
    ):
        self.intercept_x = float(intercept_x)
        self.grasp = 1.0 if grasp_closed else -1.0
        self.track_with_eye = bool(track_with_eye)
        self.gaze_range = math.radians(gaze_action_range_deg)

    def intercept_point(self, obs: np.ndarray) -> np.ndarray | None:
        """World point where the observed ball crosses the intercept plane, or None."""
        if obs[_S["ball_visible"]][0] < 0.5:
            return None
        rot = obs[_S["eye_rot"]].astype(float).reshape(3, 3)
        eye = obs[_S["eye_pos"]].astype(float) + SEAT_ORIGIN
        pos = eye + rot @ obs[_S["ball_pos"]].astype(float)
        vel = rot @ obs[_S["ball_vel"]].astype(float)
        if vel[0] >= -1e-6:
            return None
        t = (self.intercept_x - pos[0]) / vel[0]
        if t < 0:
            return None
        return pos + vel * t + 0.5 * GRAVITY * t * t

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        point = self.intercept_point(obs)
        if point is None:  # hold the hand where it is
            point = obs[_S["hand_pos"]] + SEAT_ORIGIN
        gaze = (0.0, 0.0)
        if self.track_with_eye and obs[_S["ball_visible"]][0] > 0.5:
            # Request the ball's retinal direction: a saccade when far off, pursuit when close.
            x, y, z = obs[_S["ball_pos"]]
            gaze = (math.atan2(y, x), math.atan2(z, math.hypot(x, y)))
        return hand_action(point, self.grasp > 0, gaze, gaze_range_rad=self.gaze_range), state
