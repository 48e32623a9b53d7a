"""ObstacleWalk: walk a path across obstacles seen only through a foveated, saccading eye (Iwao
et al.).

``ObstacleWalkEnv`` composes the embodiment core (:mod:`visuomotor_gym.core`), the walker
(:mod:`visuomotor_gym.body.walker_body` over the scripted gait of :mod:`visuomotor_gym.body.walker`)
and the obstacle-walk task (:mod:`visuomotor_gym.tasks.obstacle_walk`).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

from visuomotor_gym.body import names
from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import (
    TURNING_WALKER_BLOCKS,
    WALKER_BLOCKS,
    TurningWalkerBody,
    WalkerBody,
)
from visuomotor_gym.core import args
from visuomotor_gym.core.env import MAX_VISION_NOISE_SCALE, MAX_VISUAL_DELAY_S, VisuomotorEnv  # noqa: F401 (re-exported)
from visuomotor_gym.core.eye import EYE_BLOCKS
from visuomotor_gym.core.head import HEAD_BLOCKS
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.core.parts import Task
from visuomotor_gym.tasks.obstacle_walk import (
    COURSE_PRESETS,
    DEFAULT_REWARD_WEIGHTS,
    K_SLOTS,
    PERCEPT_BLOCKS,
    REWARD_TERMS,
    TRAILING_BLOCKS,
    WINDING_COURSE,
    WINDING_TRAILING_BLOCKS,
    CourseDistribution,
    ObstacleWalkTask,
)
from visuomotor_gym.vision.foveation import VisionParams, human_periphery

__all__ = ["OBSTACLE_VIEW_ANGLE_DEG", "OBSTACLE_WALK_VISION", "WALKWAY_DEFINITION", "WALK_LAYOUT", "WALK_VISION",
           "WINDING_LAYOUT", "ObstacleWalkEnv", "WalkerEnv"]

RENDER_CAMERAS = ("both", "side", "follow", "scene", "eye")
# The field in which an obstacle is seen at all: Iwao et al.'s view angle for obstacle recognition
# while walking, theta_Vmax = 20 deg (Iwao et al., Sec. 4.2.3: walkers look at an obstacle "indirectly",
# within their view angle; 20 deg walking, 30 deg running), instead of the eye's whole +-60 deg field
# (Eom et al.) of the catch family. The noise law is the same. Measured (docs/reproductions/iwao.md):
# with +-60 deg a gaze-blind twin that fuses its peripheral samples (iwao:gaze_blind=true) crossed 29 of
# 30 courses, so looking would not be tested; with 20 deg it fails most of them.
OBSTACLE_VIEW_ANGLE_DEG = 20.0
WALK_VISION = VisionParams(field_of_view_deg=OBSTACLE_VIEW_ANGLE_DEG)
# ObstacleWalk's eye: the human periphery, every family's eye (vision.foveation.HUMAN_PERIPHERY: the human field
# of Spector 1990, the position law E2 0.7 deg, crowding b = 0.5 after Bouma 1970, the depth pedestal 10 arcmin,
# the positional disarray 0.8 of Hess & Field 1993, the lateral noise drawn as an angle about the eye), in place
# of the 20 deg cone above (Iwao's downward view angle, which no source gives as a cone). Laid over WALK_VISION,
# the eye it was measured with (the human field makes field_of_view_deg moot).
OBSTACLE_WALK_VISION = human_periphery(WALK_VISION)
# ObstacleWalk-v0's first definition as constructor arguments: the straight walkway's course (bars, boxes and
# mats) and the 20 deg cone (``gym.make("ObstacleWalk-v0", **WALKWAY_DEFINITION)``).
WALKWAY_DEFINITION = {"course_distribution": "walkway", "vision_params": dataclasses.asdict(WALK_VISION)}
WALK_LAYOUT = ObservationLayout(PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + WALKER_BLOCKS + TRAILING_BLOCKS)
# The winding walkway's observation (course_distribution="winding", the default): the turning walker's blocks
# and the centre line ahead.
WINDING_LAYOUT = ObservationLayout(PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + TURNING_WALKER_BLOCKS
                                   + WINDING_TRAILING_BLOCKS)


class WalkerEnv(VisuomotorEnv):
    """What the walker families (ObstacleWalk, SteppingStones, ObstacleDodge) share on top of
    :class:`~visuomotor_gym.core.env.VisuomotorEnv`: the ``gait_params`` argument, the walk vision
    (:data:`WALK_VISION`: the 20 deg recognition field) and the walker body of ``body_class`` built on
    it (``env.gait`` is its gait); a family adds its task (:meth:`_build_task`). Not registered."""

    vision_defaults = WALK_VISION  # the walk family's 20 deg recognition field under vision_params
    body_class: type[WalkerBody] = WalkerBody
    argument_meanings = {  # noqa: RUF012  (read only: the generated Arguments table)
        "gait_params": "``GaitParams`` or dict (``visuomotor_gym.body.walker``)",
        "vision_params": ("``VisionParams`` or a dict of its fields; the default is the walk family's "
                          "(``field_of_view_deg`` = 20)"),
    }

    def __init__(self, render_mode: str | None = None, *, gait_params: GaitParams | dict | None = None,
                 **shared: Any):
        self.gait_params = args.coerce(GaitParams, gait_params, "gait_params")
        super().__init__(render_mode, **shared)

    def _build(self) -> tuple[WalkerBody, Task]:
        body = self.body_class(self.model, self.gait_params)
        self.gait = body.gait
        return body, self._build_task(body)

    def _build_task(self, body: WalkerBody) -> Task:
        """The family's task on ``body`` (called once, after the arguments are checked)."""
        raise NotImplementedError(f"{type(self).__name__} must define _build_task(body)")


class ObstacleWalkEnv(WalkerEnv):
    """
    ## Description

    A walker (pelvis, torso, two 5-DOF legs, neck and the cyclopean eye of every body in this package)
    walks a **winding** 12-14 m walkway, 1.5 m wide (2 m straight from the start, then arcs that turn the
    heading 25-50 deg left or right over 2-3.5 m, between straights of 0.5-1.5 m, the heading kept within
    60 deg of the start's either way), over **rough ground**: small flat patches (a foot must not land on one) and
    low rocks (a leg must not strike one), 15-35 cm across, about one per step, anywhere within 0.5 m of
    the centre line, so that nearly every foothold has to be chosen (``WINDING_COURSE``). It sees them
    **only through a human-like eye**: the same oculomotor plant, foveated noise (Eyecatch Eq. 1-3),
    saccadic suppression and vestibulo-ocular reflex as the catch family, with the **human periphery**
    (``vision.foveation.human_periphery``): the human field (60 deg up, 75 down, 100 to each side;
    Spector 1990), position precision falling with eccentricity (E2 0.7 deg after Levi, Klein &
    Aitsebaomo 1985), crowding (a hazard seen beside another within half its eccentricity is pooled with
    it: Bouma 1970; Parkes et al. 2001), depth precise only near the vergence distance, most of the
    periphery's position error fixed in retinal coordinates (positional disarray, Hess & Field 1993: a
    still eye cannot average it away) and the lateral error drawn as an angle about the eye. A hazard is
    placed to within a few centimetres only when it is looked at, and in a turn the footholds ahead lie
    10-30 deg off the body's heading: the walker has to fixate the footholds ahead, as humans do on rough
    ground 2-3 steps ahead (Matthis, Yates & Hayhoe 2018). The walkway's centre line ahead is given
    (``path_ahead``), not seen. The first definition (bars, boxes and mats on a straight walkway, seen
    within a 20 deg cone, 8 actions) is ``gym.make("ObstacleWalk-v0", **WALKWAY_DEFINITION)``
    (``visuomotor_gym.envs.walk``).

    Walking is a scripted gait with a **footstep-level action** (DeepLoco-style footstep planning):
    the next footstep (length, lateral offset, toe clearance, turn) is read at each mid-stance; the pelvis
    and legs follow analytic inverse kinematics tracked by servos at 500 Hz (``envs_assets/README.md``).
    MuJoCo contacts decide what happens: a leg striking an obstacle is a **trip**, a foot landing on
    one a **misstep**, a foot landing beyond the walkway's painted edges is **off path**. Physics 500 Hz, control 50 Hz. The rungs of the observability ladder are
    keyword arguments of this one class (``visuomotor_gym.registration``).

    ## Action Space

    ``Box(-1, 1, (9,), float32)`` (the turning walker of SteppingStones; on the straight courses,
    ``course_distribution="walkway"``, ``"rough"``, ``"rough_dense"`` or ``"rows"``, 8: no turn);
    ``env.unwrapped.action_structure`` gives the blocks. Finite values outside [-1, 1] are clipped; NaN,
    inf and wrong shapes raise ``ValueError``.

    | index | block | meaning |
    |---|---|---|
    | 0 | footstep | step length, linear onto [0.25, 0.95] m, forward of the other foot's foothold along the new heading |
    | 1 | footstep | lateral offset from the nominal 0.12 m step width (across the new heading), linear onto [-0.3, 0.3] m (+ = left) |
    | 2 | footstep | toe clearance (lowest sole point over the swing's carry phase), linear onto [0.02, 0.45] m |
    | 3 | footstep | turn: the new foothold's heading minus the previous foothold's, linear onto [-45, 45] deg (+ = left; 0 = straight on) |
    | 4-5 | gaze | requested gaze change in retinal coordinates (azimuth, elevation) of the current eye frame, times ``gaze_action_range_deg`` (60 deg); 0 holds gaze fixed in the world |
    | 6 | fixation | fixation (vergence) distance, log-mapped onto [0.1, 20] m; depth is precise only near it (the depth law) |
    | 7-8 | head | head target: neck yaw in [-80, 80] deg and pitch in [-50, 40] deg (negative = down), reached at <= 300 deg/s |

    The footstep is read at the mid-stance of each foot for the next step of that same foot (it lifts
    ~0.3 s later and lands ~0.7 s later): ``gait_phase[2]`` says how long until the next read.

    ## Observation Space

    ``Box(-inf, inf, (N,), float32)`` (N in the table) by default, or with ``obs_mode="dict"`` a
    ``Dict`` of the same blocks. The obstacle blocks are what the eye perceived (true points only with
    ``vision="oracle"``); everything else is proprioception. Each obstacle is seen as four points of its
    top face: the near-left and far-right corners (footprint and height of an axis-aligned box) and the
    midpoints of the near and far edges (where the eye meets a bar too wide for both ends to be in its
    field); the four slots hold the next four obstacles of the course (a slot's obstacle leaves when the pelvis is
    0.5 m past it; the id says which obstacle a slot holds). On the winding walkway the box is turned to
    the path's heading at its centre (its top points are the turned box's).

    OBSERVATION_TABLE

    On the straight courses (``"walkway"``, ``"rough"``, ``"rough_dense"``, ``"rows"``) the walker's
    blocks have no ``foothold_headings`` and there is no ``path_ahead`` (``WALK_LAYOUT``).

    ## Rewards

    A sum of named terms, each in ``info["reward_terms"]``: ``finish`` (+1 when the finish line is
    reached with no trip and no misstep), ``trip`` (-1 on the trip), ``misstep`` (-1 per misstep),
    ``off_path`` (-1 when a foot lands outside the walkway) and ``progress`` (weight 0 by default; x metres walked this step). ``reward_weights`` overrides any
    weight by name.

    ## Starting State

    The walker is in stride at 1.3 m/s, its left heel striking at the start of the path, head
    straight, gaze level along the path. The course is drawn from ``course_distribution``
    (``CourseDistribution`` in ``visuomotor_gym.tasks.obstacle_walk``; by default ``WINDING_COURSE``: 12-14 m
    of winding 1.5 m walkway, a hazard every 0.5-0.9 m along it, the first 2.5-3.5 m ahead) before any vision
    noise, so a seed gives the same course on every rung.

    ## Episode End

    Terminated at the first **trip** (``info["tripped"]``), when a foot lands outside the walkway
    (``info["off_path"]``, a failure), when the pelvis crosses the finish line
    (``info["finished"]``; ``info["is_success"]`` when nothing was tripped over or stepped on: a
    misstep does not end the walk but fails it), or when the physics diverges
    (``info["physics_diverged"]``). Truncated only by the registered ``max_episode_steps`` (2000
    steps = 40 s, three times the nominal walk of the longest course).

    The reset ``info`` holds the course (true state, for scoring only): ``course_length`` and
    ``obstacles``, an array of one row per obstacle (centre x, centre y, depth, width, height, kind)
    padded with NaN rows to the scene's 16 obstacles, of which the first ``n_obstacles`` are the
    course's (a fixed shape, so that ``gymnasium.make_vec`` can stack it).

    **Slots on the rough courses** (the winding default, ``"rough"``, ``"rough_dense"``, ``"rows"``): an
    obstacle is sampled only within 5 m of the pelvis (along the centre line), and a slot's id is a label
    given in the order the eye first saw the obstacle (an obstacle never seen takes no slot; an empty slot
    reads id -1). On ``course_distribution="walkway"`` a slot's id is the course index. Off path, the finish
    and ``to_finish`` count along the centre line; the obstacles are also given in path coordinates
    (``info["obstacles_path"]``; scoring only).

    ## Arguments

    ARGUMENTS_TABLE

    ## Version History

    * v0: initial release; redefined before release: the 1.5 m walkway (off path ends the
      episode), bars across it, four seen points per obstacle. Opt-in ``course_distribution="rough"``
      (prototype): the default course and its observations unchanged. Redefined in place for the moving
      eye: the winding walkway with the rough course's hazards is the default (``WINDING_COURSE``: the
      turning walker, 9 actions, and the centre line ahead, ``path_ahead``; ``course_distribution="walkway"``
      is the former course) and the eye has the human periphery (``human_periphery()``) instead of the
      20 deg cone (``WALKWAY_DEFINITION`` gives the first definition). On the pinned seeds 0-199 iwao
      crosses 91.0 %, its held twin 5.5 % and the best static posture of the eye (searched) 33.5 %:
      gaze gain +57.5, iwao's realism 0.90 (``docs/reproductions/data/terrain/obstacle_walk.md``). Former leaderboard entries
      are superseded.
    """

    render_cameras: ClassVar[dict[str, tuple[str, ...]]] = {
        "both": (wn.WALKER_SIDE_CAMERA, names.EYE_CAMERA),
        "side": (wn.WALKER_SIDE_CAMERA,),
        "follow": (wn.WALKER_FOLLOW_CAMERA,),
        "scene": (wn.WALKER_SCENE_CAMERA,),
        "eye": (names.EYE_CAMERA,),
    }
    eye_camera = names.EYE_CAMERA

    default_reward_weights = DEFAULT_REWARD_WEIGHTS
    reward_terms = REWARD_TERMS
    argument_meanings = {  # noqa: RUF012  (read only: the generated Arguments table)
        "course_distribution": ('``CourseDistribution``, dict, or a preset name: ``"winding"`` (``WINDING_COURSE``, '
                                'the default: the rough course on a walkway that turns left and right, the turning '
                                'walker (9 actions) and the centre line ahead (``path_ahead``)), ``"rough"`` '
                                '(``ROUGH_COURSE``: small hazards on most footholds of a straight walkway, 8 actions), '
                                '``"rough_dense"`` (``DENSE_ROUGH_COURSE``: the same, a hazard every 0.45-0.8 m), '
                                '``"rows"`` (``ROWS_COURSE``: rows of patches across the walkway, one gap each) or '
                                '``"walkway"`` (the first definition\'s course: bars, boxes and mats)'),
        "vision": ('``"foveated"``, ``"full_view"`` (foveal noise everywhere, no field-of-view limit, no saccadic '
                   'blindness) or ``"oracle"`` (true corners)'),
        "vision_params": ("``VisionParams`` or a dict of its fields; the default is the human periphery "
                          "(``vision.foveation.human_periphery()``: human field, position law, crowding, depth law, "
                          "positional disarray, angular lateral noise) over the walk family's"),
        "render_camera": '``"both"`` (side view beside the eye view), ``"side"``, ``"follow"``, ``"scene"``, ``"eye"``',
    }
    scene = wn.WALKER_SCENE
    vision_defaults = OBSTACLE_WALK_VISION

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        course_distribution: CourseDistribution | dict | str | None = None,
        **shared: Any,
    ):
        if course_distribution is None:
            course_distribution = WINDING_COURSE
        if isinstance(course_distribution, str):
            course_distribution = COURSE_PRESETS[args.choice(course_distribution, tuple(COURSE_PRESETS),
                                                             "course_distribution")]
        self.course_distribution = args.coerce(CourseDistribution, course_distribution, "course_distribution")
        if self.course_distribution.layout == "winding":
            # The winding walkway (opt-in): the turning walker of SteppingStones (a fourth footstep value, the
            # turn; the foothold_headings block) and the centre line ahead (path_ahead): WINDING_LAYOUT.
            self.body_class = TurningWalkerBody
        super().__init__(render_mode, **shared)

    def _build_task(self, body: WalkerBody) -> ObstacleWalkTask:
        return ObstacleWalkTask(self.model, body, course_distribution=self.course_distribution,
                                reward_weights=self.reward_weights, visual_delay_s=self.visual_delay_s,
                                n_substeps=self.n_substeps)

    @property
    def course(self):
        """This episode's course (:class:`~visuomotor_gym.tasks.obstacle_walk.Course`; true state)."""
        return self.task.course


assert WALK_LAYOUT.structure == {b.name: b.size for b in WALK_LAYOUT.blocks}
assert len(PERCEPT_BLOCKS) == K_SLOTS
if ObstacleWalkEnv.__doc__:
    ObstacleWalkEnv.__doc__ = ObstacleWalkEnv.__doc__.replace(
        "OBSERVATION_TABLE", "\n    ".join(WINDING_LAYOUT.markdown_table().splitlines())
    ).replace("(N,)", f"({WINDING_LAYOUT.size},)").replace("(N in the table)", "")


# ---------------------------------------------------------------- the family record (visuomotor_gym.family)
from visuomotor_gym.family import Family, FollowView, Viz

WALK_MAX_EPISODE_STEPS = 2000  # 40 s at 50 Hz: three times the nominal walk (1.3 m/s) of the longest (20 m) course

FAMILY = Family(
    name="walk",
    prefix="ObstacleWalk",
    entry_point="visuomotor_gym.envs.walk:ObstacleWalkEnv",
    max_episode_steps=WALK_MAX_EPISODE_STEPS,
    oracle_sees="obstacle",
    body="walker",
    vision_defaults=OBSTACLE_WALK_VISION,  # the human periphery (vision.foveation.human_periphery)
    summariser="visuomotor_gym.metrics.walk_realism:walk_summary",
    miss_distance="visuomotor_gym.metrics.walk_realism:distance_left",
    outcome_labels=("success rate", "time to finish (s)", "distance left, failed walks (m)"),
    agents=("iwao",),
    golden_agent="iwao",
    viz=Viz(
        figure="visuomotor_gym.viz.family_plots:walk_figure",
        contents="top view of the walkway: obstacles by kind and height, pelvis path, footholds, where the gaze "
                 "meets the floor or an obstacle (coloured by time); side view of obstacle and sole heights; gaze "
                 "angles and look-ahead distance over time",
        trace_field="obstacles",
        # From behind and to the right, above: the legs and the next 3-4 m of walkway with its obstacles.
        scene_view=FollowView(distance=5.0, azimuth=55.0, elevation=-28.0, offset=(1.6, 0.0, -0.6)),
        video_stride=2,
    ),
    doc_links=(("Iwao et al.: gaze while walking over obstacles", "reproductions/iwao.md"),
               ("PPO baselines (the walk recipe)", "baselines/ppo.md")),
    doc_pictures=(("images/obstaclewalk_iwao_seed0_frame.png",
                   "The iwao agent on the winding walkway: its line of sight on a floor hazard, and its eye camera"),),
)
