"""Kalman belief features for learned policies: the Eyecatch filter's estimate as extra inputs.

A PPO policy sees one noisy, often empty, eye-frame sample per step; remembering and fusing them is
what the Eyecatch filter does. :class:`BeliefFeatures` runs that filter (Eyecatch Eq. 4-14, with the
vision model's covariance) on the observation stream and appends, in the seat frame: estimated ball
position (3) and velocity (3), the log standard deviations of the position estimate (3) and whether
the filter has been initialised (1). The same object is used by the training wrapper and by the
evaluation-time agent, so both see identical inputs.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from visuomotor_gym.baselines.eyecatch.agent import EyecatchAgent

from visuomotor_gym.envs.catch import SEAT_ORIGIN

N_BELIEF = 10


class BeliefFeatures:
    """Stateful observation transform (reset it at every episode start)."""

    def __init__(self, env_id: str):
        # The Eyecatch agent owns the filter plumbing (delay, covariance from the prior, resets);
        # only its perception half is used.
        self._agent = EyecatchAgent.for_env(env_id)
        self.reset()

    def reset(self) -> None:
        self._agent.reset()

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        self._agent._act(np.asarray(obs, dtype=float))  # perception + bookkeeping; action ignored
        f = self._agent.filter
        extra = np.zeros(N_BELIEF)
        if f.initialised:
            delay = self._agent.delay_steps * self._agent.dt
            pos, vel = f.extrapolate(delay)
            extra[0:3] = pos - SEAT_ORIGIN
            extra[3:6] = vel
            extra[6:9] = 0.5 * np.log(np.clip(np.diag(f.P)[:3], 1e-12, None))
            extra[9] = 1.0
        return np.concatenate([np.asarray(obs, dtype=np.float32), extra.astype(np.float32)])


class BeliefObservation(gym.ObservationWrapper):
    """Gymnasium wrapper appending :class:`BeliefFeatures` to a flat EyeCatch observation."""

    def __init__(self, env: gym.Env, env_id: str):
        super().__init__(env)
        low = np.full(env.observation_space.shape[0] + N_BELIEF, -np.inf, dtype=np.float32)
        self.observation_space = gym.spaces.Box(low, -low, dtype=np.float32)
        self.features = BeliefFeatures(env_id)

    def reset(self, **kwargs):
        self.features.reset()
        return super().reset(**kwargs)

    def observation(self, observation):
        return self.features(observation)
