"""Every environment id of the package, registered from one list on ``import visuomotor_gym``.

Gymnasium 1.x has no plugin entry point, so ``gym.make("visuomotor_gym:EyeCatch-v0")`` imports
this package first, which runs :func:`register_envs`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import gymnasium as gym

CATCH_ENTRY_POINT = "visuomotor_gym.envs.catch:EyeCatchEnv"
CATCH_MAX_EPISODE_STEPS = 125  # 2.5 s at 50 Hz: the longest flight is 1.4 s
TWO_BALLS_MAX_EPISODE_STEPS = 150  # 3 s: the second ball arrives at most 2.2 s after the first release
POOR_VISION_SCALE = 2.0  # the PoorVision rungs: every vision noise x2, i.e. 20/40 (2 arcmin) acuity, the
# boundary of mild visual impairment (WHO ICD-11: presenting acuity worse than 6/12); swept against x1.5-x10 in
# docs/reproductions/gaze_default.md (x10, 20/200, leaves the slip model nearly blind: no gaze gain left)
PAPER_POOR_VISION_SCALE = 10.0  # Eyecatch section 5: every vision noise x10 (81.2 % caught in the paper)
WALK_ENTRY_POINT = "visuomotor_gym.envs.walk:ObstacleWalkEnv"
WALK_MAX_EPISODE_STEPS = 2000  # 40 s at 50 Hz: three times the nominal walk (1.3 m/s) of the longest (20 m) course
# The reach family (seed 002, Faraway, Reed & Wang 2007): ShelfReach-v0 and its vision rungs.
REACH_ENTRY_POINT = "visuomotor_gym.envs.reach:ShelfReachEnv"
REACH_MAX_EPISODE_STEPS = 150  # 3 s at 50 Hz: first saccade (~0.2 s), fixation, a ~0.6-1 s reach, slack (modelling choice)
# The dodge family (issue 13; Eom et al. section 7): ObstacleDodge-v0 and its vision rungs.
DODGE_ENTRY_POINT = "visuomotor_gym.envs.dodge:ObstacleDodgeEnv"
DODGE_MAX_EPISODE_STEPS = 2000  # 40 s at 50 Hz: about three times the nominal walk (1.3 m/s) to the farthest (20 m) goal
# The stones family (issue 13; Eom et al. 2019 section 7): SteppingStones-v0 and its vision rungs.
STONES_ENTRY_POINT = "visuomotor_gym.envs.stones:SteppingStonesEnv"
STONES_MAX_EPISODE_STEPS = 1000  # 20 s at 50 Hz: twice the nominal crossing (~18 steps of 0.5 s) (modelling choice)
VISUAL_DELAY_S = 0.1  # the Delayed rung's latency: ~100 ms of human visual processing (modelling choice)


@dataclass(frozen=True)
class EnvEntry:
    """One registered id: its entry point, keyword arguments, episode limit, family and a line of text.
    (Not Gymnasium's ``EnvSpec``, which ``gym.spec(id)`` returns once registered.)"""

    id: str
    entry_point: str
    kwargs: dict = field(default_factory=dict)
    max_episode_steps: int = CATCH_MAX_EPISODE_STEPS
    description: str = ""
    family: str = "catch"


def vision_rungs(name: str, entry_point: str, *, family: str, max_episode_steps: int, what: str,
                 kwargs: dict | None = None) -> tuple[EnvEntry, ...]:
    """The observability ladder of one family, same physics and scenario sampler on every rung:
    ``<name>Oracle-v0`` (true state of what ``what`` names), ``<name>FullView-v0`` (noise independent
    of gaze), ``<name>-v0`` (foveated), ``<name>Delayed-v0`` (+100 ms) and ``<name>PoorVision-v0``
    (every vision noise x2: 20/40 acuity). ``kwargs`` are shared by every rung."""
    base = dict(kwargs or {})

    def rung(suffix, extra, description):
        return EnvEntry(f"{name}{suffix}-v0", entry_point, {**base, **extra}, max_episode_steps, description, family)

    return (
        rung("Oracle", {"vision": "oracle"}, f"true {what} state"),
        rung("FullView", {"vision": "full_view"}, "noisy, noise independent of gaze"),
        rung("", {}, "foveated vision, saccadic blindness"),
        rung("Delayed", {"visual_delay_s": VISUAL_DELAY_S}, "foveated + 100 ms visual latency"),
        rung("PoorVision", {"vision_noise_scale": POOR_VISION_SCALE},
             f"foveated, all vision noise x{POOR_VISION_SCALE:g} (20/40 acuity)"),
    )


# The Eyecatch paper's vision model (section 3.1): lateral position noise is static 20/20 acuity whatever
# the image's speed on the retina. The default since issue 11 degrades it with retinal slip
# (VisionParams.position_slip_knee_deg_s; docs/reproductions/gaze_default.md).
PAPER_VISION = {"position_slip_knee_deg_s": math.inf}

# Every registered id, every family, one list.
ENV_SPECS: tuple[EnvEntry, ...] = (
    *vision_rungs("EyeCatch", CATCH_ENTRY_POINT, family="catch", max_episode_steps=CATCH_MAX_EPISODE_STEPS,
                  what="ball"),
    EnvEntry("EyeCatchBounce-v0", CATCH_ENTRY_POINT, {"bounce_wall": True},
             description="foveated; the ball bounces off an invisible wall mid-flight (Eyecatch 5)"),
    EnvEntry("EyeCatchTwoBalls-v0", CATCH_ENTRY_POINT, {"n_balls": 2}, max_episode_steps=TWO_BALLS_MAX_EPISODE_STEPS,
             description="foveated; two staggered balls from both sides, catch both (Eom 7)"),
    # The two vision conditions of the Eyecatch paper (section 5: 98 % normal, 81.2 % with the noise x10),
    # for its reproduction page: the paper's static 20/20 acuity at any retinal speed, no slip term.
    EnvEntry("EyeCatchPaper-v0", CATCH_ENTRY_POINT, {"vision_params": dict(PAPER_VISION)},
             description="Eyecatch paper's vision: foveated, static acuity at any retinal speed"),
    EnvEntry("EyeCatchPaperPoorVision-v0", CATCH_ENTRY_POINT,
             {"vision_params": dict(PAPER_VISION), "vision_noise_scale": PAPER_POOR_VISION_SCALE},
             description="Eyecatch paper's vision with all noise x10 (Eyecatch 5: 81.2 %)"),
    *vision_rungs("ObstacleWalk", WALK_ENTRY_POINT, family="walk", max_episode_steps=WALK_MAX_EPISODE_STEPS,
                  what="obstacle"),
    *vision_rungs("ShelfReach", REACH_ENTRY_POINT, family="reach", max_episode_steps=REACH_MAX_EPISODE_STEPS,
                  what="object"),
    *vision_rungs("ObstacleDodge", DODGE_ENTRY_POINT, family="dodge", max_episode_steps=DODGE_MAX_EPISODE_STEPS,
                  what="pedestrian"),
    *vision_rungs("SteppingStones", STONES_ENTRY_POINT, family="stones", max_episode_steps=STONES_MAX_EPISODE_STEPS,
                  what="stone"),
)
ENV_IDS = tuple(spec.id for spec in ENV_SPECS)
FAMILIES: dict[str, tuple[str, ...]] = {}
WALKER_FAMILIES = ("walk", "stones", "dodge")  # the families on the walker body (its 20 deg recognition field)
for _spec in ENV_SPECS:
    FAMILIES[_spec.family] = FAMILIES.get(_spec.family, ()) + (_spec.id,)
CATCH_ENV_IDS = FAMILIES["catch"]


def family_of(env_id: str) -> str:
    """The family of a registered id (``"catch"``, ...); ValueError for an unknown id."""
    bare = env_id.removeprefix("visuomotor_gym:")
    for spec in ENV_SPECS:
        if spec.id == bare:
            return spec.family
    raise ValueError(f"unknown env id {env_id!r}; known ids: {', '.join(ENV_IDS)}")


def env_vision(env_id: str) -> dict:
    """What the eye of a registered env gives its agent, for agents that model their own vision:
    ``vision_noise_scale`` (0 for the oracle), ``foveated``, ``visual_delay_s``, ``gaze_action_range_deg``."""
    kw = gym.spec(env_id).kwargs or {}
    return {
        "vision_noise_scale": 0.0 if kw.get("vision") == "oracle" else float(kw.get("vision_noise_scale", 1.0)),
        "foveated": kw.get("vision", "foveated") == "foveated",
        "visual_delay_s": float(kw.get("visual_delay_s", 0.0)),
        "gaze_action_range_deg": float(kw.get("gaze_action_range_deg", 60.0)),
    }


def vision_params_for(kwargs: dict, defaults=None):
    """The ``VisionParams`` an env built with ``kwargs`` gives its agent's brain to model.

    As the env builds its own (``vision_params`` fields over the family's ``defaults`` -- the catch
    family's ``VisionParams()`` when None -- times ``vision_noise_scale``; ``full_view`` drops
    foveation), except that ``vision="oracle"`` gives noise scale 0 and no foveation (the true state:
    nothing to weight).
    """
    from visuomotor_gym.vision.foveation import VisionParams

    base = kwargs.get("vision_params") or {}
    if isinstance(base, VisionParams):
        params = base
    else:
        params = VisionParams(**{**(asdict(defaults) if defaults is not None else {}), **base})
    mode = kwargs.get("vision", "foveated")
    params = params.scaled(0.0 if mode == "oracle" else float(kwargs.get("vision_noise_scale", 1.0)))
    if mode != "foveated":
        params = VisionParams(**{**asdict(params), "foveated": False})
    return params


def env_vision_params(env_id: str):
    """:func:`vision_params_for` the registered kwargs of ``env_id``: every vision constant of its eye
    (the walker families' defaults have Iwao's 20 deg recognition field, ``envs.walk.WALK_VISION``)."""
    defaults = None
    if family_of(env_id) in WALKER_FAMILIES:
        from visuomotor_gym.envs.walk import WALK_VISION

        defaults = WALK_VISION
    return vision_params_for(gym.spec(env_id).kwargs or {}, defaults)


def register_envs() -> None:
    """Register every id in :data:`ENV_SPECS` (idempotent)."""
    for spec in ENV_SPECS:
        if spec.id in gym.registry:
            continue
        gym.register(
            id=spec.id,
            entry_point=spec.entry_point,
            kwargs=dict(spec.kwargs),
            max_episode_steps=spec.max_episode_steps,
        )

