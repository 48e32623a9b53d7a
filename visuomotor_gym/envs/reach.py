"""ShelfReach: reach an object on one of 30 shelf targets while seeing it only through a foveated eye.

``ShelfReachEnv`` composes the embodiment core (:mod:`visuomotor_gym.core`), the seated body in its
reaching form (:mod:`visuomotor_gym.body.reach_body`) and the shelf-reach task
(:mod:`visuomotor_gym.tasks.reach`); this module holds its public signature, argument checks and
documentation.
"""

from __future__ import annotations

from typing import Any, ClassVar

from visuomotor_gym.body import names, reach_names
from visuomotor_gym.body.reach_body import (
    BEZIER_OFFSET_RANGE,
    HAND_ACTIONS,
    REACH_DURATION_RANGE_S,
    REACH_PROGRESS_BLOCK,
    ReachSeatedBody,
)
from visuomotor_gym.body.seated import CONTROL_MODES, SEATED_BLOCKS
from visuomotor_gym.control.hand import HandControlParams
from visuomotor_gym.core import args
from visuomotor_gym.core.env import VisuomotorEnv
from visuomotor_gym.core.eye import EYE_BLOCKS
from visuomotor_gym.core.head import HEAD_BLOCKS
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.tasks.reach import (
    OBJECT_PERCEPT_BLOCKS,
    REWARD_TERMS,
    SHAPED_WEIGHTS,
    SPARSE_WEIGHTS,
    TIME_BLOCK,
    ReachTask,
)
from visuomotor_gym.vision.foveation import human_periphery

__all__ = ["REACH_VISION", "ShelfReachEnv", "reach_observation"]

# The human periphery, every family's eye (vision.foveation.HUMAN_PERIPHERY: the human field of Spector 1990,
# the position law E2 0.7 deg, crowding b = 0.5 after Bouma 1970, the depth pedestal 10 arcmin, the positional
# disarray 0.8 of Hess & Field 1993), in place of the catch
# family's +-60 deg field with the acuity law alone.
REACH_VISION = human_periphery()
# Full shelves: every other target holds a distractor of the object's kind (modelling choice: a stocked shelf,
# as a cupboard a person fetches one cup from; with the object alone the periphery's position law already
# guides a reach from a still eye -- docs/reproductions/faraway.md).
SHELF_CLUTTER = reach_names.N_DISTRACTORS

REWARD_MODES = ("sparse", "shaped")
RENDER_CAMERAS = ("both", "scene", "eye", "over_shoulder", "top")


def reach_observation(hand_action: str = "target"):
    """The observation blocks of ShelfReach, in order."""
    extra = (REACH_PROGRESS_BLOCK,) if hand_action == "bezier" else ()
    return OBJECT_PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + SEATED_BLOCKS + extra + (TIME_BLOCK,)


class ShelfReachEnv(VisuomotorEnv):
    """
    ## Description

    The seated upper body of the catch family (3-DOF torso, 7-DOF right arm, 2-DOF neck, cyclopean
    eye) must reach, with its right hand, an object standing on one of **30 shelf targets: three
    towers (in front, 45 deg to the right, 90 deg to the right) x five heights x two depths**, the
    layout of Faraway, Reed & Wang (2007), whose Bézier model of human hand paths is the
    realism reference of this family (``visuomotor_gym.handpath``). The object is seen **only through
    the eye**: its position reaches the agent as samples of the foveated noise model (Eyecatch Eq. 1-3;
    depth noise 5 % of the distance at the fovea, growing with eccentricity), nothing during a saccade,
    with the **human periphery** (``vision.foveation.human_periphery``): the human field (60 deg up, 75
    down, 100 to each side; Spector 1990), position precision falling with eccentricity (E2 0.7 deg after
    Levi, Klein & Aitsebaomo 1985), crowding (Bouma 1970) and depth precise only near the vergence
    distance (the fixation action). The shelves are **full**: the other 29 targets each hold a distractor,
    a cylinder of the object's size (``shelf_clutter``), which the eye sees as objects of the same kind,
    so that in the periphery crowding pools them with the object (a sample at the mean of the group);
    the observation carries the object's sample only (the agent knows which object it fetches). The gaze
    starts on the front tower; a saccade (and for the right-hand tower a head turn) to the object makes
    its position and depth precise.

    Physics 500 Hz, control 50 Hz. The observability ladder (Oracle, FullView, foveated, Delayed,
    PoorVision) is keyword arguments of this class (``visuomotor_gym.registration``).

    ## Action Space

    One ``Box(-1, 1, (9,), float32)`` with ``hand_action="target"`` (default; ``(16,)`` with
    ``control="joint"``, ``(17,)`` with ``hand_action="bezier"``). ``env.unwrapped.action_structure``
    gives the blocks. Finite values outside [-1, 1] are clipped; NaN, inf and wrong shapes raise.

    ACTION_TABLE

    ## Observation Space

    ``Box(-inf, inf, (OBS_SIZE,), float32)`` (one more with ``hand_action="bezier"``), or with
    ``obs_mode="dict"`` a ``Dict`` of the same blocks; ``env.unwrapped.observation_structure`` maps
    names to sizes. The object blocks are what the eye perceived (true position only with
    ``vision="oracle"``); everything else is proprioception.

    OBSERVATION_TABLE

    With ``hand_action="bezier"``, ``reach_progress`` (1 value: relative time of the reach in
    progress, 0 when none) comes before ``time``.

    ## Rewards

    A sum of named terms, each in ``info["reward_terms"]``. ``reward="sparse"`` (default): ``reach`` =
    +1 on the step of success. ``reward="shaped"`` adds ``panel_hit`` (-0.2 once), ``approach`` (-0.01 x
    hand-object distance in m), ``foveation`` (+0.005 x exp(-(eccentricity/5 deg)^2) when the object is
    seen) and ``effort`` (-0.001 x mean squared action). ``reward_weights`` overrides any weight by name.

    ## Starting State

    The body sits upright with the hand at its home posture, in front of the belly near the midline
    (~(0.32, -0.05, 0.74) m: the seated analogue of Faraway et al.'s home shelf). The target is drawn
    uniformly from the 30, with a +-1 cm jitter on its board; the gaze starts on the front tower's middle
    level between its two depths, with a 2 deg Gaussian jitter. Then ``shelf_clutter`` of the other 29
    targets (all of them by default) are drawn to hold a distractor, at the target's centre. The same seed
    gives the same target and the same distractors on every rung of the ladder, and the same target for
    any ``shelf_clutter``. ``info`` at reset: ``target_index`` (0-29: tower-major, then level, then
    depth), ``tower``, ``level``, ``depth``, ``object_pos``, ``hand_home``, ``distractor_indices``.

    ## Episode End

    Terminated on **success** (``info["is_success"]``, ``info["reached"]``): the object's centre within
    ``reach_radius`` of the catch site with the fingers closed beyond ``grasp_closed_fraction`` and the
    hand slower than ``arrival_speed_m_s``; on a **panel touch** (``info["panel_hit"]``: any contact between
    the body and a tower's back panel, checked every physics substep); or on a physics divergence.
    Truncated by the registered ``max_episode_steps`` (150 steps = 3 s). The boards under the objects and
    the distractors are seen but not touched: the hand passes through a distractor (modelling choice: the
    task is to find and reach the object, not to avoid its neighbours; see ``envs_assets/README.md``,
    ShelfReach).

    ## Arguments

    ARGUMENTS_TABLE

    ## Version History

    * v0: initial release. Redefined in place: the eye has the human periphery (``human_periphery()``)
      instead of the +-60 deg field with the acuity law alone (``vision_params=VisionParams()`` gives the
      former eye). On the pinned seeds 0-199 faraway reaches 100 %, its held twin 82.5 % and the best
      static posture of the eye 99.0 % (docs/reproductions/faraway.md). Former leaderboard entries are
      superseded.
    * v0: redefined in place again: full shelves (``shelf_clutter=29``: a distractor of the object's size
      on each of the other 29 targets, crowding pools them with the object in the periphery;
      ``shelf_clutter=0`` gives the scene above). The same seed draws the same object as before. On the
      pinned seeds 0-199 faraway reaches 99.5 %, its held twin 23.5 % and the best static posture 29.0 %:
      gaze gain +70.5 (docs/reproductions/faraway.md). Former leaderboard entries are superseded.
    * v0: redefined in place (one eye for every family): ``human_periphery()`` now includes the positional
      disarray (0.8 of the periphery's added lateral variance fixed in retinal coordinates, Hess & Field
      1993). On the pinned seeds faraway reaches 98.0 %, its held twin 25.5 % and the best static posture
      (searched again) 26.5 %: gaze gain +71.5. ``vision_params={"position_disarray": 0.0}`` gives the
      eye above. Former leaderboard entries are superseded.
    """

    render_cameras: ClassVar[dict[str, tuple[str, ...]]] = {
        "both": (reach_names.SCENE_CAMERA, names.EYE_CAMERA),
        "scene": (reach_names.SCENE_CAMERA,),
        "eye": (names.EYE_CAMERA,),
        "over_shoulder": (reach_names.OVER_SHOULDER_CAMERA,),
        "top": (reach_names.TOP_CAMERA,),
    }
    eye_camera = names.EYE_CAMERA

    vision_defaults = REACH_VISION
    reward_terms = REWARD_TERMS
    scene = reach_names.SCENE
    argument_meanings = {  # noqa: RUF012  (read only: the generated Arguments table)
        "control": '``"hand"`` (Cartesian) or ``"joint"``',
        "hand_action": ('``"target"`` (a hand target each step) or ``"bezier"`` (reaches as cubic Bézier curves: end '
                        'point, two interior control-point offsets, duration; needs ``control="hand"``)'),
        "reward": '``"sparse"`` or ``"shaped"``',
        "hand_params": "``HandControlParams`` or dict (2 m/s cap, DLS damping)",
        "reach_radius": "success radius (m) around the catch site (the catch family's catch volume)",
        "grasp_closed_fraction": "finger closure above which the hand counts as closed",
        "arrival_speed_m_s": ("the hand must be slower than this (m/s) to count as arrived (modelling choice: "
                              "arriving, not sweeping past)"),
        "vision_params": ("``VisionParams`` or a dict of its fields; the default is the human periphery "
                          "(``vision.foveation.human_periphery()``: human field, position law, crowding, depth law, "
                          "positional disarray)"),
        "shelf_clutter": ("how many of the other 29 targets hold a distractor (a cylinder of the object's size, seen "
                          "as a target of its kind: crowding pools it with the object), drawn per episode; 0 gives "
                          "the former scene with the object alone"),
        "vision": '``"foveated"``, ``"full_view"`` or ``"oracle"`` (true object position)',
        "render_camera": ('``"both"`` (scene beside eye view), ``"scene"``, ``"eye"``, ``"over_shoulder"``, '
                          '``"top"``'),
    }

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        control: str = "hand",
        hand_action: str = "target",
        reward: str = "sparse",
        hand_params: HandControlParams | dict | None = None,
        reach_radius: float = 0.06,
        grasp_closed_fraction: float = 0.6,
        arrival_speed_m_s: float = 0.5,
        shelf_clutter: int = SHELF_CLUTTER,
        **shared: Any,
    ):
        self.control = args.choice(control, CONTROL_MODES, "control")
        self.hand_action = args.choice(hand_action, HAND_ACTIONS, "hand_action")
        if self.hand_action == "bezier" and self.control != "hand":
            raise ValueError("hand_action='bezier' needs control='hand'")
        self.hand_params = args.coerce(HandControlParams, hand_params, "hand_params")
        self.reach_radius = args.real(reach_radius, "reach_radius", low=0.0, high=0.5, low_open=True)
        self.grasp_closed_fraction = args.real(grasp_closed_fraction, "grasp_closed_fraction", low=0.0, high=1.0,
                                               low_open=True)
        self.arrival_speed_m_s = args.real(arrival_speed_m_s, "arrival_speed_m_s", low=0.0, high=100.0, low_open=True)
        self.reward_mode = args.choice(reward, REWARD_MODES, "reward")
        self.shelf_clutter = args.integer(shelf_clutter, "shelf_clutter", low=0, high=reach_names.N_DISTRACTORS)
        super().__init__(render_mode, **shared)

    def _default_reward_weights(self) -> dict[str, float]:
        return SPARSE_WEIGHTS if self.reward_mode == "sparse" else SHAPED_WEIGHTS

    def _build(self) -> tuple[ReachSeatedBody, ReachTask]:
        body = ReachSeatedBody(self.model, self.control, self.hand_params, self.dt, hand_action=self.hand_action)
        task = ReachTask(
            self.model, body, reach_radius=self.reach_radius, grasp_closed_fraction=self.grasp_closed_fraction,
            arrival_speed_m_s=self.arrival_speed_m_s, reward_weights=self.reward_weights, dt=self.dt,
            visual_delay_s=self.visual_delay_s, clutter=self.shelf_clutter,
        )
        self.hand = body.hand
        return body, task

    @property
    def target_index(self) -> int:
        """This episode's target (0-29)."""
        return self.task.target_index


def _action_table() -> str:
    from visuomotor_gym.body.seated import HAND_WORKSPACE

    (x0, x1), (y0, y1), (z0, z1) = HAND_WORKSPACE.tolist()
    lo, hi = REACH_DURATION_RANGE_S
    rows = [
        "| index (target) | index (joint) | index (bezier) | meaning |",
        "|---|---|---|---|",
        f"| 0-2 | - | 0-2 | hand target (catch-site centre; with bezier: the reach's end point), seat frame, mapped from [-1, 1] to x in [{x0}, {x1}], y in [{y0}, {y1}], z in [{z0}, {z1}] m |",
        "| - | 0-9 | - | torso (3) and arm (7) joint setpoints, mapped onto each joint's range |",
        f"| - | - | 3-5, 6-8 | interior control-point offsets Y1, Y2 per metre of reach, body frame (lateral right, forward, up), [-1, 1] onto [-{BEZIER_OFFSET_RANGE}, {BEZIER_OFFSET_RANGE}] (Faraway et al.'s axis parameterisation; 0 = straight) |",
        f"| - | - | 9 | reach duration, [-1, 1] onto [{lo}, {hi}] s |",
        "| - | - | 10 | reach start: > 0 starts a reach from the hand reference when none is in progress |",
        "| 3 | 10 | 11 | grasp: -1 open ... 1 closed |",
        "| 4-5 | 11-12 | 12-13 | requested gaze change (azimuth, elevation) of the current eye frame, times ``gaze_action_range_deg`` |",
        "| 6 | 13 | 14 | fixation (vergence) distance, log-mapped onto [0.1, 20] m |",
        "| 7-8 | 14-15 | 15-16 | head target: neck yaw in [-80, 80] deg and pitch in [-50, 40] deg |",
    ]
    return "\n    ".join(rows)


if ShelfReachEnv.__doc__:
    _layout = ObservationLayout(reach_observation())
    ShelfReachEnv.__doc__ = (ShelfReachEnv.__doc__
                             .replace("OBSERVATION_TABLE", "\n    ".join(_layout.markdown_table().splitlines()))
                             .replace("ACTION_TABLE", _action_table())
                             .replace("OBS_SIZE", str(_layout.size)))


# ---------------------------------------------------------------- the family record (visuomotor_gym.family)
from visuomotor_gym.family import Family, Viz

REACH_MAX_EPISODE_STEPS = 150  # 3 s at 50 Hz: first saccade (~0.2 s), fixation, a ~0.6-1 s reach, slack (modelling choice)

FAMILY = Family(
    name="reach",
    prefix="ShelfReach",
    entry_point="visuomotor_gym.envs.reach:ShelfReachEnv",
    max_episode_steps=REACH_MAX_EPISODE_STEPS,
    oracle_sees="object",
    body="seated",
    vision_defaults=REACH_VISION,  # the human periphery (vision.foveation.human_periphery)
    summariser="visuomotor_gym.metrics.reach_realism:reach_summary",
    miss_distance="visuomotor_gym.metrics.reach_realism:closest_distance",
    outcome_labels=("success rate", "time to success (s)", "closest distance, failed reaches (m)"),
    reaction_from_t0=True,  # the object appears at t = 0
    agents=("faraway",),
    golden_agent="faraway",
    viz=Viz(
        figure="visuomotor_gym.viz.family_plots:reach_figure",
        contents="top and side view of the shelf: object, hand path, gaze point at the object's distance (coloured "
                 "by time); gaze and object angles, gaze-object angle, hand-object distance and hand speed over time",
        trace_field="object_pos",
        scene_view="scene_camera",
        video_stride=1,
    ),
    doc_links=(("Faraway et al. 2007: reaches as Bézier curves", "reproductions/faraway.md"),),
    doc_pictures=(("images/shelfreach_record_frame.png", "The faraway agent reaching to a shelf target"),
                  ("reproductions/images/faraway_reach_paths.png",
                   "Hand paths of the faraway agent to the shelf targets")),
)
