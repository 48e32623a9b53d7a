"""The catch task: one ball (the observability ladder) or two staggered balls (Eom et al. 2019 §7)
thrown at a seated catcher, caught when a ball enters the palm's catch volume while the fingers are
closed (then welded to the hand), missed when it passes behind the body or reaches the floor.
"""

from __future__ import annotations

import enum

import mujoco
import numpy as np

from visuomotor_gym.body import names
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import FreeBodyTarget
from visuomotor_gym.geometry import norm
from visuomotor_gym.scenarios.throws import BALL_RADIUS, sample_second_throw, sample_throw
from visuomotor_gym.tasks.catch_rewards import catch_reward
from visuomotor_gym.vision import foveation

MISS_BEHIND_X = -0.3  # seat frame: the ball is behind the catcher (modelling choice)
MISS_FLOOR_Z = BALL_RADIUS + 0.02  # world frame: the ball is on the floor
PARKED_BALL_POS = (0.0, 0.0, -2.0)  # EyeCatchTwoBalls-v0: where a released ball goes (under the floor)
THROWER_BEHIND_RELEASE_M = 0.35  # the thrower marker stands this far behind the release point (visual only)

BALL_PERCEPT_BLOCKS = (
    Block("ball_pos", 3, "m", "perceived ball position, eye frame (zeros when not visible)"),
    Block("ball_vel", 3, "m/s", "perceived ball velocity, world velocity in eye-frame axes (zeros when not visible)"),
    Block("ball_visible", 1, "0/1", "1 if this step produced a visual sample of the ball"),
    Block("ball_age", 1, "s", "age of the visual sample (the visual latency; 0 without delay)"),
)
TIME_BLOCK = Block("time", 1, "s", "time since the throw")
# Appended after every other block in EyeCatchTwoBalls-v0 (``n_balls=2``) only: the single-ball layout
# is unchanged and stays a prefix, so its slices hold in both.
SECOND_BALL_BLOCKS = (
    Block("ball2_pos", 3, "m", "perceived position of the second ball, eye frame (zeros when not visible)"),
    Block("ball2_vel", 3, "m/s", "perceived velocity of the second ball, eye-frame axes (zeros when not visible)"),
    Block("ball2_visible", 1, "0/1", "1 if this step produced a visual sample of the second ball"),
    Block("balls_caught", 2, "0/1", "touch: 1 once the first / second ball has been caught (stays 1 after release)"),
    Block("holding", 1, "0/1", "touch: 1 while a caught ball is held in the hand"),
)


class BallStatus(enum.Enum):
    WAITING = "waiting"  # hidden by its thrower, not yet thrown (the second ball)
    FLYING = "flying"
    HELD = "held"  # caught, welded to the hand
    RELEASED = "released"  # caught, then let go: out of play


class Ball(FreeBodyTarget):
    """A ball: a visual target on a free joint, with its body, catch weld, geom and status."""

    def __init__(self, model: mujoco.MjModel, joint: str, body: str, weld: str, geom: str) -> None:
        m = model
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)
        super().__init__(body, int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j]))
        self.body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body)
        self.weld = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, weld)
        self.geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, geom)
        self.conaffinity = int(m.geom_conaffinity[self.geom])
        self.status = BallStatus.FLYING

    @property
    def hidden(self) -> bool:
        return self.status is BallStatus.WAITING or self.status is BallStatus.RELEASED

    @property
    def in_play_or_caught(self) -> bool:
        return self.status is BallStatus.HELD or self.status is BallStatus.RELEASED

    def pos(self, data) -> np.ndarray:
        return data.qpos[self.qpos_adr : self.qpos_adr + 3]

    def place(self, data, position, velocity) -> None:
        q, v = self.qpos_adr, self.dof_adr
        data.qpos[q : q + 3] = position
        data.qpos[q + 3 : q + 7] = (1.0, 0.0, 0.0, 0.0)
        data.qvel[v : v + 3] = velocity


def catch_scene(n_balls: int) -> str:
    """The scene file of the catch task (the single-ball scene stays byte-identical without ball 2)."""
    return "catch.xml" if n_balls == 1 else names.TWO_BALLS_SCENE


class CatchTask(Task):
    """Throws, catches, misses and rewards of the catch family.

    ``body`` is the :class:`~visuomotor_gym.body.seated.SeatedBody` (catch site, grasp, seat frame).
    """

    def __init__(self, model: mujoco.MjModel, body, *, n_balls: int, bounce_wall: bool,
                 release_after_catch_s: float, catch_radius: float, grasp_closed_fraction: float,
                 throw_distribution, reward_weights: dict, dt: float, visual_delay_s: float,
                 neutral_fixation_m: float) -> None:
        m = model
        self.model = model
        self.body = body
        self.n_balls = n_balls
        self.bounce_wall = bounce_wall
        self.release_after_catch_s = release_after_catch_s
        self.catch_radius = catch_radius
        self.grasp_closed_fraction = grasp_closed_fraction
        self.throw_distribution = throw_distribution
        self.reward_weights = reward_weights
        self.dt = dt
        self.visual_delay_s = visual_delay_s
        self._physics_dt = float(m.opt.timestep)
        self.neutral_fixation_m = float(neutral_fixation_m)
        self._seat_x = body.frame.origin_list[0]
        self.balls = [Ball(m, names.BALL_JOINT, names.BALL, names.CATCH_WELD, names.BALL_GEOM)]
        if n_balls == 2:
            self.balls.append(Ball(m, names.BALL2_JOINT, names.BALL2, names.CATCH_WELD2, names.BALL2_GEOM))
            self._thrower2_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.THROWER2)
        self.targets = self.balls  # what the retina samples, in order
        self._thrower_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.THROWER)
        self._wall_geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, names.BOUNCE_WALL_GEOM)
        self._wall_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.BOUNCE_WALL)
        self.leading_blocks = BALL_PERCEPT_BLOCKS
        self.trailing_blocks = (TIME_BLOCK,) + (SECOND_BALL_BLOCKS if n_balls == 2 else ())
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.success = False  # every ball caught
        for k, ball in enumerate(self.balls):
            ball.status = BallStatus.FLYING if k == 0 else BallStatus.WAITING
        self.holding: int | None = None  # the ball in the hand
        self.held_since = 0.0
        self.visible = [False] * self.n_balls

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the throw(s) and place the ball(s): the first is released at t = 0."""
        m, d = self.model, data
        self.throw = throw = sample_throw(rng, self.throw_distribution, self._physics_dt, self.bounce_wall)
        self.balls[0].place(d, throw.release_pos, throw.release_vel)
        m.body_pos[self._thrower_body] = (throw.release_pos[0] + THROWER_BEHIND_RELEASE_M, throw.release_pos[1], 0.0)
        self._place_wall(throw)
        d.eq_active[self.balls[0].weld] = 0
        if self.n_balls == 2:
            self._reset_second_ball(d, rng)

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        """Where gaze starts: the release point (the thrower's hand), with the throw's jitter."""
        return self.throw.release_pos, tuple(self.throw.gaze_offset)

    # --- what the evaluator records ----------------------------------------------------------
    trace_step_fields = ("ball_pos", "ball_vel")
    trace_flag_fields = ("ball_visible",)

    def trace_episode_fields(self) -> dict:
        throw = self.throw
        return {"release_pos": np.asarray(throw.release_pos), "arrival_pos": np.asarray(throw.arrival_pos),
                "flight_time": float(throw.flight_time)}

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"missed": bool(info["missed"])}

    def initial_fixation(self, distance: float) -> float:
        """The fixation (vergence) distance at reset: a fixed value, never the true distance of the
        thrower's hand (that would leak the ball's depth into the ``fixation`` observation). It is the
        distance a neutral fixation action (0) holds: the log-midpoint of the fixation range,
        sqrt(0.1 m x 20 m) = 1.41 m (modelling choice)."""
        return self.neutral_fixation_m

    def reset_info(self) -> dict:
        throw = self.throw
        info = {
            "release_pos": throw.release_pos.copy(),
            "release_vel": throw.release_vel.copy(),
            "arrival_pos": throw.arrival_pos.copy(),
            "flight_time": throw.flight_time,
            "wall_y": throw.wall_y,
        }
        if self.n_balls == 2:
            t2 = self.throw2
            info.update(release2_pos=t2.release_pos.copy(), release2_vel=t2.release_vel.copy(),
                        arrival2_pos=t2.arrival_pos.copy(), release2_time=t2.release_time,
                        flight2_time=t2.flight_time)
        return info

    def _place_wall(self, throw) -> None:
        m = self.model
        if throw.wall_y is None:
            m.geom_contype[self._wall_geom] = 0
            return
        half = float(m.geom_size[self._wall_geom, 1])
        # The ball centre reflects at wall_y, so the wall surface sits one ball radius beyond it.
        center_y = throw.wall_y + throw.wall_side * (BALL_RADIUS + half)
        mid_x = 0.5 * (throw.release_pos[0] + throw.arrival_pos[0])
        m.body_pos[self._wall_body] = (mid_x, center_y, 1.5)
        m.geom_contype[self._wall_geom] = 1

    def _reset_second_ball(self, d: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the second throw and hold its ball, weightless, at the second thrower's hand."""
        m = self.model
        self.throw2 = sample_second_throw(rng, self.throw_distribution, self._physics_dt, self.dt, self.throw)
        self.balls[1].place(d, self.throw2.release_pos, (0.0, 0.0, 0.0))
        d.qvel[self.balls[1].dof_adr + 3 : self.balls[1].dof_adr + 6] = 0.0
        m.body_pos[self._thrower2_body] = (self.throw2.release_pos[0] + THROWER_BEHIND_RELEASE_M,
                                           self.throw2.release_pos[1], 0.0)
        for k, ball in enumerate(self.balls):
            m.body_gravcomp[ball.body] = 1.0 if k == 1 else 0.0
            m.geom_conaffinity[ball.geom] = ball.conaffinity
            d.eq_active[ball.weld] = 0

    # --- physics ------------------------------------------------------------------------------
    def before_physics(self, data: mujoco.MjData) -> None:
        """Throw the waiting ball when its time has come, and let a held ball go
        ``release_after_catch_s`` after its catch (parked under the floor, out of play)."""
        if self.n_balls == 1:
            return
        m, d = self.model, data
        second = self.balls[1]
        if second.status is BallStatus.WAITING and d.time >= self.throw2.release_time - 1e-9:
            d.qvel[second.dof_adr : second.dof_adr + 3] = self.throw2.release_vel
            m.body_gravcomp[second.body] = 0.0
            second.status = BallStatus.FLYING
        k = self.holding
        if k is not None and not self.success and d.time >= self.held_since + self.release_after_catch_s - 1e-9:
            ball = self.balls[k]
            d.eq_active[ball.weld] = 0
            d.qpos[ball.qpos_adr : ball.qpos_adr + 3] = PARKED_BALL_POS
            d.qvel[ball.dof_adr : ball.dof_adr + 6] = 0.0
            m.body_gravcomp[ball.body] = 1.0
            m.geom_conaffinity[ball.geom] = 0
            ball.status = BallStatus.RELEASED
            self.holding = None

    def needs_substep_checks(self, data: mujoco.MjData) -> bool:
        """Whether a catch could happen during the coming control step (else skip substep checks)."""
        if self.success or self.holding is not None:  # the hand holds one ball at a time
            return False
        if not self.body.grasp_may_close(data, self.grasp_closed_fraction):
            return False
        if self.n_balls == 1:  # the ladder's common case, without a generator (this runs every step)
            ball = self.balls[0]
            return ball.status is BallStatus.FLYING and self._ball_near_hand(data, ball)
        return any(self._ball_near_hand(data, b) for b in self.balls if b.status is BallStatus.FLYING)

    def _ball_near_hand(self, d: mujoco.MjData, ball: Ball) -> bool:
        speed = norm(d.qvel[ball.dof_adr : ball.dof_adr + 3])
        gap = norm(ball.pos(d) - self.body.hand_pos(d)) - self.catch_radius
        return gap < (speed + 2.0 * self.body.hand_params.max_speed_m_s) * self.dt + 0.05

    def check_substep(self, data: mujoco.MjData) -> bool:
        """Catch test of every ball in flight (current kinematics); True if one was caught."""
        if self.n_balls == 1:
            return self.balls[0].status is BallStatus.FLYING and self._catch_now(data, 0)
        return any(self._catch_now(data, k) for k in range(self.n_balls) if self.balls[k].status is BallStatus.FLYING)

    def _catch_now(self, d: mujoco.MjData, k: int) -> bool:
        """Ball centre in the catch volume, fingers closed, hand empty: weld the ball to the hand."""
        if self.success or self.holding is not None:
            return False
        if not self.body.grasp_closed(d, self.grasp_closed_fraction):
            return False
        ball = self.balls[k]
        if norm(d.xpos[ball.body] - self.body.hand_pos(d)) > self.catch_radius:
            return False
        ball.status = BallStatus.HELD
        self.holding = k
        self.held_since = float(d.time)
        self.success = all(b.in_play_or_caught for b in self.balls)
        self._activate_weld(d, ball)
        return True

    def _activate_weld(self, d: mujoco.MjData, ball: Ball) -> None:
        """Hold the caught ball in the hand: weld it at its current pose relative to the hand."""
        m = self.model
        hand_body = self.body.hand_body
        hand_pos, hand_quat = d.xpos[hand_body], d.xquat[hand_body]
        ball_pos, ball_quat = d.xpos[ball.body], d.xquat[ball.body]
        rel_pos = d.xmat[hand_body].reshape(3, 3).T @ (ball_pos - hand_pos)
        inv = np.zeros(4)
        mujoco.mju_negQuat(inv, hand_quat)
        rel_quat = np.zeros(4)
        mujoco.mju_mulQuat(rel_quat, inv, ball_quat)
        m.eq_data[ball.weld, 3:6] = rel_pos
        m.eq_data[ball.weld, 6:10] = rel_quat
        d.eq_active[ball.weld] = 1

    # --- observation --------------------------------------------------------------------------
    def observe_leading(self, values: list, samples: list) -> None:
        """The first ball's percept blocks (:data:`BALL_PERCEPT_BLOCKS`)."""
        pos, vel, visible = samples[0]
        for k, sample in enumerate(samples):
            self.visible[k] = sample[2]
        values += pos
        values += vel
        values += (1.0 if visible else 0.0, self.visual_delay_s)

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        """Time, then with two balls the second ball's percept and the touch blocks."""
        values.append(data.time)
        if self.n_balls == 2:
            pos2, vel2, visible2 = samples[1]
            values += pos2
            values += vel2
            values.append(1.0 if visible2 else 0.0)
            values += (1.0 if b.in_play_or_caught else 0.0 for b in self.balls)
            values.append(0.0 if self.holding is None else 1.0)

    # --- outcome ------------------------------------------------------------------------------
    def _is_missed(self, ball: np.ndarray) -> bool:
        bx, by, bz = ball.tolist()
        x = bx - self._seat_x
        return x < MISS_BEHIND_X or bz < MISS_FLOOR_Z or abs(by) > 5.0 or x > 10.0 or bz > 15.0

    def shaping_ball(self) -> int:
        """The ball the shaping terms follow: the first still in flight (else the first)."""
        if self.n_balls == 1:
            return 0
        return next((k for k in range(self.n_balls) if self.balls[k].status is BallStatus.FLYING), 0)

    def evaluate(self, data: mujoco.MjData, caught: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        """After a step (``caught``: a substep check fired): ``(reward, terms, terminated, info fields)``."""
        d = data
        k = self.shaping_ball()
        ball = self.balls[k].pos(d)
        if self.n_balls == 1:
            missed = (not caught) and self._is_missed(ball)
        else:  # the first miss ends the episode: success (both caught) is then impossible
            missed = any(self._is_missed(b.pos(d)) for b in self.balls if b.status is BallStatus.FLYING)
        visible = self.visible[k]
        weights = self.reward_weights
        hand_ball = norm(self.body.hand_pos(d) - ball) if weights.get("approach") else 0.0
        ecc = None
        if visible and weights.get("foveation"):
            ecc = foveation.eccentricity(eye.to_eye(*self.balls[k].state(d))[0])
        effort = float(a @ a) / a.size if weights.get("effort") else 0.0
        reward, terms = catch_reward(weights, caught, missed, hand_ball, ecc, effort)
        terminated = (caught if self.n_balls == 1 else self.success) or missed
        return reward, terms, terminated, self.info(d, caught=caught, missed=missed)

    def info(self, data: mujoco.MjData, *, caught: bool = False, missed: bool = False, diverged: bool = False) -> dict:
        """The task's step information (true state: for scoring only, never for a policy). At reset and
        after a divergence nothing was caught or missed."""
        d = data
        b0 = self.balls[0]
        info = {
            "caught": caught,
            "missed": missed,
            "ball_visible": False if diverged else self.visible[0],
            "ball_pos": b0.pos(d).copy(),
            "ball_vel": d.qvel[b0.dof_adr : b0.dof_adr + 3].copy(),
        }
        if self.n_balls == 2:
            b1 = self.balls[1]
            info.update(
                ball2_pos=b1.pos(d).copy(),
                ball2_vel=d.qvel[b1.dof_adr : b1.dof_adr + 3].copy(),
                ball2_visible=bool(self.visible[1]),
                balls_caught=sum(b.in_play_or_caught for b in self.balls),
                holding=-1 if self.holding is None else int(self.holding),
            )
        return info
