"""The stepping-stones task (Eom, Han, Shin & Noh 2019, Sec. 7, "Walking on stepping stones"): cross a gap on
a path of stones seen only through the foveated eye; a foot that lands off every support ends the episode.

**Course** (:func:`sample_course`, drawn first from the env's ``np_random`` so every rung of the ladder
gets the same course for a seed): the walker starts on a slab (``envs_assets/stones.xml``) whose far
edge lies 2.3 m ahead of its first heel strike; ``n_stones`` stones follow, each ``spacing_m`` from the
previous one (0.65-0.85 m, ALLSTEPS: Xie et al. 2020, REFERENCES.md) in a direction that turns by up to
``heading_change_deg`` (+-30 deg, ALLSTEPS) from the previous step's, so the path curves. The first
stone is spaced from the nominal centre of the walker's last foot on the slab. The walker turns (the
gait of :mod:`visuomotor_gym.body.walker` gives each footstep a heading, :class:`TurningGait`, turning
by up to ``GaitParams.max_turn_deg`` = 45 deg a step), so the path's direction may drift up to
``max_heading_deg`` = +-60 deg from the slab's axis (modelling choice: three times the +-20 deg of the
walker that could not turn, and short of +-90 deg, so the path always leads away from the slab). Every
course is *steppable*: a sequence of footholds exists with alternating feet, each foot's centre on its
stone's centre, each step's heading within ``max_turn_deg - turn_slack_deg`` of the previous one's and
its lateral width inside the gait's range less ``lateral_slack_m`` (interval propagation over the
footsteps' headings; a draw that breaks it is redrawn). The slacks are modelling choices (stated with
each constant).

**Supports and falls.** The slab and the stones are MuJoCo geoms that sense the feet without pushing
(``stones.xml``). When a foot is flat after its heel strike (the end of double support), it must touch a
support (a contact in ``data.contact``) with its midfoot (the centre of the foot's box) over that
support's top (within the stone's radius): otherwise it stands over the gap, the walker **falls** and
the episode ends. Landing on the last stone is **success**. Stones may be skipped.

**What the eye sees of a stone**: the centre of its top face (:class:`~visuomotor_gym.core.retina.PointTarget`;
the radius, 0.25 m, is the same for every stone and part of the task's description). The observation
holds the percepts of the ``K_SLOTS`` = 4 next stones (slot ``k`` = stone ``n + k``, ``n`` the first
stone no foot has landed on yet): when the footstep onto stone ``n + 1`` is chosen (its mid-stance
read) the slots reach two stones beyond it, as the walker must see >= 2 steps ahead (Matthis & Fajen
2014) and ALLSTEPS' policy sees the next 2 targets. A stone not seen this step reads as zeros.

**Rough terrain (the default since the moving-eye redefinition)**: the course keeps ALLSTEPS' path
(its draws come first, so ``course_distribution="allsteps"``, the first definition's course, has the same
path for the same seed) and adds what makes footholds hard to localise without looking at them: smaller
stones (``stone_radius_m``) and, beside each stone, ``hazards_per_stone`` *hazards* (loose rocks:
:func:`sample_hazards`; the scene ``stones_rough.xml``) that never hold a foot (a foot on one stands over
the gap and falls). Hazards are seen as the stones are (the centre of the top,
:class:`~visuomotor_gym.core.retina.PointTarget` of the same kind, so with ``VisionParams.crowding`` a
stone seen in the periphery is pooled with them) while the stone they flank is in a slot; they never
appear in the observation's slots, which hold the stones only. :data:`COURSE_PRESETS` names both courses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Int, Num, Optional, Pair
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import PointTarget

STONES_SCENE = "stones.xml"
ROUGH_SCENE = "stones_rough.xml"  # stones.xml plus HAZARD_POOL hazards (the "rough" preset)
STONE_POOL = 16  # stone bodies in stones.xml (>= n_stones)
STONE_NAMES = tuple(f"stone_{i:02d}" for i in range(STONE_POOL))  # mocap bodies and their cylinder geoms
HAZARD_POOL = 32  # hazard bodies in stones_rough.xml (>= n_stones * hazards_per_stone)
HAZARD_NAMES = tuple(f"hazard_{i:02d}" for i in range(HAZARD_POOL))
# Tries to place one hazard clear of every stone and hazard before it is left out (modelling choice).
HAZARD_TRIES = 50
SLAB = "start_slab"
STONES_SCENE_CAMERA = "stones_scene"
STONE_TOP_Z = -0.005  # stones.xml: tops 5 mm below the soles' planned height (sensing, not pushing)
K_SLOTS = 4
# A steppable step leaves at least this much freedom (rad, ~1 deg) in its heading (modelling choice: a
# course steppable only through a sliver of headings would ask the agent for sub-degree precision).
MIN_HEADING_FREEDOM = math.radians(1.0)
FOOT_CENTRE_AHEAD_M = 0.07  # walker_body.xml: the foot box's centre is 7 cm ahead of the ankle (the foothold)
STONE_RADIUS_M = 0.25  # stones.xml's stones (ALLSTEPS, Xie et al. 2020); the task reads it from the model
SLAB_FAR_EDGE_M = 2.3  # stones.xml: the slab's far edge (x), 2.3 m ahead of the first heel strike
HAZARD_RGBA = (0.42, 0.30, 0.24, 1.0)
REWARD_TERMS = ("finish", "fall", "stone", "progress")
DEFAULT_REWARD_WEIGHTS = {"finish": 1.0, "fall": -1.0, "stone": 0.0, "progress": 0.0}
LAST_STONE_RGBA = (0.20, 0.65, 0.30, 1.0)
STONE_RGBA = (0.62, 0.60, 0.55, 1.0)


# What each CourseDistribution field accepts (visuomotor_gym.core.args.check_fields): modelling choices
# around the defaults; ``n_stones`` is bounded by the stones of the scene (STONE_POOL), turns stay short
# of 90 deg. Whether the gait can step from stone to stone at all is checked with the gait's parameters
# (check_steppable).
STONES_RULES = {
    "n_stones": Int(1, STONE_POOL),
    "spacing_m": Pair(Num(0.1, 2.0)),
    "heading_change_deg": Num(0.0, 89.0),
    "max_heading_deg": Num(0.0, 89.0),
    "lateral_slack_m": Num(0.0, 0.3),
    "turn_slack_deg": Num(0.0, 45.0),
    "start_foot_x_m": Num(0.0, 10.0),
    "start_foot_y_m": Num(-1.0, 1.0),
    "stone_radius_m": Optional(Num(0.08, 0.25)),
    "hazards_per_stone": Int(0, 4),
    "hazard_radius_m": Num(0.05, 0.25),
    "hazard_distance_m": Pair(Num(0.1, 1.5)),
    "hazard_clearance_m": Num(0.0, 0.5),
}


@dataclass(frozen=True)
class CourseDistribution:
    """The course sampler's parameters (metres, degrees; uniform draws). Sources in the module docstring."""

    n_stones: int = 14  # modelling choice: ~10 m of stones, 7 s of walking at 2 steps/s
    spacing_m: tuple[float, float] = (0.65, 0.85)  # ALLSTEPS (Xie et al. 2020): centre-to-centre distance
    heading_change_deg: float = 30.0  # ALLSTEPS: the path turns by up to +-30 deg from one step to the next
    # Modelling choice: the path's direction stays within +-60 deg of the slab's axis (it leads away from
    # the slab; three times the +-20 deg of the first version, whose walker could not turn).
    max_heading_deg: float = 60.0
    lateral_slack_m: float = 0.03  # modelling choice: the gait's step widths, less 3 cm at each end
    turn_slack_deg: float = 5.0  # modelling choice: a steppable course needs turns 5 deg short of the gait's limit
    start_foot_x_m: float = 1.95 + FOOT_CENTRE_AHEAD_M  # nominal foot centre of the last foothold on the slab
    start_foot_y_m: float = -0.06  # ... (the right foot, half the 0.12 m nominal step width to the right)
    # --- the rough terrain (COURSE_PRESETS: the default; "allsteps" sets stone_radius_m=None and
    # hazards_per_stone=0, ALLSTEPS' course of the first definition) ---
    # Radius of every stone (m); None: the scene's 0.25 m (ALLSTEPS). 0.15 m: modelling choice (a 30 cm
    # stone, the midfoot must land within 15 cm of its centre).
    stone_radius_m: float | None = 0.15
    # Hazards (loose rocks that do not hold a foot: a foot landing on one falls) drawn beside each stone;
    # 0: none, and the plain scene (stones.xml) without them. 2: modelling choice (see COURSE_PRESETS).
    hazards_per_stone: int = 2
    hazard_radius_m: float = 0.12  # radius of a hazard (used only with hazards)
    hazard_distance_m: tuple[float, float] = (0.32, 0.45)  # centre of a hazard from its stone's centre (modelling choice)
    hazard_clearance_m: float = 0.05  # the least gap between a hazard's rim and any stone's or hazard's rim

    def __post_init__(self) -> None:
        args.check_fields(self, STONES_RULES)
        if self.n_stones * self.hazards_per_stone > HAZARD_POOL:
            raise ValueError(f"course_distribution.hazards_per_stone * n_stones must be <= {HAZARD_POOL} (the "
                             f"hazards of {ROUGH_SCENE}); got {self.hazards_per_stone} * {self.n_stones}")

    @property
    def scene(self) -> str:
        """The scene file this distribution needs: ``stones_rough.xml`` with hazards, else ``stones.xml``."""
        return ROUGH_SCENE if self.hazards_per_stone else STONES_SCENE


# The course presets (``SteppingStonesEnv(course_distribution="rough")``). "rough", the default (its
# measurements in docs/reproductions/data/terrain/stepping_stones.md): footholds that must be located
# precisely and early, among clutter where crowding acts. Stones of radius 0.15 m (modelling choice: a
# 30 cm stone, the midfoot must land within 15 cm of its centre, where ALLSTEPS' 0.25 m stones leave 25 cm),
# the path as ALLSTEPS draws it (spacing 0.65-0.85 m, turns up to +-30 deg per step), and beside each stone
# two hazards (loose rocks, radius 0.12 m, 0.32-0.45 m from the stone's centre, at least 5 cm rim to rim
# from any other rock: modelling choices). A hazard is a flanker of the stone's own kind: seen more than
# about twice its angular distance from the line of sight (Bouma's critical spacing, b = 0.5), the stone
# is pooled with it (crowding, VisionParams.crowding): its perceived centre is the mean of the stone and
# its crowding flankers, 16-22 cm toward a lone hazard (half their distance), beyond what the stone's radius
# forgives (two hazards on opposite sides partly cancel). "allsteps": the first definition's course,
# ALLSTEPS' stones of 0.25 m and no hazards (a course one body-locked posture could cross: 79.5 % for the
# best static twin of lookahead on the pinned seeds under the 20 deg cone).
ROUGH_FIELDS = ("stone_radius_m", "hazards_per_stone", "hazard_radius_m", "hazard_distance_m", "hazard_clearance_m")
COURSE_PRESETS = {
    "rough": {f: getattr(CourseDistribution(), f) for f in ROUGH_FIELDS},  # the defaults above
    "allsteps": {"stone_radius_m": None, "hazards_per_stone": 0},
}


def course_preset(name: str) -> CourseDistribution:
    """The :class:`CourseDistribution` of a named preset (:data:`COURSE_PRESETS`)."""
    if name not in COURSE_PRESETS:
        raise ValueError(f"course_distribution={name!r} is not a preset; allowed: {sorted(COURSE_PRESETS)} "
                         "(or a CourseDistribution, a dict of its fields, or None)")
    return CourseDistribution(**COURSE_PRESETS[name])


@dataclass(frozen=True)
class Course:
    stones: np.ndarray  # (N, 2): centre x, y of each stone's top (world, the walker starts at the origin)
    headings: np.ndarray  # (N,): direction (rad) from the previous stone (stone 0: from the last slab foot)
    # (M, 2): centre x, y of each hazard ("rough" terrain; none by default) and (M,): the stone it flanks
    hazards: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    hazard_of: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


def sample_course(rng: np.random.Generator, dist: CourseDistribution, lateral_range: tuple[float, float],
                  step_width: tuple[float, float], max_turn_deg: float) -> Course:
    """One steppable course. ``lateral_range``, ``step_width`` = (nominal, minimum) and ``max_turn_deg``
    come from the gait's parameters: a footstep's heading turns by at most ``max_turn_deg`` from the
    previous foothold's, and in its own heading's frame a left foot lands ``max(nominal + lateral,
    minimum)`` left of the right foot."""
    nominal, minimum = step_width
    w_lo = max(nominal + lateral_range[0], minimum) + dist.lateral_slack_m  # narrowest step
    w_hi = nominal + lateral_range[1] - dist.lateral_slack_m  # widest
    turn, cap = math.radians(dist.heading_change_deg), math.radians(dist.max_heading_deg)
    max_turn = math.radians(max_turn_deg - dist.turn_slack_deg)
    x, y, psi = dist.start_foot_x_m, dist.start_foot_y_m, 0.0
    a, b = 0.0, 0.0  # the headings the previous foothold can have (the last slab foot: straight on)
    rows, heads = [], []
    for k in range(dist.n_stones):
        sign = 1.0 if k % 2 == 0 else -1.0  # stone 0 takes foothold 4, a left foot
        for _ in range(100):
            new_psi = min(max(psi + float(rng.uniform(-turn, turn)), -cap), cap)
            s = float(rng.uniform(*dist.spacing_m))
            # Headings h whose frame puts this step at a width w in [w_lo, w_hi] to the foot's side:
            # the step's direction less sign * asin(w / s).
            lo_h = new_psi - sign * math.asin(w_hi / s) if sign > 0 else new_psi + math.asin(w_lo / s)
            hi_h = new_psi - sign * math.asin(w_lo / s) if sign > 0 else new_psi + math.asin(w_hi / s)
            na, nb = max(lo_h, a - max_turn), min(hi_h, b + max_turn)
            if na + MIN_HEADING_FREEDOM <= nb:
                break
        else:  # no draw was steppable (never seen with the defaults): the step straight along a heading reachable from the last
            h = min(max(psi, a - max_turn), b + max_turn)
            new_psi = h + sign * math.asin(nominal / s)
            na = nb = h
        a, b = na, nb
        nx, ny = x + s * math.cos(new_psi), y + s * math.sin(new_psi)
        rows.append((nx, ny))
        heads.append(new_psi)
        x, y, psi = nx, ny, new_psi
    stones = np.array(rows, dtype=float).reshape(-1, 2)
    if not dist.hazards_per_stone:  # the default course: no further draw
        return Course(stones, np.array(heads, dtype=float))
    hazards, owner = sample_hazards(rng, dist, stones)
    return Course(stones, np.array(heads, dtype=float), hazards, owner)


def sample_hazards(rng: np.random.Generator, dist: CourseDistribution, stones: np.ndarray,
                   stone_radius: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``dist.hazards_per_stone`` hazards beside each stone, in stone order: a direction uniform round the
    stone and a centre distance uniform in ``hazard_distance_m``, redrawn (up to :data:`HAZARD_TRIES`
    times, else left out) until its rim clears every stone's and every earlier hazard's rim by
    ``hazard_clearance_m`` and its rim lies beyond the slab's far edge (x - radius > 2.3 m, so no foot on
    the slab stands beside one). Returns the (M, 2) centres and the (M,) index of the stone each flanks."""
    r_s = dist.stone_radius_m if stone_radius is None else stone_radius
    r_s = STONE_RADIUS_M if r_s is None else r_s
    r_h, gap = dist.hazard_radius_m, dist.hazard_clearance_m
    placed: list[tuple[float, float]] = []
    owner: list[int] = []
    for i, (cx, cy) in enumerate(stones.tolist()):
        for _ in range(dist.hazards_per_stone):
            for _ in range(HAZARD_TRIES):
                a = float(rng.uniform(-math.pi, math.pi))
                r = float(rng.uniform(*dist.hazard_distance_m))
                hx, hy = cx + r * math.cos(a), cy + r * math.sin(a)
                if hx - r_h <= SLAB_FAR_EDGE_M:
                    continue
                if any((hx - sx) ** 2 + (hy - sy) ** 2 < (r_s + r_h + gap) ** 2 for sx, sy in stones.tolist()):
                    continue
                if any((hx - px) ** 2 + (hy - py) ** 2 < (2.0 * r_h + gap) ** 2 for px, py in placed):
                    continue
                placed.append((hx, hy))
                owner.append(i)
                break
    return np.array(placed, dtype=float).reshape(-1, 2), np.array(owner, dtype=int)


def check_steppable(dist: CourseDistribution, gait) -> None:
    """Refuse a course distribution the gait (``GaitParams``) cannot step: the shortest spacing must exceed
    the widest step width it allows (:func:`sample_course` takes ``asin(width / spacing)``)."""
    w_hi = gait.step_width_m + gait.lateral_range_m[1] - dist.lateral_slack_m
    if not dist.spacing_m[0] > w_hi:
        raise ValueError(f"course_distribution.spacing_m must start above the widest step the gait allows "
                         f"(gait_params.step_width_m + lateral_range_m[1] - course_distribution.lateral_slack_m "
                         f"= {w_hi:g} m); got {dist.spacing_m!r}")


def stone_block(k: int) -> Block:
    return Block(f"stone_{k}", 5, "-, m, 0/1",
                 f"slot {k}: course index of the stone ({k} after the first one not yet stepped on); perceived "
                 "centre of its top, eye frame (zeros when not seen); seen flag")


PERCEPT_BLOCKS = tuple(stone_block(k) for k in range(K_SLOTS))
TRAILING_BLOCKS = (
    Block("odometry", 3, "m, m, rad", "pelvis x, y and heading relative to the start (path integration)"),
    Block("stones_left", 1, "-", "stones not yet stepped on up to and including the last one"),
    Block("time", 1, "s", "time since the start"),
)


class SteppingStonesTask(Task):
    """Course, visual targets, landings, rewards and info of SteppingStones. ``body`` is a
    :class:`~visuomotor_gym.body.walker_body.WalkerBody` on ``stones.xml``. No substep checks (the
    :class:`~visuomotor_gym.core.parts.Task` default): landings are checked once per control step, since
    they fall on control-step boundaries."""

    leading_blocks = PERCEPT_BLOCKS
    trailing_blocks = TRAILING_BLOCKS
    trace_step_fields = ("step_phase", "next_stone")
    trace_flag_fields = ("stone_seen",)

    def __init__(self, model: mujoco.MjModel, body, *, course_distribution: CourseDistribution,
                 reward_weights: dict) -> None:
        m = self.model = model
        self.body = body
        self.gait = body.gait
        self.dist = course_distribution
        check_steppable(self.dist, self.gait.p)
        self.reward_weights = reward_weights
        self.geoms = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in STONE_NAMES]
        self.mocap = [int(m.body_mocapid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)]) for n in STONE_NAMES]
        self._park = [m.body_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)].copy() for n in STONE_NAMES]
        self.slab = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, SLAB)
        if min([*self.geoms, self.slab]) < 0:
            raise ValueError(f"the model lacks stones or the slab: is it envs_assets/{STONES_SCENE}?")
        if self.dist.stone_radius_m is not None:  # the course's own stones (the "rough" preset)
            for g in self.geoms:
                m.geom_size[g, 0] = self.dist.stone_radius_m
        self.radius = float(m.geom_size[self.geoms[0], 0])  # one source: the XML (0.25 m, ALLSTEPS)
        # The hazards ("rough" terrain): in stones_rough.xml only.
        self.hazard_geoms, self.hazard_mocap, self._hazard_park = [], [], []
        if self.dist.hazards_per_stone:
            for n in HAZARD_NAMES:
                g = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)
                if g < 0:
                    raise ValueError(f"the model lacks hazards: course_distribution.hazards_per_stone needs "
                                     f"envs_assets/{ROUGH_SCENE}")
                b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)
                m.geom_size[g, 0] = self.dist.hazard_radius_m
                self.hazard_geoms.append(g)
                self.hazard_mocap.append(int(m.body_mocapid[b]))
                self._hazard_park.append(m.body_pos[b].copy())
        half_height = float(m.geom_size[self.geoms[0], 1])
        self._stone_z = STONE_TOP_Z - half_height
        sx, sy = m.geom_pos[self.slab, :2]
        hx, hy = m.geom_size[self.slab, :2]
        self.slab_box = (float(sx - hx), float(sx + hx), float(sy - hy), float(sy + hy))
        self.support_of_geom = {g: i for i, g in enumerate(self.geoms)}
        self.support_of_geom[self.slab] = -1
        self.feet = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, wn.WALKER_LEG_GEOMS[s][2]) for s in (0, 1)]
        self.all_targets = [PointTarget(n) for n in STONE_NAMES]
        # Hazards are seen as the stones are (the centre of the top; the same kind, so they crowd them).
        self.hazard_targets = [PointTarget(n) for n in HAZARD_NAMES[:len(self.hazard_geoms)]]
        self.targets = self.all_targets
        self.course = Course(np.zeros((0, 2)), np.zeros(0))
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.success = self.fell = self.finished = False
        self.next_stone = 0
        self.landings: list[tuple[int, int, float]] = []  # (foothold, support: -1 slab / stone index, time)
        self._next_check = 0  # the next foothold whose landing is checked
        self._slots_for = -1
        self._prev_x = 0.0
        self.seen = [False] * K_SLOTS

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the course and place the stones (the walker already stands at the start)."""
        m, d, p = self.model, data, self.gait.p
        self.course = course = sample_course(rng, self.dist, p.lateral_range_m, (p.step_width_m, p.min_step_width_m),
                                             p.max_turn_deg)
        n = len(course.stones)
        for i, t in enumerate(self.all_targets):
            t.hidden = True
            d.mocap_pos[self.mocap[i]] = self._park[i]
        self.targets = self.all_targets[:n]
        for i, (x, y) in enumerate(course.stones.tolist()):
            d.mocap_pos[self.mocap[i]] = (x, y, self._stone_z)
            m.geom_rgba[self.geoms[i]] = LAST_STONE_RGBA if i == n - 1 else STONE_RGBA
            self.targets[i].place(x, y, STONE_TOP_Z)
        if self.hazard_geoms:  # after the stones in the target list: the observation's slots index the stones
            for k, t in enumerate(self.hazard_targets):
                t.hidden = True
                d.mocap_pos[self.hazard_mocap[k]] = self._hazard_park[k]
            for k, (x, y) in enumerate(course.hazards.tolist()):
                d.mocap_pos[self.hazard_mocap[k]] = (x, y, self._stone_z)
                m.geom_rgba[self.hazard_geoms[k]] = HAZARD_RGBA
                self.hazard_targets[k].place(x, y, STONE_TOP_Z)
            self.targets = self.targets + self.hazard_targets[:len(course.hazards)]
        self._prev_x = float(d.qpos[0])

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        """Gaze starts level, straight ahead along the slab's axis (as in ObstacleWalk)."""
        return np.array([20.0, 0.0, 1.6]), (0.0, 0.0)

    # --- what the evaluator records ----------------------------------------------------------
    def trace_episode_fields(self) -> dict:
        fields = {"stones": self.course.stones.copy(), "stone_radius": self.radius}
        if self.hazard_geoms:
            fields.update(hazards=self.course.hazards.copy(), hazard_of=self.course.hazard_of.copy(),
                          hazard_radius=self.dist.hazard_radius_m)
        return fields

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"fell": bool(info["fell"]), "finished": bool(info["finished"])}

    # --- physics ------------------------------------------------------------------------------
    # --- landings -----------------------------------------------------------------------------
    def support_under(self, data: mujoco.MjData, side: int) -> int | None:
        """The support (-1 slab, else stone index) that foot ``side`` stands on, or None over the gap:
        a contact with the support and the midfoot over its top."""
        foot = self.feet[side]
        geom = data.contact.geom
        mx, my = data.geom_xpos[foot, :2].tolist()
        for i in range(data.ncon):
            g1, g2 = int(geom[i, 0]), int(geom[i, 1])
            other = g2 if g1 == foot else g1 if g2 == foot else None
            s = self.support_of_geom.get(other) if other is not None else None
            if s is None:
                continue
            if s < 0:
                x0, x1, y0, y1 = self.slab_box
                if x0 <= mx <= x1 and y0 <= my <= y1:
                    return -1
            else:
                cx, cy = self.course.stones[s].tolist()
                if (mx - cx) ** 2 + (my - cy) ** 2 <= self.radius ** 2:
                    return s
        return None

    def _check_landings(self, data: mujoco.MjData) -> int:
        """Check every foothold flat by now (heel strike + double support); return stones newly landed."""
        g = self.gait
        new = 0
        while not self.fell and not self.finished and self._next_check * g.T + g.T_ds <= g.tick:
            j = self._next_check
            self._next_check += 1
            s = self.support_under(data, g.side_of(j))
            self.landings.append((j, -2 if s is None else s, float(data.time)))
            if s is None:
                self.fell = True
            elif s >= 0:
                new += 1
                self.next_stone = max(self.next_stone, s + 1)
                if s == len(self.course.stones) - 1:
                    self.finished = True
        return new

    # --- observation --------------------------------------------------------------------------
    def before_observe(self, data: mujoco.MjData) -> None:
        """Sample only the slots' stones (the others cannot reach the observation)."""
        if self._slots_for != self.next_stone:
            n = self.next_stone
            n_stones = len(self.course.stones)
            for i, t in enumerate(self.targets[:n_stones]):
                t.hidden = not (n <= i < n + K_SLOTS)
            # a hazard is sampled while the stone it flanks is in a slot (modelling choice: the clutter
            # around the footholds the observation reports; farther rocks could only add crowding)
            for t, i in zip(self.targets[n_stones:], self.course.hazard_of.tolist()):
                t.hidden = not (n <= i < n + K_SLOTS)
            self._slots_for = n

    def observe_leading(self, values: list, samples: list) -> None:
        n_targets = len(self.course.stones)  # the stones come first in the target list (hazards after them)
        for k in range(K_SLOTS):
            i = self.next_stone + k
            values.append(float(i))
            if i < n_targets:
                p, _, v = samples[i]
            else:
                p, v = [0.0, 0.0, 0.0], False
            values += p
            values.append(1.0 if v else 0.0)
            self.seen[k] = bool(v)

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        d = data
        sx, sy = self.body.start_xy
        values += (float(d.qpos[0]) - sx, float(d.qpos[1]) - sy, float(d.qpos[3]) - self.body.start_yaw,
                   float(len(self.course.stones) - self.next_stone), float(d.time))

    # --- outcome ------------------------------------------------------------------------------
    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        was_fallen = self.fell
        new = self._check_landings(data)
        self.success = self.finished and not self.fell
        x = float(data.qpos[0])
        values = {"finish": 1.0 if (self.finished and new) else 0.0, "fall": 1.0 if self.fell and not was_fallen else 0.0,
                  "stone": float(new), "progress": x - self._prev_x}
        self._prev_x = x
        terms = {k: w * values[k] for k, w in self.reward_weights.items() if w != 0.0}
        return float(sum(terms.values())), terms, self.fell or self.finished, self.info(data)

    def info(self, data: mujoco.MjData, *, diverged: bool = False) -> dict:
        """Step information (no stone position: the course is in ``reset_info``, for scoring only)."""
        return {
            "fell": self.fell,
            "finished": self.finished,
            "next_stone": self.next_stone,
            "stones_landed": sum(1 for _, s, _ in self.landings if s >= 0),
            "stone_seen": False if diverged else any(self.seen),
            "step_phase": self.gait.step_phase(),
        }


__all__ = ["COURSE_PRESETS", "K_SLOTS", "ROUGH_SCENE", "STONES_SCENE", "Course", "CourseDistribution", "SteppingStonesTask",
           "course_preset", "sample_course", "sample_hazards"]
