"""Every environment id of the package, registered from one list on ``import visuomotor_gym``.

Gymnasium 1.x has no plugin entry point, so ``gym.make("visuomotor_gym:EyeCatch-v0")`` imports
this package first, which runs :func:`register_envs`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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
