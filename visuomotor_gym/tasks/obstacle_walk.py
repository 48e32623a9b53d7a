"""The obstacle-walk task (Iwao et al.): walk a straight 15-20 m path across bars,
boxes and flat mats seen only through the foveated eye; a leg striking an obstacle is a trip (the end),
a foot landing on one a misstep (no success).

**Course** (:func:`sample_course`, drawn first from the env's ``np_random`` so every rung of the ladder
gets the same course for a seed): the path runs along +x from the walker's first heel strike at the
origin to a finish line 15-20 m ahead. Obstacles follow one another along it with free gaps of
1.6-3.0 m; each is a bar (5 cm deep, spanning the walkway: stepped over), a box (20-40 cm deep, 40-80 cm
wide: stepped over or around) or a flat mat (70 x 70 cm, 1 cm: Iwao's cloth, stepped around; landing on
it is a misstep), 5-30 cm high except the mats (modelling choice). Kinds, sizes and lateral offsets are
uniform draws (modelling choice).

**The walkway**: the path is a walkway ``walkway_width_m`` = 1.5 m wide (modelling choice: the passing
width of accessible routes, ADA 2010 Standards 403.5.3, 60 in), its edges painted on the floor. A foot
that lands outside it (sole centre beyond an edge at a foothold) ends the episode, *off path*, a failure.
Without it a walker could pass every obstacle metres to the side without ever looking (a PPO policy did:
docs/reproductions/ppo.md), and bars that span the walkway can only be stepped over.

**What the eye sees of an obstacle**: four points of its top face (:data:`TOP_POINTS`): the near-left
and far-right corners and the midpoints of the near and far edges
(:class:`~visuomotor_gym.core.retina.PointTarget`), each sampled by the retina like any target
(eccentricity-dependent noise, field of view, saccadic suppression, visual delay). For the axis-aligned
boxes of v0 the corners fix the footprint and the height; the edge midpoints fix the near and far edges
and the height where the eye looks at an obstacle too wide for both corners to fall in the field (a bar
across the 1.5 m walkway: its ends lie 20 deg off a gaze 2 m ahead on its middle, at the edge of the
20 deg field of the walker family): a human looking at the middle of a bar sees its edges there. The
observation holds the percepts of
the ``K_SLOTS`` = 4 next obstacles of the course (slot ``k`` = course obstacle ``n + k``, ``n`` the
number of obstacles the pelvis has passed by more than ``PASSED_M``): with free gaps >= 1.6 m four slots
reach >= 6 m ahead, more than the 2 steps (~1.3 m) that walkers need to see (Matthis & Fajen 2014) and
the 1-2 m of travel fixations (Patla & Vickers 1997). A point not seen this step reads as zeros.

**The rough course** (opt-in, ``course_distribution="rough"``: :data:`ROUGH_COURSE`): small
hazards strewn over the walkway so that nearly every foothold has to be chosen. Instead of a few
large bars and mats with 1.6-3 m between them, up to 16 (the scene's pool) small flat *patches* (a
foot must not land on them: misstep) and low *rocks* (a leg must not strike them: trip), 15-35 cm
across, follow one another every 0.5-0.9 m along the path (near edge to near edge: about one hazard
per 0.65 m step), each anywhere across the walkway (centre within 0.5 m of the centre line),
never overlapping. Humans on such ground look at the footholds 2-3 steps ahead, ~1.5 s before the foot
lands (Matthis, Yates & Hayhoe 2018, Curr Biol 28:1224); the sizes, spacings and the 4-12 cm rocks are
modelling choices (irregular footholds smaller than a step, a few of them within each step's reach;
ALLSTEPS, Xie et al. 2020, uses stones of 25-50 cm for its stepping-stone curricula). On this course
the slots carry no hidden truth: an obstacle is sampled by the eye only within ``sight_range_m`` of the
pelvis, its slot id is a *label* given in the order the eye first saw it (never a course index), and the
slots hold the labelled obstacles not yet passed, lowest label first: an obstacle that was never seen
takes no slot and changes no id when it is passed.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Choice, Num, Pair, Weights
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import PointTarget
from visuomotor_gym.tasks.walk_contacts import LegContacts
from visuomotor_gym.tasks.walk_scene import ObstaclePool

K_SLOTS = 4
# The seen points of an obstacle's top face, in the order of the observation (module docstring).
TOP_POINTS = ("near_left", "far_right", "near_mid", "far_mid")
N_POINTS = len(TOP_POINTS)
PASSED_M = 0.5  # an obstacle whose far edge is this far behind the pelvis leaves the slots (modelling choice)
# On the rough course an obstacle leaves the slots once its far edge is less than 0.3 m ahead of the pelvis
# (modelling choice: hazards come every ~0.7 m, so the four slots must reach beyond the next two footholds,
# ~1.3-2 m ahead; the hazard under the feet is behind the leading foot by then, and an agent keeps in its
# own memory what it saw of it).
ROUGH_PASSED_M = -0.3
KINDS = ("bar", "box", "mat")
BAR, BOX, MAT = 0, 1, 2
REWARD_TERMS = ("finish", "trip", "misstep", "off_path", "progress")
DEFAULT_REWARD_WEIGHTS = {"finish": 1.0, "trip": -1.0, "misstep": -1.0, "off_path": -1.0, "progress": 0.0}
LAYOUTS = ("walkway", "rough")  # CourseDistribution.layout: today's course, the rough one (module docstring)
OBSTACLE_RGBA = {BAR: (0.80, 0.25, 0.20, 1.0), BOX: (0.85, 0.55, 0.15, 1.0), MAT: (0.08, 0.08, 0.08, 1.0)}


# What each CourseDistribution field accepts (visuomotor_gym.core.args.check_fields): modelling choices,
# generous around the defaults (a course a walker can be put on: positive sizes, obstacles at most 1 m
# high, offsets within 2 m of the path's centre line).
COURSE_RULES = {
    "length_m": Pair(Num(1.0, 200.0)),
    "first_m": Pair(Num(0.0, 200.0)),
    "gap_m": Pair(Num(0.0, 50.0)),
    "finish_clear_m": Num(0.0, 200.0),
    "kind_p": Weights(3),
    "height_m": Pair(Num(0.0, 1.0, low_open=True)),
    "walkway_width_m": Num(0.0, 100.0, low_open=True),  # a test lifts the walkway with 40 m
    "bar_depth_m": Num(0.0, 2.0, low_open=True),
    "box_depth_m": Pair(Num(0.0, 2.0, low_open=True)),
    "box_width_m": Pair(Num(0.0, 5.0, low_open=True)),
    "mat_size_m": Num(0.0, 5.0, low_open=True),
    "mat_height_m": Num(0.0, 0.1, low_open=True),
    "offset_m": Pair(Num(-2.0, 2.0)),
    "mat_offset_m": Pair(Num(-2.0, 2.0)),
    "layout": Choice(LAYOUTS),
    "rough_step_m": Pair(Num(0.05, 10.0)),
    "rough_lateral_m": Pair(Num(-2.0, 2.0)),
    "rough_patch_m": Pair(Num(0.0, 5.0, low_open=True)),
    "sight_range_m": Num(0.5, 200.0),
}


@dataclass(frozen=True)
class CourseDistribution:
    """The course sampler's ranges (metres; uniform draws). Sources in the module docstring."""

    length_m: tuple[float, float] = (15.0, 20.0)  # a 15-20 m path (modelling choice)
    first_m: tuple[float, float] = (3.0, 4.5)  # near edge of the first obstacle (>= 2 s of approach at 1.3 m/s)
    gap_m: tuple[float, float] = (1.6, 3.0)  # free gap between consecutive obstacles (modelling choice)
    finish_clear_m: float = 1.5  # no obstacle within this distance of the finish (modelling choice)
    kind_p: tuple[float, float, float] = (0.4, 0.35, 0.25)  # bar, box, mat (modelling choice)
    height_m: tuple[float, float] = (0.05, 0.30)  # bars and boxes 5-30 cm high (modelling choice)
    walkway_width_m: float = 1.5  # see the module docstring (modelling choice); bars span it
    bar_depth_m: float = 0.05
    box_depth_m: tuple[float, float] = (0.2, 0.4)
    box_width_m: tuple[float, float] = (0.4, 0.8)
    mat_size_m: float = 0.7  # Iwao et al.: a 70 cm square black cloth
    mat_height_m: float = 0.01
    offset_m: tuple[float, float] = (-0.15, 0.15)  # boxes: centre beside the path's centre line
    mat_offset_m: tuple[float, float] = (-0.3, 0.3)
    # The rough course (module docstring; used only with layout="rough", see ROUGH_COURSE): hazards
    # follow one another every rough_step_m (near edge to near edge), their centres rough_lateral_m from
    # the centre line; patches rough_patch_m along and across (drawn apart: irregular); rocks are boxes
    # (box_depth_m, box_width_m, height_m); the eye samples obstacles within sight_range_m ahead.
    layout: str = "walkway"
    rough_step_m: tuple[float, float] = (0.5, 0.9)  # modelling choice: about one hazard per 0.65 m step
    rough_lateral_m: tuple[float, float] = (-0.5, 0.5)  # modelling choice: anywhere on the 1.5 m walkway
    rough_patch_m: tuple[float, float] = (0.2, 0.35)  # modelling choice: smaller than a step, ~a foot long
    sight_range_m: float = 5.0  # modelling choice: ~4 s of walking; beyond the 2-3 steps humans fixate

    def __post_init__(self) -> None:
        args.check_fields(self, COURSE_RULES)

    @property
    def rough(self) -> bool:
        return self.layout == "rough"


# The opt-in rough course (module docstring): 12-14 m, the first hazard 2.5-3.5 m ahead, no bars,
# rocks (40 %: 15-25 cm, 4-12 cm high) and patches (60 %: 20-35 cm, 1 cm high). Modelling choices; the
# density is the highest at which the iwao planner with true footprints (ObstacleWalkOracle-v0) still
# crosses nearly every course (docs/reproductions/data/terrain/obstacle_walk.md).
ROUGH_COURSE = CourseDistribution(layout="rough", length_m=(12.0, 14.0), first_m=(2.5, 3.5), finish_clear_m=1.0,
                                  kind_p=(0.0, 0.4, 0.6), height_m=(0.04, 0.12), box_depth_m=(0.15, 0.25),
                                  box_width_m=(0.15, 0.25))
# The denser rough course (opt-in, preset "rough_dense"): ROUGH_COURSE with hazards every 0.45-0.8 m
# (near edge to near edge) instead of 0.5-0.9 m: narrower safe gaps between them, about 1.1 hazards per
# 0.65 m step (modelling choice; 0.4-0.7 m was tried: iwao with true footprints still crossed 40/40 of
# seeds 0-39, but the foveated iwao fell to 26/40 under the human periphery with disarray). The scene's
# pool of 16 obstacles ends a quarter of these courses early (seeds 0-199: 26 %, the last hazard then
# up to 1.25 m before the finish's clear zone). docs/reproductions/data/terrain/obstacle_walk.md.
DENSE_ROUGH_COURSE = replace(ROUGH_COURSE, rough_step_m=(0.45, 0.8))
COURSE_PRESETS = {"walkway": CourseDistribution(), "rough": ROUGH_COURSE, "rough_dense": DENSE_ROUGH_COURSE}


@dataclass(frozen=True)
class Course:
    length: float
    obstacles: np.ndarray  # (N, 6): centre x, centre y, depth (along x), width, height, kind


def sample_course(rng: np.random.Generator, dist: CourseDistribution, max_obstacles: int) -> Course:
    """One course: obstacles in path order, free gaps between them, none near the finish."""
    if not dist.walkway_width_m > 0.0:
        raise ValueError(f"course_distribution.walkway_width_m must be > 0 m, got {dist.walkway_width_m!r}")
    if dist.rough:
        return _sample_rough(rng, dist, max_obstacles)
    length = float(rng.uniform(*dist.length_m))
    rows = []
    near = float(rng.uniform(*dist.first_m))
    while len(rows) < max_obstacles:
        kind = int(rng.choice(3, p=np.asarray(dist.kind_p) / sum(dist.kind_p)))
        if kind == BAR:
            depth, width, height = dist.bar_depth_m, dist.walkway_width_m, float(rng.uniform(*dist.height_m))
            y = 0.0
        elif kind == BOX:
            depth, width = float(rng.uniform(*dist.box_depth_m)), float(rng.uniform(*dist.box_width_m))
            height, y = float(rng.uniform(*dist.height_m)), float(rng.uniform(*dist.offset_m))
        else:
            depth = width = dist.mat_size_m
            height, y = dist.mat_height_m, float(rng.uniform(*dist.mat_offset_m))
        if near + depth > length - dist.finish_clear_m:
            break
        rows.append((near + 0.5 * depth, y, depth, width, height, kind))
        near += depth + float(rng.uniform(*dist.gap_m))
    return Course(length, np.array(rows, dtype=float).reshape(-1, 6))


ROUGH_TRIES = 6  # lateral draws before a hazard that overlaps another is moved along the path
ROUGH_CLEAR_M = 0.05  # free space kept between two hazards' footprints (modelling choice)


def _sample_rough(rng: np.random.Generator, dist: CourseDistribution, max_obstacles: int) -> Course:
    """The rough course (module docstring): hazards every ``rough_step_m`` along the path, each at a
    lateral offset drawn until its footprint keeps ``ROUGH_CLEAR_M`` from every earlier one (after
    ``ROUGH_TRIES`` draws it moves on along the path, past the far edge of the hazards it overlaps)."""
    length = float(rng.uniform(*dist.length_m))
    rows: list[tuple] = []
    near = float(rng.uniform(*dist.first_m))
    w = np.asarray(dist.kind_p, dtype=float)
    while len(rows) < max_obstacles:
        kind = int(rng.choice(3, p=w / w.sum()))
        if kind == MAT:
            depth, width = float(rng.uniform(*dist.rough_patch_m)), float(rng.uniform(*dist.rough_patch_m))
            height = dist.mat_height_m
        elif kind == BOX:
            depth, width = float(rng.uniform(*dist.box_depth_m)), float(rng.uniform(*dist.box_width_m))
            height = float(rng.uniform(*dist.height_m))
        else:  # a bar across the walkway
            depth, width, height = dist.bar_depth_m, dist.walkway_width_m, float(rng.uniform(*dist.height_m))
        for _ in range(ROUGH_TRIES):
            y = 0.0 if kind == BAR else float(rng.uniform(*dist.rough_lateral_m))
            hit = [r for r in rows if _overlap(near, depth, y, width, r)]
            if not hit:
                break
        else:
            while hit:  # keep the last lateral draw; move on past what it overlaps
                near = max(r[0] + 0.5 * r[2] for r in hit) + ROUGH_CLEAR_M
                hit = [r for r in rows if _overlap(near, depth, y, width, r)]
        if near + depth > length - dist.finish_clear_m:
            break
        rows.append((near + 0.5 * depth, y, depth, width, height, kind))
        near += float(rng.uniform(*dist.rough_step_m))
    rows.sort(key=lambda r: r[0] - 0.5 * r[2])  # path order of the near edges
    return Course(length, np.array(rows, dtype=float).reshape(-1, 6))


def _overlap(near: float, depth: float, y: float, width: float, row: tuple) -> bool:
    """Whether a footprint (near edge, depth, centre y, width) comes within ``ROUGH_CLEAR_M`` of ``row``'s."""
    x, ry, d, w = row[:4]
    return (near < x + 0.5 * d + ROUGH_CLEAR_M and near + depth > x - 0.5 * d - ROUGH_CLEAR_M
            and abs(y - ry) < 0.5 * (width + w) + ROUGH_CLEAR_M)


def obstacle_blocks(k: int) -> Block:
    return Block(f"obstacle_{k}", 1 + 4 * N_POINTS, "-, m, 0/1",
                 f"slot {k}: course index of the obstacle ({k} after the last one passed); perceived near-left "
                 "corner, far-right corner, near-edge midpoint and far-edge midpoint of its top face, eye frame "
                 "(zeros when not seen); seen flags of the four points")


PERCEPT_BLOCKS = tuple(obstacle_blocks(k) for k in range(K_SLOTS))
TRAILING_BLOCKS = (
    Block("odometry", 3, "m, m, rad", "pelvis x, y and heading relative to the start (path integration)"),
    Block("to_finish", 1, "m", "distance from the pelvis to the finish line along the path"),
    Block("time", 1, "s", "time since the start"),
)


class ObstacleWalkTask(Task):
    """Course, visual targets, events, rewards and info of ObstacleWalk. ``body`` is a
    :class:`~visuomotor_gym.body.walker_body.WalkerBody`."""

    leading_blocks = PERCEPT_BLOCKS
    trailing_blocks = TRAILING_BLOCKS
    trace_step_fields = ("step_phase",)
    trace_flag_fields = ("obstacle_seen",)

    def __init__(self, model: mujoco.MjModel, body, *, course_distribution: CourseDistribution,
                 reward_weights: dict, visual_delay_s: float, n_substeps: int) -> None:
        self.model = model
        self.n_substeps = int(n_substeps)  # physics substeps per control step (the env's)
        self.body = body
        self.gait = body.gait
        self.pool = ObstaclePool(model)  # the obstacles of the course (scene state)
        self.contacts = LegContacts(model, body.gait, self.pool)  # trips and missteps
        self.dist = course_distribution
        self.reward_weights = reward_weights
        self.visual_delay_s = visual_delay_s
        n = len(self.pool)
        # group: the four points of one obstacle do not crowd one another (VisionParams.crowding)
        self.all_targets = [PointTarget(f"obstacle_{i:02d}_{c}", group=f"obstacle_{i:02d}") for i in range(n)
                            for c in TOP_POINTS]
        self.targets = self.all_targets
        self._finish_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, wn.WALKER_FINISH)
        self._finish_mocap = int(model.body_mocapid[self._finish_body])
        self._edge_mocaps = [int(model.body_mocapid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)])
                             for name in wn.WALKER_WALKWAY_EDGES]
        self._sole_sites = list(body.gait.sole_sites)
        self.half_width = 0.5 * course_distribution.walkway_width_m
        self.rough = course_distribution.rough  # labelled slots, sight range (module docstring)
        self.sight_range = course_distribution.sight_range_m
        self.course = Course(0.0, np.zeros((0, 6)))
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.contacts.reset()
        self.success = False
        self.tripped = False
        self.misstepped = False
        self.off_path = False
        self.finished = False
        self._next_check = 0  # the next foothold whose landing is checked against the walkway's edges
        self.n_passed = 0
        self._slots_set = False
        self._n_events = 0
        self._prev_x = 0.0
        self.seen = [False] * K_SLOTS
        self.labels: dict[int, int] = {}  # rough course: course index -> label (order of first sighting)
        self._passed: list[bool] = []  # rough course: each obstacle passed by the pelvis

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the course, place the obstacles and the finish line (the walker is already at the start)."""
        m, d = self.model, data
        self.course = course = sample_course(rng, self.dist, len(self.pool))
        self.pool.park_all(m, d)
        for t in self.all_targets:
            t.hidden = True
        self.targets = self.all_targets[: N_POINTS * len(course.obstacles)]  # what the retina samples
        for i, (x, y, depth, width, height, kind) in enumerate(course.obstacles.tolist()):
            self.pool.place(m, d, i, x, y, depth, width, height, rgba=OBSTACLE_RGBA[int(kind)])
            for t, point in zip(self.targets[N_POINTS * i: N_POINTS * (i + 1)], top_points(x, y, depth, width, height)):
                t.place(*point)
        d.mocap_pos[self._finish_mocap] = (course.length, 0.0, 0.0)
        for mocap, sign in zip(self._edge_mocaps, (1.0, -1.0)):  # the painted edges (walker.xml: 30 m from x = -5 m)
            d.mocap_pos[mocap] = (10.0, sign * self.half_width, 0.0)
        self._prev_x = float(d.qpos[0])

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        """Gaze starts level, straight ahead along the path (at the finish line, at eye height)."""
        return np.array([self.course.length, 0.0, 1.6]), (0.0, 0.0)

    def reset_info(self) -> dict:
        """The course (true state, scoring only). Fixed shapes whatever the seed, so that Gymnasium's vector
        envs can stack it: ``obstacles`` is (pool size, 6), its first ``n_obstacles`` rows the course's
        obstacles (:attr:`Course.obstacles`), the rest NaN."""
        obstacles = self.course.obstacles
        padded = np.full((len(self.pool), obstacles.shape[1]), np.nan)
        padded[: len(obstacles)] = obstacles
        return {"course_length": float(self.course.length), "obstacles": padded, "n_obstacles": len(obstacles)}

    # --- what the evaluator records ----------------------------------------------------------
    def trace_episode_fields(self) -> dict:
        return {"course_length": float(self.course.length), "obstacles": self.course.obstacles.copy()}

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"tripped": bool(info["tripped"]), "misstepped": bool(info["misstepped"]),
                "off_path": bool(info["off_path"]), "finished": bool(info["finished"])}

    # --- physics ------------------------------------------------------------------------------
    def needs_substep_checks(self, data: mujoco.MjData) -> bool:
        """Contact checks every substep only while an obstacle is within reach of a leg: then the
        substeps are *watched* (:meth:`LegContacts.watch`) and still run as one ``mj_step``
        call (so this returns False); :meth:`check_substep`, called once after them, classifies their
        contacts exactly as checks after every substep would have (replaying them when MuJoCo saw a
        contact)."""
        if self.contacts.near(data):
            self.contacts.watch(data)
        return False

    def check_substep(self, data: mujoco.MjData) -> bool:
        """Classify leg-obstacle contacts (:meth:`LegContacts.check`): True on a new event.
        After watched substeps: as the env's substep loop would have (checks after each substep until
        the first new event, then once more on the final kinematics)."""
        return self.contacts.watched(data, self.n_substeps)

    # --- observation --------------------------------------------------------------------------
    def before_observe(self, data: mujoco.MjData) -> None:
        """Advance the first slot past obstacles the pelvis has left behind (before the retina samples)."""
        obs = self.course.obstacles
        x = float(data.qpos[0])
        n0 = self.n_passed
        while self.n_passed < len(obs) and obs[self.n_passed, 0] + 0.5 * obs[self.n_passed, 2] < x - PASSED_M:
            self.n_passed += 1
        if self.rough:
            # Sampled: every obstacle not yet passed whose near edge lies within the sight range.
            self._passed = passed = [row[0] + 0.5 * row[2] < x - ROUGH_PASSED_M for row in obs.tolist()]
            for i, row in enumerate(obs.tolist()):
                hidden = passed[i] or row[0] - 0.5 * row[2] > x + self.sight_range
                for t in self.targets[N_POINTS * i: N_POINTS * (i + 1)]:
                    t.hidden = hidden
            return
        if n0 != self.n_passed or not self._slots_set:
            # Only the slots' obstacles are sampled (the others would not reach the observation; those
            # passed lie behind the walker, beyond any reach of the eye and the head).
            for i in range(len(obs)):
                hidden = not (self.n_passed <= i < self.n_passed + K_SLOTS)
                for t in self.targets[N_POINTS * i: N_POINTS * (i + 1)]:
                    t.hidden = hidden
            self._slots_set = True

    def observe_leading(self, values: list, samples: list) -> None:
        """The :data:`PERCEPT_BLOCKS`: per slot, id, the four points (eye frame) and their seen flags."""
        n_obstacles = len(samples) // N_POINTS
        if self.rough:
            self._observe_labelled(values, samples, n_obstacles)
            return
        for k in range(K_SLOTS):
            i = self.n_passed + k
            values.append(float(i))
            if i < n_obstacles:
                seen = []
                for p, _, v in samples[N_POINTS * i: N_POINTS * (i + 1)]:
                    values += p
                    seen.append(1.0 if v else 0.0)
                values += seen
                self.seen[k] = 1.0 in seen
            else:
                values += _UNSEEN_SLOT
                self.seen[k] = False

    def _observe_labelled(self, values: list, samples: list, n_obstacles: int) -> None:
        """The rough course's slots (module docstring): labels in the order of first sighting (course
        order within a step), the labelled obstacles not yet passed, lowest label first; an empty slot
        reads id -1, zeros and unseen flags."""
        labels = self.labels
        for i in range(n_obstacles):
            if i not in labels and any(v for _, _, v in samples[N_POINTS * i: N_POINTS * (i + 1)]):
                labels[i] = len(labels)
        slots = sorted((label, i) for i, label in labels.items() if not self._passed[i])[:K_SLOTS]
        for k in range(K_SLOTS):
            if k < len(slots):
                label, i = slots[k]
                values.append(float(label))
                seen = []
                for p, _, v in samples[N_POINTS * i: N_POINTS * (i + 1)]:
                    values += p
                    seen.append(1.0 if v else 0.0)
                values += seen
                self.seen[k] = 1.0 in seen
            else:
                values.append(-1.0)
                values += _UNSEEN_SLOT
                self.seen[k] = False

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        d = data
        sx, sy = self.body.start_xy
        x, y, _, yaw = d.qpos[:4].tolist()
        values += (x - sx, y - sy, yaw - self.body.start_yaw, self.course.length - (x - sx), d.time)

    # --- outcome ------------------------------------------------------------------------------
    def _check_footholds(self, data: mujoco.MjData) -> bool:
        """Check every foothold flat by now (heel strike + double support) against the walkway's edges:
        True when a sole's centre lies beyond one (the walker left the walkway)."""
        g = self.gait
        y0 = self.body.start_xy[1]
        while not self.off_path and self._next_check * g.T + g.T_ds <= g.tick:
            side = self._next_check % 2  # g.side_of
            self._next_check += 1
            if abs(float(data.site_xpos[self._sole_sites[side], 1]) - y0) > self.half_width:
                self.off_path = True
        return self.off_path

    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        d = data
        g = self.contacts
        new_trip = g.tripped and not self.tripped
        events = g.events
        n_events = len(events)
        new_missteps = sum(e.kind == "misstep" for e in events[self._n_events:]) if n_events != self._n_events else 0
        self._n_events = n_events
        self.tripped = g.tripped
        self.misstepped = g.misstepped
        was_off = self.off_path
        self._check_footholds(d)
        x = float(d.qpos[0])
        arrived = not self.finished and not self.off_path and x - self.body.start_xy[0] >= self.course.length
        self.finished = self.finished or arrived
        self.success = self.finished and not self.tripped and not self.misstepped
        values = {"finish": 1.0 if (arrived and self.success) else 0.0, "trip": 1.0 if new_trip else 0.0,
                  "misstep": float(new_missteps), "off_path": 1.0 if self.off_path and not was_off else 0.0,
                  "progress": x - self._prev_x}
        self._prev_x = x
        terms = {k: w * values[k] for k, w in self.reward_weights.items() if w != 0.0}
        terminated = self.tripped or self.off_path or self.finished
        return float(sum(terms.values())), terms, terminated, self.info(d)

    def info(self, data: mujoco.MjData, *, diverged: bool = False) -> dict:
        """Step information (the course is true state: for scoring only, never for a policy)."""
        if diverged and self.contacts.watching:
            # The physics diverged in watched substeps (the env returns before check_substep): their
            # checks, as the substep loop made them before it noticed (no final check).
            self.contacts.watched(data, self.n_substeps, final=False, replay=True)
        return {
            "tripped": self.tripped,
            "misstepped": self.misstepped,
            "off_path": self.off_path,
            "finished": self.finished,
            "events": len(self.contacts.events),
            "obstacles_passed": self.n_passed,
            "obstacle_seen": False if diverged else any(self.seen),
            "step_phase": (self.gait.tick % self.gait.T) / self.gait.T,  # gait.step_phase()
        }


def top_points(x: float, y: float, depth: float, width: float, height: float) -> tuple:
    """The :data:`TOP_POINTS` of an obstacle's top face (centre x, y; extents along x and y; height)."""
    x0, x1, y0, y1 = x - 0.5 * depth, x + 0.5 * depth, y - 0.5 * width, y + 0.5 * width
    return (x0, y1, height), (x1, y0, height), (x0, y, height), (x1, y, height)


def top_points_of(obstacles: np.ndarray) -> np.ndarray:
    """(N, 4, 3) :data:`TOP_POINTS` of course obstacles (rows of :attr:`Course.obstacles`)."""
    return np.array([top_points(*row[:5]) for row in obstacles.tolist()], dtype=float).reshape(-1, N_POINTS, 3)


_UNSEEN_SLOT = [0.0] * (4 * N_POINTS)


__all__ = ["COURSE_PRESETS", "DENSE_ROUGH_COURSE", "KINDS", "K_SLOTS", "LAYOUTS", "N_POINTS", "ROUGH_COURSE", "TOP_POINTS", "Course",
           "CourseDistribution", "ObstacleWalkTask",
           "sample_course", "top_points", "top_points_of"]
