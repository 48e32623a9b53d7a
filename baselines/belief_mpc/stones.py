"""``belief_mpc`` on SteppingStones-v0: Eom et al.'s (2019) belief-space MPC choosing where to look.

Every 20 ms control step the agent

1. **updates its beliefs with the real observation** (:mod:`.stone_belief`): each percept of a stone
   is fused into its mean (the lookahead agent's plane fusion, Eom Eq. 3 for a static object) and Eom's
   compact covariance ``sp`` (Eq. 4 with ``F = I``) is propagated with the gaze the eye really had:
   shrunk by a sample with the env's foveated noise at the stone's real eccentricity and retinal slip,
   only grown by the process noise when the stone was not seen (outside the 20 deg field, during a
   saccade). A stone not seen yet has the spread of the course generator relative to the stone before
   it (``prior_var_m2``: ALLSTEPS' spacing and turn, Xie et al. 2020) and a mean extrapolated from the
   two before it (or the task's nominal spacing);
2. **re-plans the gaze over a receding window** (``window_s`` = 1.2 s, Eom section 7: 0.6-1.2 s, at
   ``plan_dt_s`` = 0.1 s nodes): the candidates are the tracked stones still to be committed (at most
   4: the observation's slots, Eom's N_obj <= 4); the planner predicts when each will be committed
   (the gait's mid-stance reads, every ``step_s``, and the footstep planner's own slab steps), the
   eye's path (its velocity over the last step), and picks the fixation schedule minimising Eom's cost
   -- the uncertainty term over the tracked stones plus the task term's expectation at each
   commitment (:func:`.stone_belief.plan_gaze`); no rule says which stone to look at;
3. **executes** the first node of the plan: the eye is asked for the direction of the chosen stone's
   believed centre (a saccade when far, pursuit when near; the env's plant decides), the head taking
   ``head_share`` of it (the lookahead agent's split); the footstep at each mid-stance read is the
   lookahead agent's planner on the same belief means (foot centre on the believed stone, the step's
   heading turned toward it within the gait's 45 deg a step).

``gaze_blind:belief_mpc`` on a stones env is its gaze-blind twin (gaze and head held; the same belief
and planners).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.lookahead.agent import (
    NECK_PITCH_DOWN_DEG,
    NECK_YAW_DEG,
    LookaheadAgent,
    LookaheadParams,
    beyond_fovea,
)
from visuomotor_gym.baselines.lookahead.perception import STONE_PLANE_Z, StoneMemory

from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.envs.stones import STONES_LAYOUT
from visuomotor_gym.registration import env_vision, env_vision_params
from visuomotor_gym.tasks.stepping_stones import FOOT_CENTRE_AHEAD_M, K_SLOTS, CourseDistribution
from visuomotor_gym.vision.foveation import DEG, VisionParams

from .field import field_limit_eye
from .stone_belief import plan_gaze, plane_variance, static_sigma_step

_S = STONES_LAYOUT.slices
_COURSE = CourseDistribution()


def _course_prior_var() -> float:
    """Isotropic variance (m^2) of a stone's centre given the stone before it, from the course
    generator's distribution (ALLSTEPS, Xie et al. 2020): spacing uniform on 0.65-0.85 m (variance
    0.2^2 / 12 along the path) and a turn uniform within +-30 deg (variance s^2 (60 deg)^2 / 12
    across it, small angles), their mean (Eom's R = r I is isotropic)."""
    lo, hi = _COURSE.spacing_m
    s = 0.5 * (lo + hi)
    turn = 2.0 * math.radians(_COURSE.heading_change_deg)
    return 0.5 * ((hi - lo) ** 2 / 12.0 + s * s * turn * turn / 12.0)


@dataclass(frozen=True)
class StonesBeliefMPCParams(LookaheadParams):
    """The lookahead agent's footstep and execution constants, plus the planner's (Eom section 6-7)."""

    # Cost weights: Eom section 7 (w_uct = 1; the stepping-stone task weight w_tsk = 10).
    w_uct: float = 1.0
    w_tsk: float = 10.0
    # Process noise of a stone's believed position, m^2 per second (Eom's alpha for a static object:
    # how fast an unattended stone's position is forgotten). Modelling choice: (3 cm)^2/s -- memory of a
    # stone fades over a few seconds on the scale of the footstep margin (~10 cm); swept in the docs.
    q_m2_per_s: float = 9e-4
    # Receding window and node spacing (Eom section 7: windows of 0.6-1.2 s).
    window_s: float = 1.2
    plan_dt_s: float = 0.1
    max_switches: int = 2  # switches per window (modelling choice: 3 fixations in 1.2 s, > 0.2 s each)
    n_tracked: int = K_SLOTS  # Eom: N_obj <= 4
    prior_var_m2: float = _course_prior_var()  # an unseen stone, relative to the one before it
    saccade_refractory_s: float = 0.2  # the plant's (Young & Stark 1963)
    saccade_threshold_deg: float = 3.0  # the plant's: gaze within this of a stone fixates it
    velocity_window_s: float = 0.5  # the eye's velocity is measured over one step (averages the sway)

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or v is None:  # None: a LookaheadParams switch left to the vision model
                continue
            if not math.isfinite(v) or v < 0:
                raise ValueError(f"StonesBeliefMPCParams.{f.name} must be finite and >= 0, got {v!r}")
        if self.plan_dt_s <= 0 or self.window_s < 2 * self.plan_dt_s:
            raise ValueError("plan_dt_s must be > 0 and window_s at least two nodes long")
        if not 1 <= self.n_tracked <= K_SLOTS or int(self.max_switches) != self.max_switches:
            raise ValueError(f"n_tracked must be in [1, {K_SLOTS}] and max_switches a whole number")


# The name the committed policy files' "note" uses (their bytes are re-exported and compared by the
# leaderboard check, so the note stays as written): the walker families' vision of a registered id.
stones_vision = env_vision_params


class StonesBeliefMPCAgent(LookaheadAgent):
    """See the module docstring. ``predict(obs) -> (action, state)`` on flat SteppingStones observations."""

    def __init__(self, params: StonesBeliefMPCParams | None = None, gait: GaitParams | None = None,
                 vision: VisionParams | None = None) -> None:
        self.timing: dict[str, float] = {}
        super().__init__(params or StonesBeliefMPCParams(), gait, vision)
        p = self.params
        self.n_nodes = max(2, int(round(p.window_s / p.plan_dt_s)))
        self.q_step = p.q_m2_per_s * p.control_dt

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> StonesBeliefMPCAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = StonesBeliefMPCParams(**env_vision(env_id))
        known = {f.name for f in fields(StonesBeliefMPCParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown belief_mpc parameter(s) for the stones family {unknown}; known: {sorted(known)}")
        return cls(replace(base, **overrides), vision=env_vision_params(env_id))

    def reset(self) -> None:
        super().reset()
        self.sigma: dict[int, float] = {}  # stone -> Eom's compact covariance sp (m^2), once seen
        self.fixating = -1  # the stone the last plan chose
        self.stones_left = _COURSE.n_stones
        self.eye_hist: list[tuple[float, tuple]] = []
        self.plan_log: list[dict] = []  # per step: t, fixated stone, next stone, committed stone, sp
        self.solve_ms: list[float] = []

    # ------------------------------------------------------------------------------------------
    def _lap(self, name: str) -> None:
        now = time.perf_counter()
        self.timing[name] = self.timing.get(name, 0.0) + now - self._tick
        self._tick = now

    def _act(self, obs: np.ndarray) -> np.ndarray:
        self._tick = time.perf_counter()
        p = self.params
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
        seen_world = StoneMemory.eye_pose(*seen_pose)
        self.next_stone = round(ol[_S["stone_0"].start])
        t = ol[_S["time"].start]

        # --- 1. real belief update: means (plane fusion) and Eom's compact covariance ------------------
        seen_now = {}
        # with crowding in the vision model, samples beyond the crowding-free fovea are fused with the
        # crowding zone's spread (the lookahead agent's distrust_periphery; none without crowding)
        crowd = self.vision.foveated and bool(getattr(self.vision, "crowding", False)) \
            and p.distrust_periphery is not False
        fovea = self.vision.crowding_fovea_deg * DEG
        for k in range(K_SLOTS):
            b = _S[f"stone_{k}"].start
            i = round(ol[b])
            if ol[b + 4] > 0.0:
                flag = crowd and bool(beyond_fovea([ol[b + 1:b + 4]], fovea))
                self.memory.add(i, ol[b + 1:b + 4], seen_pose[0], seen_pose[1], seen_pose[2], prev, p.control_dt,
                                crowded=flag)
                seen_now[i] = True
            else:
                seen_now.setdefault(i, False)
        for i, seen in seen_now.items():
            if not seen and i not in self.sigma:
                continue
            est = self.memory.estimate(i)
            if i not in self.sigma:
                self.sigma[i] = self.prior_sp(i)
            r = math.inf
            if seen and est is not None:
                r = self._sample_variance(est[0], seen_world, prev)
            self.sigma[i] = float(static_sigma_step(self.sigma[i], r, self.q_step))
        self._lap("perception")

        latch_in = ol[_S["gait_phase"].start + 2]
        reads_now = latch_in <= p.control_dt + 1e-6
        if reads_now:  # this step's command is read at mid-stance
            self.footstep = self._plan(obs, odo)
        self._lap("footsteps")
        action = np.zeros(9, dtype=np.float32)
        action[0:4] = self.footstep

        # --- 2. the gaze plan ---------------------------------------------------------------------------
        world = StoneMemory.eye_pose(*pose)
        self._track_eye(t, world[0])
        target = self._plan_gaze(obs, odo, world, latch_in + (self.gait.step_s if reads_now else 0.0))
        self._lap("plan")
        # --- 3. execute -----------------------------------------------------------------------------------
        self.log.append((t, target))
        if not self.params.gaze_blind:
            action[4:9] = self._look_at(self._believed_xy(target), pose)
        self._lap("execution")
        return action

    # --- belief ---------------------------------------------------------------------------------------
    def prior_sp(self, i: int) -> float:
        """Compact covariance of stone ``i`` before it is seen: the one before it plus the course's spread."""
        p = self.params
        j, extra = i - 1, p.prior_var_m2
        while j >= 0 and j not in self.sigma and extra < 50.0 * p.prior_var_m2:
            j, extra = j - 1, extra + p.prior_var_m2
        return extra + (self.sigma[j] if j >= 0 and j in self.sigma else 0.0)

    def sp_of(self, i: int) -> float:
        return self.sigma[i] if i in self.sigma else self.prior_sp(i)

    def _believed_xy(self, i: int, depth: int = 0) -> tuple[float, float]:
        """Believed centre of stone ``i``: its estimate, else extrapolated from the two before it, else
        the nominal spacing ahead of the one before it (stone 0: of the last foothold on the slab)."""
        xy = self.stone_xy(i)
        if xy is not None:
            return xy
        if i <= 0 or depth > 20:
            return (_COURSE.start_foot_x_m + self.params.spacing_m, _COURSE.start_foot_y_m)
        bx, by = self._believed_xy(i - 1, depth + 1)
        head = 0.0
        if i >= 2:
            ax, ay = self._believed_xy(i - 2, depth + 1)
            head = math.atan2(by - ay, bx - ax)
        return bx + self.params.spacing_m * math.cos(head), by + self.params.spacing_m * math.sin(head)

    def _sample_variance(self, xy, world, prev) -> float:
        """``r`` of this step's sample of the stone believed at ``xy``, seen from ``world`` (eye pose in the
        path frame) with the gaze it had (eccentricity, slip from the eye's own motion)."""
        (ex, ey, ez), rows = world
        dx, dy, dz = xy[0] - ex, xy[1] - ey, STONE_PLANE_Z - ez
        d = math.sqrt(dx * dx + dy * dy + dz * dz) or 1e-9
        gx, gy, gz = rows[0][0], rows[1][0], rows[2][0]
        ecc = math.acos(max(-1.0, min(1.0, (gx * dx + gy * dy + gz * dz) / d)))
        slip = self.memory.retinal_slip(xy[0], xy[1], world, prev, self.params.control_dt)
        limit = None
        if self.vision.field_shape == "human":  # the field in the eye's own frame (columns: its axes)
            uy = (rows[0][1] * dx + rows[1][1] * dy + rows[2][1] * dz) / d
            uz = (rows[0][2] * dx + rows[1][2] * dy + rows[2][2] * dz) / d
            limit = field_limit_eye(uy, uz, self.vision)
        return float(plane_variance(d, ecc, slip, -dz / d, self.vision, limit=limit))

    # --- gaze plan ------------------------------------------------------------------------------------
    def _track_eye(self, t: float, eye) -> None:
        self.eye_hist.append((t, tuple(eye)))
        while len(self.eye_hist) > 1 and t - self.eye_hist[0][0] > self.params.velocity_window_s + 1e-9:
            self.eye_hist.pop(0)

    def _eye_velocity(self, heading: float) -> np.ndarray:
        (t0, a), (t1, b) = self.eye_hist[0], self.eye_hist[-1]
        if t1 - t0 < 0.5 * self.params.velocity_window_s:  # the start: the gait's nominal speed
            v = self.gait.nominal_step_m / self.gait.step_s
            return np.array([v * math.cos(heading), v * math.sin(heading), 0.0])
        return np.array([(b[0] - a[0]) / (t1 - t0), (b[1] - a[1]) / (t1 - t0), 0.0])

    def candidates(self) -> list[int]:
        """The tracked stones still to be committed (at most ``n_tracked``, within the observation's slots)."""
        first = max(self.planned_stone + 1, self.next_stone)
        last = min(self.next_stone + self.params.n_tracked, self.next_stone + self.stones_left)
        return list(range(first, last))

    def commit_times(self, obs: np.ndarray, odo, cands: list[int], first_read_s: float) -> np.ndarray:
        """Seconds until each candidate's foothold is committed (inf beyond the window): the mid-stance
        reads come every ``step_s``; each commits the next stone unless the footstep planner still takes
        equal steps on the slab toward it (as ``LookaheadAgent._plan``)."""
        g = self.gait
        out = np.full(len(cands), np.inf)
        if not cands:
            return out
        u = self._footholds(obs, odo)[-1][0]
        horizon = self.params.window_s
        t_read, c = first_read_s, 0
        while t_read <= horizon + 1e-9 and c < len(cands):
            x = self._believed_xy(cands[c])[0]
            dist = x - FOOT_CENTRE_AHEAD_M - u
            if dist > g.step_range_m[1] - 0.05:
                u += dist / max(math.ceil(dist / (g.step_range_m[1] - 0.05)), round(dist / g.nominal_step_m))
            else:
                out[c] = t_read
                u = x - FOOT_CENTRE_AHEAD_M
                c += 1
            t_read += g.step_s
        return out

    def _plan_gaze(self, obs: np.ndarray, odo, world, first_read_s: float) -> int:
        p = self.params
        self.stones_left = round(float(obs[_S["stones_left"]][0]))
        cands = self.candidates()
        if not cands:  # every stone committed: stay on the last one planned for
            return max(self.planned_stone, 0)
        start = time.perf_counter()
        xy = np.array([self._believed_xy(i) for i in cands])
        sp0 = np.array([self.sp_of(i) for i in cands])
        (ex, ey, ez), rows = world
        gaze = np.array([rows[0][0], rows[1][0], rows[2][0]])
        eye = np.array([ex, ey, ez])
        # the stone the line of sight is on now (or, in flight, the one the saccade goes to)
        current = -1
        rel = np.column_stack([xy - eye[:2], np.full(len(cands), STONE_PLANE_Z - ez)])
        ang = np.arccos(np.clip(rel @ gaze / np.linalg.norm(rel, axis=1), -1.0, 1.0))
        in_saccade = obs[_S["saccade"]][0] > 0.5
        since_onset = float(obs[_S["saccade"]][1])
        if in_saccade and self.fixating in cands:
            current = cands.index(self.fixating)
        elif float(ang.min()) <= p.saccade_threshold_deg * DEG:
            current = int(np.argmin(ang))
        earliest = max(0.0, p.saccade_refractory_s - since_onset) if not in_saccade else p.saccade_refractory_s
        commit = self.commit_times(obs, odo, cands, first_read_s)
        plan = plan_gaze(xy, sp0, eye, self._eye_velocity(odo[2]), gaze, commit, current, earliest, self.vision,
                         h=p.plan_dt_s, n=self.n_nodes, dt=p.control_dt, q_node=p.q_m2_per_s * p.plan_dt_s,
                         w_uct=p.w_uct, w_tsk=p.w_tsk, plane_z=STONE_PLANE_Z, refractory_s=p.saccade_refractory_s,
                         max_switches=int(p.max_switches))
        self.fixating = cands[int(plan.targets[0])]
        self.solve_ms.append(1e3 * (time.perf_counter() - start))
        self.plan_log.append({"t": float(obs[_S["time"]][0]), "fixate": self.fixating, "next_stone": self.next_stone,
                              "planned_stone": self.planned_stone, "candidates": cands,
                              "sp": sp0.tolist(), "commit_s": commit.tolist()})
        return self.fixating

    def _look_at(self, xy, pose) -> list:
        """Gaze and head actions toward the point ``xy`` of the stones' plane (the lookahead agent's
        request: the eye to its direction, the head ``head_share`` of the pitch and yaw)."""
        p = self.params
        eye_pos, rot, odo = pose
        c, s = math.cos(odo[2]), math.sin(odo[2])
        ex, ey = odo[0] + c * eye_pos[0] - s * eye_pos[1], odo[1] + s * eye_pos[0] + c * eye_pos[1]
        ez = odo[3] + eye_pos[2]
        dx, dy, dz = xy[0] - ex, xy[1] - ey, STONE_PLANE_Z - ez
        wx, wy = c * dx + s * dy, -s * dx + c * dy  # pelvis frame
        (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = rot
        e0 = a00 * wx + a10 * wy + a20 * dz  # R^T w: in the eye frame
        e1 = a01 * wx + a11 * wy + a21 * dz
        e2 = a02 * wx + a12 * wy + a22 * dz
        d_az, d_el = math.atan2(e1, e0), math.atan2(e2, math.hypot(e0, e1))
        pitch = math.atan2(-dz, math.hypot(wx, wy))
        yaw = math.atan2(wy, wx)
        r = self.gaze_range
        return [min(max(d_az / r, -1.0), 1.0), min(max(d_el / r, -1.0), 1.0), 0.0,
                min(max(p.head_share * yaw / (NECK_YAW_DEG * DEG), -1.0), 1.0),
                min(max(-p.head_share * pitch / (NECK_PITCH_DOWN_DEG * DEG), -1.0), 0.0)]


__all__ = ["StonesBeliefMPCAgent", "StonesBeliefMPCParams"]
