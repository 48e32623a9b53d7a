"""The obstacle-dodge task (Eom, Han, Shin & Noh 2019, Sec. 7, "Moving obstacle avoidance"): walk to a goal
15-20 m ahead while pedestrians cross the path, seen only through the foveated eye; coming closer to one than
the two bodies' radii is a collision and ends the episode.

**Scenario** (:func:`sample_crowd`, drawn first from the env's ``np_random`` so every rung of the ladder
gets the same crowd for a seed): the walker starts at the origin walking along +x at 1.3 m/s; the goal
line lies 15-20 m ahead (modelling choice). ``N_PEDESTRIANS`` = 4 pedestrians appear one after the other
(onset 0.3-1.5 s after the start, then every 1.5-3 s: modelling choice, so that two or three walk at once),
each 4-6 m to one side, and walk straight across the path at 1.0-1.5 m/s (adults' comfortable walking
speeds are 1.27-1.46 m/s, Bohannon 1997, Age Ageing 26:15; the wider range is a modelling choice), up to
30 deg off the perpendicular (modelling choice). Each crosses the path where a walker going straight at
the nominal 1.3 m/s would arrive ``timing_s`` later than the pedestrian (uniform in +-1.2 s: about 40 %
of the crossers would hit a walker that neither looks nor steers; modelling choice). A pedestrian
**veers** with probability 0.1 (Jovancevic, Sullivan & Hayhoe: 10 % of the pedestrians veered onto a
collision course; REFERENCES.md): it starts on a course that misses (|timing| 1.0-1.5 s), and when it
comes within 3-5 m of the walker it turns onto a collision course (toward the point where it would meet
the walker if both kept their velocities) for ``veer_s`` = 1.0 s (the veer in Jovancevic et al. lasted
~1 s; REFERENCES.md "(10 %, ~1 s)"), then resumes its course. (In the first definition of v0 ``veer_s`` was
1.5 s, a modelling choice; docs/reproductions/dodge.md has both.)

The ranges above are ``CrowdDistribution``'s own defaults, the preset ``"groups"`` (ObstacleDodge-v0's second
definition). **The env's default crowd is the preset ``"wide"``** (``DEFAULT_CROWD``; its ranges and sources at
``CROWD_PRESETS``): singles and pairs, a new party every 1-2 s, crossing up to 70 deg off the perpendicular
from 3-8 m to the side, so that the threats come from bearings no single posture of the eye covers. The opt-in
preset ``"wide_collision"`` is the same crowd with the timing within +-0.5 s, so that about three crossers in four
that do not veer are on a collision course with a walker going straight (45 % under ``"wide"``); measured, not
adopted (it widens the gaze gain only while the moving eye fixates more pedestrians than people do; with
fixations in the human range the gain is +37, as under ``"wide"``).

**Give way** (``CrowdDistribution.give_way``, opt-in: on only in the preset ``"wide_give_way"``, off in ``"wide"``,
the env's default, and in ``"wide_collision"``, ``"groups"`` and ``"single"``): the pedestrians otherwise walk
straight (and veer) whatever the walker does, so one overtaking the walker from behind, outside the human field for seconds, would walk into its back, which no eye
looking ahead can prevent. In real crowds the one who sees the other and passes second, behind it, does most of
the avoiding (Olivier et al. 2013; Knorr et al. 2016). A pedestrian behind the walker's frontal field (bearing from
the walker's direction of travel beyond ``give_way_bearing_deg`` = 90 deg), with the walker ahead in its own frontal
half-field and a minimal predicted distance (Olivier et al. 2012's MPD, axis to axis) under ``give_way_distance_m`` =
1 m within ``give_way_horizon_s`` = 3 s (Karamouzas, Skinner & Guy 2014), walks at the velocity nearest its course,
turned and/or slowed, that keeps 1 m and passes behind the walker (:func:`give_way_velocity`), until its course
keeps 1 m again; then it takes up its course's velocity. It judges the walker's velocity over one step of the
gait (``GIVE_WAY_WALKER_WINDOW_S``). No random draws: a seed's crowd is the same with the rule on or off and on
every rung. A veering pedestrian never gives way during its veer. Measured (docs/reproductions/data/terrain/
dodge_groups.md, "Overtakers giving way"): on the 200 pinned seeds it fixes every overtaking collision of
``fajen_warren`` (181 -> 192/200) but spares the still eye's walker more (its twin 102 -> 124/200), so the gaze gain
falls from +39.5 to +34.0 points; the definition keeps it off.

**Groups** (``CrowdDistribution.group_size`` = (2, 3) in the preset ``"groups"``, (1, 2) in ``"wide"``;
``"single"``, ``group_size=(1, 1)``, gives the first definition's crowds;
:func:`sample_groups`): the same
4 pedestrians come as groups (e.g. ``group_size=(2, 3)``: pairs and triads, the commonest groups of
Moussaid, Perozo, Garnier, Helbing & Theraulaz 2010, PLoS ONE 5:e10047, Fig. 1), one group per onset,
members walking abreast ``group_spacing_m`` = 0.7-0.9 m apart (their "side by side" formation at low
density, around the fitted preferred distance of 0.8 m, Fig. 4) across the path together; one member
of a group may veer alone (so that 10 % of the pedestrians still veer). A group is a wider obstacle
than a pedestrian, its members close enough to be pooled by crowding in the periphery
(``VisionParams.crowding``), so that each has to be looked at. With groups the observation's slots
are given in order of first sight (below), not of onset.

**What the eye sees of a pedestrian**: one point on its axis at 1.5 m (upper chest, a modelling choice
near the eyes' height so a level gaze sees it) with its velocity (:class:`PedestrianTarget`), sampled by
the retina like any target (eccentricity-dependent noise on position and velocity, the walk family's 20
deg recognition field, saccadic suppression, visual delay; with ``vision_params=human_periphery()`` the
human field, position noise growing with eccentricity, crowding between pedestrians closer than half
their eccentricity and depth precise only near the vergence distance instead). The observation holds ``K_SLOTS`` = 4 slots,
slot ``k`` = pedestrian ``k`` of the episode (in onset order; the number of pedestrians never exceeds the
slots): seen flag, position and velocity in the eye frame (zeros when not seen this step). With groups,
slot ``k`` = the ``k``-th pedestrian the eye has seen (those first seen on one step from left to right as
perceived), so that no slot id tells of a pedestrian not seen yet.

**Collision**: the horizontal distance from the pelvis axis to a pedestrian's axis below
``PEDESTRIAN_RADIUS_M`` + the walker's half-width (its chest and arms, read from the model), checked every
control step (closing speeds are <= 3.4 m/s: <= 7 cm per 20 ms step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Num, Pair
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import VisualTarget

N_PEDESTRIANS = 4
K_SLOTS = N_PEDESTRIANS
PEDESTRIAN_NAMES = tuple(f"pedestrian_{i}" for i in range(N_PEDESTRIANS))  # mocap bodies (envs_assets/dodge.xml)
PEDESTRIAN_RADIUS_M = 0.25  # capsule radius in dodge.xml (shoulder breadth ~0.45-0.5 m; modelling choice)
SEEN_HEIGHT_M = 1.5  # the point the eye sees on a pedestrian's axis (modelling choice, see above)
NOMINAL_SPEED = 1.3  # m/s, the walker's nominal gait (visuomotor_gym.body.walker.GaitParams)
PARK = (-30.0, 30.0, -5.0)
WIDE_ANGLE_DEG = 70.0  # the "wide" preset's crossing angles off the perpendicular (modelling choice, CROWD_PRESETS)
WIDE_SIDE_M = (3.0, 8.0)  # the "wide" preset's lateral start distances (modelling choice, CROWD_PRESETS)
WIDE_GROUP_SIZE = (1.0, 2.0)  # the "wide" preset's groups: singles and pairs (CROWD_PRESETS)
WIDE_ONSET_GAP_S = (1.0, 2.0)  # the "wide" preset's onset gaps (modelling choice, CROWD_PRESETS)
# The opt-in "wide_collision" preset's timing: +-0.5 s instead of +-1.2 s, so that about three crossers in four are on a
# collision course with a walker going straight (modelling choice, CROWD_PRESETS; sweep in
# docs/reproductions/data/terrain/dodge_groups.md, "Most crossings on a collision course")
COLLISION_TIMING_S = 0.5
# Give way (CrowdDistribution.give_way): the velocities a pedestrian giving way chooses from, its course turned by
# up to 90 deg either way in 5 deg steps and slowed in tenths down to a stop (a turn, a slowing or both: the one
# who gives way slows down and deviates, Olivier et al. 2013; both adjustments at acute crossing angles, Huber
# et al. 2014; the grid: modelling choice), and the window over which it judges the walker's velocity (one step
# of the gait, 0.5 s, so that the pelvis's sway within a step does not count: modelling choice).
GIVE_WAY_TURNS_DEG = tuple(range(-90, 91, 5))
GIVE_WAY_SPEED_FRACTIONS = tuple(k / 10.0 for k in range(10, -1, -1))
GIVE_WAY_WALKER_WINDOW_S = 0.5
REWARD_TERMS = ("goal", "collision", "progress")
DEFAULT_REWARD_WEIGHTS = {"goal": 1.0, "collision": -1.0, "progress": 0.0}


# What each CrowdDistribution field accepts (visuomotor_gym.core.args.check_fields): modelling choices
# around the defaults (positive walking speeds up to a sprint, crossing directions short of parallel to
# the path, a probability in [0, 1], times and distances of one 200 m walk at most).
CROWD_RULES = {
    "goal_m": Pair(Num(1.0, 200.0)),
    "first_onset_s": Pair(Num(0.0, 120.0)),
    "onset_gap_s": Pair(Num(0.0, 120.0)),
    "side_m": Pair(Num(0.0, 50.0, low_open=True)),
    "speed_m_s": Pair(Num(0.0, 5.0, low_open=True)),
    "angle_deg": Num(0.0, 80.0),
    "timing_s": Num(0.0, 20.0),
    "veer_p": Num(0.0, 1.0),
    "veer_timing_s": Pair(Num(0.0, 20.0)),
    "veer_distance_m": Pair(Num(0.0, 50.0)),
    "veer_s": Num(0.0, 20.0),
    "min_crossing_m": Num(0.0, 200.0),
    "goal_clear_m": Num(0.0, 200.0),
    # groups: whole members per group, at most the episode's pedestrians; spacings of people
    # walking abreast, short of a street's width (modelling choice)
    "group_size": lambda v, name: _group_size(v, name),
    "group_spacing_m": Pair(Num(0.0, 5.0, low_open=True)),
    # give way (opt-in, preset "wide_give_way"): a switch; a bearing beyond which a pedestrian is
    # behind the walker's frontal field (a half-turn at most); a comfortable distance and a prediction horizon
    # short of a street's width and of an episode (modelling choices)
    "give_way": args.Flag(),
    "give_way_bearing_deg": Num(0.0, 180.0),
    "give_way_distance_m": Num(0.0, 10.0, low_open=True),
    "give_way_horizon_s": Num(0.0, 20.0, low_open=True),
}


def crowd_preset(value) -> CrowdDistribution | dict:
    """``value`` itself, or the :data:`CROWD_PRESETS` entry it names (a ``ValueError`` naming the presets
    for an unknown name); ``None`` names :data:`DEFAULT_CROWD`, the env's default crowd."""
    if value is None:
        value = DEFAULT_CROWD
    if isinstance(value, str):
        if value not in CROWD_PRESETS:
            raise ValueError(f"crowd_distribution: unknown preset {value!r}; presets: {sorted(CROWD_PRESETS)}, "
                             "or a CrowdDistribution, a dict of its fields or None")
        return CROWD_PRESETS[value]
    return value


def _group_size(value, name: str) -> tuple[float, float]:
    lo, hi = Pair(Num(1.0, float(N_PEDESTRIANS)))(value, name)
    if lo != int(lo) or hi != int(hi):
        raise ValueError(f"{name} must be a (low, high) pair of whole numbers of pedestrians in "
                         f"[1, {N_PEDESTRIANS}]; got {value!r}")
    return (lo, hi)


@dataclass(frozen=True)
class CrowdDistribution:
    """The scenario sampler's ranges (SI units; uniform draws). Sources in the module docstring."""

    goal_m: tuple[float, float] = (15.0, 20.0)  # modelling choice
    first_onset_s: tuple[float, float] = (0.3, 1.5)
    onset_gap_s: tuple[float, float] = (1.5, 3.0)
    side_m: tuple[float, float] = (4.0, 6.0)  # lateral distance of the start from the path
    speed_m_s: tuple[float, float] = (1.0, 1.5)
    angle_deg: float = 30.0  # crossing direction within +-angle of the perpendicular
    timing_s: float = 1.2  # walker's nominal arrival at the crossing point minus the pedestrian's
    veer_p: float = 0.1  # Jovancevic, Sullivan & Hayhoe: 10 % veered onto a collision course
    veer_timing_s: tuple[float, float] = (1.0, 1.5)  # |timing| of a veering pedestrian's first course
    veer_distance_m: tuple[float, float] = (3.0, 5.0)  # the veer starts within this distance of the walker
    veer_s: float = 1.0  # Jovancevic, Sullivan & Hayhoe: the veer lasted ~1 s
    min_crossing_m: float = 3.0  # crossing points between this far from the start ...
    goal_clear_m: float = 1.0  # ... and this far before the goal
    # Groups (since ObstacleDodge-v0's second definition; preset "single", (1, 1): every pedestrian alone,
    # the first definition's draws). Members per group, uniform over
    # the whole numbers of the range (pairs the commonest group, then triads: Moussaid et al. 2010, Fig. 1),
    # walking abreast (Moussaid et al. 2010: at low density "group members tend to walk side by side,
    # forming a line perpendicular to the walking direction") with this centre-to-centre spacing between
    # neighbours (around the 0.8 m preferred distance d_o of their fitted model, Fig. 4; the range is a
    # modelling choice).
    group_size: tuple[float, float] = (2.0, 3.0)
    group_spacing_m: tuple[float, float] = (0.7, 0.9)
    # Give way (opt-in: on only in the preset "wide_give_way"; off here and in "wide", "wide_collision", "groups"
    # and "single"):
    # a pedestrian overtaking the walker from behind its frontal field adapts its velocity to pass at a
    # comfortable distance, then resumes its course (:func:`give_way_velocity`, sources there). Off: the
    # pedestrians walk straight (and veer), whatever the walker does, as in every definition so far.
    give_way: bool = False
    # The pedestrian is behind the walker's frontal field: its bearing from the walker's direction of travel
    # beyond 90 deg, i.e. behind the walker's frontal plane, where it would pass second (behind the walker),
    # the role that adapts most (Olivier et al. 2013), at the edge of or outside the human field (100 deg to
    # the side, Spector 1990) and seen, if at all, in its far periphery (the 90 deg: modelling choice)
    give_way_bearing_deg: float = 90.0
    # Comfortable distance: walkers adapt only when the minimal predicted distance (MPD, axis to axis) is
    # under about 1 m, and raise it to about 1 m (Olivier, Marin, Cretual & Pettre 2012, Gait Posture 36:399)
    give_way_distance_m: float = 1.0
    # Prediction horizon: pedestrians' interactions vanish beyond a time to collision of about 3 s
    # (Karamouzas, Skinner & Guy 2014, Phys Rev Lett 113:238701, tau_0 ~ 3 s; "an interaction time
    # horizon of 2-4 s")
    give_way_horizon_s: float = 3.0

    def __post_init__(self) -> None:
        args.check_fields(self, CROWD_RULES)

    @property
    def groups(self) -> bool:
        """Whether pedestrians walk in groups (``group_size`` other than (1, 1))."""
        return self.group_size != (1.0, 1.0)


# "wide" (the default of ObstacleDodge-v0 since its third definition, DEFAULT_CROWD: a crowd no single eye
# posture covers); "groups": the second definition, pairs and triads (Moussaid et al. 2010), and the
# dataclass's own defaults; "single": the first definition's crowds, every pedestrian alone. "wide": more,
# smaller parties from more directions, overlapping in time. Singles and pairs (WIDE_GROUP_SIZE, uniform over
# parties, the fourth pedestrian's cut to what is left: 43 % of the pedestrians alone, 57 % in pairs;
# Moussaid et al. 2010: up to 70 % of pedestrians walk in groups, pairs the commonest), one party every
# WIDE_ONSET_GAP_S (instead of 1.5-3 s: a denser stream, so that parties from both sides of the path are on
# the scene at once; modelling choice),
# crossing up to WIDE_ANGLE_DEG off the perpendicular, so that a party may come nearly head-on (starting
# ahead, walking toward the walker) or overtake obliquely (starting beside or behind, walking the walker's
# way), starting WIDE_SIDE_M to the side. On a collision course a pedestrian's bearing stays constant, the
# direction of the relative velocity: with the default's +-30 deg the threats' bearings 2 s before contact
# lie at 30-56 deg (10th-90th percentile, 1000 seeds, a walker going straight at 1.3 m/s;
# docs/reproductions/data/terrain/dodge_wide_bearings.py), with "wide" at 15-64 deg. Pedestrians cross
# streets at all angles, not only at right angles; the 70 deg and 3-8 m are modelling choices, short of the
# rules' 80 deg (walkers parallel to the path, who never cross it). Veers as "groups" (Jovancevic,
# Sullivan & Hayhoe: 10 %, ~1 s).
#
# "wide_collision" (opt-in, measured and not adopted: docs/reproductions/data/terrain/dodge_groups.md, "Most crossings
# on a collision course"): "wide" with the crossing timing drawn within +-COLLISION_TIMING_S instead of +-1.2 s.
# Under "wide" 45 % of the crossers that do not veer would come within the contact distance of a walker going
# straight at 1.3 m/s, and 14 % of the crowds hold none that would; under "wide_collision" 74 %, and 1 % (1000
# seeds of sample_crowd; the rest cross too obliquely or too near the start or the goal). Walkers adapt only to a
# pedestrian whose predicted distance of closest approach is under ~1 m (Olivier et al. 2012), so a crossing that
# misses by more asks nothing of the eye or the legs. Modelling choice, with its sweep on that page.
DEFAULT_CROWD = "wide"  # the env's crowd when none is given (see CROWD_PRESETS)
_WIDE = CrowdDistribution(angle_deg=WIDE_ANGLE_DEG, side_m=WIDE_SIDE_M, group_size=WIDE_GROUP_SIZE,
                          onset_gap_s=WIDE_ONSET_GAP_S)
CROWD_PRESETS = {"groups": CrowdDistribution(), "single": CrowdDistribution(group_size=(1.0, 1.0)),
                 "wide": _WIDE,
                 "wide_collision": replace(_WIDE, timing_s=COLLISION_TIMING_S),
                 # "wide" with overtakers giving way (opt-in; measured: the gaze gain falls, dodge_groups.md)
                 "wide_give_way": replace(_WIDE, give_way=True)}


@dataclass(frozen=True)
class Crowd:
    goal: float
    # (N, 9): onset time, start x, start y, velocity x, velocity y, crossing x, timing, veers (0/1), veer distance
    pedestrians: np.ndarray


def sample_crowd(rng: np.random.Generator, dist: CrowdDistribution, n: int = N_PEDESTRIANS) -> Crowd:
    if dist.groups:
        return sample_groups(rng, dist, n)
    goal = float(rng.uniform(*dist.goal_m))
    rows = []
    onset = float(rng.uniform(*dist.first_onset_s))
    for _ in range(n):
        side = 1.0 if rng.random() < 0.5 else -1.0
        lateral = float(rng.uniform(*dist.side_m))
        speed = float(rng.uniform(*dist.speed_m_s))
        angle = float(rng.uniform(-dist.angle_deg, dist.angle_deg)) * math.pi / 180.0
        veers = bool(rng.random() < dist.veer_p)
        if veers:
            timing = float(rng.uniform(*dist.veer_timing_s)) * (1.0 if rng.random() < 0.5 else -1.0)
        else:
            timing = float(rng.uniform(-dist.timing_s, dist.timing_s))
        veer_distance = float(rng.uniform(*dist.veer_distance_m))
        path = lateral / math.cos(angle)  # walked from the start to the crossing
        t_cross = onset + path / speed
        x_cross = NOMINAL_SPEED * (t_cross + timing)
        x_cross = min(max(x_cross, dist.min_crossing_m), goal - dist.goal_clear_m)
        vx, vy = speed * math.sin(angle), -side * speed * math.cos(angle)
        x0, y0 = x_cross - vx * path / speed, -vy * path / speed
        rows.append((onset, x0, y0, vx, vy, x_cross, timing, float(veers), veer_distance))
        onset += float(rng.uniform(*dist.onset_gap_s))
    return Crowd(goal, np.array(rows, dtype=float).reshape(-1, 9))


def sample_groups(rng: np.random.Generator, dist: CrowdDistribution, n: int = N_PEDESTRIANS) -> Crowd:
    """:func:`sample_crowd` with groups (``dist.group_size`` other than (1, 1)): the ``n`` pedestrians
    come as groups of ``group_size`` members (the last group cut to what is left), one group after the
    other (``onset_gap_s`` between groups). A group draws one side, start distance, speed, crossing
    angle and timing like a lone pedestrian (its centre crosses where a lone one would), and its
    members walk abreast: on a line through the centre perpendicular to their common velocity,
    ``group_spacing_m`` apart (one spacing per group). **A member veers alone**: with probability
    ``min(1, veer_p * size)`` the group's course misses (``veer_timing_s``, as a veering pedestrian's)
    and one member, drawn uniformly, veers onto a collision course within ``veer_distance_m``; the
    others keep the course (so ``veer_p`` of the pedestrians veer, as without groups: Jovancevic, Sullivan &
    Hayhoe). Rows are in onset order, then left to right along the line as each member's own walking
    direction sees it. Each member's row has its own crossing point and timing."""
    goal = float(rng.uniform(*dist.goal_m))
    rows: list[tuple] = []
    onset = float(rng.uniform(*dist.first_onset_s))
    lo, hi = (int(v) for v in dist.group_size)
    while len(rows) < n:
        size = min(int(rng.integers(lo, hi + 1)), n - len(rows))
        side = 1.0 if rng.random() < 0.5 else -1.0
        lateral = float(rng.uniform(*dist.side_m))
        speed = float(rng.uniform(*dist.speed_m_s))
        angle = float(rng.uniform(-dist.angle_deg, dist.angle_deg)) * math.pi / 180.0
        veers = bool(rng.random() < min(1.0, dist.veer_p * size))
        if veers:
            timing = float(rng.uniform(*dist.veer_timing_s)) * (1.0 if rng.random() < 0.5 else -1.0)
        else:
            timing = float(rng.uniform(-dist.timing_s, dist.timing_s))
        veer_distance = float(rng.uniform(*dist.veer_distance_m))
        veerer = int(rng.integers(size)) if veers else -1
        spacing = float(rng.uniform(*dist.group_spacing_m))
        path = lateral / math.cos(angle)
        t_cross = onset + path / speed
        x_cross = NOMINAL_SPEED * (t_cross + timing)
        x_cross = min(max(x_cross, dist.min_crossing_m), goal - dist.goal_clear_m)
        vx, vy = speed * math.sin(angle), -side * speed * math.cos(angle)
        x0, y0 = x_cross - vx * path / speed, -vy * path / speed
        lx, ly = -vy / speed, vx / speed  # the members' left, as they walk
        for m in range(size):
            off = ((size - 1) / 2.0 - m) * spacing  # first row leftmost
            mx0, my0 = x0 + lx * off, y0 + ly * off
            t_m = -my0 / vy  # after the onset, when this member's line crosses the path (y = 0)
            mx_cross = mx0 + vx * t_m
            m_timing = mx_cross / NOMINAL_SPEED - (onset + t_m)
            rows.append((onset, mx0, my0, vx, vy, mx_cross, m_timing, float(m == veerer), veer_distance))
        onset += float(rng.uniform(*dist.onset_gap_s))
    return Crowd(goal, np.array(rows, dtype=float).reshape(-1, 9))


class PedestrianTarget(VisualTarget):
    """A pedestrian as the eye sees it: a point on its axis at ``SEEN_HEIGHT_M`` and its velocity, both
    written by the task each step (world frame); hidden before its onset."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.position = np.array(PARK)
        self.velocity = np.zeros(3)
        self.hidden = True

    def state(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        return self.position, self.velocity


def pedestrian_block(k: int) -> Block:
    return Block(f"pedestrian_{k}", 7, "0/1, m, m/s",
                 f"pedestrian {k} (onset order): seen flag, perceived position of its upper body (1.5 m up its "
                 "axis) and perceived velocity, both in the eye frame (zeros when not seen this step)")


PERCEPT_BLOCKS = tuple(pedestrian_block(k) for k in range(K_SLOTS))
TRAILING_BLOCKS = (
    Block("odometry", 3, "m, m, rad", "pelvis x, y and heading relative to the start (path integration)"),
    Block("to_goal", 2, "m", "the goal line's centre relative to the pelvis, pelvis frame (x ahead, y left)"),
    Block("time", 1, "s", "time since the start"),
)


class ObstacleDodgeTask(Task):
    """Crowd, visual targets, collision, rewards and info of ObstacleDodge. ``body`` is a
    :class:`~visuomotor_gym.body.dodge_body.DodgeBody`."""

    leading_blocks = PERCEPT_BLOCKS
    trailing_blocks = TRAILING_BLOCKS
    trace_step_fields = ("pedestrian_pos", "step_phase")
    trace_flag_fields = ("pedestrian_seen",)

    def __init__(self, model: mujoco.MjModel, body, *, crowd_distribution: CrowdDistribution,
                 reward_weights: dict, dt: float) -> None:
        self.model = model
        self.body = body
        self.gait = body.gait
        self.dist = crowd_distribution
        self.reward_weights = reward_weights
        self.dt = dt
        m = model
        bodies = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in PEDESTRIAN_NAMES]
        if min(bodies) < 0:
            raise ValueError("the model lacks the pedestrian bodies of envs_assets/dodge.xml")
        self._mocap = [int(m.body_mocapid[b]) for b in bodies]
        self._finish_mocap = int(m.body_mocapid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, wn.WALKER_FINISH)])
        chest = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "chest")
        arm = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "left_arm")
        arm_y = float(m.body_pos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "left_arm")][1])
        self.walker_radius = max(float(m.geom_size[chest][1] + m.geom_size[chest][0]),
                                 arm_y + float(m.geom_size[arm][0]))
        self.contact_distance = PEDESTRIAN_RADIUS_M + self.walker_radius
        self.targets = [PedestrianTarget(n) for n in PEDESTRIAN_NAMES]
        self.crowd = Crowd(0.0, np.zeros((0, 9)))
        self.pos = np.zeros((N_PEDESTRIANS, 2))
        self.vel = np.zeros((N_PEDESTRIANS, 2))
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.success = self.collided = self.finished = False
        self.active = [False] * N_PEDESTRIANS
        self.veer_until = [-1.0] * N_PEDESTRIANS
        self.veered = [False] * N_PEDESTRIANS
        self.giving_way = [False] * N_PEDESTRIANS  # giving way now (CrowdDistribution.give_way)
        self.gave_way = [False] * N_PEDESTRIANS  # gave way at some time this episode
        self._walker_track: list[tuple[float, float]] = []  # the walker's positions, one per control step
        self.seen = [False] * N_PEDESTRIANS
        # Groups: slot k holds the k-th pedestrian the eye has seen (-1: not seen yet), see observe_leading
        self.slot_of = [-1] * N_PEDESTRIANS
        self.min_gap = math.inf
        self._prev_x = 0.0

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        self.crowd = sample_crowd(rng, self.dist)
        self.pos = self.crowd.pedestrians[:, 1:3].copy()
        self.vel = self.crowd.pedestrians[:, 3:5].copy()
        for i in range(N_PEDESTRIANS):
            self._park(data, i)
        data.mocap_pos[self._finish_mocap] = (self.crowd.goal, 0.0, 0.0)
        self._prev_x = float(data.qpos[0])
        self._activate(data, 0.0)

    def _park(self, data, i: int) -> None:
        data.mocap_pos[self._mocap[i]] = PARK
        t = self.targets[i]
        t.hidden = True
        t.position[:] = PARK
        t.velocity[:] = 0.0

    def _activate(self, data, t: float) -> None:
        for i, row in enumerate(self.crowd.pedestrians.tolist()):
            if not self.active[i] and t >= row[0] - 1e-9:
                self.active[i] = True
                self.targets[i].hidden = False
                self._write(data, i)

    def _write(self, data, i: int) -> None:
        x, y = self.pos[i].tolist()
        data.mocap_pos[self._mocap[i]] = (x, y, 0.0)
        t = self.targets[i]
        t.position[:] = (x, y, SEEN_HEIGHT_M)
        t.velocity[:2] = self.vel[i]

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        """Gaze starts level, straight ahead at the goal, at eye height."""
        return np.array([self.crowd.goal, 0.0, 1.6]), (0.0, 0.0)

    def trace_episode_fields(self) -> dict:
        return {"goal_distance": float(self.crowd.goal), "pedestrians": self.crowd.pedestrians.copy()}

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"collided": bool(info["collided"]), "finished": bool(info["finished"]),
                "veered": np.asarray(info["veered"], dtype=bool), "min_gap": float(info["min_gap"])}

    # --- physics: the pedestrians move kinematically, once per control step ------------------
    def before_physics(self, data: mujoco.MjData) -> None:
        t_end = float(data.time) + self.dt - self.body.gait.t0
        wx, wy = float(data.qpos[0]), float(data.qpos[1])
        wvx, wvy = float(data.qvel[0]), float(data.qvel[1])
        rows = self.crowd.pedestrians
        if self.dist.give_way:
            ux, uy = self._walker_velocity(wx, wy, wvx, wvy)
        for i in range(N_PEDESTRIANS):
            if not self.active[i]:
                continue
            row = rows[i]
            px, py = self.pos[i].tolist()
            if row[7] > 0.0 and not self.veered[i] and math.hypot(px - wx, py - wy) < row[8] and px > wx:
                self.veered[i] = True
                self.veer_until[i] = t_end + self.dist.veer_s
                self.vel[i] = intercept_velocity(px, py, float(np.hypot(*row[3:5])), wx, wy, wvx, wvy)
                self.giving_way[i] = False  # a veer overrides giving way
            elif self.veered[i] and 0.0 <= self.veer_until[i] <= t_end:
                self.vel[i] = row[3:5]
                self.veer_until[i] = -1.0
            if self.dist.give_way and self.veer_until[i] < 0.0:  # never during a veer
                self._give_way(i, px - wx, py - wy, ux, uy, float(data.qpos[3]))
            self.pos[i] += self.vel[i] * self.dt
            self._write(data, i)
        self._activate(data, t_end)

    def _walker_velocity(self, wx: float, wy: float, wvx: float, wvy: float) -> tuple[float, float]:
        """The walker's velocity as a pedestrian judges it: its displacement over the last
        ``GIVE_WAY_WALKER_WINDOW_S`` (one step of the gait; the instantaneous velocity until then)."""
        n = max(1, round(GIVE_WAY_WALKER_WINDOW_S / self.dt))
        track = self._walker_track
        track.append((wx, wy))
        if len(track) > n + 1:
            del track[0]
        if len(track) < n + 1:
            return wvx, wvy
        (x0, y0) = track[0]
        return (wx - x0) / (n * self.dt), (wy - y0) / (n * self.dt)

    def _give_way(self, i: int, rx: float, ry: float, ux: float, uy: float, yaw: float) -> None:
        """Pedestrian ``i`` (at ``(rx, ry)`` from the walker, who moves at ``(ux, uy)``) starts giving way when
        it is behind the walker's frontal field (bearing from the walker's direction of travel beyond
        ``give_way_bearing_deg``; its facing ``yaw`` when the walker barely moves), the walker is ahead within
        its own frontal half-field (its course's direction within 90 deg of the walker) and its course
        predicts a closest approach under ``give_way_distance_m`` within ``give_way_horizon_s``
        (:func:`min_predicted_distance`). While its course still does (wherever the walker is then: a
        pedestrian that has come alongside or ahead while giving way still knows it is there), it walks at
        :func:`give_way_velocity`; then it takes up its course's velocity again."""
        d = self.dist
        course = self.crowd.pedestrians[i, 3:5]
        cx, cy = float(course[0]), float(course[1])
        mpd, closing = min_predicted_distance(rx, ry, cx - ux, cy - uy, d.give_way_horizon_s)
        threat = closing and mpd < d.give_way_distance_m
        speed = math.hypot(ux, uy)
        hx, hy = (ux / speed, uy / speed) if speed > 0.1 else (math.cos(yaw), math.sin(yaw))
        if not self.giving_way[i]:
            ahead = -(rx * cx + ry * cy) > 0.0  # the walker within 90 deg of the pedestrian's course
            if not (threat and ahead):
                return
            cos_bearing = (rx * hx + ry * hy) / (math.hypot(rx, ry) or 1.0)
            if math.degrees(math.acos(max(-1.0, min(1.0, cos_bearing)))) <= d.give_way_bearing_deg:
                return
            self.giving_way[i] = self.gave_way[i] = True
        elif not threat:
            self.giving_way[i] = False
            self.vel[i] = course
            return
        self.vel[i] = give_way_velocity(rx, ry, cx, cy, ux, uy, hx, hy, d.give_way_distance_m, d.give_way_horizon_s)

    # --- observation --------------------------------------------------------------------------
    def observe_leading(self, values: list, samples: list) -> None:
        if self.dist.groups:
            self._observe_by_sight(values, samples)
            return
        for k in range(K_SLOTS):
            p, v, visible = samples[k]
            self.seen[k] = visible
            values.append(1.0 if visible else 0.0)
            values += p
            values += v

    def _observe_by_sight(self, values: list, samples: list) -> None:
        """With groups, slot ``k`` holds the ``k``-th pedestrian the eye has seen, so a slot id says
        nothing about pedestrians not seen yet (in onset order, seeing one member of a group would tell
        that a member with a lower slot exists). Pedestrians first seen on the same step take their slots
        from left to right as they are perceived (perceived azimuth, largest first; their index breaks a
        tie), never by their hidden order."""
        new = [i for i in range(N_PEDESTRIANS) if samples[i][2] and self.slot_of[i] < 0]
        new.sort(key=lambda i: (-math.atan2(samples[i][0][1], samples[i][0][0]), i))
        nxt = max(self.slot_of) + 1
        for i in new:
            self.slot_of[i] = nxt
            nxt += 1
        by_slot = [-1] * K_SLOTS
        for i, k in enumerate(self.slot_of):
            if k >= 0:
                by_slot[k] = i
        for i in range(N_PEDESTRIANS):
            self.seen[i] = bool(samples[i][2])
        for k in range(K_SLOTS):
            i = by_slot[k]
            if i < 0 or not samples[i][2]:
                values += (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
                continue
            p, v, _ = samples[i]
            values.append(1.0)
            values += p
            values += v

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        sx, sy = self.body.start_xy
        x, y = float(data.qpos[0]), float(data.qpos[1])
        gx, gy, _ = self.body.frame.to_local(sx + self.crowd.goal, sy, 0.0)
        values += (x - sx, y - sy, float(data.qpos[3]) - self.body.start_yaw, gx, gy, float(data.time))

    # --- outcome ------------------------------------------------------------------------------
    def gaps(self, data: mujoco.MjData) -> list[float]:
        """Horizontal distance minus the contact distance, per active pedestrian (inf when inactive)."""
        x, y = float(data.qpos[0]), float(data.qpos[1])
        return [math.hypot(px - x, py - y) - self.contact_distance if a else math.inf
                for (px, py), a in zip(self.pos.tolist(), self.active)]

    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        gap = min(self.gaps(data))
        self.min_gap = min(self.min_gap, gap)
        new_collision = gap < 0.0 and not self.collided
        self.collided = self.collided or gap < 0.0
        x = float(data.qpos[0])
        arrived = not self.finished and x - self.body.start_xy[0] >= self.crowd.goal
        self.finished = self.finished or arrived
        self.success = self.finished and not self.collided
        values = {"goal": 1.0 if (arrived and self.success) else 0.0, "collision": 1.0 if new_collision else 0.0,
                  "progress": x - self._prev_x}
        self._prev_x = x
        terms = {k: w * values[k] for k, w in self.reward_weights.items() if w != 0.0}
        return float(sum(terms.values())), terms, self.collided or self.finished, self.info(data)

    def info(self, data: mujoco.MjData, *, diverged: bool = False) -> dict:
        """Step information (pedestrian positions are true state: for scoring only, never for a policy)."""
        ped = np.empty((N_PEDESTRIANS, 3))  # the seen points; parked (PARK) before the onset
        for i in range(N_PEDESTRIANS):
            ped[i] = (self.pos[i, 0], self.pos[i, 1], SEEN_HEIGHT_M) if self.active[i] else PARK
        return {
            "collided": self.collided,
            "finished": self.finished,
            "min_gap": self.min_gap,
            "veered": list(self.veered),
            "pedestrian_pos": ped,
            "pedestrian_seen": False if diverged else any(self.seen),
            "step_phase": self.gait.step_phase(),
        }


def intercept_velocity(px: float, py: float, speed: float, wx: float, wy: float, wvx: float, wvy: float):
    """The velocity of the given speed that meets a walker at (wx, wy) moving at (wvx, wvy) (the
    smallest positive meeting time; straight at the walker when no meeting is possible)."""
    rx, ry = wx - px, wy - py
    a = wvx * wvx + wvy * wvy - speed * speed
    b = 2.0 * (rx * wvx + ry * wvy)
    c = rx * rx + ry * ry
    t = math.inf
    if abs(a) < 1e-9:
        t = -c / b if b < 0.0 else math.inf
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            roots = [(-b - math.sqrt(disc)) / (2.0 * a), (-b + math.sqrt(disc)) / (2.0 * a)]
            positive = [r for r in roots if r > 0.0]
            t = min(positive) if positive else math.inf
    if math.isfinite(t):
        dx, dy = rx + wvx * t, ry + wvy * t
    else:
        dx, dy = rx, ry
    n = math.hypot(dx, dy) or 1.0
    return np.array([speed * dx / n, speed * dy / n])


def _closest_approach(rx, ry, vx, vy, horizon: float):
    """The time within ``[0, horizon]`` at which a pedestrian at ``(rx, ry)`` from the walker, moving at ``(vx, vy)``
    relative to it, comes closest; and ``r . v`` (negative: closing in). Scalars or arrays of ``vx, vy``."""
    vv = np.asarray(vx, dtype=float) ** 2 + np.asarray(vy, dtype=float) ** 2
    rv = rx * np.asarray(vx, dtype=float) + ry * np.asarray(vy, dtype=float)
    return np.clip(-rv / np.maximum(vv, 1e-12), 0.0, horizon), rv


def min_predicted_distance(rx, ry, vx, vy, horizon: float):
    """The minimal predicted distance (Olivier et al. 2012's MPD) of a pedestrian at ``(rx, ry)`` from the
    walker, moving at ``(vx, vy)`` relative to it, over the next ``horizon`` seconds if both keep their
    velocities, and whether they are closing in (the distance falling now). Scalars or arrays of ``vx, vy``."""
    t, rv = _closest_approach(rx, ry, vx, vy, horizon)
    mpd = np.hypot(rx + vx * t, ry + vy * t)
    if np.ndim(mpd) == 0:
        return float(mpd), bool(rv < 0.0)
    return mpd, rv < 0.0


def give_way_velocity(rx: float, ry: float, cx: float, cy: float, ux: float, uy: float, hx: float, hy: float,
                      distance: float, horizon: float) -> np.ndarray:
    """The velocity of a pedestrian giving way, at ``(rx, ry)`` from the walker, who moves at ``(ux, uy)``
    in the direction ``(hx, hy)`` (a unit vector). Of its course ``(cx, cy)`` turned by
    ``GIVE_WAY_TURNS_DEG`` and slowed by ``GIVE_WAY_SPEED_FRACTIONS``, the one nearest the course (the least
    change: Moussaid, Helbing & Theraulaz 2011, PNAS 108:6884, pedestrians take the direction of least detour
    free of collisions) whose minimal predicted distance from the walker over ``horizon`` is at least
    ``distance`` and which **passes behind the walker** (at the closest approach, behind the walker's
    frontal plane); without one that passes behind, the nearest the course that keeps the distance; without
    any, the one that keeps farthest. Deterministic (ties: the first of the grid, the turns from right to
    left, the faster first).

    Sources (module docstring of the crowd): in pedestrian pairs the walker who passes second, behind the
    other, contributes most to the avoidance, slowing down and deviating (Olivier, Marin, Cretual, Berthoz &
    Pettre 2013, Gait Posture 38:751; Knorr et al. 2016, J Exp Psychol Hum Percept Perform: the role-dependent
    contribution of the one giving way matters most): the overtaker, behind, takes that role; walkers keep a
    minimal predicted distance of about 1 m (Olivier et al. 2012); the adjustments combine path and speed at
    acute crossing angles (Huber et al. 2014, PLoS ONE 9:e89589)."""
    turns = np.radians(np.asarray(GIVE_WAY_TURNS_DEG, dtype=float))[:, None]
    frac = np.asarray(GIVE_WAY_SPEED_FRACTIONS, dtype=float)[None, :]
    c, s = np.cos(turns), np.sin(turns)
    vx = (c * cx - s * cy) * frac
    vy = (s * cx + c * cy) * frac
    wx, wy = vx - ux, vy - uy  # relative to the walker
    t, _ = _closest_approach(rx, ry, wx, wy, horizon)
    mpd = np.hypot(rx + wx * t, ry + wy * t)
    behind = (rx + wx * t) * hx + (ry + wy * t) * hy <= 0.0  # at the closest approach
    change = np.hypot(vx - cx, vy - cy)
    ok = mpd >= distance
    for keep in (ok & behind, ok):
        if keep.any():
            k = int(np.argmin(np.where(keep, change, np.inf)))
            break
    else:
        k = int(np.argmax(mpd))
    return np.array([float(vx.flat[k]), float(vy.flat[k])])


__all__ = ["CROWD_PRESETS", "DEFAULT_CROWD", "K_SLOTS", "N_PEDESTRIANS", "Crowd", "CrowdDistribution", "ObstacleDodgeTask",
           "PedestrianTarget", "crowd_preset", "give_way_velocity", "intercept_velocity", "min_predicted_distance",
           "sample_crowd", "sample_groups"]
