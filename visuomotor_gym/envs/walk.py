"""ObstacleWalk: walk a path across obstacles seen only through a foveated, saccading eye (Iwao
et al.).

``ObstacleWalkEnv`` composes the embodiment core (:mod:`visuomotor_gym.core`), the walker
(:mod:`visuomotor_gym.body.walker_body` over the scripted gait of :mod:`visuomotor_gym.body.walker`)
and the obstacle-walk task (:mod:`visuomotor_gym.tasks.obstacle_walk`).
"""

from __future__ import annotations

from typing import Any, ClassVar

from visuomotor_gym.body import names
from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.walker import GaitParams
from visuomotor_gym.body.walker_body import WALKER_BLOCKS, WalkerBody
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
    CourseDistribution,
    ObstacleWalkTask,
)
from visuomotor_gym.vision.foveation import VisionParams

__all__ = ["OBSTACLE_VIEW_ANGLE_DEG", "WALK_LAYOUT", "WALK_VISION", "ObstacleWalkEnv", "WalkerEnv"]

RENDER_CAMERAS = ("both", "side", "follow", "scene", "eye")
# The field in which an obstacle is seen at all: Iwao et al.'s view angle for obstacle recognition
# while walking, theta_Vmax = 20 deg (Iwao et al., Sec. 4.2.3: walkers look at an obstacle "indirectly",
# within their view angle; 20 deg walking, 30 deg running), instead of the eye's whole +-60 deg field
# (Eom et al.) of the catch family. The noise law is the same. Measured (docs/reproductions/iwao.md):
# with +-60 deg a gaze-blind twin that fuses its peripheral samples (iwao:gaze_blind=true) crossed 29 of
# 30 courses, so looking would not be tested; with 20 deg it fails most of them.
OBSTACLE_VIEW_ANGLE_DEG = 20.0
WALK_VISION = VisionParams(field_of_view_deg=OBSTACLE_VIEW_ANGLE_DEG)
WALK_LAYOUT = ObservationLayout(PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + WALKER_BLOCKS + TRAILING_BLOCKS)


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
    walks a straight 15-20 m walkway, 1.5 m wide, across bars that span it and boxes 5-30 cm high and
    flat 70 cm mats, **seeing them only through a human-like eye**: the same oculomotor plant, foveated noise (Eyecatch Eq. 1-3),
    field of view, saccadic suppression and vestibulo-ocular reflex as the catch family. An obstacle
    2 m ahead lies ~40 deg below a level gaze, where the noise is ~20x the fovea's: to place its feet
    the walker has to look down (Iwao et al.; Patla & Vickers 1997). An obstacle is seen
    only within **20 deg of the line of sight**, Iwao et al.'s view angle for obstacle recognition while
    walking (Iwao et al., Sec. 4.2.3), not the eye's whole +-60 deg field: with the whole field, a
    walker whose gaze stays level fused enough peripheral glimpses to cross 29 of 30 courses.

    Walking is a scripted gait with a **footstep-level action** (DeepLoco-style footstep planning):
    the next footstep (length, lateral offset, toe clearance) is read at each mid-stance; the pelvis
    and legs follow analytic inverse kinematics tracked by servos at 500 Hz (``envs_assets/README.md``).
    MuJoCo contacts decide what happens: a leg striking an obstacle is a **trip**, a foot landing on
    one a **misstep**, a foot landing beyond the walkway's painted edges is **off path**. Physics 500 Hz, control 50 Hz. The rungs of the observability ladder are
    keyword arguments of this one class (``visuomotor_gym.registration``).

    ## Action Space

    ``Box(-1, 1, (8,), float32)``; ``env.unwrapped.action_structure`` gives the blocks. Finite values
    outside [-1, 1] are clipped; NaN, inf and wrong shapes raise ``ValueError``.

    | index | block | meaning |
    |---|---|---|
    | 0 | footstep | step length, linear onto [0.25, 0.95] m, forward of the other foot's foothold |
    | 1 | footstep | lateral offset from the nominal 0.12 m step width, linear onto [-0.3, 0.3] m (+ = left) |
    | 2 | footstep | toe clearance (lowest sole point over the swing's carry phase), linear onto [0.02, 0.45] m |
    | 3-4 | gaze | requested gaze change in retinal coordinates (azimuth, elevation) of the current eye frame, times ``gaze_action_range_deg`` (60 deg); 0 holds gaze fixed in the world |
    | 5 | fixation | fixation (vergence) distance, log-mapped onto [0.1, 20] m; does not change the noise in v0 |
    | 6-7 | head | head target: neck yaw in [-80, 80] deg and pitch in [-50, 40] deg (negative = down), reached at <= 300 deg/s |

    The footstep is read at the mid-stance of each foot for the next step of that same foot (it lifts
    ~0.3 s later and lands ~0.7 s later): ``gait_phase[2]`` says how long until the next read.

    ## Observation Space

    ``Box(-inf, inf, (N,), float32)`` (N in the table) by default, or with ``obs_mode="dict"`` a
    ``Dict`` of the same blocks. The obstacle blocks are what the eye perceived (true points only with
    ``vision="oracle"``); everything else is proprioception. Each obstacle is seen as four points of its
    top face: the near-left and far-right corners (footprint and height of an axis-aligned box) and the
    midpoints of the near and far edges (where the eye meets a bar too wide for both ends to be in its
    field); the four slots hold the next four obstacles of the course (a slot's obstacle leaves when the pelvis is
    0.5 m past it; the id says which obstacle a slot holds).

    OBSERVATION_TABLE

    ## Rewards

    A sum of named terms, each in ``info["reward_terms"]``: ``finish`` (+1 when the finish line is
    reached with no trip and no misstep), ``trip`` (-1 on the trip), ``misstep`` (-1 per misstep),
    ``off_path`` (-1 when a foot lands outside the walkway) and ``progress`` (weight 0 by default; x metres walked this step). ``reward_weights`` overrides any
    weight by name.

    ## Starting State

    The walker is in stride at 1.3 m/s, its left heel striking at the start of the path, head
    straight, gaze level along the path. The course is drawn from ``course_distribution``
    (``CourseDistribution`` in ``visuomotor_gym.tasks.obstacle_walk``: 15-20 m of 1.5 m walkway; bars,
    boxes and mats with free gaps of 1.6-3 m, the first 3-4.5 m ahead) before any vision noise, so a seed gives the
    same course on every rung.

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

    **The rough course** (opt-in, ``course_distribution="rough"``; ``ROUGH_COURSE`` in
    ``visuomotor_gym.tasks.obstacle_walk``): 12-14 m with up to 16 small patches and rocks (15-35 cm,
    about one per step, anywhere across the walkway), so that nearly every foothold must be chosen. On it
    an obstacle is sampled only within 5 m of the pelvis, and a slot's id is a label given in the order
    the eye first saw the obstacle (an obstacle never seen takes no slot; an empty slot reads id -1).

    ## Arguments

    ARGUMENTS_TABLE

    ## Version History

    * v0: initial release; redefined before release: the 1.5 m walkway (off path ends the
      episode), bars across it, four seen points per obstacle. Opt-in ``course_distribution="rough"``
      (prototype): the default course and its observations unchanged.
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
        "course_distribution": ('``CourseDistribution``, dict, or a preset name: ``"walkway"`` (the default) or '
                                '``"rough"`` (``ROUGH_COURSE``: small hazards on most footholds, opt-in) or ``"rough_dense"`` '
                                '(``DENSE_ROUGH_COURSE``: the same, a hazard every 0.45-0.8 m, opt-in)'),
        "vision": ('``"foveated"``, ``"full_view"`` (foveal noise everywhere, no field-of-view limit, no saccadic '
                   'blindness) or ``"oracle"`` (true corners)'),
        "vision_params": ("``VisionParams`` or a dict of its fields; the default is the catch family's except "
                          "``field_of_view_deg`` = 20 (see below)"),
        "render_camera": '``"both"`` (side view beside the eye view), ``"side"``, ``"follow"``, ``"scene"``, ``"eye"``',
    }
    scene = wn.WALKER_SCENE

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        course_distribution: CourseDistribution | dict | str | None = None,
        **shared: Any,
    ):
        if isinstance(course_distribution, str):
            course_distribution = COURSE_PRESETS[args.choice(course_distribution, tuple(COURSE_PRESETS),
                                                             "course_distribution")]
        self.course_distribution = args.coerce(CourseDistribution, course_distribution, "course_distribution")
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
        "OBSERVATION_TABLE", "\n    ".join(WALK_LAYOUT.markdown_table().splitlines())
    ).replace("(N,)", f"({WALK_LAYOUT.size},)").replace("(N in the table)", "")


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
    vision_defaults=WALK_VISION,  # Iwao's 20 deg recognition field
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
                   "The iwao agent on ObstacleWalk-v0: side view with the line of sight, and its eye camera"),),
)
