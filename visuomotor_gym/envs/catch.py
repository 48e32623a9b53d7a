"""EyeCatch: catch a thrown ball while seeing it only through a foveated, saccading eye."""

from __future__ import annotations

import math
import os
import warnings
from collections import deque
from dataclasses import asdict, fields
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

from visuomotor_gym.assets import asset_path
from visuomotor_gym.body import names
from visuomotor_gym.control.hand import HandController, HandControlParams
from visuomotor_gym.envs.observation import SECOND_BALL_OBSERVATION, ObservationLayout, catch_observation
from visuomotor_gym.envs.rewards import REWARD_TERMS, SHAPED_WEIGHTS, SPARSE_WEIGHTS, catch_reward
from visuomotor_gym.geometry import norm, rotate, rotate_t, unit_from_angles
from visuomotor_gym.oculomotor.plant import (
    DEG,
    OculomotorParams,
    OculomotorPlant,
    angles_from_direction,
    direction_from_angles,
)
from visuomotor_gym.scenarios.throws import BALL_RADIUS, ThrowDistribution, sample_second_throw, sample_throw
from visuomotor_gym.vision import foveation
from visuomotor_gym.vision.foveation import VisionParams

VISION_MODES = ("foveated", "full_view", "oracle")
CONTROL_MODES = ("hand", "joint")
OBS_MODES = ("flat", "dict")
REWARD_MODES = ("sparse", "shaped")
RENDER_CAMERAS = ("both", "scene", "eye", "over_shoulder")

SEAT_ORIGIN = np.array([0.0, 0.0, 0.5])  # the pelvis joint, world frame
_SEAT_X, _SEAT_Y, _SEAT_Z = SEAT_ORIGIN.tolist()
# Hand workspace of control="hand": an axis-aligned box in the seat frame (min, max), metres.
HAND_WORKSPACE = np.array([[-0.1, 0.7], [-0.8, 0.3], [0.0, 1.0]])
# Ready posture at reset (degrees): hand in front of the belly, palm facing the body's midline.
READY_POSTURE_DEG = {
    "shoulder_flex": 30.0,
    "shoulder_abd": 10.0,
    "shoulder_rot": 0.0,
    "elbow": 80.0,
    "forearm_rot": 0.0,
    "wrist_flex": 0.0,
    "wrist_dev": 0.0,
}
MISS_BEHIND_X = -0.3  # seat frame: the ball is behind the catcher
MISS_FLOOR_Z = BALL_RADIUS + 0.02  # world frame: the ball is on the floor
GAZE_AGE_CAP_S = 1.0
PARKED_BALL_POS = (0.0, 0.0, -2.0)  # EyeCatchTwoBalls-v0: where a released ball goes (under the floor)


def _coerce(cls, value, arg_name):
    """Accept a params dataclass, a dict of its fields, or None (defaults)."""
    if value is None:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, dict):
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(value) - allowed)
        if unknown:
            raise TypeError(f"{arg_name}: unknown field(s) {unknown}; allowed: {sorted(allowed)}")
        return cls(**value)
    raise TypeError(f"{arg_name} must be a {cls.__name__}, a dict of its fields or None; got {type(value).__name__}")


def _index(ids) -> slice | np.ndarray:
    """A slice when ``ids`` are consecutive (a view, cheaper than fancy indexing), else the array."""
    ids = np.asarray(ids, dtype=int)
    if len(ids) and np.all(np.diff(ids) == 1):
        return slice(int(ids[0]), int(ids[-1]) + 1)
    return ids


def _choice(value, allowed, arg_name):
    if value not in allowed:
        raise ValueError(f"{arg_name}={value!r} is not one of {list(allowed)}")
    return value


class EyeCatchEnv(gym.Env):
    """
    ## Description

    A seated upper body (3-DOF torso, 7-DOF right arm, 2-DOF neck, cyclopean eye) must catch a ball
    thrown from 3-6 m away, **seeing it only through a human-like eye** (Yeo et al., *Eyecatch*,
    SIGGRAPH 2012; Eom et al., TOG 2019). The eye perceives the ball's position and velocity in the
    eye frame with Gaussian noise whose covariance grows with distance and, steeply, with
    eccentricity from the line of sight (Eyecatch Eq. 1-3), and whose lateral position part grows with
    the ball's speed on the retina above 2.5 deg/s (moving-target localisation: an eye that does not
    pursue the ball localises it poorly); nothing is seen outside the +-60 deg field
    of view or during a saccade. The eye moves under human limits: saccades of main-sequence
    duration (<= 800 deg/s, at most one per 200 ms, ballistic) or pursuit (<= 100 deg/s), with a
    vestibulo-ocular reflex that keeps gaze fixed in the world while the head and torso move. The
    hand catches only if the ball enters the palm's catch volume while the fingers are closed;
    otherwise it bounces off (MuJoCo contact).

    Physics runs at 500 Hz, control at 50 Hz (the Kalman step of Eyecatch). The variants of the
    observability ladder are keyword arguments of this one class (see ``visuomotor_gym.registration``).

    ## Action Space

    One ``Box(-1, 1, (9,), float32)`` with ``control="hand"`` (``(16,)`` with ``control="joint"``).
    ``env.unwrapped.action_structure`` gives the blocks. Finite values outside [-1, 1] are clipped;
    NaN, inf and wrong shapes raise ``ValueError``.

    | index (hand) | index (joint) | meaning |
    |---|---|---|
    | 0-2 | - | hand target (catch-site centre), seat frame, mapped from [-1, 1] to x in [-0.1, 0.7], y in [-0.8, 0.3], z in [0.0, 1.0] m; the hand reference moves toward it at <= 2 m/s and damped least squares turns it into torso + arm setpoints |
    | - | 0-9 | torso (3) and arm (7) joint setpoints, mapped linearly onto each joint's range |
    | 3 | 10 | grasp: -1 open ... 1 closed (the fingers close in ~60 ms) |
    | 4-5 | 11-12 | requested gaze change in retinal coordinates (azimuth, elevation) of the current eye frame, times ``gaze_action_range_deg`` (60 deg); 0 holds gaze fixed in the world |
    | 6 | 13 | fixation (vergence) distance, log-mapped onto [0.1, 20] m; does not change the noise in v0 |
    | 7-8 | 14-15 | head target: neck yaw in [-80, 80] deg and pitch in [-50, 40] deg (0 = straight ahead), reached at <= 300 deg/s |

    ## Observation Space

    ``Box(-inf, inf, (57,), float32)`` by default, or with ``obs_mode="dict"`` a ``Dict`` of the
    same blocks. ``env.unwrapped.observation_structure`` maps block names to sizes. The ball blocks
    are what the eye perceived (true state only in ``vision="oracle"``); everything else is
    proprioception (an efference copy of the eye pose included).

    OBSERVATION_TABLE

    With ``n_balls=2`` (``EyeCatchTwoBalls-v0``) the same blocks come first, for the first ball, and
    these follow (``Box(-inf, inf, (67,), float32)``):

    TWO_BALL_OBSERVATION_TABLE

    ## Two balls (``n_balls=2``, EyeCatchTwoBalls-v0; Eom et al. 2019, section 7)

    The first ball is the ladder's throw for the seed. A second ball waits, weightless and hidden (not
    seen until it is thrown), at a second thrower on the other side (1-2 m to the side, 3-6 m ahead)
    and is released 0.2-0.5 s later (a whole number of control steps), arriving 0.5-0.8 s after the
    first in the same catchable region (``sample_second_throw`` in
    ``visuomotor_gym.scenarios.throws``; drawn after the first throw). The
    catch rule is the same for both balls; the hand holds one ball at a time, and a caught ball is
    released ``release_after_catch_s`` after its catch (it leaves the scene: parked under the floor,
    no longer seen), so the hand can take the second. ``info["is_success"]`` needs both catches;
    ``info["balls_caught"]`` counts them. The episode ends when both are caught or at the first miss
    (success is then impossible). The catch reward is paid per ball; shaping terms follow the first
    ball in flight. ``info`` adds ``ball2_pos``, ``ball2_vel``, ``ball2_visible``, ``balls_caught`` and
    ``holding`` (the held ball's index, -1 for none), and at reset ``release2_pos``, ``release2_vel``,
    ``arrival2_pos``, ``release2_time`` and ``flight2_time``. Registered with ``max_episode_steps``
    150 (3 s). The scene is ``envs_assets/catch_two_balls.xml`` (``catch.xml`` plus the second
    ball, its thrower and its catch weld), so the single-ball scene is unchanged. Not combinable with
    ``bounce_wall``.

    ## Rewards

    A sum of named terms, each in ``info["reward_terms"]``. ``reward="sparse"`` (default): ``catch``
    = +1 on the step of a catch. ``reward="shaped"`` adds ``miss`` (-0.2 once), ``approach``
    (-0.01 x hand-ball distance in m), ``foveation`` (+0.005 x exp(-(eccentricity/5 deg)^2) when the
    ball is seen) and ``effort`` (-0.001 x mean squared action). ``reward_weights`` overrides any
    weight by name.

    ## Starting State

    The body starts upright in a ready posture with the hand open in front of the belly. A throw is
    drawn from ``throw_distribution`` (``visuomotor_gym.scenarios.throws``): release 3-6 m ahead,
    1-2 m high, +-1 m lateral; flight time 0.8-1.4 s; arrival in the catchable region in front of the
    right shoulder. The ball is released at t = 0; gaze starts on the release point with a 2 deg
    Gaussian jitter. The same seed gives the same throw across the whole ladder.

    ## Episode End

    Terminated when the ball is caught (``info["is_success"]``), missed (behind the body, on the
    floor or far away) or the physics diverges (``info["physics_diverged"]``: MuJoCo's bad-state
    warnings; the last finite observation is returned). Truncated only by the registered
    ``max_episode_steps`` (125 steps = 2.5 s).

    ## Arguments

    | argument | default | meaning |
    |---|---|---|
    | ``render_mode`` | None | ``"rgb_array"`` or ``"human"`` |
    | ``vision`` | ``"foveated"`` | ``"foveated"``, ``"full_view"`` (foveal noise everywhere, no field-of-view limit, no saccadic blindness) or ``"oracle"`` (true ball state) |
    | ``vision_noise_scale`` | 1.0 | multiplies every vision standard deviation (10: poor vision) |
    | ``vision_params`` | None | ``VisionParams`` or a dict of its fields (acuity, retinal-slip knee, Weber fraction, depth noise, field of view) |
    | ``visual_delay_s`` | 0.0 | visual latency, a multiple of the control period |
    | ``bounce_wall`` | False | an invisible wall deflects the ball mid-flight |
    | ``n_balls`` | 1 | 1, or 2 for two staggered balls (see Two balls) |
    | ``release_after_catch_s`` | 0.2 | with two balls, a caught ball leaves the hand this long after its catch |
    | ``control`` | ``"hand"`` | ``"hand"`` (Cartesian) or ``"joint"`` |
    | ``obs_mode`` | ``"flat"`` | ``"flat"`` or ``"dict"`` |
    | ``reward`` | ``"sparse"`` | ``"sparse"`` or ``"shaped"`` |
    | ``reward_weights`` | None | dict overriding term weights |
    | ``oculomotor_params`` | None | ``OculomotorParams`` or dict (saccade and pursuit limits, eye ranges, head speed) |
    | ``hand_params`` | None | ``HandControlParams`` or dict (2 m/s cap, DLS damping) |
    | ``throw_distribution`` | None | ``ThrowDistribution`` or dict |
    | ``control_dt`` | 0.02 | control period (s); must be a whole multiple of the 2 ms physics step |
    | ``catch_radius`` | 0.06 | radius (m) of the palm's catch volume |
    | ``grasp_closed_fraction`` | 0.6 | finger closure above which the hand counts as closed |
    | ``gaze_action_range_deg`` | 60.0 | gaze change at action +-1 |
    | ``render_camera`` | ``"both"`` | ``"both"`` (scene beside eye view), ``"scene"``, ``"eye"``, ``"over_shoulder"`` |
    | ``width``, ``height`` | 480, 360 | size of each rendered camera image |
    | ``record_plant`` | False | keep the 500 Hz gaze trace (``env.unwrapped.plant.trace()``) |

    ## Version History

    * v0: initial release. Before the first release (issue 11) the default vision gained the retinal-slip
      term of moving-target localisation (``VisionParams.position_slip_knee_deg_s`` = 2.5), so that where
      the eye looks decides the catch; the Eyecatch paper's static acuity is ``EyeCatchPaper-v0`` and
      ``EyeCatchPaperPoorVision-v0`` (x10).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 50}

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        vision: str = "foveated",
        vision_noise_scale: float = 1.0,
        vision_params: VisionParams | dict | None = None,
        visual_delay_s: float = 0.0,
        bounce_wall: bool = False,
        n_balls: int = 1,
        release_after_catch_s: float = 0.2,
        control: str = "hand",
        obs_mode: str = "flat",
        reward: str = "sparse",
        reward_weights: dict[str, float] | None = None,
        oculomotor_params: OculomotorParams | dict | None = None,
        hand_params: HandControlParams | dict | None = None,
        throw_distribution: ThrowDistribution | dict | None = None,
        control_dt: float = 0.02,
        catch_radius: float = 0.06,
        grasp_closed_fraction: float = 0.6,
        gaze_action_range_deg: float = 60.0,
        render_camera: str = "both",
        width: int = 480,
        height: int = 360,
        record_plant: bool = False,
        **unknown: Any,
    ):
        if unknown:
            raise TypeError(
                f"EyeCatchEnv got unknown argument(s) {sorted(unknown)}; allowed: {sorted(self._argument_names())}"
            )
        if render_mode is not None:
            _choice(render_mode, self.metadata["render_modes"], "render_mode")
        self.render_mode = render_mode
        self.vision = _choice(vision, VISION_MODES, "vision")
        self.control = _choice(control, CONTROL_MODES, "control")
        self.obs_mode = _choice(obs_mode, OBS_MODES, "obs_mode")
        self.render_camera = _choice(render_camera, RENDER_CAMERAS, "render_camera")
        if not (math.isfinite(vision_noise_scale) and vision_noise_scale >= 0):
            raise ValueError(f"vision_noise_scale must be finite and >= 0, got {vision_noise_scale!r}")
        base_vision = _coerce(VisionParams, vision_params, "vision_params")
        self.vision_params = base_vision.scaled(vision_noise_scale)
        if vision == "full_view":
            self.vision_params = VisionParams(**{**asdict(self.vision_params), "foveated": False})
        self.oculomotor_params = _coerce(OculomotorParams, oculomotor_params, "oculomotor_params")
        self.hand_params = _coerce(HandControlParams, hand_params, "hand_params")
        self.throw_distribution = _coerce(ThrowDistribution, throw_distribution, "throw_distribution")
        self.bounce_wall = bool(bounce_wall)
        if isinstance(n_balls, bool) or n_balls not in (1, 2):
            raise ValueError(f"n_balls must be 1 or 2, got {n_balls!r}")
        if n_balls == 2 and self.bounce_wall:
            raise ValueError("n_balls=2 cannot be combined with bounce_wall")
        if not (math.isfinite(release_after_catch_s) and release_after_catch_s >= 0):
            raise ValueError(f"release_after_catch_s must be finite and >= 0, got {release_after_catch_s!r}")
        self.n_balls = int(n_balls)
        self.release_after_catch_s = float(release_after_catch_s)
        self.catch_radius = float(catch_radius)
        self.grasp_closed_fraction = float(grasp_closed_fraction)
        self.gaze_action_range = float(gaze_action_range_deg) * DEG
        if not (self.catch_radius > 0 and 0 < self.grasp_closed_fraction <= 1 and self.gaze_action_range > 0):
            raise ValueError("catch_radius and gaze_action_range_deg must be > 0; grasp_closed_fraction in (0, 1]")
        weights = dict(SPARSE_WEIGHTS if _choice(reward, REWARD_MODES, "reward") == "sparse" else SHAPED_WEIGHTS)
        for name, value in (reward_weights or {}).items():
            if name not in REWARD_TERMS:
                raise ValueError(f"reward_weights: unknown term {name!r}; known terms: {list(REWARD_TERMS)}")
            weights[name] = float(value)
        self.reward_mode = reward
        self.reward_weights = weights
        self.width, self.height = int(width), int(height)

        # --- MuJoCo model and name lookups --------------------------------------------------
        scene = "catch.xml" if self.n_balls == 1 else names.TWO_BALLS_SCENE
        self.model = mujoco.MjModel.from_xml_path(str(asset_path(scene)))
        self.data = mujoco.MjData(self.model)
        m = self.model
        physics_dt = float(m.opt.timestep)
        ratio = control_dt / physics_dt
        if not (control_dt > 0 and abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1):
            raise ValueError(
                f"control_dt={control_dt} must be a positive whole multiple of the physics timestep {physics_dt}"
            )
        self.n_substeps = int(round(ratio))
        self.dt = self.n_substeps * physics_dt
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.dt))}
        delay_steps = visual_delay_s / self.dt
        if not (visual_delay_s >= 0 and abs(delay_steps - round(delay_steps)) < 1e-9):
            raise ValueError(f"visual_delay_s={visual_delay_s} must be >= 0 and a whole multiple of {self.dt} s")
        self.visual_delay_s = float(visual_delay_s)
        self.delay_steps = int(round(delay_steps))

        def jid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)

        def aid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)

        body_j = [jid(n) for n in names.BODY_JOINTS]
        self._body_qpos = _index([m.jnt_qposadr[j] for j in body_j])
        self._body_dof = _index([m.jnt_dofadr[j] for j in body_j])
        self._body_range = m.jnt_range[body_j].copy()
        body_act = [aid(n) for n in names.BODY_ACTUATORS]
        self._body_act = _index(body_act)
        self._body_actadr = _index([m.actuator_actadr[a] for a in body_act])
        neck_j = [jid(n) for n in names.NECK_JOINTS]
        self._neck_qpos = _index([m.jnt_qposadr[j] for j in neck_j])
        self._neck_dof = _index([m.jnt_dofadr[j] for j in neck_j])
        self._neck_range = m.jnt_range[neck_j].copy()
        self._neck_range_list = self._neck_range.tolist()
        self._neck_act = [aid(n) for n in names.NECK_ACTUATORS]
        self._neck_actadr = [int(m.actuator_actadr[a]) for a in self._neck_act]
        self._grasp_act = aid(names.GRASP_ACTUATOR)
        grasp_j = jid(names.GRASP)
        self._grasp_qpos = int(m.jnt_qposadr[grasp_j])
        self._grasp_max = float(m.jnt_range[grasp_j, 1])
        self._eye_qpos = np.array([m.jnt_qposadr[jid(n)] for n in (names.EYE_AZIMUTH, names.EYE_ELEVATION)])
        self._eye_dof = _index([m.jnt_dofadr[jid(n)] for n in (names.EYE_AZIMUTH, names.EYE_ELEVATION)])
        self._eye_qpos_az, self._eye_qpos_el = (int(i) for i in self._eye_qpos)
        self._fix_qpos = int(m.jnt_qposadr[jid(names.EYE_FIXATION)])
        ball_j = jid(names.BALL_JOINT)
        self._ball_qpos = int(m.jnt_qposadr[ball_j])
        self._ball_dof = int(m.jnt_dofadr[ball_j])
        self._head_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.HEAD)
        self._hand_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.HAND)
        self._ball_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.BALL)
        self._thrower_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.THROWER)
        self._eye_offset = m.body_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.EYE)].copy()
        self._eye_offset_list = self._eye_offset.tolist()
        self._catch_site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, names.CATCH_SITE)
        self._wall_geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, names.BOUNCE_WALL_GEOM)
        self._weld = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, names.CATCH_WELD)
        # Per ball: (qpos address, dof address, body, catch weld, geom); ball 0 is the ladder's ball.
        self._balls = [(self._ball_qpos, self._ball_dof, self._ball_body, self._weld,
                        mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, names.BALL_GEOM))]
        if self.n_balls == 2:
            ball2_j = jid(names.BALL2_JOINT)
            self._balls.append((int(m.jnt_qposadr[ball2_j]), int(m.jnt_dofadr[ball2_j]),
                                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.BALL2),
                                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, names.CATCH_WELD2),
                                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, names.BALL2_GEOM)))
            self._thrower2_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.THROWER2)
            self._ball_conaffinity = [int(m.geom_conaffinity[b[4]]) for b in self._balls]
        self._ready = np.array(
            [0.0, 0.0, 0.0] + [READY_POSTURE_DEG[n] * DEG for n in names.ARM_JOINTS]
        )
        if not np.all(m.actuator_ctrllimited[body_act]):
            raise ValueError("the body servos must have a ctrlrange (it is their speed limit)")
        self._ws_lo = HAND_WORKSPACE[:, 0] + SEAT_ORIGIN  # world frame
        self._ws_half = 0.5 * (HAND_WORKSPACE[:, 1] - HAND_WORKSPACE[:, 0])
        self._ws_lo_half = (tuple(self._ws_lo.tolist()), tuple(self._ws_half.tolist()))
        self.hand = HandController(
            m, self._catch_site, self._body_dof, self._body_qpos, self._body_range, self._ready,
            n_torso=len(names.TORSO_JOINTS), params=self.hand_params,
        )
        self.plant = OculomotorPlant(self.oculomotor_params, record=record_plant)
        op = self.oculomotor_params
        self._az_range = (op.eye_azimuth_range_deg[0] * DEG, op.eye_azimuth_range_deg[1] * DEG)
        self._el_range = (op.eye_elevation_range_deg[0] * DEG, op.eye_elevation_range_deg[1] * DEG)
        self._head_vmax = op.head_max_deg_s * DEG
        self._bad_warnings = [
            int(w) for w in (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                             mujoco.mjtWarning.mjWARN_BADQACC)
        ]
        self._log_fix = (math.log(op.fixation_range_m[0]), math.log(op.fixation_range_m[1]))

        # --- spaces -----------------------------------------------------------------------------
        if self.control == "hand":
            self.action_structure = {"hand_target": 3, "grasp": 1, "gaze": 2, "fixation": 1, "head": 2}
        else:
            self.action_structure = {"body_joints": 10, "grasp": 1, "gaze": 2, "fixation": 1, "head": 2}
        n_act = sum(self.action_structure.values())
        self._n_body_act = n_act - 6
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_act,), dtype=np.float32)
        self.layout = ObservationLayout(catch_observation(self.n_balls))
        self.observation_structure = self.layout.structure
        self.observation_space = self.layout.flat_space() if obs_mode == "flat" else self.layout.dict_space()
        self._s = self.layout.slices
        expected = ("ball_pos", "ball_vel", "ball_visible", "ball_age", "eye_pos", "eye_rot", "eye_in_head",
                    "fixation", "saccade", "head_qpos", "head_qvel", "body_qpos", "body_qvel", "hand_pos",
                    "hand_vel", "grasp", "time")
        if self.n_balls == 2:
            expected += ("ball2_pos", "ball2_vel", "ball2_visible", "balls_caught", "holding")
        assert tuple(b.name for b in self.layout.blocks) == expected, "update _observe with the layout"

        self._renderers: dict[str, mujoco.Renderer] = {}
        self._viewer = None
        self._warned_human = False
        self._reset_episode_state()

    @classmethod
    def _argument_names(cls) -> list[str]:
        import inspect

        params = inspect.signature(cls.__init__).parameters
        return [p for p in params if p not in ("self", "unknown")]

    # ------------------------------------------------------------------------------------------
    # Gymnasium API
    # ------------------------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if options:
            raise ValueError(f"reset options are not supported; got {sorted(options)}")
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        self._reset_episode_state()
        self.throw = sample_throw(self.np_random, self.throw_distribution, float(m.opt.timestep), self.bounce_wall)
        throw = self.throw

        # Body in the ready posture, servo setpoints equal to it.
        d.qpos[self._body_qpos] = self._ready
        d.act[self._body_actadr] = self._ready
        d.qpos[self._neck_qpos] = 0.0
        d.act[self._neck_actadr] = 0.0
        d.ctrl[:] = 0.0
        # Ball at the release point, already thrown.
        d.qpos[self._ball_qpos : self._ball_qpos + 3] = throw.release_pos
        d.qpos[self._ball_qpos + 3 : self._ball_qpos + 7] = (1.0, 0.0, 0.0, 0.0)
        d.qvel[self._ball_dof : self._ball_dof + 3] = throw.release_vel
        m.body_pos[self._thrower_body] = (throw.release_pos[0] + 0.35, throw.release_pos[1], 0.0)
        self._place_wall(throw)
        d.eq_active[self._weld] = 0
        if self.n_balls == 2:
            self._reset_second_ball()
        mujoco.mj_forward(m, d)
        # Live views of MuJoCo's bad-state warning counters (reading one costs ~0.1 us).
        self._warning_stats = [d.warning[i] for i in self._bad_warnings]
        self._warning_total = sum(w.number for w in self._warning_stats)
        self._half_timestep = 0.5 * float(m.opt.timestep)

        # Gaze on the release point (the thrower's hand), with a small jitter.
        eye_pos = d.xpos[self._head_body] + d.xmat[self._head_body].reshape(3, 3) @ self._eye_offset
        az, el = angles_from_direction(throw.release_pos - eye_pos)
        gaze = direction_from_angles(az + throw.gaze_offset[0], el + throw.gaze_offset[1])
        self.plant.reset(gaze, time=0.0)
        self._fixation = float(np.linalg.norm(throw.release_pos - eye_pos))
        self._apply_gaze()
        self._prev_eye_pos = self._eye_pos_list
        self._prev_gaze = self._eye_rot_flat[0::3]
        self.hand.reset(d.site_xpos[self._catch_site])
        self._hand_prev = tuple(d.site_xpos[self._catch_site].tolist())
        obs = self._observe(saccading=False)
        self._last_obs = obs.copy()
        info = self._info(caught=False, missed=False, diverged=False, terms={}, visible=self._visible)
        info.update(
            release_pos=throw.release_pos.copy(),
            release_vel=throw.release_vel.copy(),
            arrival_pos=throw.arrival_pos.copy(),
            flight_time=throw.flight_time,
            wall_y=throw.wall_y,
        )
        if self.n_balls == 2:
            info.update(release2_pos=self.throw2.release_pos.copy(), release2_vel=self.throw2.release_vel.copy(),
                        arrival2_pos=self.throw2.arrival_pos.copy(), release2_time=self.throw2.release_time,
                        flight2_time=self.throw2.flight_time)
        return self._format(obs), info

    def step(self, action):
        a, al = self._check_action(action)  # al: the same values in a list (cheaper to read than slices)
        m, d = self.model, self.data
        dt = self.dt
        nb = self._n_body_act

        # --- eye: requested gaze change, in retinal coordinates of the current eye frame --------
        g_az, g_el, g_fix = al[nb + 1 : nb + 4]
        u = unit_from_angles(g_az * self.gaze_action_range, g_el * self.gaze_action_range)  # eye frame
        target = np.array(rotate(self._eye_rot_flat, *u))  # world
        plant_step = self.plant.step(target, dt, self.n_substeps, self.np_random)
        lo, hi = self._log_fix
        fix_target = math.exp(lo + (g_fix + 1.0) * 0.5 * (hi - lo))
        vergence = self.oculomotor_params.vergence_max_diopter_s * dt  # rate limit in diopters
        inv = min(max(1.0 / fix_target, 1.0 / self._fixation - vergence), 1.0 / self._fixation + vergence)
        self._fixation = 1.0 / inv

        # --- head: velocity-limited position servo -------------------------------------------
        vmax = self._head_vmax
        act, ctrl = d.act, d.ctrl
        head_a = al[nb + 4 : nb + 6]
        for k in range(2):
            h = head_a[k]
            lo_h, hi_h = self._neck_range_list[k]
            v = ((h * hi_h if h >= 0 else -h * lo_h) - act[self._neck_actadr[k]]) / dt
            ctrl[self._neck_act[k]] = min(max(v, -vmax), vmax)

        # --- torso and arm ----------------------------------------------------------------------
        setpoint = d.act[self._body_actadr]
        if self.control == "hand":
            (lx, ly, lz), (hx, hy, hz) = self._ws_lo_half
            self.hand.advance_reference((lx + (al[0] + 1.0) * hx, ly + (al[1] + 1.0) * hy, lz + (al[2] + 1.0) * hz), dt)
            new_setpoint = self.hand.setpoints(d, setpoint)
        else:
            r = self._body_range
            new_setpoint = r[:, 0] + (a[:10].astype(float) + 1.0) * 0.5 * (r[:, 1] - r[:, 0])
        d.ctrl[self._body_act] = (new_setpoint - setpoint) / dt  # MuJoCo clamps to ctrlrange: a rate limit
        d.ctrl[self._grasp_act] = (al[nb] + 1.0) * 0.5 * self._grasp_max

        if self.n_balls == 2:
            self._launch_and_release()

        # --- physics ---------------------------------------------------------------------------
        caught, diverged = self._simulate()
        if diverged:
            info = self._info(caught=False, missed=False, diverged=True, terms={}, visible=False)
            return self._format(self._last_obs.copy()), 0.0, True, False, info
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        caught = caught or self._catch_any()
        self._apply_gaze()
        obs = self._observe(saccading=plant_step.saccading)
        self._last_obs = obs.copy()  # the fallback after divergence; the caller may edit ``obs``
        self._prev_eye_pos = self._eye_pos_list
        self._prev_gaze = self._eye_rot_flat[0::3]

        # --- outcome and reward --------------------------------------------------------------
        k = self._shaping_ball()
        qa = self._balls[k][0]
        ball = d.qpos[qa : qa + 3]
        if self.n_balls == 1:
            missed = (not caught) and self._is_missed(ball)
        else:  # the first miss ends the episode: success (both caught) is then impossible
            missed = any(self._is_missed(d.qpos[self._balls[j][0] : self._balls[j][0] + 3])
                         for j in range(self.n_balls) if self._status[j] == "flying")
        visible = self._visible if k == 0 else self._visible2
        weights = self.reward_weights
        hand_ball = norm(d.site_xpos[self._catch_site] - ball) if weights.get("approach") else 0.0
        ecc = foveation.eccentricity(self._true_ball_eye(k)[0]) if visible and weights.get("foveation") else None
        effort = float(a @ a) / a.size if weights.get("effort") else 0.0
        reward, terms = catch_reward(weights, caught, missed, hand_ball, ecc, effort)
        info = self._info(caught=caught, missed=missed, diverged=False, terms=terms, visible=self._visible)
        info["saccade_onset"] = plant_step.saccade_started
        if self.render_mode == "human":
            self.render()
        return self._format(obs), reward, (caught if self.n_balls == 1 else self._caught) or missed, False, info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' or 'human'")
            return None
        mujoco.mj_kinematics(self.model, self.data)  # the eye joints were written after the last step
        if self.render_mode == "human":
            return self._render_human()
        cams = {
            "both": (names.SCENE_CAMERA, names.EYE_CAMERA),
            "scene": (names.SCENE_CAMERA,),
            "eye": (names.EYE_CAMERA,),
            "over_shoulder": (names.OVER_SHOULDER_CAMERA,),
        }[self.render_camera]
        frames = [self._render_camera(c) for c in cams]
        return frames[0] if len(frames) == 1 else np.concatenate(frames, axis=1)

    def close(self):
        for r in self._renderers.values():
            r.close()
        self._renderers = {}
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderers"] = {}
        state["_viewer"] = None
        state.pop("_warning_stats", None)  # views into self.data: rebuilt on load
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        if "_warning_total" in state:
            self._warning_stats = [self.data.warning[i] for i in self._bad_warnings]

    # ------------------------------------------------------------------------------------------
    # Pieces of a step
    # ------------------------------------------------------------------------------------------
    def _reset_episode_state(self) -> None:
        self._caught = False  # every ball caught (success)
        self._status = ["flying"] + ["waiting"] * (self.n_balls - 1)  # waiting/flying/held/released
        self._holding: int | None = None  # the ball in the hand
        self._held_since = 0.0
        self._visible2 = False
        self._delay_buffer: deque = deque(maxlen=self.delay_steps + 1)
        self._fixation = 1.0
        self._eye_rot_flat = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        self._eye_pos_list = [0.0, 0.0, 0.0]
        self._eye_in_head = (0.0, 0.0)

    def _check_action(self, action) -> tuple[np.ndarray, list]:
        """The action as float64, clipped to [-1, 1], and the same values as a list; errors say why not."""
        if type(action) is np.ndarray and action.shape == self.action_space.shape and action.dtype.kind == "f":
            a = action.astype(np.float64)  # the common case: a float array of the right shape
        else:
            try:
                a = np.asarray(action)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"action must be a numeric array of shape {self.action_space.shape}; got {action!r}") from exc
            if a.dtype.kind not in "biuf":
                raise ValueError(
                    f"action must be a real numeric array of shape {self.action_space.shape}; got dtype {a.dtype}"
                )
            a = a.astype(np.float64)
            if a.shape != self.action_space.shape:
                raise ValueError(
                    f"action must have shape {self.action_space.shape} (blocks {self.action_structure}), got shape {a.shape}"
                )
        values = a.tolist()
        if not math.isfinite(sum(values)) and not all(map(math.isfinite, values)):  # NaN or inf somewhere
            bad = np.flatnonzero(~np.isfinite(a)).tolist()
            raise ValueError(f"action contains NaN or inf at index {bad}: {values}; actions must be finite in [-1, 1]")
        if min(values) < -1.0 or max(values) > 1.0:
            a = np.clip(a, -1.0, 1.0)
            values = a.tolist()
        return a, values

    def _place_wall(self, throw) -> None:
        m = self.model
        if throw.wall_y is None:
            m.geom_contype[self._wall_geom] = 0
            return
        half = float(m.geom_size[self._wall_geom, 1])
        # The ball centre reflects at wall_y, so the wall surface sits one ball radius beyond it.
        center_y = throw.wall_y + throw.wall_side * (BALL_RADIUS + half)
        mid_x = 0.5 * (throw.release_pos[0] + throw.arrival_pos[0])
        m.body_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.BOUNCE_WALL)] = (mid_x, center_y, 1.5)
        m.geom_contype[self._wall_geom] = 1

    def _simulate(self) -> tuple[bool, bool]:
        """Run the physics substeps; return (caught, diverged)."""
        m, d = self.model, self.data
        caught = False
        t_expected = d.time + self.dt
        if self._caught or not self._catch_possible():
            mujoco.mj_step(m, d, nstep=self.n_substeps)
        else:  # a ball may cross the catch volume within this step: check every substep
            for _ in range(self.n_substeps):
                mujoco.mj_step(m, d)
                if not caught and self._catch_any():
                    caught = True
        # MuJoCo checks qpos/qvel/qacc every substep (NaN, inf or > 1e10), counts a warning and resets
        # the data (time back to 0) when one is bad: either sign is our divergence signal.
        total = self._warning_stats[0].number + self._warning_stats[1].number + self._warning_stats[2].number
        return caught, total != self._warning_total or abs(d.time - t_expected) > self._half_timestep

    def _catch_possible(self) -> bool:
        """Whether a catch could happen during the coming control step (else skip substep checks)."""
        d = self.data
        if self._holding is not None:  # the hand holds one ball at a time
            return False
        closing = self.grasp_closed_fraction * self._grasp_max
        if d.qpos[self._grasp_qpos] < closing and d.ctrl[self._grasp_act] < closing:
            return False
        if self.n_balls == 1:
            return self._status[0] == "flying" and self._ball_near_hand(0)
        return any(self._ball_near_hand(k) for k in range(self.n_balls) if self._status[k] == "flying")

    def _ball_near_hand(self, k: int = 0) -> bool:
        d = self.data
        qa, da = self._balls[k][0], self._balls[k][1]
        ball = d.qpos[qa : qa + 3]
        speed = norm(d.qvel[da : da + 3])
        gap = norm(ball - d.site_xpos[self._catch_site]) - self.catch_radius
        return gap < (speed + 2.0 * self.hand_params.max_speed_m_s) * self.dt + 0.05

    def _catch_any(self) -> bool:
        """Catch test of every ball in flight (current kinematics); True if one was caught."""
        if self.n_balls == 1:
            return self._status[0] == "flying" and self._catch_now(0)
        return any(self._catch_now(k) for k in range(self.n_balls) if self._status[k] == "flying")

    def _catch_now(self, k: int = 0) -> bool:
        """Catch test on consistent kinematics: ball centre in the catch volume, fingers closed, hand empty."""
        if self._caught or self._holding is not None:
            return False
        d = self.data
        closed = d.qpos[self._grasp_qpos] >= self.grasp_closed_fraction * self._grasp_max
        if not closed:
            return False
        if norm(d.xpos[self._balls[k][2]] - d.site_xpos[self._catch_site]) > self.catch_radius:
            return False
        self._status[k] = "held"
        self._holding = k
        self._held_since = float(d.time)
        self._caught = all(status == "held" or status == "released" for status in self._status)
        self._activate_weld(k)
        return True

    def _activate_weld(self, k: int = 0) -> None:
        """Hold the caught ball in the hand: weld it at its current pose relative to the hand."""
        m, d = self.model, self.data
        _, _, body, weld, _ = self._balls[k]
        hand_pos, hand_quat = d.xpos[self._hand_body], d.xquat[self._hand_body]
        ball_pos, ball_quat = d.xpos[body], d.xquat[body]
        rel_pos = d.xmat[self._hand_body].reshape(3, 3).T @ (ball_pos - hand_pos)
        inv = np.zeros(4)
        mujoco.mju_negQuat(inv, hand_quat)
        rel_quat = np.zeros(4)
        mujoco.mju_mulQuat(rel_quat, inv, ball_quat)
        m.eq_data[weld, 3:6] = rel_pos
        m.eq_data[weld, 6:10] = rel_quat
        d.eq_active[weld] = 1

    # --- two balls ----------------------------------------------------------------------------
    def _reset_second_ball(self) -> None:
        """Draw the second throw and hold its ball, weightless, at the second thrower's hand."""
        m, d = self.model, self.data
        self.throw2 = sample_second_throw(self.np_random, self.throw_distribution, float(m.opt.timestep),
                                          self.dt, self.throw)
        qa, da, _, _, _ = self._balls[1]
        d.qpos[qa : qa + 3] = self.throw2.release_pos
        d.qpos[qa + 3 : qa + 7] = (1.0, 0.0, 0.0, 0.0)
        d.qvel[da : da + 6] = 0.0
        m.body_pos[self._thrower2_body] = (self.throw2.release_pos[0] + 0.35, self.throw2.release_pos[1], 0.0)
        for k, ball in enumerate(self._balls):
            m.body_gravcomp[ball[2]] = 1.0 if k == 1 else 0.0
            m.geom_conaffinity[ball[4]] = self._ball_conaffinity[k]
            d.eq_active[ball[3]] = 0

    def _launch_and_release(self) -> None:
        """Before the physics of a step: throw the waiting ball when its time has come, and let a held
        ball go ``release_after_catch_s`` after its catch (parked under the floor, out of play)."""
        m, d = self.model, self.data
        if self._status[1] == "waiting" and d.time >= self.throw2.release_time - 1e-9:
            qa, da, body, _, _ = self._balls[1]
            d.qvel[da : da + 3] = self.throw2.release_vel
            m.body_gravcomp[body] = 0.0
            self._status[1] = "flying"
        k = self._holding
        if k is not None and not self._caught and d.time >= self._held_since + self.release_after_catch_s - 1e-9:
            qa, da, body, weld, geom = self._balls[k]
            d.eq_active[weld] = 0
            d.qpos[qa : qa + 3] = PARKED_BALL_POS
            d.qvel[da : da + 6] = 0.0
            m.body_gravcomp[body] = 1.0
            m.geom_conaffinity[geom] = 0
            self._status[k] = "released"
            self._holding = None

    def _shaping_ball(self) -> int:
        """The ball the shaping terms follow: the first still in flight (else the first)."""
        if self.n_balls == 1:
            return 0
        return next((k for k in range(self.n_balls) if self._status[k] == "flying"), 0)

    def _is_missed(self, ball: np.ndarray) -> bool:
        bx, by, bz = ball.tolist()
        x = bx - _SEAT_X
        return x < MISS_BEHIND_X or bz < MISS_FLOOR_Z or abs(by) > 5.0 or x > 10.0 or bz > 15.0

    def _apply_gaze(self) -> None:
        """Vestibulo-ocular reflex: turn the world gaze into eye-in-head angles for the current head.

        Clamps to the eye's range (Eom 4.1); if clamped, the plant's gaze becomes what was reached.
        Needs current head kinematics. Sets the eye joints and the cached eye frame (``_eye_rot_flat``:
        the rotation's 9 numbers, row-major; ``_eye_pos_list``; scalar maths: this runs every step,
        and numpy's per-call cost dominates 3x3 products).
        """
        d = self.data
        h0, h1, h2, h3, h4, h5, h6, h7, h8 = d.xmat[self._head_body].tolist()  # head rotation, row-major
        head = (h0, h1, h2, h3, h4, h5, h6, h7, h8)
        gx, gy, gz = rotate_t(head, *self.plant.gaze.tolist())  # gaze in head coordinates
        az = math.atan2(gy, gx)
        el = math.atan2(gz, math.hypot(gx, gy))
        az_c = min(max(az, self._az_range[0]), self._az_range[1])
        el_c = min(max(el, self._el_range[0]), self._el_range[1])
        ca, sa, ce, se = math.cos(az_c), math.sin(az_c), math.cos(el_c), math.sin(el_c)
        # Eye in head: Rz(azimuth) Ry(-elevation) (Donders/Fick order of the eye joints):
        # [[ca ce, -sa, -ca se], [sa ce, ca, -sa se], [se, 0, ce]]; the eye frame is head_rot @ that.
        e00, e01, e02, e10, e11, e12, e20, e22 = ca * ce, -sa, -ca * se, sa * ce, ca, -sa * se, se, ce
        flat = [
            h0 * e00 + h1 * e10 + h2 * e20, h0 * e01 + h1 * e11, h0 * e02 + h1 * e12 + h2 * e22,
            h3 * e00 + h4 * e10 + h5 * e20, h3 * e01 + h4 * e11, h3 * e02 + h4 * e12 + h5 * e22,
            h6 * e00 + h7 * e10 + h8 * e20, h6 * e01 + h7 * e11, h6 * e02 + h7 * e12 + h8 * e22,
        ]
        self._eye_rot_flat = flat
        if az_c != az or el_c != el:
            self.plant.constrain(np.array(flat[0::3]))
        px, py, pz = d.xpos[self._head_body].tolist()
        ox, oy, oz = rotate(head, *self._eye_offset_list)
        self._eye_pos_list = [px + ox, py + oy, pz + oz]
        self._eye_in_head = (az_c, el_c)
        qpos = d.qpos
        qpos[self._eye_qpos_az] = az_c
        qpos[self._eye_qpos_el] = el_c
        qpos[self._fix_qpos] = self._fixation
        d.qvel[self._eye_dof] = 0.0

    @property
    def _eye_rot(self) -> np.ndarray:
        """The eye frame's rotation (columns: visual axis, left, up in the world), as an array."""
        return np.array(self._eye_rot_flat).reshape(3, 3)

    @property
    def _eye_pos(self) -> np.ndarray:
        """The eye's centre (world), as an array."""
        return np.array(self._eye_pos_list)

    def _true_ball_eye(self, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """True ball position and velocity in the current eye frame (Eyecatch Eq. 6-7, no noise)."""
        d = self.data
        qa, da = self._balls[k][0], self._balls[k][1]
        ball = d.qpos[qa : qa + 3]
        vel = d.qvel[da : da + 3]
        rot = self._eye_rot
        return (ball - self._eye_pos) @ rot, vel @ rot  # R^T v

    def _see_ball(self, saccading: bool, k: int = 0) -> tuple[list, list, bool]:
        """One visual sample of ball ``k``: (position, velocity, visible), eye frame, float lists."""
        if self._status[k] in ("waiting", "released"):  # hidden by its thrower / out of play
            return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False
        if self.vision == "oracle":
            pos_eye, vel_eye = self._true_ball_eye(k)
            return pos_eye.tolist(), vel_eye.tolist(), True
        vp = self.vision_params
        if vp.foveated and saccading:  # saccadic suppression
            return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False
        d = self.data
        bq, bd = self._balls[k][0], self._balls[k][1]
        rot = self._eye_rot_flat
        ex, ey, ez = self._eye_pos_list
        bx, by, bz = d.qpos[bq : bq + 3].tolist()
        vx, vy, vz = d.qvel[bd : bd + 3].tolist()
        rx, ry, rz = bx - ex, by - ey, bz - ez
        pos_eye = list(rotate_t(rot, rx, ry, rz))  # R^T (p - r) and R^T v: Eyecatch Eq. 6-7
        vel_eye = list(rotate_t(rot, vx, vy, vz))
        # Retinal slip: line-of-sight angular velocity minus the gaze's own angular velocity over the
        # step (pursuit, or the head carrying a clamped eye), perpendicular to the line of sight.
        inv_dt = 1.0 / self.dt
        px, py, pz = self._prev_eye_pos
        dt = self.dt
        ux, uy, uz = vx - (ex - px) / dt, vy - (ey - py) / dt, vz - (ez - pz) / dt
        ax, ay, az = self._prev_gaze
        r0, r3, r6 = rot[0::3]  # the line of sight now
        wx, wy, wz = (ay * r6 - az * r3) * inv_dt, (az * r0 - ax * r6) * inv_dt, (ax * r3 - ay * r0) * inv_dt
        dist2 = rx * rx + ry * ry + rz * rz
        sx = (ry * uz - rz * uy) / dist2 - wx
        sy = (rz * ux - rx * uz) / dist2 - wy
        sz = (rx * uy - ry * ux) / dist2 - wz
        along = (sx * rx + sy * ry + sz * rz) / dist2
        sx, sy, sz = sx - along * rx, sy - along * ry, sz - along * rz
        retinal_speed = math.sqrt(sx * sx + sy * sy + sz * sz)
        return foveation.perceive(pos_eye, vel_eye, retinal_speed, vp, self.np_random)

    def _observe(self, saccading: bool) -> np.ndarray:
        d = self.data
        sample = self._see_ball(saccading)
        if self.n_balls == 2:
            sample = (sample, self._see_ball(saccading, 1))
        if self.delay_steps:
            self._delay_buffer.append(sample)
            if len(self._delay_buffer) <= self.delay_steps:
                nothing = ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False)  # nothing has reached the brain yet
                sample = nothing if self.n_balls == 1 else (nothing, nothing)
            else:
                sample = self._delay_buffer[0]
        if self.n_balls == 2:
            sample, (pos2, vel2, visible2) = sample
            self._visible2 = visible2
        pos, vel, visible = sample
        self._visible = visible
        hx, hy, hz = d.site_xpos[self._catch_site].tolist()
        px, py, pz = self._hand_prev
        dt = self.dt
        ex, ey, ez = self._eye_pos_list
        plant = self.plant
        qpos, qvel = d.qpos, d.qvel
        values = [
            *pos,
            *vel,
            1.0 if visible else 0.0,
            self.visual_delay_s,
            ex - _SEAT_X, ey - _SEAT_Y, ez - _SEAT_Z,
            *self._eye_rot_flat,
            *self._eye_in_head,
            self._fixation,
            1.0 if plant.saccade is not None else 0.0,
            min(plant.time - plant.last_onset, GAZE_AGE_CAP_S),
            *qpos[self._neck_qpos].tolist(),
            *qvel[self._neck_dof].tolist(),
            *qpos[self._body_qpos].tolist(),
            *qvel[self._body_dof].tolist(),
            hx - _SEAT_X, hy - _SEAT_Y, hz - _SEAT_Z,
            (hx - px) / dt, (hy - py) / dt, (hz - pz) / dt,
            qpos[self._grasp_qpos] / self._grasp_max,
            d.time,
        ]
        if self.n_balls == 2:
            values += [*pos2, *vel2, 1.0 if visible2 else 0.0,
                       *(0.0 if status == "waiting" or status == "flying" else 1.0 for status in self._status),
                       0.0 if self._holding is None else 1.0]
        self._hand_prev = (hx, hy, hz)
        return np.array(values, dtype=np.float32)

    def _format(self, obs: np.ndarray):
        if self.obs_mode == "flat":
            return obs
        return self.layout.to_dict(obs)

    def _info(self, *, caught: bool, missed: bool, diverged: bool, terms: dict, visible: bool) -> dict:
        """Step information. The true state in here is for scoring only: never feed it to a policy."""
        d = self.data
        info = {
            "is_success": bool(self._caught),
            "caught": caught,
            "missed": missed,
            "physics_diverged": diverged,
            "reward_terms": terms,
            "ball_visible": visible,
            "in_saccade": self.plant.saccade is not None,
            "saccade_onset": False,
            "time": float(d.time),
            "ball_pos": d.qpos[self._ball_qpos : self._ball_qpos + 3].copy(),
            "ball_vel": d.qvel[self._ball_dof : self._ball_dof + 3].copy(),
            "hand_pos": d.site_xpos[self._catch_site].copy(),
            "gaze_dir": self.plant.gaze.copy(),
            "eye_pos": np.array(self._eye_pos_list),
            "head_qpos": d.qpos[self._neck_qpos].copy(),
            "head_dir": d.xmat[self._head_body, 0::3].copy(),  # the head's forward axis, world
        }
        if self.n_balls == 2:
            qa, da = self._balls[1][0], self._balls[1][1]
            info.update(
                ball2_pos=d.qpos[qa : qa + 3].copy(),
                ball2_vel=d.qvel[da : da + 3].copy(),
                ball2_visible=bool(self._visible2),
                balls_caught=sum(status in ("held", "released") for status in self._status),
                holding=-1 if self._holding is None else int(self._holding),
            )
        return info

    # ------------------------------------------------------------------------------------------
    # Rendering
    # ------------------------------------------------------------------------------------------
    def _render_camera(self, camera: str) -> np.ndarray:
        renderer = self._renderers.get(camera)
        if renderer is None:
            renderer = mujoco.Renderer(self.model, self.height, self.width)
            self._renderers[camera] = renderer
        renderer.update_scene(self.data, camera=camera)
        if camera != names.EYE_CAMERA:
            self._draw_gaze(renderer.scene)
        return renderer.render().copy()

    def _draw_gaze(self, scene: mujoco.MjvScene) -> None:
        """Draw the line of sight, eye to fixation point, into a rendered scene (not the physics)."""
        if scene.ngeom >= scene.maxgeom:
            return
        start = self._eye_pos
        end = start + self.plant.gaze * self._fixation
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), np.zeros(3), np.eye(3).ravel(),
                            np.array([0.1, 0.9, 0.2, 0.6], dtype=np.float32))
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.004, start, end)
        scene.ngeom += 1

    def _render_human(self):
        headless = not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
        if headless or os.environ.get("MUJOCO_GL", "glfw") in ("egl", "osmesa"):
            if not self._warned_human:
                warnings.warn(
                    "render_mode='human' needs a display and MUJOCO_GL=glfw; nothing is shown. "
                    "Use render_mode='rgb_array' headless.",
                    stacklevel=2,
                )
                self._warned_human = True
            return None
        if self._viewer is None:
            import mujoco.viewer

            self._viewer = mujoco.viewer.launch_passive(self.model, self.data)
        self._viewer.sync()
        return None


if EyeCatchEnv.__doc__:
    EyeCatchEnv.__doc__ = EyeCatchEnv.__doc__.replace("TWO_BALL_OBSERVATION_TABLE", "\n    ".join(
        row for row in ObservationLayout(catch_observation(2)).markdown_table().splitlines()
        if row.startswith("| index") or row.startswith("|---")
        or any(f"| {b.name} |" in row for b in SECOND_BALL_OBSERVATION)))
    EyeCatchEnv.__doc__ = EyeCatchEnv.__doc__.replace("OBSERVATION_TABLE", ObservationLayout().markdown_table())
