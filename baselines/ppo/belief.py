"""Kalman belief features for learned policies, and an optional belief-relative hand action.

A PPO policy sees one noisy, often empty, eye-frame sample per step; remembering and fusing them is
what the Eyecatch filter does. :class:`BeliefFeatures` runs that filter (Eyecatch Eq. 4-14, with the
vision model's covariance) on the observation stream and appends, in the seat frame: estimated ball
position (3) and velocity (3), the log standard deviations of the position estimate (3) and whether
the filter has been initialised (1).

With ``hand_action="intercept"`` it also appends where the hand should meet the ball according to
that belief (the Eyecatch proactive interception point: the predicted path's entry into the
preferred-distance sphere around the head, pulled within reach; before the first sighting, the
ready pose of Eyecatch Eq. 19) and in how many seconds (4 values), and the policy's three hand
values become a *residual* around that point (± ``residual_m`` per axis) instead of an absolute
target in the workspace. Gaze, fixation, head and grasp stay the policy's own. This is residual
policy learning (Silver et al. 2018, Johannink et al. 2019): the belief does the ballistic
extrapolation, the policy learns where to look, when to grasp and how to correct the hand.

The same object is used by the training wrapper and by the evaluation-time agent, so both see
identical inputs and produce identical env actions.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from visuomotor_gym.baselines.eyecatch.agent import EyecatchAgent

from visuomotor_gym.envs.actions import hand_target_action
from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.envs.observation import ObservationLayout

N_BELIEF = 10
N_INTERCEPT = 4
HAND_ACTIONS = ("absolute", "intercept")
_S = ObservationLayout().slices


class BeliefFeatures:
    """Stateful observation transform (reset it at every episode start).

    ``hand_action="intercept"`` adds the interception features and makes :meth:`env_action` map a
    policy action (residual hand block) to the env's action.
    """

    def __init__(self, env_id: str, hand_action: str = "absolute", residual_m: float = 0.15):
        if hand_action not in HAND_ACTIONS:
            raise ValueError(f"hand_action must be one of {HAND_ACTIONS}, got {hand_action!r}")
        if not (math.isfinite(residual_m) and residual_m > 0):
            raise ValueError(f"residual_m must be a positive number of metres, got {residual_m!r}")
        # The Eyecatch agent owns the filter plumbing (delay, covariance from the prior, resets);
        # only its perception half and its interception geometry are used.
        self._agent = EyecatchAgent.for_env(env_id)
        self.hand_action = hand_action
        self.residual_m = float(residual_m)
        self.size = N_BELIEF + (N_INTERCEPT if hand_action == "intercept" else 0)
        self.reset()

    def reset(self) -> None:
        self._agent.reset()
        self.intercept_point = None  # world point the residual hand action is relative to

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        obs64 = np.asarray(obs, dtype=float)
        self._agent._act(obs64)  # perception + bookkeeping; action ignored
        f = self._agent.filter
        extra = np.zeros(self.size)
        if f.initialised:
            delay = self._agent.delay_steps * self._agent.dt
            pos, vel = f.extrapolate(delay)
            extra[0:3] = pos - SEAT_ORIGIN
            extra[3:6] = vel
            extra[6:9] = 0.5 * np.log(np.clip(np.diag(f.P)[:3], 1e-12, None))
            extra[9] = 1.0
        if self.hand_action == "intercept":
            point, seconds = self._intercept(obs64)
            self.intercept_point = point
            extra[N_BELIEF : N_BELIEF + 3] = point - SEAT_ORIGIN
            extra[N_BELIEF + 3] = seconds
        return np.concatenate([np.asarray(obs, dtype=np.float32), extra.astype(np.float32)])

    def _intercept(self, obs: np.ndarray) -> tuple[np.ndarray, float]:
        """(world point, seconds until the ball gets there) from the current belief."""
        agent, p = self._agent, self._agent.params
        eye = obs[_S["eye_pos"]] + SEAT_ORIGIN
        if not agent.filter.initialised:  # nothing seen yet: the ready pose (Eyecatch Eq. 19)
            return agent._within_reach(agent.ready_point(obs[_S["eye_rot"]].reshape(3, 3), eye)), p.prediction_horizon_s
        point, seconds = agent._interception(eye, agent.delay_steps * agent.dt)
        return agent._within_reach(point), seconds

    def env_action(self, action: np.ndarray) -> np.ndarray:
        """The env action for a policy action (identity unless ``hand_action="intercept"``)."""
        if self.hand_action != "intercept":
            return action
        if self.intercept_point is None:
            raise RuntimeError("call the features on an observation before mapping an action")
        out = np.array(action, dtype=np.float32, copy=True)
        residual = np.clip(np.asarray(action[:3], dtype=float), -1.0, 1.0) * self.residual_m
        out[:3] = hand_target_action(self.intercept_point + residual)
        return out


class BeliefObservation(gym.Wrapper):
    """Gymnasium wrapper appending :class:`BeliefFeatures` to a flat EyeCatch observation (and, with
    ``hand_action="intercept"``, reading the hand block of actions as a residual around the belief's
    interception point)."""

    def __init__(self, env: gym.Env, env_id: str, hand_action: str = "absolute", residual_m: float = 0.15):
        super().__init__(env)
        self.features = BeliefFeatures(env_id, hand_action, residual_m)
        low = np.full(env.observation_space.shape[0] + self.features.size, -np.inf, dtype=np.float32)
        self.observation_space = gym.spaces.Box(low, -low, dtype=np.float32)

    def reset(self, **kwargs):
        self.features.reset()
        obs, info = self.env.reset(**kwargs)
        return self.features(obs), info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(self.features.env_action(action))
        return self.features(obs), reward, terminated, truncated, info


class InterceptBase:
    """The fixed policy PPO's residual starts from, with nothing learned: hand block 0 (the closed
    hand at the belief's interception point), grasp closed, gaze, fixation and head held still.

    It measures how much of a ``hand_action="intercept"`` policy's catch rate the structure alone
    gives (``vmgym bench --agent belief_intercept``).
    """

    def __init__(self, env_id: str, residual_m: float = 0.15):
        self.features = BeliefFeatures(env_id, "intercept", residual_m)

    def reset(self) -> None:
        self.features.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]):
            self.reset()
        self.features(observation)
        action = np.zeros(9, dtype=np.float32)
        action[3] = 1.0  # grasp closed
        return self.features.env_action(action), state
