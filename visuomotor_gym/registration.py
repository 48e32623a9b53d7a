"""Every environment id of the package, registered from one list on ``import visuomotor_gym``.

Gymnasium 1.x has no plugin entry point, so ``gym.make("visuomotor_gym:EyeCatch-v0")`` imports
this package first, which runs :func:`register_envs`.
"""

from __future__ import annotations

from dataclasses import asdict

import gymnasium as gym

# The per-family constants of earlier versions, importable as before (each family's env module declares them).
from visuomotor_gym.envs.catch import (  # noqa: F401 (re-exported)
    CATCH_MAX_EPISODE_STEPS,
    PAPER_POOR_VISION_SCALE,
    PAPER_VISION,
    TWO_BALLS_MAX_EPISODE_STEPS,
)
from visuomotor_gym.envs.catch import FAMILY as _CATCH
from visuomotor_gym.envs.dodge import DODGE_MAX_EPISODE_STEPS  # noqa: F401 (re-exported)
from visuomotor_gym.envs.dodge import FAMILY as _DODGE
from visuomotor_gym.envs.reach import FAMILY as _REACH
from visuomotor_gym.envs.reach import REACH_MAX_EPISODE_STEPS  # noqa: F401 (re-exported)
from visuomotor_gym.envs.stones import FAMILY as _STONES
from visuomotor_gym.envs.stones import STONES_MAX_EPISODE_STEPS  # noqa: F401 (re-exported)
from visuomotor_gym.envs.walk import FAMILY as _WALK
from visuomotor_gym.envs.walk import WALK_MAX_EPISODE_STEPS  # noqa: F401 (re-exported)
from visuomotor_gym.families import families, family_for
from visuomotor_gym.family import (  # noqa: F401 (re-exported)
    POOR_VISION_SCALE,
    VISUAL_DELAY_S,
    EnvEntry,
    ExtraEnv,
    vision_rungs,
)

CATCH_ENTRY_POINT = _CATCH.entry_point
WALK_ENTRY_POINT = _WALK.entry_point
REACH_ENTRY_POINT = _REACH.entry_point
DODGE_ENTRY_POINT = _DODGE.entry_point
STONES_ENTRY_POINT = _STONES.entry_point

# Every registered id, every family, one list: each family's rungs and extra ids, in FAMILY_MODULES order.
ENV_SPECS: tuple[EnvEntry, ...] = tuple(entry for record in families() for entry in record.env_entries())
ENV_IDS = tuple(spec.id for spec in ENV_SPECS)
FAMILIES: dict[str, tuple[str, ...]] = {record.name: tuple(e.id for e in record.env_entries()) for record in families()}
WALKER_FAMILIES = tuple(record.name for record in families() if record.body == "walker")  # its 20 deg field
CATCH_ENV_IDS = FAMILIES[_CATCH.name]


def family_of(env_id: str) -> str:
    """The family of a registered id (``"catch"``, ...); ValueError for an unknown id.
    (:func:`visuomotor_gym.families.family_for` returns its record.)"""
    return family_for(env_id).name


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
    over its family's ``vision_defaults`` (the walker families': Iwao's 20 deg recognition field)."""
    return vision_params_for(gym.spec(env_id).kwargs or {}, family_for(env_id).vision_defaults)


# Agent-spec overrides that change the eye the agent assumes (``eyecatch:vision_noise_scale=5``): with one of
# them an agent keeps the eye its own parameters build instead of the registered id's.
ASSUMED_EYE_FIELDS = frozenset({"vision_noise_scale", "foveated"})


def agent_eye(env_id: str, overrides):
    """The ``VisionParams`` an agent built for ``env_id`` models (:func:`env_vision_params`), or None when
    the agent spec's ``overrides`` change the eye it assumes (:data:`ASSUMED_EYE_FIELDS`)."""
    return None if ASSUMED_EYE_FIELDS & set(overrides) else env_vision_params(env_id)


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

