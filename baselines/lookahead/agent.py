"""The ``lookahead`` agent for SteppingStones: gaze two steps ahead, a footstep planner on its belief.

**Gaze** (Patla & Vickers 2003; Eom et al. 2019 section 7). The agent looks at the stone *two steps
ahead of the foot in stance*: stone ``n + 1``, ``n`` being the stone the swinging foot is headed for (the
first stone no foot has landed on: the observation's slot 0). The env moves ``n`` on when a landed foot
is flat, at the end of double support, which is when the other foot's swing starts, so gaze switches to
the next stone *as the swing starts* (Eom section 7) and a stone is first fixated ~0.9 s before its foot
lands: the mid-stance read that commits that foot comes 0.2 s into the fixation, the heel strike 0.9 s
into it (Patla & Vickers 2003: stepping targets fixated ~2 steps ahead, 0.8-1.0 s before the foot
lands). At the start, while footholds are still planned on the slab, it looks at the first stone not
yet planned for. The eye is asked for the direction of the stone's current estimate every step (a
saccade when far, pursuit when near; the plant decides); the head takes ``head_share`` of the pitch and
yaw (modelling choice, the iwao agent's head/eye split).

**Belief**: :class:`~.perception.StoneMemory` fuses every percept of a stone.

**Footsteps**: at each mid-stance read the next foothold goes onto the first stone ahead of the last
latched foothold: the foot's centre on the stone's estimated centre, nudged toward the foot's own
side. The walker turns (:class:`~visuomotor_gym.body.walker.TurningGait`): the footstep's **heading**
is the direction of that step less the angle of the nominal step width (so the step is straight ahead
in its own frame, the feet its width apart), clipped to the gait's largest turn from the previous
foothold's heading; length and width follow in that frame. An unseen stone is extrapolated from the two
before it; beyond the longest step (still on the slab) the distance is split into equal nominal steps
along the current heading.

``gaze_blind=True`` holds gaze and head (gaze action 0: gaze stays level along the slab where the
episode put it; head straight): the gaze-blind twin (docs/gaze_gain.md), the same belief and planner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.crowding import crowded

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import TurningWalkerBody as WalkerBody
from visuomotor_gym.envs.stones import STONES_LAYOUT
from visuomotor_gym.registration import env_vision, env_vision_params
from visuomotor_gym.tasks.stepping_stones import FOOT_CENTRE_AHEAD_M, K_SLOTS
from visuomotor_gym.vision.foveation import VisionParams

from .perception import StoneMemory

_S = STONES_LAYOUT.slices
DEG = math.pi / 180.0
NECK_PITCH_DOWN_DEG = 50.0  # the head action's -1 (envs_assets/common/head_eye.xml: neck_pitch -50 .. 40)
NECK_YAW_DEG = 80.0  # the head action's +-1 (neck_yaw -80 .. 80)


@dataclass(frozen=True)
class LookaheadParams:
    # Vision assumed by the agent (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    control_dt: float = 0.02
    gaze_blind: bool = False
    # Fraction of the gaze's pitch and yaw taken by the head (modelling choice: a third, as the iwao
    # agent's alpha = 0.5).
    head_share: float = 1.0 / 3.0
    # Where the foot's centre aims on a stone: this far toward the foot's own side, across the step's
    # heading (modelling choice: keeps the feet apart at a third of the gait's nominal 0.12 m step width).
    side_offset_m: float = 0.04
    # A turn is planned at most this far short of the gait's largest (modelling choice: margin for the
    # clipping of the action's float32 round trip).
    turn_margin_deg: float = 0.5
    # Nominal spacing used to extrapolate a stone not seen yet (the middle of ALLSTEPS' 0.65-0.85 m).
    spacing_m: float = 0.75


class LookaheadAgent:
    """See the module docstring. ``predict(obs) -> (action, state)`` on flat SteppingStones observations."""

    def __init__(self, params: LookaheadParams | None = None, gait: GaitParams | None = None,
                 vision: VisionParams | None = None) -> None:
        self.params = p = params or LookaheadParams()
        self.gait = gait or GaitParams()
        self.memory = StoneMemory(vision or VisionParams(noise_scale=p.vision_noise_scale, foveated=p.foveated))
        self.delay_steps = round(p.visual_delay_s / p.control_dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> LookaheadAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = LookaheadParams(**env_vision(env_id))
        known = {f.name for f in fields(LookaheadParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown lookahead parameter(s) {unknown}; known: {sorted(known)}")
        return cls(replace(base, **overrides), vision=env_vision_params(env_id))

    @property
    def vision(self) -> VisionParams:
        """The vision model the agent weights its samples with: its stone memory's (one object, so
        ``agents.match_vision`` setting it reaches the memory too)."""
        return self.memory.vision

    @vision.setter
    def vision(self, value: VisionParams) -> None:
        self.memory.vision = value

    def reset(self) -> None:
        self.memory.reset()
        self.started = False
        self.poses: list = []
        self.planned_stone = -1  # the stone the last latched foothold was planned onto
        self.next_stone = 0
        self.footstep = [*WalkerBody.action_from_footstep(self.gait.nominal_step_m, 0.0, self.gait.nominal_clearance_m,
                                                          self.gait), 0.0]
        self.log: list[tuple] = []  # (time, gaze target stone) per step

    # ------------------------------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if obs.shape != (STONES_LAYOUT.size,):
            raise ValueError(f"LookaheadAgent expects the flat SteppingStones observation of size "
                             f"{STONES_LAYOUT.size}, got shape {obs.shape}")
        if not np.isfinite(obs).all():
            raise ValueError("LookaheadAgent got a non-finite observation")
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        self.started = True
        return self._act(obs), state

    def _act(self, obs: np.ndarray) -> np.ndarray:
        ol = obs.tolist()
        e0, r0, o0, p0 = _S["eye_pos"].start, _S["eye_rot"].start, _S["odometry"].start, _S["pelvis"].start
        eye_pos = ol[e0:e0 + 3]
        rot = [ol[r0:r0 + 3], ol[r0 + 3:r0 + 6], ol[r0 + 6:r0 + 9]]
        odo = (ol[o0], ol[o0 + 1], ol[o0 + 2], ol[p0])
        pose = (eye_pos, rot, odo)
        self.poses.append(pose)
        if len(self.poses) > self.delay_steps + 2:
            self.poses.pop(0)
        seen_pose = self.poses[-self.delay_steps - 1] if len(self.poses) > self.delay_steps else pose
        seen_prev = self.poses[-self.delay_steps - 2] if len(self.poses) >= self.delay_steps + 2 else None
        prev = None if seen_prev is None else StoneMemory.eye_pose(*seen_prev)
        self.next_stone = round(ol[_S["stone_0"].start])
        seen = [_S[f"stone_{k}"].start for k in range(K_SLOTS) if ol[_S[f"stone_{k}"].start + 4] > 0.0]
        # with crowding in the vision model, a sample that may be pooled with a neighbour's is fused with the
        # spread of its crowding zone (baselines.crowding)
        drop = crowded([ol[b + 1:b + 4] for b in seen], [round(ol[b]) for b in seen], self.vision) \
            if self.vision.crowding else ()
        for n, b in enumerate(seen):
            self.memory.add(round(ol[b]), ol[b + 1:b + 4], seen_pose[0], seen_pose[1], seen_pose[2], prev,
                            self.params.control_dt, crowded=n in drop)
        latch_in = ol[_S["gait_phase"].start + 2]
        if latch_in <= self.params.control_dt + 1e-6:  # this step's command is read at mid-stance
            self.footstep = self._plan(obs, odo)
        action = np.zeros(9, dtype=np.float32)
        action[0:4] = self.footstep
        if not self.params.gaze_blind:
            action[4:9] = self._look(obs, pose)
        return action

    # --- belief -------------------------------------------------------------------------------
    def stone_xy(self, i: int) -> tuple[float, float] | None:
        """Estimated centre of stone ``i``; an unseen one extrapolated from the two before it."""
        est = self.memory.estimate(i)
        if est is not None:
            return est[0]
        a, b = (self.memory.estimate(i - 2), self.memory.estimate(i - 1)) if i >= 2 else (None, None)
        if a is None or b is None:
            return None
        (ax, ay), (bx, by) = a[0], b[0]
        h = math.atan2(by - ay, bx - ax)
        return bx + self.params.spacing_m * math.cos(h), by + self.params.spacing_m * math.sin(h)

    def _footholds(self, obs: np.ndarray, odo) -> list[tuple[float, float, float, float]]:
        """The three observed footholds in the path frame: (x, y, side, heading)."""
        f = obs[_S["footholds"]].reshape(3, 3)
        hd = obs[_S["foothold_headings"]].tolist()
        c, s = math.cos(odo[2]), math.sin(odo[2])
        return [(odo[0] + c * x - s * y, odo[1] + s * x + c * y, side, odo[2] + h)
                for (x, y, side), h in zip(f.tolist(), hd)]

    # --- footsteps ----------------------------------------------------------------------------
    def _plan(self, obs: np.ndarray, odo) -> list[float]:
        g, p = self.gait, self.params
        x_b, y_b, side_b, h_b = self._footholds(obs, odo)[-1]
        side = 1 - round(side_b)  # the new foothold's foot
        sign = 1.0 if side == 0 else -1.0
        target = max(self.planned_stone + 1, self.next_stone)
        xy = self.stone_xy(target)
        length, width, heading = g.nominal_step_m, g.step_width_m, h_b
        if xy is None and target >= 1 and self.planned_stone == target - 1:
            self.planned_stone = target  # an unseen stone: a nominal step toward where it should be
        if xy is not None:
            cb, sb = math.cos(h_b), math.sin(h_b)
            ahead = (xy[0] - x_b) * cb + (xy[1] - y_b) * sb - FOOT_CENTRE_AHEAD_M
            if ahead > g.step_range_m[1] - 0.05:  # still on the slab: equal steps up to the stone
                length = ahead / max(math.ceil(ahead / (g.step_range_m[1] - 0.05)), round(ahead / g.nominal_step_m))
            else:
                lim = (g.max_turn_deg - p.turn_margin_deg) * DEG
                heading = h_b
                for _ in range(3):  # the aim depends on the heading (foot centre ahead, side offset across)
                    c, s = math.cos(heading), math.sin(heading)
                    fx = xy[0] - FOOT_CENTRE_AHEAD_M * c - sign * p.side_offset_m * s
                    fy = xy[1] - FOOT_CENTRE_AHEAD_M * s + sign * p.side_offset_m * c
                    dx, dy = fx - x_b, fy - y_b
                    dist = math.hypot(dx, dy)
                    w = min(g.step_width_m, 0.9 * dist)
                    want = math.atan2(dy, dx) - sign * math.asin(w / dist)
                    heading = h_b + min(max(math.remainder(want - h_b, 2.0 * math.pi), -lim), lim)
                c, s = math.cos(heading), math.sin(heading)
                length = dx * c + dy * s
                width = sign * (-dx * s + dy * c)
                self.planned_stone = target
        lateral = sign * (width - g.step_width_m)
        turn = WalkerBody.action_from_turn(heading - h_b, g)
        return [*WalkerBody.action_from_footstep(length, lateral, g.nominal_clearance_m, g), turn]

    # --- gaze ---------------------------------------------------------------------------------
    def _look(self, obs: np.ndarray, pose) -> list:
        p = self.params
        target = min(self.next_stone + 1, self.planned_stone + 1)
        xy = self.stone_xy(target)
        eye_pos, rot, odo = pose
        c, s = math.cos(odo[2]), math.sin(odo[2])
        ex, ey = odo[0] + c * eye_pos[0] - s * eye_pos[1], odo[1] + s * eye_pos[0] + c * eye_pos[1]
        ez = odo[3] + eye_pos[2]
        if xy is None:  # nothing known: the ground ~2 steps ahead on the slab's axis
            xy = (ex + 1.5, 0.0)
        self.log.append((float(obs[_S["time"]][0]), target))
        dx, dy, dz = xy[0] - ex, xy[1] - ey, -0.005 - ez
        wx, wy = c * dx + s * dy, -s * dx + c * dy  # pelvis frame
        (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = rot
        e0 = a00 * wx + a10 * wy + a20 * dz  # R^T w: in the eye frame
        e1 = a01 * wx + a11 * wy + a21 * dz
        e2 = a02 * wx + a12 * wy + a22 * dz
        d_az, d_el = math.atan2(e1, e0), math.atan2(e2, math.hypot(e0, e1))
        pitch = math.atan2(-dz, math.hypot(wx, wy))  # below the horizontal, positive
        yaw = math.atan2(wy, wx)
        r = self.gaze_range
        return [min(max(d_az / r, -1.0), 1.0), min(max(d_el / r, -1.0), 1.0), 0.0,
                min(max(p.head_share * yaw / (NECK_YAW_DEG * DEG), -1.0), 1.0),
                min(max(-p.head_share * pitch / (NECK_PITCH_DOWN_DEG * DEG), -1.0), 0.0)]
