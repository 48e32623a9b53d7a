"""PushRecovery: stay upright after a push by putting a hand on a wall of cube blocks, seen only
through a foveated eye (Eom et al. 2019, section 7, "Balancing after a push").

``PushRecoveryEnv`` composes the embodiment core (:mod:`visuomotor_gym.core`), the standing body
(:mod:`visuomotor_gym.body.standing`) and the push-recovery task
(:mod:`visuomotor_gym.tasks.push_recovery`); this module holds its public signature, argument checks
and documentation, and ends with the family record.
"""

from __future__ import annotations

from typing import Any, ClassVar

from visuomotor_gym.body import names
from visuomotor_gym.body import standing as sn
from visuomotor_gym.body.standing import STANDING_BLOCKS, StandingBody
from visuomotor_gym.control.hand import HandControlParams
from visuomotor_gym.core import args
from visuomotor_gym.core.env import VisuomotorEnv
from visuomotor_gym.core.eye import EYE_BLOCKS
from visuomotor_gym.core.head import HEAD_BLOCKS
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.tasks import push_recovery as pr
from visuomotor_gym.tasks.push_recovery import (
    BLOCK_PERCEPT_BLOCKS,
    REWARD_TERMS,
    SHAPED_WEIGHTS,
    SPARSE_WEIGHTS,
    TIME_BLOCK,
    PushRecoveryTask,
)
from visuomotor_gym.vision.foveation import human_periphery

__all__ = ["PushRecoveryEnv", "push_observation"]

REWARD_MODES = ("sparse", "shaped")
# The family's eye: human peripheral vision, the four mechanisms of vision.foveation.HUMAN_PERIPHERY (human
# field, position law E2 0.7 deg, crowding, depth pedestal 10 arcmin) with the retinotopic positional disarray at
# 0.8 (Hess & Field 1993; the suite's one eye); see docs/reproductions/gaze_default.md, "The human periphery,
# mechanism by mechanism".
PUSH_VISION = human_periphery(position_disarray=0.8)


def push_observation():
    """The observation blocks of PushRecovery, in order."""
    return BLOCK_PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + STANDING_BLOCKS + (TIME_BLOCK,)


class PushRecoveryEnv(VisuomotorEnv):
    """
    ## Description

    A **standing body that can fall** (the walker's legs and pelvis on a free joint, standing on the
    floor through real foot contact, the seated body's waist, its 7-DOF right arm and that arm mirrored as
    the left, the shared head and cyclopean eye; ``envs_assets/push.xml``) stands beside a **wall of cube
    blocks** (Eom et al. 2019, section 7) on its right or its left (drawn per episode, 50/50), the wall
    turned 0-30 deg forward per episode. Between 1.0 and 2.0 s after the start
    a **push** (a 150 ms horizontal force of 300-350 N on the torso, along the wall's normal within +-10 deg)
    tips it toward the wall: the legs hold their stance through position servos with an automatic ankle
    response to the extrapolated centre of mass, but cannot stop the fall (a centre of mass carried past the
    feet's edge falls). It stays upright only if a hand lands on a cube and holds: **there is nothing
    behind or between the cubes**, so a hand that lands in a gap, slides off an edge or stops short of
    the wall does not hold. Some cubes are **loose** (they give way under a hand: modelled as cubes that collide
    with nothing, a simplification): of the two cubes nearest the bracing shoulder exactly one, each other cube with
    probability 1/2; whether a cube is firm is seen only by **central vision** (``block_firm``: a line of sight within
    2 atan(1 cm / d) of the cube's face, 1.4-1.9 deg at 0.6-0.8 m, from Bouma's law on a 1 cm texture; not during a
    saccade). The wall's distance (0.60-0.80 m from the body's midline), each cube's size
    (14-22 cm), the gaps (12-30 cm), the cubes' heights (1.00-1.35 m) and how far each stands out of the
    wall (0-10 cm)
    are drawn per episode and reach the agent only as the eye's samples of the cubes' faces (foveated
    noise, field of view, saccadic suppression, delay): where the eye looks decides where the hand can go.
    The eye has the **human periphery** (``vision.foveation.human_periphery(position_disarray=0.8)``: the
    human field, position law E2 0.7 deg, crowding, depth pedestal 10 arcmin, positional disarray 0.8), as
    every family's.

    Physics 500 Hz, control 50 Hz. The observability ladder (Oracle, FullView, foveated, Delayed,
    PoorVision) is keyword arguments of this class (``visuomotor_gym.registration``).

    ## Action Space

    ``Box(-1, 1, (10,), float32)``; ``env.unwrapped.action_structure`` gives the blocks. Finite values
    outside [-1, 1] are clipped; NaN, inf and wrong shapes raise.

    ACTION_TABLE

    ## Observation Space

    ``Box(-inf, inf, (OBS_SIZE,), float32)``, or with ``obs_mode="dict"`` a ``Dict`` of the same blocks;
    ``env.unwrapped.observation_structure`` maps names to sizes. The block percepts are what the eye
    perceived (true face centres only with ``vision="oracle"``); everything else is proprioception,
    including a vestibular signal of the push and the feet's centre of pressure.

    OBSERVATION_TABLE

    ## Rewards

    A sum of named terms, each in ``info["reward_terms"]``. ``reward="sparse"`` (default): ``upright`` =
    +1 on the step of success. ``reward="shaped"`` adds ``fall`` (-1 on the step of a fall) and ``effort``
    (-0.001 x mean squared action). ``reward_weights`` overrides any weight by name.

    ## Starting State

    Standing still, legs straight, feet at shoulder width (sole centres 32 cm apart), the hand in front of the belly, looking straight
    ahead (3 m away at 1.3 m height, with a 2 deg Gaussian jitter); the right arm drives, the left hangs.
    ``info`` at reset: ``block_faces`` ((n, 3) true face centres), ``block_half_sizes``, ``push_time``,
    ``push_force``, ``push_dir``, ``wall_distance``, ``wall_side`` (-1 right, +1 left), ``block_loose`` (scoring
    only). The same seed gives the same wall and push on every rung.

    ## Episode End

    Terminated on **success** (``info["is_success"]``): upright 2.5 s after the push's onset; on a
    **fall** (``info["fallen"]``): a contact between the floor or a cube and any body geom other than
    the feet and the palm, or the head below 1.0 m (checked after every physics substep); or on a physics
    divergence. Truncated by the registered ``max_episode_steps`` (250 steps = 5 s; never reached: the
    push comes by 2.0 s and the episode ends 2.5 s later).

    ## Arguments

    ARGUMENTS_TABLE

    ## Version History

    * v0: initial release. Redefined in place for the moving eye: the eye has the human periphery
      (``human_periphery()``) instead of the acuity law with a 60 deg cone. On the pinned seeds 0-199 the
      best static posture of the eye (with eom_brace) held 72 % of the bodies upright under the former
      eye and holds 73.5 % under this one (verged at 0.5 m; eom_brace 82 % and 77.5 %). Former
      leaderboard entries are superseded.
    * v0, redefined in place again (PushRecovery's fourth pass): the wall turned 0-30 deg forward per episode (the
      cube the hand needs moves up to ~25 cm and ~30 deg of gaze), the stance's automatic ankle response on,
      and the eye with the positional disarray at 0.8 (the suite's one eye). On the pinned seeds 0-199
      eom_brace (its new defaults: the active hold, choice by direction) keeps 91 % upright (77.5 % before),
      the Oracle rung 97.5 %; the best static posture searched on the design seeds holds 75 % (gaze gain
      +16) and a posture picked by hand 86.5 % (docs/reproductions/eom.md). Former leaderboard entries are
      superseded.
    * v0, redefined in place again (PushRecovery's eighth pass): the wall (with its turn and the push) on the body's
      right or left, 50/50 per episode (drawn last: a seed's left wall is its right wall mirrored), and a left
      arm, the right one mirrored; the action gains the ``arm`` value (10 values), the observation the left
      arm's joints, its palm and the active arm (113 values). No one posture of the eye sees both walls within
      40 deg. On the pinned seeds 0-199 eom_brace keeps 90 % upright, the Oracle rung 97.5 %; the static
      posture searched on the design seeds holds 46.5 % (gaze gain +43.5), the held twin 22.5 %; a posture
      picked by hand toward the left wall 55 % (107 of the 200 walls are on the left; docs/reproductions/eom.md,
      eighth pass). Former leaderboard entries are superseded. With the one eye's lateral noise drawn as an
      angle (``human_periphery()``'s ``angular_lateral_noise``, on for every family): eom_brace 91.0 %, the
      held twin 23.5 %, the searched posture 46.0 %, the hand-picked posture toward the left wall 54.0 %, kept
      as the static twin (gaze gain +37.0; +45.0 against the searched posture).
    * v0, redefined in place again (PushRecovery's eleventh pass): **loose cubes** (of the two cubes nearest the
      bracing shoulder exactly one, each other cube with probability 1/2; a loose cube collides with nothing), seen
      only by central vision: the observation gains ``block_firm`` (6 values, 119 in all; the action is unchanged);
      the push comes 1.0-2.0 s after the start (0.6-1.4 s before) and episodes last 250 steps (200 before). The loose
      draws take nothing from the episode's generator: every other draw of a seed is unchanged. On the pinned seeds
      0-199 eom_brace (its new defaults: identification looks, the vergence search) keeps 90.0 % upright, the Oracle
      rung 91.5 %; the best still posture found (the hand-picked one toward the left wall) 45.5 %, the static
      search's posture 38.0 %, the held twin 16.0 %: gaze gain +44.5 (docs/reproductions/eom.md, eleventh pass).
      Former leaderboard entries are superseded.
    """

    render_cameras: ClassVar[dict[str, tuple[str, ...]]] = {
        "both": (sn.SCENE_CAMERA, names.EYE_CAMERA),
        "scene": (sn.SCENE_CAMERA,),
        "eye": (names.EYE_CAMERA,),
        "front": (sn.FRONT_CAMERA,),
    }
    eye_camera = names.EYE_CAMERA

    reward_terms = REWARD_TERMS
    scene = sn.SCENE
    vision_defaults = PUSH_VISION  # human peripheral vision (vision.foveation.human_periphery)
    argument_meanings = {  # noqa: RUF012  (read only: the generated Arguments table)
        "reward": '``"sparse"`` or ``"shaped"``',
        "hand_params": ("``HandControlParams`` or dict (2 m/s cap, DLS damping; default: the waist weighted 0.05, "
                        "``body.standing.STANDING_HAND_PARAMS``)"),
        "push_force_n": "range (N) the push's magnitude is drawn from (150 ms, on the torso)",
        "n_blocks": "cubes in the wall (2-6)",
        "vision": '``"foveated"``, ``"full_view"`` or ``"oracle"`` (true face centres of the cubes)',
        "render_camera": '``"both"`` (scene beside eye view), ``"scene"``, ``"eye"``, ``"front"``',
    }

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        reward: str = "sparse",
        hand_params: HandControlParams | dict | None = None,
        push_force_n: tuple[float, float] = pr.PUSH_FORCE_N,
        n_blocks: int = sn.N_BLOCKS,
        **shared: Any,
    ):
        self.reward_mode = args.choice(reward, REWARD_MODES, "reward")
        if hand_params is None:
            hand_params = sn.STANDING_HAND_PARAMS
        self.hand_params = args.coerce(HandControlParams, hand_params, "hand_params")
        try:
            lo, hi = (float(v) for v in push_force_n)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"push_force_n must be a (low, high) pair of forces in N, got {push_force_n!r}") from exc
        lo = args.real(lo, "push_force_n[0]", low=0.0, high=5000.0)
        hi = args.real(hi, "push_force_n[1]", low=0.0, high=5000.0)
        if hi < lo:
            raise ValueError(f"push_force_n must be (low, high) with low <= high, got {push_force_n!r}")
        self.push_force_n = (lo, hi)
        self.n_blocks = args.integer(n_blocks, "n_blocks", low=2, high=sn.N_BLOCKS)
        super().__init__(render_mode, **shared)

    def _default_reward_weights(self) -> dict[str, float]:
        return SPARSE_WEIGHTS if self.reward_mode == "sparse" else SHAPED_WEIGHTS

    def _build(self) -> tuple[StandingBody, PushRecoveryTask]:
        body = StandingBody(self.model, self.hand_params, self.dt)
        task = PushRecoveryTask(self.model, body, reward_weights=self.reward_weights, dt=self.dt,
                                visual_delay_s=self.visual_delay_s, push_force_n=self.push_force_n,
                                n_blocks=self.n_blocks)
        self.hand = body.hand
        return body, task

    def _assemble(self, **kw) -> None:
        super()._assemble(**kw)
        self.task.attach_eye(self.eye, self.retina, self.vision, self.vision_params.crowding_bouma)


def _action_table() -> str:
    (x0, x1), (y0, y1), (z0, z1) = sn.HAND_WORKSPACE.tolist()
    rows = [
        "| index | meaning |",
        "|---|---|",
        f"| 0-2 | hand target (the active arm's palm centre), stance frame, mapped from [-1, 1] to x in [{x0}, {x1}], y in [{y0}, {y1}], z in [{z0}, {z1}] m |",
        f"| 3 | brace: both arms' stiffness, -1 relaxed ({sn.RELAXED_STIFFNESS:g} of the servo gain) ... 1 braced (full gain) |",
        "| 4 | arm: the hand target drives the right arm (<= 0) or the left arm (> 0); the idle arm hangs at the side |",
        "| 5-6 | requested gaze change (azimuth, elevation) of the current eye frame, times ``gaze_action_range_deg`` |",
        "| 7 | fixation (vergence) distance, log-mapped onto [0.1, 20] m |",
        "| 8-9 | head target: neck yaw in [-80, 80] deg and pitch in [-50, 40] deg |",
    ]
    return "\n    ".join(rows)


if PushRecoveryEnv.__doc__:
    _layout = ObservationLayout(push_observation())
    PushRecoveryEnv.__doc__ = (PushRecoveryEnv.__doc__
                               .replace("OBSERVATION_TABLE", "\n    ".join(_layout.markdown_table().splitlines()))
                               .replace("ACTION_TABLE", _action_table())
                               .replace("OBS_SIZE", str(_layout.size)))


# ---------------------------------------------------------------- the family record (visuomotor_gym.family)
from visuomotor_gym.family import Family, Viz

PUSH_MAX_EPISODE_STEPS = 250  # 5 s at 50 Hz: the push by 2.0 s, then 2.5 s to stay upright (never reached)

FAMILY = Family(
    name="push",
    prefix="PushRecovery",
    entry_point="visuomotor_gym.envs.push:PushRecoveryEnv",
    max_episode_steps=PUSH_MAX_EPISODE_STEPS,
    oracle_sees="cube blocks",
    body="standing",
    vision_defaults=PUSH_VISION,
    summariser="visuomotor_gym.metrics.push_realism:push_summary",
    miss_distance="visuomotor_gym.metrics.push_realism:hand_miss_distance",
    outcome_labels=("upright rate", "episode end of the upright episodes (s)",
                    "hand-to-nearest-face distance, falls (m)"),
    reaction_from_t0=False,
    agents=("eom_brace",),
    golden_agent="eom_brace",
    viz=Viz(
        figure="visuomotor_gym.viz.push_plots:push_figure",
        contents="top and side view of the wall: cube faces, hand path, gaze point (coloured by time); gaze-to-"
                 "block angle, hand-to-block distance and centre of pressure over time, push and contact marked",
        trace_field="block_faces",
        scene_view="front_camera",
        video_stride=1,
    ),
    doc_links=(("Eom et al. 2019: balancing after a push", "reproductions/eom.md"),),
    doc_pictures=(("images/pushrecovery_record_frame.png", "The eom_brace agent's hand on a cube after the push "
                                                           "(seed 1, front camera; the green line: its gaze)"),),
)
