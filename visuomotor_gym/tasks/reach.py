"""The shelf-reach task (Faraway, Reed & Wang 2007): an object stands on one of 30 shelf
targets (3 towers x 5 heights x 2 depths); the seated body must reach it with the right hand, seeing
it only through the eye.

The object is a :class:`~visuomotor_gym.core.retina.VisualTarget`: its position reaches the agent only
as the retina's samples (foveated noise, field of view, saccadic suppression, delay), so an accurate
reach needs it fixated (the depth noise is 5 % of the distance at the fovea and grows ~1 + theta/2 deg
away from it). Success: the object's centre inside the catch volume (``reach_radius``, 6 cm, as in the
catch family) with the fingers closed and the hand nearly still (``arrival_speed_m_s``), before the
time limit, without touching a tower's back panel (MuJoCo contact). Episodes end on success, on a
touch, or by the registered step limit.

The shelf clutter (``clutter``: 0-29, the default env has 29): distractors stand on that many of the
other 29 targets, drawn per episode after the scenario. Each is a cylinder of the object's size, seen by
the retina as a target of the object's kind, so that crowding (Bouma 1970; compulsory averaging, Parkes
et al. 2001) pools it with the object in the periphery; the observation still carries only the object's
sample (the agent knows which object it reaches for, as a person told to fetch "the red cup").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from visuomotor_gym.body import reach_names
from visuomotor_gym.body.reach_body import home_hand_position
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Many, Num, Pair
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import VisualTarget
from visuomotor_gym.vision import foveation

DEG = math.pi / 180.0


# What each ShelfLayout field accepts (visuomotor_gym.core.args.check_fields): modelling choices around the
# layout of envs_assets/reach.xml (azimuths within a turn, targets within the seated reach's 1.5 m).
SHELF_RULES = {
    "tower_azimuth_deg": Many(3, Num(-180.0, 180.0)),
    "depth_m": Pair(Num(0.1, 1.5), strict=True),
    "level0_z_m": Num(0.0, 2.0),
    "level_step_m": Num(0.0, 0.5, low_open=True),
    "object_radius_m": Num(0.0, 0.2, low_open=True),
    "object_half_height_m": Num(0.0, 0.3, low_open=True),
    "panel_gap_m": Num(0.0, 1.0),
}


@dataclass(frozen=True)
class ShelfLayout:
    """The 30 targets, world frame (x forward, y left, z up; the seat axis is x = y = 0). ``envs_assets/reach.xml``
    is built from these numbers (a test compares them)."""

    # Faraway et al. (2007), Sec. 2: towers "in front of the subject, to the right-hand side and 45 deg to the
    # right" (sourced); azimuth measured about the body's vertical (seat) axis, negative = to the right.
    tower_azimuth_deg: tuple[float, float, float] = (0.0, -45.0, -90.0)
    # Horizontal distance of the object centres from the seat axis, near and far (modelling choice: the
    # seated arm reaches both with the torso's help; the median reach, 0.53 m, is near the paper's 56.7 cm).
    depth_m: tuple[float, float] = (0.50, 0.65)
    # Object-centre heights: 5 levels from seat height (0.55 m) to 0.18 m above the seated eye (1.13 m),
    # the seated analogue of the paper's "five levels ranging from eye to ankle level" (modelling choice).
    level0_z_m: float = 0.55
    level_step_m: float = 0.19
    # The object: "a vertical cylinder", as the paper's subjects moved; size modelling choice.
    object_radius_m: float = 0.03
    object_half_height_m: float = 0.06
    # Back panel of each tower, this far behind the far depth (modelling choice: ~7 cm of room for the palm,
    # which extends 5 cm past the catch site along the forearm).
    panel_gap_m: float = 0.12

    def __post_init__(self) -> None:
        args.check_fields(self, SHELF_RULES)

    def targets(self) -> np.ndarray:
        """(30, 3) object-centre positions, in the order tower, level, depth (near first)."""
        out = []
        for az in self.tower_azimuth_deg:
            c, s = math.cos(az * DEG), math.sin(az * DEG)
            for k in range(reach_names.LEVELS):
                for r in self.depth_m:
                    out.append((r * c, r * s, self.level0_z_m + k * self.level_step_m))
        return np.array(out)

    @staticmethod
    def describe(index: int) -> tuple[int, int, int]:
        """(tower, level, depth) of a target index."""
        tower, rest = divmod(int(index), reach_names.LEVELS * 2)
        level, depth = divmod(rest, 2)
        return tower, level, depth


SHELF_LAYOUT = ShelfLayout()
N_TARGETS = 30
TARGET_JITTER_M = 0.01  # uniform +-1 cm in x and y on the board (modelling choice: "small jitter")
GAZE_JITTER_DEG = 2.0  # Gaussian jitter of the initial gaze (as the catch family's start, modelling choice)

OBJECT_PERCEPT_BLOCKS = (
    Block("object_pos", 3, "m", "perceived object position, eye frame at the sample (zeros when not visible)"),
    Block("object_visible", 1, "0/1", "1 if this step produced a visual sample of the object"),
    Block("object_age", 1, "s", "age of the visual sample (the visual latency; 0 without delay)"),
)
TIME_BLOCK = Block("time", 1, "s", "time since the episode started")
REWARD_TERMS = ("reach", "panel_hit", "approach", "foveation", "effort")
SPARSE_WEIGHTS = {"reach": 1.0}
SHAPED_WEIGHTS = {"reach": 1.0, "panel_hit": -0.2, "approach": -0.01, "foveation": 0.005, "effort": -0.001}
FOVEATION_WIDTH_DEG = 5.0  # as the catch family's shaping term


class ShelfObject(VisualTarget):
    """A still mocap body on the shelves (velocity zero): the object (``body_name`` ``reach_names.OBJECT``,
    shown from the start) or one distractor of the shelf clutter (a body of the object's size and kind, so
    crowding pools it with the object: modelling choice; ``hidden``, parked below the floor, until
    :meth:`place` stands it on a target)."""

    def __init__(self, model: mujoco.MjModel, body_name: str = reach_names.OBJECT, name: str = "object",
                 hidden: bool = False) -> None:
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body_name)
        self.name = name
        self.mocap = int(model.body_mocapid[body])
        self.hidden = hidden
        self._zero = np.zeros(3)

    def state(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        return data.mocap_pos[self.mocap], self._zero

    def place(self, data: mujoco.MjData, position) -> None:
        data.mocap_pos[self.mocap] = position
        self.hidden = False


class ReachTask(Task):
    """Targets, contacts, success and rewards of the shelf-reach task (``body``: a reach body)."""

    trace_step_fields = ()
    trace_flag_fields = ("object_visible",)

    def __init__(self, model: mujoco.MjModel, body, *, reach_radius: float, grasp_closed_fraction: float,
                 arrival_speed_m_s: float, reward_weights: dict, dt: float, visual_delay_s: float,
                 clutter: int = 0) -> None:
        self.model = model
        self.body = body
        self.reach_radius = reach_radius
        self.grasp_closed_fraction = grasp_closed_fraction
        self.arrival_speed = arrival_speed_m_s
        self.reward_weights = reward_weights
        self.dt = dt
        self.visual_delay_s = visual_delay_s
        self.object = ShelfObject(model)
        # The clutter's distractors follow the object in the retina's target list (the observation reads
        # only the first sample, the object's); the unused mocap bodies stay parked below the floor.
        self.clutter = args.integer(clutter, "clutter", low=0, high=reach_names.N_DISTRACTORS)
        self.distractors = [ShelfObject(model, b, f"distractor_{i:02d}", hidden=True)
                            for i, b in enumerate(reach_names.DISTRACTORS[: self.clutter])]
        self.targets = [self.object, *self.distractors]
        self.distractor_indices: tuple[int, ...] = ()
        self.positions = SHELF_LAYOUT.targets()
        self.home = home_hand_position(model)
        self._panels = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in reach_names.PANELS}
        # The initial gaze point: the front tower's middle level, between its depths (modelling choice).
        self._gaze_point = np.array([np.mean(SHELF_LAYOUT.depth_m), 0.0, SHELF_LAYOUT.level0_z_m + 2 * SHELF_LAYOUT.level_step_m])
        self.leading_blocks = OBJECT_PERCEPT_BLOCKS
        self.trailing_blocks = (TIME_BLOCK,)
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.success = False
        self.hit = False
        self.hit_geoms: tuple[str, str] | None = None
        self.visible = False
        self._hand_prev = None

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the target (index, jitter) and the initial gaze jitter, in that order, from ``rng``; then,
        with clutter, which of the other targets hold a distractor (one ``rng.integers`` seeding a generator
        of its own: the scenario above is the former scene's for the same seed)."""
        self.target_index = int(rng.integers(N_TARGETS))
        jitter = rng.uniform(-TARGET_JITTER_M, TARGET_JITTER_M, 2)
        self.gaze_offset = rng.normal(0.0, GAZE_JITTER_DEG * DEG, 2)
        pos = self.positions[self.target_index].copy()
        pos[:2] += jitter
        self.object_pos = pos
        self.object.place(data, pos)
        self.place_clutter(data, rng)

    def place_clutter(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Stand the distractors on ``clutter`` of the other targets (uniformly, without replacement), at
        the targets' centres (no jitter: modelling choice). Draws nothing without clutter."""
        if not self.clutter:
            return
        g = np.random.default_rng(int(rng.integers(2**31)))
        others = [i for i in range(N_TARGETS) if i != self.target_index]
        chosen = g.choice(others, self.clutter, replace=False)
        self.distractor_indices = tuple(int(k) for k in chosen)
        for d, k in zip(self.distractors, self.distractor_indices):
            d.place(data, self.positions[k])

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        return self._gaze_point, (float(self.gaze_offset[0]), float(self.gaze_offset[1]))

    def reset_info(self) -> dict:
        tower, level, depth = ShelfLayout.describe(self.target_index)
        return {"target_index": self.target_index, "tower": tower, "level": level, "depth": depth,
                "object_pos": self.object_pos.copy(), "hand_home": self.home.copy(),
                "distractor_indices": self.distractor_indices}

    # --- what the evaluator records ----------------------------------------------------------
    def trace_episode_fields(self) -> dict:
        return {"object_pos": self.object_pos.copy(), "target_index": self.target_index,
                "hand_home": self.home.copy()}

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"panel_hit": bool(info["panel_hit"])}

    # --- physics ------------------------------------------------------------------------------
    def before_physics(self, data: mujoco.MjData) -> None:
        self._hand_prev = self.body.hand_pos(data).copy()

    def needs_substep_checks(self, data: mujoco.MjData) -> bool:
        """Touches are checked after every physics substep (a brush may last less than a control step)."""
        return not (self.hit or self.success)

    def check_substep(self, data: mujoco.MjData) -> bool:
        """True on the first contact between the body and a back panel (the only contacts the scene has)."""
        if self.hit:
            return True
        d = data
        for i in range(d.ncon):
            c = d.contact[i]
            if c.geom1 in self._panels or c.geom2 in self._panels:
                self.hit = True
                m = self.model
                self.hit_geoms = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, c.geom1),
                                  mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, c.geom2))
                return True
        return False

    # --- observation --------------------------------------------------------------------------
    def observe_leading(self, values: list, samples: list) -> None:
        pos, _vel, visible = samples[0]
        self.visible = visible
        values += pos
        values += (1.0 if visible else 0.0, self.visual_delay_s)

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        values.append(data.time)

    # --- outcome ------------------------------------------------------------------------------
    def _reached(self, d: mujoco.MjData) -> bool:
        hand = self.body.hand_pos(d)
        if float(np.linalg.norm(hand - self.object_pos)) > self.reach_radius:
            return False
        if not self.body.grasp_closed(d, self.grasp_closed_fraction):
            return False
        prev = hand if self._hand_prev is None else self._hand_prev
        return float(np.linalg.norm(hand - prev)) / self.dt <= self.arrival_speed

    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        d = data
        hit = bool(fired or self.hit)
        reached = (not hit) and self._reached(d)
        self.success = reached
        w = self.reward_weights
        terms = {}
        if w.get("reach"):
            terms["reach"] = w["reach"] * float(reached)
        if w.get("panel_hit"):
            terms["panel_hit"] = w["panel_hit"] * float(hit)
        if w.get("approach"):
            terms["approach"] = w["approach"] * float(np.linalg.norm(self.body.hand_pos(d) - self.object_pos))
        if w.get("foveation"):
            ecc = foveation.eccentricity(eye.to_eye(self.object_pos, np.zeros(3))[0]) if self.visible else None
            terms["foveation"] = 0.0 if ecc is None else w["foveation"] * math.exp(-(ecc / (FOVEATION_WIDTH_DEG * DEG)) ** 2)
        if w.get("effort"):
            terms["effort"] = w["effort"] * float(a @ a) / a.size
        reward = float(sum(terms.values()))
        return reward, terms, reached or hit, self.info(d, reached=reached, hit=hit)

    def info(self, data: mujoco.MjData, *, reached: bool = False, hit: bool = False, diverged: bool = False) -> dict:
        """Task information; the object's true position is for scoring only, never for a policy."""
        return {
            "reached": reached,
            "panel_hit": hit,
            "object_visible": False if diverged else bool(self.visible),
            "object_pos": self.object_pos.copy(),
            "hand_object_distance": float(np.linalg.norm(self.body.hand_pos(data) - self.object_pos)),
        }
