"""The ``iwao`` agent for ObstacleWalk: Iwao et al.'s head and eye pitch per gait cycle (seed 003,
Eq. 1-10; :mod:`.gaze`) aimed at the next obstacle, its own memory of what it has seen
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
episode put it; head straight): the gaze-blind twin of DESIGN section 4, the same perception and planner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import WalkerBody
from visuomotor_gym.envs.walk import WALK_LAYOUT
from visuomotor_gym.registration import env_vision
from visuomotor_gym.tasks.obstacle_walk import K_SLOTS
from visuomotor_gym.vision.foveation import VisionParams

from .gaze import DEG, IwaoGazeParams, peak_angles, pitch_at
from .perception import ObstacleMemory
from .planner import FootstepPlanner, PlannerParams

_S = WALK_LAYOUT.slices
NECK_PITCH_DOWN_DEG = 50.0  # the head action's -1 (envs_assets/common/head_eye.xml: neck_pitch -50 .. 40)


@dataclass(frozen=True)
class IwaoParams:
    # Vision assumed by the agent (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    # With no obstacle known ahead, look at the ground this far ahead of the eye: travel fixations 1-2 m
    # ahead of the feet (Patla & Vickers 1997); 2 m, the far end (modelling choice: the farther the
    # point, the more of the path ahead lies near the fovea).
    travel_look_ahead_m: float = 2.0
    gaze_blind: bool = False
    control_dt: float = 0.02


class IwaoAgent:
    """See the module docstring. ``predict(obs) -> (action, state)`` on flat ObstacleWalk observations."""

    def __init__(self, params: IwaoParams | None = None, gaze: IwaoGazeParams | None = None,
                 planner: PlannerParams | None = None, gait: GaitParams | None = None) -> None:
        self.params = p = params or IwaoParams()
        self.gaze_params = gaze or IwaoGazeParams()
        self.gait = gait or GaitParams()
        self.planner = FootstepPlanner(self.gait, planner)
        self.vision = VisionParams(noise_scale=p.vision_noise_scale, foveated=p.foveated)
        self.delay_steps = round(p.visual_delay_s / p.control_dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        self.memory = ObstacleMemory(self.vision)
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> IwaoAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = IwaoParams(**env_vision(env_id))
        known = {f.name for f in fields(IwaoParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown iwao parameter(s) {unknown}; known: {sorted(known)}")
        return cls(replace(base, **overrides))

    def reset(self) -> None:
        self.memory.reset()
        self.started = False
        self.poses: list = []  # (eye_pos, rot rows, odometry) of the last steps, for delayed percepts
        self.cycle_start_phase = None
        self.peaks = (0.0, 0.0)
        self.target = None  # (x, y, z) of the point looked at this cycle, path frame
        self.target_id = -1
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
        e0, r0, o0, p0 = _S["eye_pos"].start, _S["eye_rot"].start, _S["odometry"].start, _S["pelvis"].start
        eye_pos = ol[e0:e0 + 3]
        rot = [ol[r0:r0 + 3], ol[r0 + 3:r0 + 6], ol[r0 + 6:r0 + 9]]
        odo = ol[o0:o0 + 3]
        pose = (eye_pos, rot, (odo[0], odo[1], odo[2], ol[p0]))
        self.poses.append(pose)
        if len(self.poses) > self.delay_steps + 1:
            self.poses.pop(0)
        seen_pose = self.poses[0] if len(self.poses) > self.delay_steps else pose
        self._perceive(ol, seen_pose)

        g0 = _S["gait_phase"].start
        phase, latch_in = ol[g0], ol[g0 + 2]
        if latch_in <= self.params.control_dt + 1e-6:  # this step's command is read at mid-stance
            self.footstep = self._plan(obs, odo)
        action = np.zeros(8, dtype=np.float32)
        action[0:3] = self.footstep
        if not self.params.gaze_blind:
            action[3:8] = self._look(obs, phase, pose)
        return action

    def _perceive(self, ol: list, pose) -> None:
        eye_pos, rot_rows, odo = pose
        for k in range(K_SLOTS):
            b = _S[f"obstacle_{k}"].start
            near, far = ol[b + 7], ol[b + 8]
            if near == 0.0 and far == 0.0:
                continue
            index = round(ol[b])
            if near > 0.0:
                self.memory.add(index, 0, ol[b + 1:b + 4], eye_pos, rot_rows, odo)
            if far > 0.0:
                self.memory.add(index, 1, ol[b + 4:b + 7], eye_pos, rot_rows, odo)

    def _footholds(self, obs: np.ndarray, odo) -> list[tuple[float, float, float]]:
        f = obs[_S["footholds"]].reshape(3, 3)
        c, s = math.cos(odo[2]), math.sin(odo[2])
        return [(odo[0] + c * x - s * y, odo[1] + s * x + c * y, side) for x, y, side in f.tolist()]

    def _plan(self, obs: np.ndarray, odo) -> list[float]:
        footholds = self._footholds(obs, odo)
        u_last = footholds[-1][0]
        ahead = [o for o in self.memory.known() if o.x1 > footholds[0][0] - 0.3 and o.x0 < u_last + 6.0]
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
        # Slots seen on one corner only, or not yet: the travel point ahead on the ground.
        eye_x = odo[0] + pose[0][0]
        return (eye_x + self.params.travel_look_ahead_m, odo[1], 0.0), -1

    def _look(self, obs: np.ndarray, phase: float, pose) -> list:
        gp = self.gaze_params
        T = self.gait.step_s
        t = phase * T
        eye_pos, rot, odo = pose
        ex, ey, ez = odo[0] + eye_pos[0], odo[1] + eye_pos[1], odo[3] + eye_pos[2]
        new_cycle = self.cycle_start_phase is None or phase < self.cycle_start_phase
        self.cycle_start_phase = phase
        if new_cycle or self.target is None:
            self.target, self.target_id = self._choose_target(obs, pose)
            # theta_G and l predicted at the cycle's middle (Eq. 8 evaluates them at t = T_F / 2).
            l_mid = max(self.target[0] - ex - self.gait.nominal_step_m / T * (0.5 * T - t), 0.3)
            theta_g = math.atan2(ez - self.target[2], l_mid)
            self.peaks = peak_angles(theta_g, l_mid, gp)
        head, eye = pitch_at(t, T, self.peaks[0], self.peaks[1], gp)
        self.log.append((float(obs[_S["time"]][0]), self.target_id, head, eye))
        pitch = head + eye  # downward gaze below the horizontal
        az = math.atan2(self.target[1] - ey, max(self.target[0] - ex, 0.3))
        cp = math.cos(pitch)
        wx, wy, wz = cp * math.cos(az), cp * math.sin(az), -math.sin(pitch)  # pelvis-frame axes
        (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = rot
        e0 = a00 * wx + a10 * wy + a20 * wz  # R^T w: in the eye frame
        e1 = a01 * wx + a11 * wy + a21 * wz
        e2 = a02 * wx + a12 * wy + a22 * wz
        d_az = math.atan2(e1, e0)
        d_el = math.atan2(e2, math.hypot(e0, e1))
        r = self.gaze_range
        return [min(max(d_az / r, -1.0), 1.0), min(max(d_el / r, -1.0), 1.0),
                0.0,  # fixation distance: unused in v0
                0.0,  # head yaw straight
                min(max(-head / (NECK_PITCH_DOWN_DEG * DEG), -1.0), 0.0)]
