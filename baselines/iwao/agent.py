"""The ``iwao`` agent for ObstacleWalk: Iwao et al.'s head and eye pitch per gait cycle
(Eq. 1-10; :mod:`.gaze`) aimed at the next obstacle, its own memory of what it has seen
(:mod:`.perception`) and a footstep planner on that memory (:mod:`.planner`).

Each step (one gait cycle of the head's bob, heel strike to heel strike) the agent picks its *target*:
the first obstacle of the course that no foothold has been committed over yet (an obstacle whose far
edge lies behind the last latched foothold is being stepped over and is no longer looked at: Patla &
Vickers 1997), or, with none known ahead, a travel point ``travel_look_ahead_m`` ahead on the ground.
At the cycle's start it sets the peaks of Eq. 8-10 from ``theta_G = arctan(h / l)`` predicted at mid-cycle
(``h`` the eye's height above the target's top, ``l`` the horizontal distance); during the cycle it asks
for the gaze pitch ``theta_H(t) + theta_E(t)`` (toward the target's azimuth) and the head pitch
``theta_H(t)``; the plant makes the saccades and the pursuit, the VOR the rest. At every footstep read it
plans the next foothold from its memory.

``gaze_blind=True`` holds gaze and head (gaze action 0: gaze stays level along the path where the
episode put it; head straight): the gaze-blind twin (docs/gaze_gain.md), the same perception and planner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.crowding import crowded

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import WalkerBody
from visuomotor_gym.envs.walk import WALK_LAYOUT
from visuomotor_gym.oculomotor.plant import OculomotorParams
from visuomotor_gym.registration import env_vision, env_vision_params
from visuomotor_gym.tasks.obstacle_walk import K_SLOTS, N_POINTS
from visuomotor_gym.vision.foveation import VisionParams

from .gaze import DEG, IwaoGazeParams, peak_angles, pitch_at
from .perception import ObstacleMemory, eye_motion
from .planner import FootstepPlanner, PlannerParams

_S = WALK_LAYOUT.slices
# Where the blocks the agent reads start in the flat observation (read from a list of floats each step).
_EYE_POS, _EYE_ROT, _ODOMETRY, _PELVIS = (_S[b].start for b in ("eye_pos", "eye_rot", "odometry", "pelvis"))
_FIXATION = _S["fixation"].start  # the eye's vergence distance (m): proprioception
# The plant's fixation range, onto which the fixation action is log-mapped (core.eye.Eye.command).
_LOG_FIX = tuple(math.log(x) for x in OculomotorParams().fixation_range_m)
_GAIT_PHASE, _FOOTHOLDS, _TIME = _S["gait_phase"].start, _S["footholds"].start, _S["time"].start
_SLOTS = tuple(_S[f"obstacle_{k}"].start for k in range(K_SLOTS))
# With gaze_mode="footholds" the planner sees an obstacle's footprint std capped at this (m): a far, crowded
# glimpse (its keep-out zone grown by 2 std would close the walkway) keeps a zone of its estimate's size plus
# 2 caps; the gaze fixates it before a foothold near it is chosen (modelling choice).
FOOTHOLDS_PLAN_MAX_SD_M = 0.1
# With gaze_mode="footholds", when no foothold is clear of the 2-std zones, the planner tries 1 std, then
# the estimates themselves (PlannerParams.fallback_sigmas; modelling choice), before the blind nominal step.
FOOTHOLDS_FALLBACK_SIGMAS = (1.0, 0.0)
NECK_PITCH_DOWN_DEG = 50.0  # the head action's -1 (envs_assets/common/head_eye.xml: neck_pitch -50 .. 40)


@dataclass(frozen=True)
class IwaoParams:
    # Vision assumed by the agent (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    # The knee of the eye's slip term (VisionParams.position_slip_knee_deg_s; Westheimer & McKee 1975):
    # the agent predicts each sample's retinal slip from its own eye motion and weights it accordingly
    # (a brain adapted to its own eye); set from the env id by ``for_env``.
    position_slip_knee_deg_s: float = 2.5
    # With no obstacle known ahead, look at the ground this far ahead of the eye: travel fixations 1-2 m
    # ahead of the feet (Patla & Vickers 1997); 2 m, the far end (modelling choice: the farther the
    # point, the more of the path ahead lies near the fovea).
    travel_look_ahead_m: float = 2.0
    # Around the peak of each cycle's Gaussians (|t - T_F/2| <= this many sigma) the gaze holds the
    # cycle's fixation point instead of sweeping with the Gaussian (modelling choice; see _look).
    fixation_window_sigma: float = 1.0
    # The fixation point lies at most this far beyond the target (modelling choice: keeps it on the
    # ground near the obstacle when theta_V is large).
    fixation_beyond_max_m: float = 2.0
    # An optional pursuit lead (s): the request runs this far ahead on the eye's predicted path, as humans
    # pursue predictable targets without the onset latency (Bahill & McDonald 1983). 0 by default: a lead
    # of the plant's 150 ms latency did not lower the fixated point's slip (docs/reproductions/iwao.md).
    pursuit_lead_s: float = 0.0
    gaze_blind: bool = False
    control_dt: float = 0.02
    # Where the gaze goes: "iwao" (the Gaussians of Eq. 1-10 toward the next obstacle, the default) or
    # "footholds" (for the rough course, tasks.obstacle_walk.ROUGH_COURSE; set by ``for_env`` when the
    # registered course is rough): fixations of 0.24-0.4 s, each held on a hazard among the next footholds
    # (the least certain first) or on the ground ahead (see _foothold_target, _look_footholds).
    gaze_mode: str = "iwao"
    # Hazards whose near edge lies within this many steps of the last latched foothold are candidates
    # (Matthis, Yates & Hayhoe 2018: fixations on footholds 2-3 steps ahead on rough terrain).
    foothold_look_steps: float = 3.0
    # ... and one whose footprint is known to within this std (m) needs no fixation (modelling choice: a
    # tenth of the smallest hazard, the 4 cm lateral margin of the planner is then hardly used).
    foothold_precise_m: float = 0.02
    # With no hazard to look at, the gaze goes to the ground this many steps ahead of the last latched
    # foothold, where the next hazards come into the fovea's reach (Matthis et al. 2018: 2-3 steps;
    # 1.5 steps, nearer Patla & Vickers' 1-2 m travel fixations, crossed 21 of 24 design courses, 2.5 steps 24).
    foothold_travel_steps: float = 2.5
    # A hazard known precisely is looked at (again) once it lies this many steps beyond the last latched
    # foothold: 2-3 steps ahead of the feet (Matthis, Yates & Hayhoe 2018).
    foothold_ahead_steps: float = 1.0
    # A fixation lasts at least foothold_min_fixation_s before the gaze moves on from a target known
    # precisely by then (or from the ground), and at most foothold_max_fixation_s (fixations last ~0.2-0.4 s
    # in real environments: Tatler & Land 2016; modelling choices within that range).
    foothold_min_fixation_s: float = 0.24
    foothold_max_fixation_s: float = 0.4
    # With gaze_mode="footholds": (mean, std) of an obstacle's top above the floor before any sample, or
    # None. Walkers place what lies on the ground by the angle of its line of sight below the horizon,
    # given their eye height (Ooi, Wu & He 2001, Nature 414:197): with depth from disparity poor away
    # from the vergence distance (VisionParams.depth_pedestal_arcmin), the lateral (angular) precision
    # of each sample then fixes the point along the path. The values: modelling choice (the rough
    # course's tops lie 1-12 cm above the floor, tasks.obstacle_walk.ROUGH_COURSE); under the human
    # periphery (all four mechanisms) it crossed 7/16 of seeds 0-15 without a prior; seeds 0-39 with std
    # 0.05 / 0.1 / 0.2: 36 / 36 / 32 of 40 (its static twin 25 / 20 / 17).
    height_prior_m: tuple[float, float] | None = (0.06, 0.1)
    # With gaze_mode="footholds": a sample whose line of sight misses its point's estimate by more than this
    # many combined lateral stds is not fused (ObstacleMemory.gate), or None. A crowded percept pooled with
    # a flanker that is in no slot of the observation (the agent cannot flag it: baselines.crowding) is
    # biased by up to the crowding zone, far beyond its noise (Bouma 1970; Parkes et al. 2001). Modelling
    # choice: 2 (rough course, human periphery, seeds 0-39: 38/40 against 36/40 without, 1.5: 31/40; seeds
    # 40-79: 36/40).
    sample_gate: float | None = 2.0


class IwaoAgent:
    """See the module docstring. ``predict(obs) -> (action, state)`` on flat ObstacleWalk observations."""

    def __init__(self, params: IwaoParams | None = None, gaze: IwaoGazeParams | None = None,
                 planner: PlannerParams | None = None, gait: GaitParams | None = None,
                 vision: VisionParams | None = None) -> None:
        self.params = p = params or IwaoParams()
        self.gaze_params = gaze or IwaoGazeParams()
        self.gait = gait or GaitParams()
        if planner is None and p.gaze_mode == "footholds":
            planner = PlannerParams(fallback_sigmas=FOOTHOLDS_FALLBACK_SIGMAS)
        self.planner = FootstepPlanner(self.gait, planner)
        self.memory = ObstacleMemory(vision or VisionParams(noise_scale=p.vision_noise_scale, foveated=p.foveated,
                                                           position_slip_knee_deg_s=p.position_slip_knee_deg_s),
                                     self.planner.p.walkway_half_width_m,
                                     *((p.height_prior_m, p.sample_gate) if p.gaze_mode == "footholds" else (None, None)))
        self.delay_steps = round(p.visual_delay_s / p.control_dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        self.period_steps = round(self.gait.step_s / p.control_dt)
        self.lead_steps = min(round(p.pursuit_lead_s / p.control_dt), self.period_steps)
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> IwaoAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = IwaoParams(**env_vision(env_id),
                          position_slip_knee_deg_s=env_vision_params(env_id).position_slip_knee_deg_s)
        known = {f.name for f in fields(IwaoParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown iwao parameter(s) {unknown}; known: {sorted(known)}")
        # The eye's every constant (env_vision_params: the walk family's, with the human periphery's
        # fields when the id is registered with them), so the obstacle memory weights each sample as
        # this eye makes it; the noise scale, foveation and slip knee given as overrides win.
        params = replace(base, **overrides)
        if "gaze_mode" not in overrides and _registered_course_is_rough(env_id):
            params = replace(params, gaze_mode="footholds")
        vision = env_vision_params(env_id)
        mine = {"vision_noise_scale": "noise_scale", "foveated": "foveated",
                "position_slip_knee_deg_s": "position_slip_knee_deg_s"}
        vision = replace(vision, **{mine[k]: getattr(params, k) for k in overrides if k in mine})
        return cls(params, vision=vision)

    @property
    def vision(self) -> VisionParams:
        """The vision model the agent weights its samples with: its obstacle memory's (one object, so
        ``agents.match_vision`` setting it reaches the memory too)."""
        return self.memory.vision

    @vision.setter
    def vision(self, value: VisionParams) -> None:
        self.memory.vision = value

    def reset(self) -> None:
        self.memory.reset()
        self.started = False
        self.poses: list = []  # (eye_pos, rot rows, odometry) of the last steps, for delayed percepts
        self.prev_seen_eye = None
        self.eye_history: list = []  # eye positions (path frame) of the last step, for the pursuit lead
        self.fix_offset = None  # (azimuth, elevation) offset of the led request, set at each fixation's start  # (eye position, gaze direction), path frame, of the last percepts' pose
        self.cycle_start_phase = None
        self.peaks = (0.0, 0.0)
        self.target = None  # (x, y, z) of the point looked at this cycle, path frame
        self.target_id = -1
        self.fix_steps = 0  # control steps since the footholds gaze picked its target
        self.fix_count: dict[int, int] = {}  # fixations per hazard label (footholds gaze)
        self.footstep = WalkerBody.action_from_footstep(self.gait.nominal_step_m, 0.0, self.gait.nominal_clearance_m,
                                                        self.gait)
        self.log: list[tuple] = []  # (time, target id, theta_H, theta_E) per step, for plots

    # ------------------------------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if obs.shape != (WALK_LAYOUT.size,):
            raise ValueError(f"IwaoAgent expects the flat ObstacleWalk observation of size {WALK_LAYOUT.size}, "
                             f"got shape {obs.shape}")
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        self.started = True
        return self._act(obs), state

    def _act(self, obs: np.ndarray) -> np.ndarray:
        ol = obs.tolist()
        e0, r0, o0, p0 = _EYE_POS, _EYE_ROT, _ODOMETRY, _PELVIS
        eye_pos = ol[e0:e0 + 3]
        rot = [ol[r0:r0 + 3], ol[r0 + 3:r0 + 6], ol[r0 + 6:r0 + 9]]
        odo = ol[o0:o0 + 3]
        pose = (eye_pos, rot, (odo[0], odo[1], odo[2], ol[p0]))
        self.poses.append(pose)
        if len(self.poses) > self.delay_steps + 1:
            self.poses.pop(0)
        seen_pose = self.poses[0] if len(self.poses) > self.delay_steps else pose
        self._perceive(ol, seen_pose, ol[_FIXATION])

        g0 = _GAIT_PHASE
        phase, latch_in = ol[g0], ol[g0 + 2]
        if latch_in <= self.params.control_dt + 1e-6:  # this step's command is read at mid-stance
            self.footstep = self._plan(obs, odo)
        # (One float32 array from the list: the same rounding as writing into np.zeros(8, float32).)
        if self.params.gaze_blind:
            return np.array(self.footstep + [0.0, 0.0, 0.0, 0.0, 0.0], dtype=np.float32)
        if self.params.gaze_mode == "footholds":
            return np.array(self.footstep + self._look_footholds(obs, phase, pose), dtype=np.float32)
        return np.array(self.footstep + self._look(obs, phase, pose), dtype=np.float32)

    def _perceive(self, ol: list, pose, vergence: float | None = None) -> None:
        eye_pos, rot_rows, odo = pose
        seen_eye = _eye_in_path(pose)
        prev, self.prev_seen_eye = self.prev_seen_eye, seen_eye
        motion = None if prev is None else eye_motion(prev, seen_eye, self.params.control_dt)
        f = 1 + 3 * N_POINTS  # the seen flags follow the id and the points
        if self.vision.crowding:
            # with crowding in the vision model, a point that may be pooled with another obstacle's is fused
            # with the spread of its crowding zone (baselines.crowding); one obstacle's points do not crowd
            seen = [(round(ol[b]), which, ol[b + 1 + 3 * which:b + 4 + 3 * which]) for b in _SLOTS
                    for which in range(N_POINTS) if ol[b + f + which] > 0.0]
            drop = crowded([p for _, _, p in seen], [index for index, _, _ in seen], self.vision)
            for n, (index, which, p_eye) in enumerate(seen):
                self.memory.add(index, which, p_eye, eye_pos, rot_rows, odo, motion, vergence, crowded=n in drop)
            return
        for b in _SLOTS:
            flags = ol[b + f:b + f + N_POINTS]
            if 1.0 not in flags:
                continue
            index = round(ol[b])
            for which, seen in enumerate(flags):
                if seen > 0.0:
                    self.memory.add(index, which, ol[b + 1 + 3 * which:b + 4 + 3 * which], eye_pos, rot_rows, odo, motion,
                                    vergence)

    def _footholds(self, obs: np.ndarray, odo) -> list[tuple[float, float, float]]:
        f = obs[_S["footholds"]].reshape(3, 3)
        c, s = math.cos(odo[2]), math.sin(odo[2])
        return [(odo[0] + c * x - s * y, odo[1] + s * x + c * y, side) for x, y, side in f.tolist()]

    def _plan(self, obs: np.ndarray, odo) -> list[float]:
        footholds = self._footholds(obs, odo)
        u_last = footholds[-1][0]
        ahead = [o for o in self.memory.known() if o.x1 > footholds[0][0] - 0.3 and o.x0 < u_last + 6.0]
        if self.params.gaze_mode == "footholds":
            cap = FOOTHOLDS_PLAN_MAX_SD_M
            ahead = [o if max(o.sx, o.sy, o.sz) <= cap else replace(o, sx=min(o.sx, cap), sy=min(o.sy, cap), sz=min(o.sz, cap))
                     for o in ahead]
        length, lateral, clearance = self.planner.plan(footholds, ahead)
        return WalkerBody.action_from_footstep(length, lateral, clearance, self.gait)

    # --- gaze (Iwao Eq. 1-10) -----------------------------------------------------------------
    def _choose_target(self, obs: np.ndarray, pose):
        """The point to look at this cycle (path frame) and its obstacle id (-1: a travel point)."""
        odo = pose[2]
        footholds = self._footholds(obs, odo)
        u_last = footholds[-1][0]
        for o in self.memory.known():
            if o.x1 > u_last:  # not yet stepped over: the next obstacle
                return (o.x0, 0.5 * (o.y0 + o.y1), o.height), o.index
        # Slots seen on one edge only, or not yet: the travel point ahead on the ground.
        eye_x = odo[0] + pose[0][0]
        return (eye_x + self.params.travel_look_ahead_m, odo[1], 0.0), -1

    def _foothold_target(self, obs: np.ndarray, pose):
        """The rough course's next fixation target (path frame) and its label (-1: a ground point).

        Among the hazards not yet stepped over whose near edge lies within ``foothold_look_steps`` of the
        last latched foothold: the one whose footprint is least certain, if its std exceeds
        ``foothold_precise_m`` (an obstacle seen at one edge only counts as uncertain, at its seen point);
        else, of those at least ``foothold_ahead_steps`` beyond that foothold (2-3 steps ahead), the one
        fixated least often so far, the nearest on ties; else the ground ``foothold_travel_steps`` ahead
        of that foothold, on the centre line."""
        p = self.params
        footholds = self._footholds(obs, pose[2])
        u_last = footholds[-1][0]
        step = self.gait.nominal_step_m
        reach = u_last + p.foothold_look_steps * step
        unsure, unsure_sd = None, p.foothold_precise_m
        sure = []
        known = {o.index: o for o in self.memory.known()}
        for index, points in self.memory.corners.items():
            o = known.get(index)
            if o is not None:
                if o.x1 <= u_last or o.x0 > reach:
                    continue
                sd = max(o.sx, o.sy)
                centre = (0.5 * (o.x0 + o.x1), 0.5 * (o.y0 + o.y1), o.height)
            else:
                seen = [pt.estimate()[0] for pt in points if pt.n >= 2]
                if not seen:
                    continue
                centre = tuple(float(c) for c in seen[0])
                if centre[0] <= u_last or centre[0] > reach:
                    continue
                sd = math.inf
            if sd > unsure_sd or (sd == unsure_sd and unsure is not None and centre[0] < unsure[0][0]):
                unsure, unsure_sd = (centre, index), sd
            elif o is not None and o.x0 >= u_last + p.foothold_ahead_steps * step:
                sure.append((self.fix_count.get(index, 0), centre[0], centre, index))
        if unsure is not None:
            return unsure
        if sure:
            _, _, centre, index = min(sure)
            return centre, index
        return (u_last + p.foothold_travel_steps * step, 0.0, 0.0), -1

    def _look_footholds(self, obs: np.ndarray, phase: float, pose) -> list:
        """The rough course's gaze (``gaze_mode="footholds"``): at each step's start a saccade to
        :meth:`_foothold_target`, held there for the step (the request follows the point's direction, so
        the plant's pursuit stabilises it while walking: Matthis, Yates & Hayhoe 2018); the head pitched
        down by Iwao's share ``alpha / (1 + alpha)`` of the gaze's depression (Eq. 6), the eye the rest;
        vergence on the target under the depth law."""
        _, rot, odo = pose
        p = self.params
        self.fix_steps += 1
        held = self.fix_steps * p.control_dt
        if self.target is None or held >= p.foothold_max_fixation_s:
            decide = True
        elif held >= p.foothold_min_fixation_s:  # on once the target is known well enough (or is the ground)
            o = self.memory.obstacle(self.target_id) if self.target_id >= 0 else None
            decide = self.target_id < 0 or (o is not None and max(o.sx, o.sy) <= p.foothold_precise_m)
        else:
            decide = False
        if decide:
            target, target_id = self._foothold_target(obs, pose)
            if target_id != self.target_id or target_id < 0 or self.target is None:
                self.target, self.target_id = target, target_id
                self.fixation = target
                if target_id >= 0:
                    self.fix_count[target_id] = self.fix_count.get(target_id, 0) + 1
            self.fix_steps = 0
        ex, ey, ez = _eye_in_path(pose)[0]
        fx, fy, fz = self.fixation
        az, el = _angles(fx - ex, fy - ey, fz - ez)
        a = self.gaze_params.alpha
        head = max(-el, 0.0) * a / (1.0 + a)
        self.log.append((float(obs[_TIME]), self.target_id, head, max(-el, 0.0) - head))
        ce = math.cos(el)
        wx, wy, wz = ce * math.cos(az), ce * math.sin(az), math.sin(el)
        return self._gaze_request(wx, wy, wz, odo, rot, (ex, ey, ez), head, True)

    def _verge(self, ex, ey, ez, wx, wy, wz, fixating: bool) -> float:
        """The fixation (vergence) action. Without the depth law in the agent's vision model 0 (the
        fixation range's log midpoint, 1.4 m: iwao v0, golden digests). With it (``depth_pedestal_arcmin``:
        depth is precise only near the vergence distance, Blakemore 1970), verge on what the gaze is
        sent to: the cycle's fixation point while fixating, else where the requested line of sight
        (path frame ``wx, wy, wz``; pelvis yaw does not change its pitch) meets the plane of the target's
        top, at most the target's distance when it points above that plane (modelling choice: humans
        verge on the fixated point)."""
        if self.vision.depth_pedestal_arcmin is None:
            return 0.0
        if fixating:
            fx, fy, fz = self.fixation
            d = math.sqrt((fx - ex) ** 2 + (fy - ey) ** 2 + (fz - ez) ** 2)
        else:
            tx, ty, tz = self.target
            d = math.sqrt((tx - ex) ** 2 + (ty - ey) ** 2 + (tz - ez) ** 2)
            if wz < -0.05:
                d = min((ez - tz) / -wz, d) if ez > tz else d
        return _fixation_action(min(max(d, 0.3), 20.0))

    def _look(self, obs: np.ndarray, phase: float, pose) -> list:
        gp = self.gaze_params
        T = self.gait.step_s
        t = phase * T
        eye_pos, rot, odo = pose
        ex, ey, ez = odo[0] + eye_pos[0], odo[1] + eye_pos[1], odo[3] + eye_pos[2]
        new_cycle = self.cycle_start_phase is None or phase < self.cycle_start_phase
        self.cycle_start_phase = phase
        if new_cycle or self.target is None:
            self.fix_offset = None
            self.target, self.target_id = self._choose_target(obs, pose)
            # theta_G and l predicted at the cycle's middle (Eq. 8 evaluates them at t = T_F / 2).
            l_mid = max(self.target[0] - ex - self.gait.nominal_step_m / T * (0.5 * T - t), 0.3)
            theta_g = math.atan2(ez - self.target[2], l_mid)
            self.peaks = peak_angles(theta_g, l_mid, gp)
            # The cycle's fixation point: where the peak gaze (theta_G - theta_V below the horizontal,
            # from the eye at mid-cycle) meets the plane of the target's top; the target itself when
            # theta_V = 0 (beyond beta * theta_Vmax).
            peak = self.peaks[0] + self.peaks[1]
            reach = (ez - self.target[2]) / math.tan(peak) if peak > 1e-3 else 1e3
            reach = min(max(reach, l_mid), l_mid + self.params.fixation_beyond_max_m)
            mx = self.target[0] - l_mid  # the eye's predicted x at mid-cycle
            dx, dy = self.target[0] - mx, self.target[1] - ey
            k = reach / max(math.hypot(dx, dy), 1e-6)
            self.fixation = (mx + k * dx, ey + k * dy, self.target[2])
        head, eye = pitch_at(t, T, self.peaks[0], self.peaks[1], gp)
        ex, ey, ez = _eye_in_path(pose)[0]
        sigma = gp.sigma_fraction * T
        fixating = abs(t - 0.5 * T) <= self.params.fixation_window_sigma * sigma
        self.log.append((float(obs[_TIME]), self.target_id, head, eye))
        self.eye_history.append((ex, ey, ez))
        n = len(self.eye_history)
        if n > self.period_steps + 1:
            self.eye_history.pop(0)
            n -= 1
        if fixating:
            # Hold the fixation point: ask for its direction every step, so the request moves as the point's
            # image would and the plant's pursuit counter-rotates the eye (gaze stabilised on a ground point
            # while walking: Matthis, Yates & Hayhoe 2018). Pursuit answers the request's motion after its
            # latency; for a predictable target humans pursue with none (Bahill & McDonald 1983), so the
            # request moves as the point's direction will from the eye ``pursuit_lead_s`` ahead, the eye's
            # path predicted as the last step's path moved on by one step (the bob repeats every step),
            # offset so that it starts where the point is now.
            fx, fy, fz = self.fixation
            k = self.lead_steps
            if self.params.pursuit_lead_s > 0.0 and n > self.period_steps:
                h = self.eye_history
                a, b = h[n - 1 - self.period_steps + k], h[0]
                px, py, pz = ex + a[0] - b[0], ey + a[1] - b[1], ez + a[2] - b[2]
            else:
                px, py, pz = ex, ey, ez
            az_now, el_now = _angles(fx - ex, fy - ey, fz - ez)
            az_lead, el_lead = _angles(fx - px, fy - py, fz - pz)
            if self.fix_offset is None:
                self.fix_offset = (az_now - az_lead, el_now - el_lead)
            az_r, el_r = az_lead + self.fix_offset[0], el_lead + self.fix_offset[1]
            ce = math.cos(el_r)
            wx, wy, wz = ce * math.cos(az_r), ce * math.sin(az_r), math.sin(el_r)
        else:
            self.fix_offset = None
            pitch = head + eye  # downward gaze below the horizontal
            az = math.atan2(self.target[1] - ey, max(self.target[0] - ex, 0.3))
            cp = math.cos(pitch)
            wx, wy, wz = cp * math.cos(az), cp * math.sin(az), -math.sin(pitch)
        return self._gaze_request(wx, wy, wz, odo, rot, (ex, ey, ez), head, fixating)

    def _gaze_request(self, wx, wy, wz, odo, rot, eye, head: float, fixating: bool) -> list:
        """The gaze, vergence and head action that points the line of sight along ``(wx, wy, wz)`` (path
        frame) from the eye at ``eye``, with the neck pitched down by ``head`` (rad) and yaw straight."""
        ex, ey, ez = eye
        c, s_ = math.cos(odo[2]), math.sin(odo[2])
        wx, wy = c * wx + s_ * wy, -s_ * wx + c * wy  # path frame to pelvis frame (yaw)
        (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = rot
        e0 = a00 * wx + a10 * wy + a20 * wz  # R^T w: in the eye frame
        e1 = a01 * wx + a11 * wy + a21 * wz
        e2 = a02 * wx + a12 * wy + a22 * wz
        d_az = math.atan2(e1, e0)
        d_el = math.atan2(e2, math.hypot(e0, e1))
        r = self.gaze_range
        return [min(max(d_az / r, -1.0), 1.0), min(max(d_el / r, -1.0), 1.0),
                self._verge(ex, ey, ez, wx, wy, wz, fixating),
                0.0,  # head yaw straight
                min(max(-head / (NECK_PITCH_DOWN_DEG * DEG), -1.0), 0.0)]


def _registered_course_is_rough(env_id: str) -> bool:
    """Whether ``env_id`` is registered (in this process) with the rough course of ObstacleWalk."""
    import gymnasium as gym

    from visuomotor_gym.tasks.obstacle_walk import CourseDistribution

    try:
        course = (gym.spec(env_id).kwargs or {}).get("course_distribution")
    except gym.error.Error:
        return False
    if isinstance(course, str):
        from visuomotor_gym.tasks.obstacle_walk import COURSE_PRESETS

        return course in COURSE_PRESETS and COURSE_PRESETS[course].rough
    if isinstance(course, dict):
        return course.get("layout") == "rough"
    return isinstance(course, CourseDistribution) and course.rough


def _fixation_action(distance: float) -> float:
    """The fixation action that asks for vergence at ``distance`` m (the log map of ``Eye.command``)."""
    lo, hi = _LOG_FIX
    return min(max(2.0 * (math.log(distance) - lo) / (hi - lo) - 1.0, -1.0), 1.0)


def _angles(x: float, y: float, z: float) -> tuple[float, float]:
    """(azimuth, elevation) of a direction."""
    return math.atan2(y, x), math.atan2(z, math.hypot(x, y))


def _eye_in_path(pose):
    """(eye position, gaze direction) in the path frame from a pose (eye_pos and rot rows in the pelvis
    frame, odometry (x, y, yaw, pelvis height))."""
    eye_pos, rot, (ox, oy, yaw, pz) = pose
    c, s = math.cos(yaw), math.sin(yaw)
    gx, gy, gz = rot[0][0], rot[1][0], rot[2][0]
    ex, ey = eye_pos[0], eye_pos[1]
    return ((ox + c * ex - s * ey, oy + s * ex + c * ey, pz + eye_pos[2]), (c * gx - s * gy, s * gx + c * gy, gz))
