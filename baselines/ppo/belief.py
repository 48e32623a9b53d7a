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

With ``gaze_action="gated"`` (docs/baselines/ppo.md) it also appends where the belief's ball is on the retina
(azimuth, elevation, rad) and the log angular std of that estimate (3 values), and the policy gets a
tenth action value, the **look gate**, and a gaze block that is a *residual* (± ``gaze_residual_deg``):

* gate > 0: the gaze request is the Eyecatch 4.1 request (the belief's ball at the next step, or where
  it will be when a saccade lands when one can start) plus the residual: the plant turns the moving
  request into pursuit and catch-up saccades;
* gate <= 0 (the zero action): the request is the residual alone around the current line of sight
  (0 holds gaze fixed in the world, as the gaze-blind twin does).

So *how* to look at the believed ball is given by the structure; *whether and when* to look (the
gate), the head, the residual gaze, grasp and the hand residual are the policy's. Before the filter
has a sample, the gate does nothing (there is no believed ball to look at).

With ``gaze_action="free_belief"`` the inputs are the gated mode's (the believed ball on the retina and
its log angular std, besides the belief) plus the log of the believed ball's distance from the eye (where
vergence should be; the catch env's depth law makes a fixation far from the ball a disparity pedestal), but the action is the env's 9 values and the gaze, fixation and
head blocks pass to the env exactly as the policy gives them: no gate, no residual, no scripted look. The
env reads the gaze block as the requested retinal offset over ``gaze_action_range_deg``, so looking at the
believed ball is a near-linear map from the retinal inputs to the gaze action, which the policy has to
learn (docs/baselines/rl.md, "A learned gaze without a gate").

With ``gaze_action="frozen"`` the inputs are the gated mode's, the action is the env's 9 values, and
the gaze and head blocks are held at 0 whatever the policy outputs (as ``gaze_blind:<agent>`` holds
them): a policy *trained* with its gaze frozen, the comparison the issue asks for beside the gated
policy with its gaze frozen only at evaluation.

The same object is used by the training wrapper and by the evaluation-time agent, so both see
identical inputs and produce identical env actions.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from visuomotor_gym.baselines.eyecatch.agent import EyecatchAgent

from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.envs.actions import hand_target_action
from visuomotor_gym.envs.observation import ObservationLayout
from visuomotor_gym.registration import env_vision_params

N_BELIEF = 10
N_INTERCEPT = 4
N_GAZE = 3
N_FREE = 1  # free_belief's extra input: log of the believed ball's distance from the eye (vergence target)
HAND_ACTIONS = ("absolute", "intercept")
GAZE_ACTIONS = ("free", "gated", "frozen", "free_belief")
GAZE_HEAD = (slice(4, 6), slice(7, 9))  # the env action's gaze and head blocks (held with "frozen")
ENV_ACTION_DIM = 9
_S = ObservationLayout().slices


class BeliefFeatures:
    """Stateful observation transform (reset it at every episode start).

    ``hand_action="intercept"`` adds the interception features and makes :meth:`env_action` map a
    policy action (residual hand block) to the env's action.
    """

    def __init__(self, env_id: str, hand_action: str = "absolute", residual_m: float = 0.15,
                 gaze_action: str = "free", gaze_residual_deg: float = 3.0):
        if hand_action not in HAND_ACTIONS:
            raise ValueError(f"hand_action must be one of {HAND_ACTIONS}, got {hand_action!r}")
        if not (math.isfinite(residual_m) and residual_m > 0):
            raise ValueError(f"residual_m must be a positive number of metres, got {residual_m!r}")
        if gaze_action not in GAZE_ACTIONS:
            raise ValueError(f"gaze_action must be one of {GAZE_ACTIONS}, got {gaze_action!r}")
        if gaze_action != "free" and hand_action != "intercept":
            raise ValueError(f"gaze_action={gaze_action!r} needs hand_action='intercept'")
        if not (math.isfinite(gaze_residual_deg) and gaze_residual_deg >= 0):
            raise ValueError(f"gaze_residual_deg must be a number of degrees >= 0, got {gaze_residual_deg!r}")
        # The Eyecatch agent owns the filter plumbing (delay, covariance from the prior, resets);
        # only its perception half and its interception geometry are used.
        # Given every constant of the registered env's eye (the human periphery, the paper conditions'
        # vision_params), as the eyecatch spec gets it (agents.match_vision).
        self._agent = EyecatchAgent.for_env(env_id)
        self._agent.vision = env_vision_params(env_id)
        self.hand_action = hand_action
        self.residual_m = float(residual_m)
        self.gaze_action = gaze_action
        self.gaze_residual = math.radians(float(gaze_residual_deg))
        self.size = (N_BELIEF + (N_INTERCEPT if hand_action == "intercept" else 0) + (N_GAZE if gaze_action != "free" else 0)
                     + (N_FREE if gaze_action == "free_belief" else 0))
        # the policy's action: the env's 9 values, plus the look gate with gaze_action="gated"
        self.action_dim = ENV_ACTION_DIM + (1 if gaze_action == "gated" else 0)
        self.reset()

    def reset(self) -> None:
        self._agent.reset()
        self.intercept_point = None  # world point the residual hand action is relative to
        self.look_gaze = None  # (azimuth, elevation) rad of the gated gaze's look request; None: nothing to look at

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
        if self.gaze_action != "free":  # gated, frozen and free_belief see the same inputs
            k = N_BELIEF + N_INTERCEPT
            self.look_gaze = self._look(obs64)
            if self.look_gaze is not None:
                extra[k : k + 2] = self.look_gaze
                std = self._agent._retinal_std(self._agent.delay_steps * self._agent.dt)
                extra[k + 2] = math.log(min(max(std, 1e-6), 10.0))
            else:
                extra[k + 2] = math.log(10.0)
        if self.gaze_action == "free_belief":  # where vergence should be: ln of the believed distance (m) of
            # the ball one control step ahead, when the eye takes its next sample (as the Eyecatch agent's
            # vergence_lead_s); 0 (1 m) before the filter's first sample
            k = N_BELIEF + N_INTERCEPT + N_GAZE
            if f.initialised:
                agent = self._agent
                eye = obs64[_S["eye_pos"]] + SEAT_ORIGIN
                ahead = agent.filter.extrapolate(agent.delay_steps * agent.dt + agent.dt)[0]
                extra[k] = math.log(max(float(np.linalg.norm(ahead - eye)), 0.05))
        return np.concatenate([np.asarray(obs, dtype=np.float32), extra.astype(np.float32)])

    def _intercept(self, obs: np.ndarray) -> tuple[np.ndarray, float]:
        """(world point, seconds until the ball gets there) from the current belief."""
        agent, p = self._agent, self._agent.params
        eye = obs[_S["eye_pos"]] + SEAT_ORIGIN
        if not agent.filter.initialised:  # nothing seen yet: the ready pose (Eyecatch Eq. 19)
            return agent._within_reach(agent.ready_point(obs[_S["eye_rot"]].reshape(3, 3), eye)), p.prediction_horizon_s
        point, seconds = agent._interception(eye, agent.delay_steps * agent.dt)
        return agent._within_reach(point), seconds

    def _look(self, obs: np.ndarray) -> tuple[float, float] | None:
        """The Eyecatch 4.1 gaze request toward the believed ball (retinal azimuth, elevation, rad):
        the ball predicted at the next step (the plant pursues the request's motion), or, when a
        saccade can start and the ball is beyond the saccade threshold, where it will be when the
        saccade lands. None before the filter has a sample."""
        agent, p = self._agent, self._agent.params
        if not agent.filter.initialised:
            return None
        rot = obs[_S["eye_rot"]].reshape(3, 3)
        eye = obs[_S["eye_pos"]] + SEAT_ORIGIN
        delay = agent.delay_steps * agent.dt
        to_ball = rot.T @ (agent.filter.extrapolate(delay)[0] - eye)
        error = math.atan2(math.hypot(to_ball[1], to_ball[2]), to_ball[0])
        in_saccade = obs[_S["saccade"]][0] > 0.5
        ready = not in_saccade and obs[_S["saccade"]][1] >= p.saccade_refractory_s - 1e-9
        lead = p.saccade_lead_s if (ready and error > p.saccade_threshold_deg * math.pi / 180.0) else agent.dt
        return agent._retinal_angles(rot, eye, agent.filter.extrapolate(delay + lead)[0])

    def env_action(self, action: np.ndarray) -> np.ndarray:
        """The env action (9 values) for a policy action (identity unless ``hand_action="intercept"``)."""
        if self.hand_action != "intercept":
            return action
        if self.intercept_point is None:
            raise RuntimeError("call the features on an observation before mapping an action")
        action = np.asarray(action)
        if action.shape != (self.action_dim,):
            raise ValueError(f"expected a policy action of shape ({self.action_dim},), got {action.shape}")
        out = np.array(action[:ENV_ACTION_DIM], dtype=np.float32, copy=True)
        residual = np.clip(np.asarray(action[:3], dtype=float), -1.0, 1.0) * self.residual_m
        out[:3] = hand_target_action(self.intercept_point + residual)
        if self.gaze_action == "gated":
            gaze = np.clip(np.asarray(action[4:6], dtype=float), -1.0, 1.0) * self.gaze_residual
            if float(action[ENV_ACTION_DIM]) > 0.0 and self.look_gaze is not None:
                gaze = gaze + np.asarray(self.look_gaze)
            out[4:6] = np.clip(gaze / self._agent.gaze_range, -1.0, 1.0)
        elif self.gaze_action == "frozen":
            for block in GAZE_HEAD:
                out[block] = 0.0
        return out


class BeliefObservation(gym.Wrapper):
    """Gymnasium wrapper appending :class:`BeliefFeatures` to a flat EyeCatch observation (and, with
    ``hand_action="intercept"``, reading the hand block of actions as a residual around the belief's
    interception point)."""

    def __init__(self, env: gym.Env, env_id: str, hand_action: str = "absolute", residual_m: float = 0.15,
                 gaze_action: str = "free", gaze_residual_deg: float = 3.0):
        super().__init__(env)
        self.features = BeliefFeatures(env_id, hand_action, residual_m, gaze_action, gaze_residual_deg)
        low = np.full(env.observation_space.shape[0] + self.features.size, -np.inf, dtype=np.float32)
        self.observation_space = gym.spaces.Box(low, -low, dtype=np.float32)
        if self.features.action_dim != env.action_space.shape[0]:
            self.action_space = gym.spaces.Box(-1.0, 1.0, (self.features.action_dim,), dtype=np.float32)

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

    With ``gaze_action="gated"`` it is the base of the gated-gaze structure: ``look=False`` (the
    zero action: gate 0, gaze held) or ``look=True`` (gate on all the time: the Eyecatch 4.1 request
    toward the believed ball from the first sample on); head straight ahead, grasp closed either way.
    """

    def __init__(self, env_id: str, residual_m: float = 0.15, gaze_action: str = "free", look: bool = False,
                 grasp: float = 1.0):
        self.features = BeliefFeatures(env_id, "intercept", residual_m, gaze_action)
        self.look = bool(look)
        self.grasp = float(grasp)

    def reset(self) -> None:
        self.features.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]):
            self.reset()
        self.features(observation)
        action = np.zeros(self.features.action_dim, dtype=np.float32)
        action[3] = self.grasp  # grasp closed by default
        if self.features.gaze_action == "gated" and self.look:
            action[ENV_ACTION_DIM] = 1.0
        return self.features.env_action(action), state


class LookTeacher:
    """A scripted demonstrator for the behaviour-cloning warm start of the free-gaze recipe (``bc_episodes`` in
    hyperparams.yml; training only, never at evaluation): the policy action (``gaze_action="free_belief"``, 9
    values) that looks at, verges on and turns the head toward the believed ball, from the policy's own
    inputs (the flat observation and the free_belief features) only.

    * hand residual 0 (the belief's interception point), grasp closed (1);
    * gaze: the believed ball's retinal azimuth and elevation (the free_belief inputs) over the gaze range:
      the request the gated mode's open gate makes (Eyecatch 4.1);
    * fixation: the believed distance one step ahead (the free_belief input; Eyecatch agent's vergence lead);
    * head: neck target = present neck angles + half the believed ball's retinal angles (modelling choice: the
      head takes over part of each gaze shift, as in Eyecatch 4.2, so the eye stays off its orbital limit).

    Before the filter's first sample: gaze, fixation and head 0 (held). On the 200 pinned throws of EyeCatch-v0
    it catches 93.5 % (86 % with noise of std 0.01 on its gaze block; docs/baselines/rl.md).
    """

    HEAD_SHARE = 0.5  # the head's share of the believed ball's retinal angle per step (modelling choice)

    def __init__(self, features: BeliefFeatures):
        if features.gaze_action != "free_belief":
            raise ValueError(f"LookTeacher needs gaze_action='free_belief' features, got {features.gaze_action!r}")
        self.features = features

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The teacher's policy action for the features' latest input ``x`` (flat observation + features)."""
        from visuomotor_gym.envs.actions import eye_head_action

        f = self.features
        action = np.zeros(ENV_ACTION_DIM, dtype=np.float32)
        action[3] = 1.0
        if f.look_gaze is None:
            return action
        look = np.asarray(f.look_gaze, dtype=float)
        n_obs = len(x) - f.size
        distance = math.exp(float(x[n_obs + N_BELIEF + N_INTERCEPT + N_GAZE]))
        head = np.asarray(x[_S["head_qpos"]], dtype=float) + self.HEAD_SHARE * look
        action[4:9] = eye_head_action(look, distance, head, f._agent.gaze_range)
        return action
