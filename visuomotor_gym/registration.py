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


@dataclass(frozen=True)
class EnvSpec:
    id: str
    entry_point: str
    kwargs: dict = field(default_factory=dict)
    max_episode_steps: int = CATCH_MAX_EPISODE_STEPS
    description: str = ""


# The Eyecatch paper's vision model (section 3.1): lateral position noise is static 20/20 acuity whatever
# the image's speed on the retina. The default since issue 11 degrades it with retinal slip
# (VisionParams.position_slip_knee_deg_s; docs/reproductions/gaze_default.md).
PAPER_VISION = {"position_slip_knee_deg_s": math.inf}

# The observability ladder of the catch family (DESIGN 2): same physics, same throw sampler.
ENV_SPECS: tuple[EnvSpec, ...] = (
    EnvSpec("EyeCatchOracle-v0", CATCH_ENTRY_POINT, {"vision": "oracle"}, description="true ball state"),
    EnvSpec("EyeCatchFullView-v0", CATCH_ENTRY_POINT, {"vision": "full_view"},
            description="noisy, noise independent of gaze"),
    EnvSpec("EyeCatch-v0", CATCH_ENTRY_POINT, {}, description="foveated vision, saccadic blindness"),
    EnvSpec("EyeCatchDelayed-v0", CATCH_ENTRY_POINT, {"visual_delay_s": 0.1},
            description="foveated + 100 ms visual latency"),
    EnvSpec("EyeCatchPoorVision-v0", CATCH_ENTRY_POINT, {"vision_noise_scale": 10.0},
            description="foveated, all vision noise x10 (Eyecatch 5)"),
    EnvSpec("EyeCatchBounce-v0", CATCH_ENTRY_POINT, {"bounce_wall": True},
            description="foveated; the ball bounces off an invisible wall mid-flight (Eyecatch 5)"),
    EnvSpec("EyeCatchTwoBalls-v0", CATCH_ENTRY_POINT, {"n_balls": 2}, max_episode_steps=TWO_BALLS_MAX_EPISODE_STEPS,
            description="foveated; two staggered balls from both sides, catch both (Eom 7)"),
    # The two vision conditions of the Eyecatch paper (section 5: 98 % normal, 81.2 % with the noise x10),
    # for its reproduction page: the paper's static 20/20 acuity at any retinal speed, no slip term.
    EnvSpec("EyeCatchPaper-v0", CATCH_ENTRY_POINT, {"vision_params": dict(PAPER_VISION)},
            description="Eyecatch paper's vision: foveated, static acuity at any retinal speed"),
    EnvSpec("EyeCatchPaperPoorVision-v0", CATCH_ENTRY_POINT,
            {"vision_params": dict(PAPER_VISION), "vision_noise_scale": 10.0},
            description="Eyecatch paper's vision with all noise x10 (Eyecatch 5: 81.2 %)"),
)
CATCH_ENV_IDS = tuple(spec.id for spec in ENV_SPECS if spec.entry_point == CATCH_ENTRY_POINT)


def env_vision(env_id: str) -> dict:
    """What the eye of a registered catch env gives its agent, for agents that model their own vision:
    ``vision_noise_scale`` (0 for the oracle), ``foveated``, ``visual_delay_s``, ``gaze_action_range_deg``."""
    kw = gym.spec(env_id).kwargs or {}
    return {
        "vision_noise_scale": 0.0 if kw.get("vision") == "oracle" else float(kw.get("vision_noise_scale", 1.0)),
        "foveated": kw.get("vision", "foveated") == "foveated",
        "visual_delay_s": float(kw.get("visual_delay_s", 0.0)),
        "gaze_action_range_deg": float(kw.get("gaze_action_range_deg", 60.0)),
    }


def vision_params_for(kwargs: dict):
    """The ``VisionParams`` an ``EyeCatchEnv`` built with ``kwargs`` gives its agent's brain to model.

    As the env builds its own (``vision_params`` fields, times ``vision_noise_scale``; ``full_view``
    drops foveation), except that ``vision="oracle"`` gives noise scale 0 and no foveation (the true
    state: nothing to weight).
    """
    from visuomotor_gym.vision.foveation import VisionParams

    base = kwargs.get("vision_params") or {}
    params = base if isinstance(base, VisionParams) else VisionParams(**base)
    mode = kwargs.get("vision", "foveated")
    params = params.scaled(0.0 if mode == "oracle" else float(kwargs.get("vision_noise_scale", 1.0)))
    if mode != "foveated":
        params = VisionParams(**{**asdict(params), "foveated": False})
    return params


def env_vision_params(env_id: str):
    """:func:`vision_params_for` the registered kwargs of ``env_id``: every vision constant of its eye."""
    return vision_params_for(gym.spec(env_id).kwargs or {})


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
