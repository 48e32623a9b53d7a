"""Belief-space MPC of Eom, Han, Shin & Noh (TOG 2019) for the catch family, in real time.

Every 20 ms control step the agent

1. **updates its beliefs with the real observation** (:mod:`.tracker`): per ball, the Eyecatch Kalman
   filter fuses the eye's sample (Eom Eq. 3 with the real ``z``), and Eom's compact covariance
   ``sigma`` (Eq. 4) is propagated with the gaze the eye actually had;
2. every ``replan_every`` steps (default: every step), **re-plans** over a receding window
   (``window_s``, default 0.72 s, at ``plan_dt_s`` = 40 ms nodes) with iLQR (:mod:`.ilqr`) on the
   reduced internal model (:mod:`.model`): gaze, head, hand point and the compact covariances under
   the deterministic mean update (Eom section 6). The previous solution, shifted to the new start
   time, warm-starts the next one, and ``iterations`` (default 1) iLQR iterations run per step, so
   the optimisation continues across steps as the window recedes (real-time iteration, Diehl et al.
   2005). Because the gaze cost is far from convex (the fovea is 2 deg wide), each window starts from
   the cheapest of a few candidates evaluated in one batched rollout: the warm start, and gaze paths
   that follow each ball (with two balls, also switching once between them), the head taking up what
   the eye's range cannot;
3. **executes** the plan through the env's own low levels: gaze through the human oculomotor plant
   (saccades; pursuit of the request stream's motion with latency and gain): the plan chooses the
   object to look at (the one nearest its gaze ``fixation_lookahead_s`` ahead) and the request is
   that object's predicted direction a step ahead (pursuit), or where it will be when a saccade lands
   when the plant can start one and the object is beyond its threshold (catch-up saccades; see
   ``_gaze_request``; gaze held for the human first-saccade latency); the head target and the hand
   target (seat frame, the env's DLS arm controller) are the plan's a little ahead, to cover the
   servos' lag (``head_lead_s``, ``hand_lead_s``); the fixation distance is the target ball's (the next
   to arrive among the balls known to ``hold_path_std_m``); the grasp closes when the target ball is ``grasp_lead_s`` from the
   interception point (as the Eyecatch heuristic does) and stays closed while a ball is held.

The catching task (Eom section 7): ``c_tsk = |p_hand - p_arrival|^2``, where ``p_arrival`` is where the
believed path of the next ball to arrive first enters the preferred-distance sphere around the eye
(Eyecatch's interception point), weighted ``w_tsk_reactive`` until ``proactive_lead_s`` before the
arrival and ``w_tsk_proactive`` after (Eom: reactive 1e-3, proactive 0.1, proactive from 0.5-1 s
before the arrival; we take the middle, 0.75 s).

With two balls (``EyeCatchTwoBalls-v0``) each has its own belief and the uncertainty term sums over
the balls in play (``gaze_cost="uncertainty"``, Eom); ``"distance"`` replaces it with the sum of squared
angular distances of the line of sight to the balls, and ``"sequential"`` keeps the uncertainty of
the target ball only (the one-after-the-other tracking Eom attribute to Yeo et al.).

Parameters are named in :class:`BeliefMPCParams`; ``BeliefMPCAgent.for_env`` sets the vision
assumptions from the registered env id, as the Eyecatch agent does.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.eyecatch import EyecatchAgent, KalmanParams
from visuomotor_gym.baselines.eyecatch.agent import SHOULDER_WORLD

from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.envs.actions import hand_action
from visuomotor_gym.envs.observation import ObservationLayout, catch_observation
from visuomotor_gym.geometry import angle_between
from visuomotor_gym.registration import env_vision
from visuomotor_gym.vision.foveation import VisionParams

from . import ilqr
from .belief import ObservationNoise, gaze_vector
from .model import N_BODY, GazeBeliefProblem, HandProblem, Limits, PlannerWeights
from .tracker import ObjectBelief

DEG = math.pi / 180.0
CONTROL_DT_REFERENCE = 0.02  # Eom's alpha is per integration step h; we read it per 20 ms
GAZE_COSTS = ("uncertainty", "distance", "sequential")
HAND_UPDATES = ("plan", "saccade")
_LAYOUTS = {ObservationLayout(catch_observation(n)).size: (n, ObservationLayout(catch_observation(n)))
            for n in (1, 2)}


@dataclass(frozen=True)
class BeliefMPCParams:
    """Every constant of the planner; override any by name (``belief_mpc:alpha=0.4,window_s=1.0``)."""

    # Belief model (Eom 4.3).
    alpha: float = 0.2  # process noise Q = alpha I per 20 ms (Eom's alpha; 0.2 "realistic")
    fovea_smoothing_deg: float = 0.2  # eps of the smoothed eccentricity
    angular_uncertainty: bool = False  # r without its d^2 factor: uncertainty relative to distance
    planner_slip: bool = True  # r grows with retinal slip, as the env's lateral noise (belief.py)
    alpha_in_filter: bool = False  # also scale the real update's process noise by alpha / 0.2 (Eom's own
    # model uses one Q in planning and in the actual estimate; ours keeps the calibrated filter by default)
    prior_position_var: float = 1.0  # compact covariance of an object before its first observation (m^2)
    prior_velocity_var: float = 1.0  # ((m/s)^2); Eom do not give theirs
    # Receding window (Eom 7: 0.6-1.2 s) and solver.
    window_s: float = 0.72
    plan_dt_s: float = 0.04  # node spacing of the window (2 control steps)
    iterations: int = 1  # iLQR iterations per re-plan: warm-started every step, the iterations continue
    # across steps as the window recedes (a real-time iteration scheme, Diehl et al. 2005)
    replan_every: int = 1  # control steps between re-plans
    gaze_cost: str = "uncertainty"  # "uncertainty" (Eom), "distance" or "sequential" (Eom Fig. 4)
    # Cost weights (see model.PlannerWeights for units and the correspondence with Eom's).
    w_uct: float = 1.0
    w_eye: float = 1e-4
    w_head: float = 2e-3
    w_hand: float = 2e-3
    w_trk_head: float = 0.05
    w_trk_hand: float = 0.1
    w_bnd: float = 1e3
    w_tsk_reactive: float = 0.1
    w_tsk_proactive: float = 10.0
    w_dist: float = 1.0
    proactive_lead_s: float = 0.75  # Eom: the proactive phase starts 0.5-1 s before the arrival
    commit_proactive: bool = True  # the hand's target ball is kept once in its proactive phase
    hold_path_std_m: float = 0.3  # a ball whose believed position is less certain than this (std, m)
    # is planned for where it is now, not along its extrapolated path (its velocity is unknown)
    # Interception (Eyecatch 4.3, as the heuristic).
    preferred_distance_m: float = 0.5
    max_reach_m: float = 0.6
    prediction_horizon_s: float = 1.5
    # Execution.
    hand_lead_s: float = 0.06  # the arm servos lag ~60 ms
    head_lead_s: float = 0.08
    grasp_lead_s: float = 0.4  # close the hand when the ball is this far (in time) from the interception
    saccade_threshold_deg: float = 3.0  # the plant's
    saccade_refractory_s: float = 0.2  # the plant's (Young & Stark 1963)
    fixation_lookahead_s: float = 0.08  # the plan's fixated object is read this far ahead (2 nodes), where
    # the plan has caught up with it (modelling choice)
    # When the hand takes a new plan. "saccade": the hand keeps its plan between visuomotor updates and
    # takes the latest one at each saccade onset (none before the first saccade is due: it waits at its ready point), or
    # after hand_update_max_gap_s without one (Eyecatch Sec. 1, Fig. 4 and 4.1: hand submovements start
    # with the catch-up saccades; the gap is one 400 ms submovement, modelling choice). On EyeCatch-v0
    # seeds 0-39: 37/40 caught either way, saccade-hand synchrony 0.46 with "plan", 0.96 with "saccade".
    # "plan": every re-plan (Eom: the whole state is re-optimised each window).
    hand_update: str = "saccade"
    hand_update_max_gap_s: float = 0.4
    # > 0: the planner keeps the eye within this of the head's axis (a soft bound, as its range's), so the
    # head takes up the rest of the gaze: the dead zone of Eyecatch Eq. 17 (0.349 rad = 20 deg). 0: the
    # plant's eye range only (Eom 4.1). Seeds 0-39: head contribution 0.28 with 0, 0.97 with 20 deg.
    eye_dead_zone_deg: float = 20.0
    first_saccade_min_latency_s: float = 0.18  # gaze held until then: human saccadic latency 180-200 ms
    # (REFERENCES.md; the Eyecatch agent's value)
    # Vision assumed by the brain (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    # Under the human periphery (the one eye), the one ball's real belief update is the Eyecatch agent's
    # (EyecatchAgent.perceive: its model of that eye: the throw prior, the RMS eccentricity and disparity
    # pedestal, the positional disarray, the vergence of the sample's step; module docstring 5-6 of
    # baselines/eyecatch/agent.py); this planner's own update (tracker.ObjectBelief.fuse) knows only the
    # plain noise law and misreads the one eye's depth (EyeCatch-v0 seeds 0-39: 21/40 caught with it, 37/40
    # with the Eyecatch perception). Eom et al. 2019 use a Kalman filter of the object without giving its noise
    # model (Appendix A), so the choice of filter is ours. False: the planner's own update.
    eyecatch_perception: bool = True
    reset_mahalanobis: float = KalmanParams().reset_mahalanobis  # real filter's adaptive reset: the one
    # threshold of the Eyecatch filter (KalmanParams, chi^2 6 dof: one threshold)

    def __post_init__(self) -> None:
        if self.gaze_cost not in GAZE_COSTS:
            raise ValueError(f"gaze_cost must be one of {GAZE_COSTS}, got {self.gaze_cost!r}")
        if self.hand_update not in HAND_UPDATES:
            raise ValueError(f"BeliefMPCParams.hand_update must be one of {HAND_UPDATES}, got {self.hand_update!r}")
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, (bool, str)):
                continue
            if not math.isfinite(value) or value < 0:
                raise ValueError(f"BeliefMPCParams.{f.name} must be finite and >= 0, got {value!r}")
        if self.plan_dt_s <= 0 or self.window_s < 2 * self.plan_dt_s:
            raise ValueError("plan_dt_s must be > 0 and window_s at least two nodes long")
        if int(self.iterations) != self.iterations or int(self.replan_every) != self.replan_every or self.replan_every < 1:
            raise ValueError("iterations and replan_every must be whole numbers (replan_every >= 1)")

    def weights(self) -> PlannerWeights:
        return PlannerWeights(uct=self.w_uct, eye=self.w_eye, head=self.w_head, hand=self.w_hand,
                              trk_head=self.w_trk_head, trk_hand=self.w_trk_hand, bnd=self.w_bnd,
                              tsk_reactive=self.w_tsk_reactive, tsk_proactive=self.w_tsk_proactive,
                              dist=self.w_dist)


@dataclass
class Plan:
    t0: float  # time of node 0
    X: np.ndarray  # (N+1, n)
    U: np.ndarray  # (N, m)

    def state_at(self, t: float, h: float) -> np.ndarray:
        """Plan state at time ``t`` (linear interpolation between nodes, held past the end)."""
        s = (t - self.t0) / h
        n = self.X.shape[0] - 1
        if s <= 0.0:
            return self.X[0]
        if s >= n:
            return self.X[n]
        i = int(s)
        f = s - i
        return (1.0 - f) * self.X[i] + f * self.X[i + 1]


class BeliefMPCAgent:
    """Eom-style belief-space MPC behind the stable-baselines3 ``predict`` interface."""

    def __init__(self, params: BeliefMPCParams | None = None, dt: float = 0.02):
        self.params = params or BeliefMPCParams()
        p = self.params
        self.dt = float(dt)
        self.env_id: str | None = None  # the registered id (for_env and the leaderboard loader set it)
        self.vision = VisionParams(noise_scale=p.vision_noise_scale, foveated=p.foveated)
        self.noise = ObservationNoise.from_vision(self.vision, eps_deg=p.fovea_smoothing_deg,
                                                  angular=p.angular_uncertainty)
        self.kalman = KalmanParams(reset_mahalanobis=p.reset_mahalanobis)
        self.delay_steps = int(round(p.visual_delay_s / self.dt))
        self.N = max(2, int(round(p.window_s / p.plan_dt_s)))
        self.h = float(p.plan_dt_s)
        self.q_control = p.alpha * self.dt / CONTROL_DT_REFERENCE
        self.q_plan = p.alpha * self.h / CONTROL_DT_REFERENCE
        self.gaze_range = p.gaze_action_range_deg * DEG
        self._problems: dict[int, tuple[GazeBeliefProblem, HandProblem]] = {}
        self.timing: dict[str, float] = {}  # seconds per part of the policy, accumulated over episodes
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> BeliefMPCAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = BeliefMPCParams(**env_vision(env_id))
        known = {f.name for f in fields(BeliefMPCParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown belief_mpc parameter(s) {unknown}; known: {sorted(known)}")
        agent = cls(replace(base, **overrides))
        agent.env_id = env_id
        return agent

    def _eyecatch_perception(self, n_balls: int):
        """The Eyecatch agent whose perception is the one ball's real update (``eyecatch_perception``; one ball,
        the human periphery, an agent made by :meth:`for_env`), with this agent's eye; None otherwise."""
        if not (self.params.eyecatch_perception and n_balls == 1 and self.env_id and self.vision.periphery_on):
            return None
        from visuomotor_gym.baselines.eyecatch import EyecatchAgent

        eyes = EyecatchAgent.for_env(self.env_id)
        eyes.vision = self.vision
        return eyes

    def problems(self, n_objects: int) -> tuple[GazeBeliefProblem, HandProblem]:
        if n_objects not in self._problems:
            p = self.params
            gaze = GazeBeliefProblem(n_objects, self.N, self.h, self.planning_noise, self.q_plan, p.weights(),
                                     self.gaze_limits(),
                                     gaze_cost="distance" if p.gaze_cost == "distance" else "uncertainty")
            self._problems[n_objects] = (gaze, HandProblem(self.N, self.h, p.weights(), Limits()))
        return self._problems[n_objects]

    def gaze_limits(self) -> Limits:
        """The planner's soft bounds of the gaze problem: the eye-in-head range narrowed to
        ``eye_dead_zone_deg`` when that is > 0 (the head then takes up the gaze beyond it)."""
        z = self.params.eye_dead_zone_deg
        if z <= 0.0:
            return Limits()
        lim = Limits()
        m = lim.range_margin_deg
        clip = lambda r: (max(r[0], -z - m), min(r[1], z + m))  # noqa: E731
        return replace(lim, eye_azimuth_deg=clip(lim.eye_azimuth_deg), eye_elevation_deg=clip(lim.eye_elevation_deg))

    @property
    def planning_noise(self) -> ObservationNoise:
        """The observation-noise model of the planner and of Eom's compact covariance: the env's vision
        (``self.noise``, set by ``match_vision``), without its slip term when ``planner_slip`` is off."""
        if self.params.planner_slip:
            return self.noise
        return replace(self.noise, knee_rad_s=math.inf)

    def reset(self) -> None:
        """Forget the episode (called by the evaluator, and on ``episode_start``)."""
        self.started = False
        self.balls: list[ObjectBelief] = []
        self.plan: Plan | None = None
        self.hand_plan: Plan | None = None  # the plan the hand follows (hand_update)
        self.steps = 0
        self.ready: np.ndarray | None = None
        self.pose_history: list[tuple[np.ndarray, np.ndarray]] = []
        self._eyes = None  # the Eyecatch perception of the one ball (eyecatch_perception), made at the first step
        self.prev_gaze: np.ndarray | None = None
        self.grasp = False
        self.target_ball: int | None = None
        self.reg = 1e-6
        # Per-step log for plots and the reproduction page: (t, target, sigma per ball, plan ms).
        self.log: list[dict] = []
        self.solve_ms: list[float] = []

    # ------------------------------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        if obs.ndim != 1 or obs.shape[0] not in _LAYOUTS:
            raise ValueError(f"BeliefMPCAgent expects a flat catch observation of size {sorted(_LAYOUTS)}, "
                             f"got shape {obs.shape}")
        return self._act(obs), state

    def _lap(self, name: str) -> None:
        now = time.perf_counter()
        self.timing[name] = self.timing.get(name, 0.0) + now - self._tick
        self._tick = now

    def _act(self, obs: np.ndarray) -> np.ndarray:
        self._tick = time.perf_counter()
        p = self.params
        n_balls, layout = _LAYOUTS[obs.shape[0]]
        S = layout.slices
        t = float(obs[S["time"]][0])
        rot = obs[S["eye_rot"]].reshape(3, 3)
        eye = obs[S["eye_pos"]] + SEAT_ORIGIN
        hand = obs[S["hand_pos"]] + SEAT_ORIGIN
        head = obs[S["head_qpos"]].copy()
        gaze = rot[:, 0]
        g_az, g_el = math.atan2(gaze[1], gaze[0]), math.atan2(gaze[2], math.hypot(gaze[0], gaze[1]))
        if not self.started:
            self.started = True
            prior = (p.prior_position_var, p.prior_velocity_var, 0.0)
            self.balls = [ObjectBelief(self.dt, self.kalman, prior) for _ in range(n_balls)]
            self._eyes = self._eyecatch_perception(n_balls)
            if p.alpha_in_filter:  # alpha = 0.2 keeps the calibrated filter; 0 removes its process noise
                for ball in self.balls:
                    ball.filter.Q = ball.filter.Q * (p.alpha / 0.2)
            self.ready = hand.copy()
        caught = obs[S["balls_caught"]] > 0.5 if n_balls > 1 else np.zeros(1, bool)
        holding = bool(obs[S["holding"]][0] > 0.5) if n_balls > 1 else False

        # --- 1. real belief update -----------------------------------------------------------------
        self.pose_history.append((rot.copy(), eye.copy()))
        if len(self.pose_history) > self.delay_steps + 1:
            self.pose_history.pop(0)
        s_rot, s_eye = self.pose_history[0]
        eye_turn = np.zeros(3)
        if self.prev_gaze is not None:
            eye_turn = rot.T @ (np.cross(self.prev_gaze, gaze) / self.dt)
        self.prev_gaze = gaze.copy()
        blocks = (("ball_pos", "ball_vel", "ball_visible"), ("ball2_pos", "ball2_vel", "ball2_visible"))
        for j, ball in enumerate(self.balls):
            eyes = j == 0 and self._eyes is not None
            if eyes:
                self._eyes.perceive(obs)
                ball.filter = self._eyes.filter
            else:
                ball.predict()
            if caught[j]:
                continue
            bp, bv, vis = blocks[j]
            seen = bool(obs[S[vis]][0] > 0.5)
            if seen and not eyes:
                ball.fuse(np.concatenate([obs[S[bp]], obs[S[bv]]]), s_rot, s_eye, eye_turn, self.vision)
            s_az, s_el = math.atan2(s_rot[1, 0], s_rot[0, 0]), math.atan2(s_rot[2, 0], math.hypot(s_rot[0, 0], s_rot[1, 0]))
            slip = 0.0
            if seen and ball.tracked:  # the retinal slip of the believed object during the step
                f = ball.filter
                slip = EyecatchAgent._retinal_speed(s_rot.T @ (f.x[:3] - s_eye), s_rot.T @ f.x[3:], eye_turn)
            ball.update_sigma(seen, s_az, s_el, s_eye, self.planning_noise, self.q_control, slip=slip)
        delay = self.delay_steps * self.dt
        live = [j for j, b in enumerate(self.balls) if b.tracked and not caught[j]]
        self._lap("perception")

        # --- target ball: the next to arrive ---------------------------------------------------------
        # An object whose believed position is still vague (a first peripheral sighting of the second
        # ball: depth std ~ 5 % of d / alpha, i.e. metres at 30 deg) has a meaningless arrival time; it
        # becomes the hand's target only once known to ``hold_path_std_m`` (or when no other is).
        target, t_arr = None, math.inf
        intercepts = {}
        for j in live:
            intercepts[j] = self._interception(self.balls[j], eye, delay)
        known = [j for j in live if np.trace(self.balls[j].filter.P[:3, :3]) / 3.0 <= p.hold_path_std_m**2]
        for j in known or live:
            when = intercepts[j][1]
            if when < t_arr:
                target, t_arr = j, when
        # A proactive reach is not abandoned for another ball (modelling choice): a peripheral first
        # estimate of the second ball can be confident and wrong by metres, and switching the hand to
        # its phantom arrival lost the first ball.
        prev = self.target_ball
        if p.commit_proactive and prev in intercepts and prev != target and intercepts[prev][1] <= p.proactive_lead_s:
            target, t_arr = prev, intercepts[prev][1]
        self.target_ball = target
        self._lap("interception")

        # --- 2. re-plan -------------------------------------------------------------------------------
        if live and (self.plan is None or self.steps % p.replan_every == 0):
            self._replan(t, g_az, g_el, head, hand, eye, obs, S, live, target, intercepts, delay)
        self.steps += 1
        self._tick = time.perf_counter()

        # --- 3. execute -------------------------------------------------------------------------------
        if holding:
            self.grasp = True
        else:
            self.grasp = target is not None and t_arr <= p.grasp_lead_s
        if self.plan is None:
            self._log(t, target)
            return self._action(hand if self.ready is None else self.ready, gaze_ret=(0.0, 0.0), head=head,
                                fixation=None)
        h = self.h
        gaze_target = self._gaze_request(t, obs, S, gaze, eye, live, delay)
        gaze_ret = _retinal(rot, gaze_target)
        head_t = self.plan.state_at(t + p.head_lead_s, h)[2:4]
        hand_plan = self._hand_plan(t, obs, S)
        hand_t = self.ready if hand_plan is None else hand_plan.state_at(t + p.hand_lead_s, h)
        fixation = None
        if target is not None:
            fixation = float(np.linalg.norm(self.balls[target].filter.extrapolate(delay)[0] - eye))
        self._log(t, target)
        action = self._action(_within_reach(hand_t, p.max_reach_m), gaze_ret=gaze_ret, head=head_t, fixation=fixation)
        self._lap("execution")
        return action

    def _hand_plan(self, t: float, obs, S) -> Plan | None:
        """The plan the hand follows (``hand_update``): the latest, or the one taken at the last visuomotor
        update; None (hold the ready point) before the first update under ``"saccade"``."""
        p = self.params
        latest = Plan(t0=self.plan.t0, X=self.plan.X[:, 4:7], U=self.plan.U[:, 4:])
        if p.hand_update == "plan":
            return latest
        # a saccade started during the last step (the plant's flag and time since onset, as Eyecatch's agent)
        onset = bool(obs[S["saccade"]][0] > 0.5) and float(obs[S["saccade"]][1]) < 1.5 * self.dt
        if self.hand_plan is None:  # the first update: with the first saccade, or when it is due (as
            # Eyecatch's agent, whose hand starts when it releases its first saccade, whether the eye moves)
            if onset or t >= p.first_saccade_min_latency_s - 0.5 * self.dt:
                self.hand_plan = latest
            return self.hand_plan
        if onset or t - self.hand_plan.t0 >= p.hand_update_max_gap_s - 0.5 * self.dt:
            self.hand_plan = latest
        return self.hand_plan

    # ------------------------------------------------------------------------------------------
    def _replan(self, t, g_az, g_el, head, hand, eye, obs, S, live, target, intercepts, delay) -> None:
        p = self.params
        start = time.perf_counter()
        nb = len(self.balls)
        gprob, hprob = self.problems(nb)
        N, h = self.N, self.h
        times = np.arange(N + 1) * h
        ball_pos = np.zeros((N + 1, nb, 3))
        active = np.zeros(nb, bool)
        for j in live:
            f = self.balls[j].filter
            if np.trace(f.P[:3, :3]) / 3.0 > p.hold_path_std_m**2:
                ball_pos[:, j] = f.extrapolate(delay)[0]  # a first sighting: look where it is
            else:
                ball_pos[:, j] = f.trajectory(times + delay)
                # The catch ends the flight: past its interception the ball is in the hand, not on its
                # ballistic path (planning along that path turned the head after a ball flying past it).
                point, when = intercepts[j]
                ball_pos[times > when, j] = point
            active[j] = self.balls[j].sigma is not None
        uct_weight = np.ones(nb)
        if p.gaze_cost == "sequential":
            uct_weight = np.array([1.0 if j == target else 0.0 for j in range(nb)])
        eih = obs[S["eye_in_head"]]
        offset = np.array([g_az - head[0] - eih[0], g_el - head[1] - eih[1]])
        gprob.configure(eye=eye, eih_offset=offset, ball_pos=ball_pos, active=active, uct_weight=uct_weight)
        w_task = np.zeros(N + 1)
        task_point = self.ready
        if target is not None:
            point, when = intercepts[target]
            task_point = _within_reach(point, p.max_reach_m)
            w_task = np.where(times >= when - p.proactive_lead_s, p.w_tsk_proactive, p.w_tsk_reactive)
        hprob.configure(ready=self.ready, target=task_point, w_task=w_task)

        x0 = np.empty(gprob.n)
        x0[0:2] = (g_az, g_el)
        x0[2:4] = head
        for j, b in enumerate(self.balls):
            x0[4 + 3 * j: 7 + 3 * j] = b.sigma if active[j] else 0.0
        U_warm = self._warm_start(t)
        self._lap("plan: set-up")
        U0, X0 = self._initial_guess(gprob, x0, U_warm[:, 0:4], [j for j in live if active[j]])
        self._lap("plan: initial-guess search")
        its = int(p.iterations)
        sub: dict[str, float] = {}
        g_res = ilqr.solve(gprob, x0, U0, iterations=its, reg=self.reg, X0=X0, timing=sub)
        self.reg = g_res.reg
        for k, v in sub.items():
            self.timing["plan: gaze iLQR " + k] = self.timing.get("plan: gaze iLQR " + k, 0.0) + v
        self._tick = time.perf_counter()
        # Linear-quadratic but for the soft speed bound: solve it exactly, and fall back to iLQR (with
        # the bound) from there only when the exact solution is too fast.
        hX, hU = hprob.solve_lq(hand.copy())
        if np.max(np.sum(hU * hU, axis=1)) > hprob.lim.hand_speed_m_s**2:
            h_res = ilqr.solve(hprob, hand.copy(), hU, iterations=int(p.iterations), X0=hX)
            hX, hU = h_res.X, h_res.U
        self._lap("plan: hand (LQ + iLQR when the speed bound binds)")
        X = np.empty((N + 1, N_BODY + 3 * nb))
        X[:, 0:4] = g_res.X[:, 0:4]
        X[:, 4:7] = hX
        X[:, 7:] = g_res.X[:, 4:]
        self.plan = Plan(t0=t, X=X, U=np.concatenate([g_res.U, hU], axis=1))
        self.solve_ms.append(1e3 * (time.perf_counter() - start))
        self._lap("plan: set-up")

    def _initial_guess(self, prob: GazeBeliefProblem, x0: np.ndarray, U_warm: np.ndarray, balls: list[int]):
        """The cheapest of a few initial control sequences (one batched rollout): the shifted previous
        solution, and gaze sequences that follow each ball (and, with two, switch between them once,
        a third or two thirds into the window). The gaze cost is far from convex (the fovea is 2 deg
        wide), so iLQR from a single start settles on poor local minima; the candidates only choose
        where it starts, the cost decides."""
        if not balls:
            return U_warm, None
        N, h = self.N, self.h
        ang = [np.stack([np.arctan2(d[:, 1], d[:, 0]), np.arcsin(np.clip(d[:, 2], -1.0, 1.0))], axis=1)
               for d in (prob.ball_dir[:, j] for j in balls)]  # (N+1, 2) per ball
        nxt = np.minimum(np.arange(1, N + 1), N)  # gaze at node k looks at the ball at node k+1

        seqs = list(ang)
        if len(ang) == 2:
            for ks in (N // 3, 2 * N // 3):
                for first, second in ((0, 1), (1, 0)):
                    seq = ang[first].copy()
                    seq[ks:] = ang[second][ks:]
                    seqs.append(seq)
        C = len(seqs)
        path = np.empty((C, N + 1, 2))  # gaze at nodes 0..N
        path[:, 0] = x0[0:2]
        path[:, 1:] = np.stack(seqs)[:, nxt]
        # the head takes up what the eye's range cannot (as far as the neck allows)
        lo, hi = prob.lo[:2] + prob.eih_offset, prob.hi[:2] + prob.eih_offset
        head = np.empty((C, N + 1, 2))
        head[:, 0] = x0[2:4]
        for k in range(1, N + 1):
            rel = path[:, k] - head[:, k - 1]
            head[:, k] = head[:, k - 1] + np.maximum(rel - hi, 0.0) + np.minimum(rel - lo, 0.0)
        head = np.clip(head, prob.lo[2:], prob.hi[2:])
        U_all = np.empty((C + 1, N, 4))
        U_all[0] = U_warm
        U_all[1:, :, 0:2] = np.diff(path, axis=1) / h
        U_all[1:, :, 2:4] = np.diff(head, axis=1) / h
        X_all = ilqr.rollout_batch(prob, x0, U_all)
        best = int(np.argmin(prob.cost(X_all, U_all)))
        return U_all[best], X_all[best]

    def _warm_start(self, t: float) -> np.ndarray:
        """The previous controls, shifted to start at ``t`` (zeros past their end)."""
        U = np.zeros((self.N, 7))
        if self.plan is None:
            return U
        old = self.plan
        s = (t - old.t0) / self.h
        shift = int(round(s))
        if abs(s - shift) < 1e-6:
            n_keep = max(self.N - shift, 0)
            U[:n_keep] = old.U[shift:shift + n_keep]
            return U
        src = old.t0 + np.arange(self.N) * self.h
        dst = t + np.arange(self.N) * self.h
        for c in range(7):
            U[:, c] = np.interp(dst, src, old.U[:, c], right=0.0)
        return U

    def _desired_gaze(self, t: float, live: list[int], eye: np.ndarray, delay: float):
        """The planned line of sight as a function of time: the predicted direction of the object the
        plan fixates (the plan's own gaze when no object is tracked).

        The plan starts at the eye's actual gaze and models the eye as an integrator (Eom 4.1); the
        human plant is not one (saccades, pursuit with latency and gain), so what is executed is the
        plan's *choice* of what to look at, not its first nodes: executing those (the request a step
        along the plan) left the request stream moving with the eye itself, so the plant's pursuit
        decayed and the eye fell 10-15 deg behind a fast ball (the miss rate doubled). The
        fixated object is the one nearest the plan's gaze ``fixation_lookahead_s`` ahead, where the
        plan has reached it."""
        p, plan, h = self.params, self.plan, self.h
        t_look = t + p.fixation_lookahead_s
        g_look = gaze_vector(*plan.state_at(t_look, h)[0:2])
        best, best_ang = None, math.inf
        for j in live:
            d = self.balls[j].filter.extrapolate(delay + p.fixation_lookahead_s)[0] - eye
            ang = angle_between(g_look, d / max(float(np.linalg.norm(d)), 1e-9))
            if ang <= best_ang:
                best, best_ang = j, ang
        if best is None:
            return lambda s: gaze_vector(*plan.state_at(s, h)[0:2])
        f = self.balls[best].filter

        def direction(s: float) -> np.ndarray:
            d = f.extrapolate(delay + (s - t))[0] - eye
            return d / max(float(np.linalg.norm(d)), 1e-9)

        return direction

    def _gaze_request(self, t, obs, S, gaze, eye, live, delay) -> np.ndarray:
        """The gaze request (world direction) that makes the human plant follow the planned line of
        sight ``D``: as the Eyecatch agent does, the request is ``D`` a step ahead, so the request
        stream moves with the fixated object and the plant pursues that motion (with its latency and
        gain); when the plant can start a saccade and ``D`` is beyond its threshold, the request is
        where ``D`` will be when the saccade lands (main-sequence duration plus a step), so the
        catch-up saccade lands on the object rather than behind it. Until ``first_saccade_min_latency_s``
        the gaze is held (human saccadic latency, as the Eyecatch agent's)."""
        p = self.params
        if t < p.first_saccade_min_latency_s - 1e-9:
            return gaze
        D = self._desired_gaze(t, live, eye, delay)
        in_saccade = obs[S["saccade"]][0] > 0.5
        since_onset = float(obs[S["saccade"]][1])
        ready = not in_saccade and since_onset >= p.saccade_refractory_s - 1e-9
        nxt = D(t + self.dt)
        error = angle_between(gaze, nxt)
        if ready and error > p.saccade_threshold_deg * DEG:
            lead = self.dt
            for _ in range(2):  # the landing time depends on the amplitude, which depends on it
                amp_deg = angle_between(gaze, D(t + lead)) / DEG
                lead = self.dt + max(0.021 + 0.0022 * amp_deg, 1.875 * amp_deg / 800.0)  # plant's main sequence
            return D(t + lead)
        return nxt

    def _interception(self, ball: ObjectBelief, eye: np.ndarray, delay: float) -> tuple[np.ndarray, float]:
        """Where and when (s from now) the believed path first enters the preferred-distance sphere
        around the eye, or its closest approach (the Eyecatch heuristic's interception point)."""
        p = self.params
        times = np.arange(0.0, p.prediction_horizon_s, 0.005)
        path = ball.filter.trajectory(times + delay)
        dist = np.linalg.norm(path - eye, axis=1)
        inside = np.flatnonzero(dist <= p.preferred_distance_m)
        i = int(inside[0]) if inside.size else int(np.argmin(dist))
        return path[i], float(times[i])

    def _log(self, t: float, target) -> None:
        self.log.append({"t": t, "target": -1 if target is None else int(target),
                         "sigma": [None if b.sigma is None else b.sigma.copy() for b in self.balls]})

    def _action(self, hand_target, gaze_ret, head, fixation) -> np.ndarray:
        return hand_action(hand_target, self.grasp, gaze_ret, head, fixation, self.gaze_range)


def _retinal(rot: np.ndarray, direction: np.ndarray) -> tuple[float, float]:
    v = rot.T @ direction
    return math.atan2(v[1], v[0]), math.atan2(v[2], math.hypot(v[0], v[1]))


def _within_reach(point: np.ndarray, max_reach: float) -> np.ndarray:
    v = point - SHOULDER_WORLD
    n = float(np.linalg.norm(v))
    return SHOULDER_WORLD + v * (max_reach / n) if n > max_reach else point
