"""One policy interface for every agent, and the registry of agent names.

Every agent is a :class:`Policy`: ``predict(observation, state, episode_start, deterministic) ->
(action, state)``, the stable-baselines3 ``PolicyPredictor`` protocol, so SB3 models plug in
unchanged. Agents see observations only, never ``info`` (the true state).

Agent names (``make_agent``):

* ``eyecatch``: the Eyecatch heuristic of Yeo et al. 2012 (``visuomotor_gym.baselines.eyecatch``);
  keyword overrides as ``eyecatch:param=value,param=value``; on two-ball envs it tracks the balls
  one after the other;
* ``belief_mpc``: the belief-space MPC of Eom et al. 2019 (``visuomotor_gym.baselines.belief_mpc``);
* ``oracle``: the scripted interception oracle (true state; meaningful on ``EyeCatchOracle-v0`` only);
* ``random``: uniform random actions (seeded);
* ``zero``: all-zero actions (gaze held, hand at the workspace centre);
* ``ppo:<path>``: a policy trained by ``vmgym train ppo`` (``visuomotor_gym.baselines.ppo``).
* ``belief_intercept``: no learning, the base of PPO's belief-relative hand action (closed hand at the
  Eyecatch filter's interception point, gaze held still).
* ``gaze_blind:<agent spec>``: any agent with its gaze and head held (:class:`GazeBlind`): the gaze
  action is 0 (gaze held fixed in the world, where reset put it: on the thrower) and the head action
  0 (the reset pose, straight ahead); everything else is the base agent's. The *gaze-blind twin* of
  (docs/gaze_gain.md): the agent's success minus its twin's on the same seeds is the gaze gain.
* ``static_gaze:[<posture>:]<agent spec>``: any agent with its gaze, fixation and head held at one
  constant posture in the body frame (:mod:`visuomotor_gym.static_gaze`): its best static twin when
  the posture is the searched one (``static_gaze:<agent>``).
* ``fixed_gaze``: ``gaze_blind:eyecatch`` (the Eyecatch filter and hand, gaze and head held);
  ``fixed_gaze:param=value`` passes overrides to the Eyecatch agent.

Further names register with :func:`register_agent`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Policy(Protocol):
    """What the evaluator needs from an agent (the SB3 ``PolicyPredictor`` protocol)."""

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: np.ndarray | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]: ...


AgentFactory = Callable[..., Policy]
_REGISTRY: dict[str, tuple[AgentFactory, str, bool]] = {}
_WRAPPERS: set[str] = set()  # names whose text after ':' is a whole agent spec (``gaze_blind:<spec>``)


def register_agent(name: str, factory: AgentFactory, description: str = "", deterministic: bool = True,
                   wraps: bool = False) -> None:
    """Register ``factory(env_id=..., action_dim=..., seed=..., **overrides) -> Policy`` under ``name``.

    With ``wraps=True`` the name wraps another agent: ``name:<agent spec>`` calls
    ``factory(env_id=..., action_dim=..., seed=..., base=<agent spec>)`` and the wrapper is as
    deterministic as its base.
    """
    if ":" in name:
        raise ValueError(f"agent names cannot contain ':' (it separates overrides): {name!r}")
    _REGISTRY[name] = (factory, description, deterministic)
    if wraps:
        _WRAPPERS.add(name)
    else:
        _WRAPPERS.discard(name)


def agent_names() -> list[str]:
    return sorted(_REGISTRY)


def agent_description(name: str) -> str:
    return _REGISTRY[name][1]


def is_deterministic(spec: str) -> bool:
    """Whether the named agent gives the same actions for the same observations (re-scorable)."""
    name, overrides = parse_agent_spec(spec)
    if name in _WRAPPERS:
        return is_deterministic(overrides["base"])
    return _REGISTRY[name][2]


# Agents whose spec is ``name:<path>`` (everything after the colon is one file path, which may hold
# '=' or ','), rather than ``name:key=value,...`` overrides.
PATH_AGENTS = ("ppo",)


class PolicyFileError(ValueError):
    """A policy file named by an agent spec cannot be loaded (missing, corrupt, not a policy)."""


class PolicyFileNotFound(FileNotFoundError, PolicyFileError):
    """The policy file of an agent spec does not exist (a FileNotFoundError and a ValueError)."""


def parse_agent_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """``"eyecatch:alpha=1,beta=x"`` -> ``("eyecatch", {"alpha": 1, "beta": "x"})``;
    ``"ppo:runs/a=b/model.zip"`` -> ``("ppo", {"path": "runs/a=b/model.zip"})`` (:data:`PATH_AGENTS`);
    a value with semicolons is a tuple: ``"fajen_warren:search_azimuths_deg=45;70"``."""
    if not isinstance(spec, str):
        raise ValueError(f"an agent spec is a string such as 'eyecatch', got {spec!r}")
    name, colon, rest = spec.partition(":")
    if name not in _REGISTRY:
        raise ValueError(f"unknown agent {name!r}; known agents: {agent_names()}")
    if name in _WRAPPERS:  # "gaze_blind:eyecatch:alpha=1": the rest is the base agent's whole spec
        own: dict[str, Any] = {}
        head, _, tail = rest.partition(":")
        if "=" in head:  # "static_gaze:az=-9,el=35:eyecatch": the wrapper's own key=value options first
            own, rest = _parse_overrides(head, spec), tail  # (agent names never contain '=')
        if not rest:
            raise ValueError(f"{name!r} wraps another agent: write {name}:<agent spec>, e.g. {name}:eyecatch")
        parse_agent_spec(rest)  # an unknown base agent fails here, naming the known ones
        return name, {**own, "base": rest}
    overrides: dict[str, Any] = {}
    if name in PATH_AGENTS:
        if colon and not rest.strip():
            raise ValueError(f"agent spec {spec!r} names no file: use {name}:<path to the policy file>")
        return name, ({"path": rest} if rest else {})
    if rest and "=" not in rest:  # "name:<path>": one positional argument
        return name, {"path": rest}
    if rest:
        overrides = _parse_overrides(rest, spec)
    return name, overrides


def _parse_overrides(text: str, spec: str) -> dict[str, Any]:
    overrides: dict[str, Any] = {}
    for item in text.split(","):
        key, eq, value = item.partition("=")
        if not eq or not key:
            raise ValueError(f"agent override {item!r} in {spec!r} is not key=value")
        overrides[key.strip()] = _parse_value(value.strip())
    return overrides


def _parse_value(text: str) -> Any:
    if ";" in text:  # "search_azimuths_deg=45;70": a tuple (a comma separates overrides)
        return tuple(_parse_value(v.strip()) for v in text.split(";") if v.strip())
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    if text.lower() == "none":  # "max_speed_m_s=none": an optional parameter turned off
        return None
    return text


def _agent_families() -> dict[str, tuple[str, ...]]:
    """Agent name -> the families whose record lists it (``Family.agents``), in registration order."""
    from visuomotor_gym.families import families

    out: dict[str, tuple[str, ...]] = {}
    for record in families():
        for agent in record.agents:
            out[agent] = (*out.get(agent, ()), record.name)
    return out


# The env families each agent is built for (each family's record lists its agents); an agent no family
# lists plays every family (random, zero; ppo: its policy file says what it was trained on; gaze_blind:
# its base agent's families).
AGENT_FAMILIES: dict[str, tuple[str, ...]] = _agent_families()


def check_agent_family(spec: str, env_id: str) -> None:
    """ValueError (one line naming the agent and the env's family) if ``spec``'s agent is not built for
    ``env_id``'s family; an unknown agent or env id raises as :func:`parse_agent_spec` /
    :func:`~visuomotor_gym.registration.family_of` do."""
    from visuomotor_gym.registration import FAMILIES, family_of

    name, overrides = parse_agent_spec(spec)
    if name in _WRAPPERS:
        return check_agent_family(overrides["base"], env_id)
    families = AGENT_FAMILIES.get(name)
    family = family_of(env_id)
    if families is not None and family not in families:
        ids = ", ".join(min(FAMILIES[f], key=len) for f in families if FAMILIES.get(f))
        names = families[0] if len(families) == 1 else f"{', '.join(families[:-1])} and {families[-1]}"
        raise ValueError(f"agent {name!r} plays the {names} famil{'ies' if len(families) > 1 else 'y'} "
                         f"(e.g. {ids}), not {env_id}'s {family} family")


def make_agent(spec: str, env_id: str, action_dim: int, seed: int = 0) -> Policy:
    """Build the agent named by ``spec`` for ``env_id`` (refused if it is not built for the env's family)."""
    check_agent_family(spec, env_id)
    name, overrides = parse_agent_spec(spec)
    factory = _REGISTRY[name][0]
    return factory(env_id=env_id, action_dim=action_dim, seed=seed, **overrides)


class RandomAgent:
    """Uniform random actions in [-1, 1], from its own seeded generator."""

    def __init__(self, action_dim: int, seed: int = 0):
        self.action_dim = action_dim
        self.rng = np.random.default_rng(seed)

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.rng.uniform(-1.0, 1.0, self.action_dim).astype(np.float32), state


class ZeroAgent:
    """All-zero actions."""

    def __init__(self, action_dim: int):
        self.action_dim = action_dim

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return np.zeros(self.action_dim, dtype=np.float32), state


def _with_env_vision(agent, env_id, overrides):
    """``agent`` given every vision constant of the registered ``env_id`` (``for_env`` sets the noise
    scale, foveation and latency only; the paper-condition ids also change ``vision_params``), unless
    the spec overrides the vision the agent assumes (``eyecatch:vision_noise_scale=5``)."""
    from visuomotor_gym.registration import agent_eye

    vision = agent_eye(env_id, overrides)
    if vision is not None:
        match_vision(agent, vision)
    return agent


def match_vision(policy, vision) -> None:
    """Give a model-based agent (its gaze-blind wrapper included) the exact ``VisionParams`` of its eye.

    The Eyecatch and belief-MPC agents weight each sample with the vision model's covariance (a brain
    adapted to its own eye); ``for_env`` gives them the registered id's noise scale and foveation on
    top of the default constants. This sets every constant, for envs made with non-default
    ``vision_params`` (the paper conditions, the sweeps of ``benchmarks/gaze_gain_sweep.py``).
    Agents without a vision model are left alone.
    """
    inner = policy
    while isinstance(inner, GazeBlind):
        inner.hold_vergence = has_depth_law(vision)
        inner = inner.base
    for agent in (inner, getattr(inner, "_agent", None)):  # PPO's belief features wrap an Eyecatch agent
        if agent is None or not hasattr(agent, "vision"):
            continue
        agent.vision = vision
        if hasattr(agent, "noise") and hasattr(agent, "_problems"):  # belief_mpc: its planning noise too
            from visuomotor_gym.baselines.belief_mpc.belief import ObservationNoise

            p = agent.params
            agent.noise = ObservationNoise.from_vision(vision, eps_deg=p.fovea_smoothing_deg,
                                                       angular=p.angular_uncertainty)
            agent._problems = {}


class GazeBlind:
    """Any agent with its gaze and head held: the *gaze-blind twin* (docs/gaze_gain.md).

    Every action of the base agent passes through unchanged except two blocks, overwritten with 0:
    the **gaze** change (0 holds gaze fixed in the world, so the eye stays where reset put it, on the
    thrower's hand, and never saccades; the vestibulo-ocular reflex keeps it there while the torso
    moves, up to the eye's range) and the **head** target (0 is the reset pose, straight ahead). The
    fixation (vergence) action is the base agent's while vergence changes nothing that is seen; when the
    eye has the depth law (``VisionParams.depth_pedestal_arcmin``: depth is precise only near the vergence
    distance) vergence is an eye movement too and is held as well, at the fixation action 0 (the middle of
    the log-mapped fixation range, ~1.4 m: modelling choice, a held eye has no target to verge on).
    ``hold_vergence`` says which (set from the registered id by ``make_agent`` and from the env's own
    vision by :func:`match_vision`).

    The base agent still runs its own filter on the observations, which report the held eye pose, so
    its estimate stays consistent; only where the eye looks changes. The action layout follows the
    env's ``action_structure`` (its ``"gaze"`` and ``"head"`` blocks), so it works for every family.
    """

    HELD_BLOCKS = ("gaze", "head")
    VERGENCE_BLOCK = "fixation"

    def __init__(self, base: Policy, action_structure: dict[str, int], hold_vergence: bool = False):
        if not isinstance(action_structure, dict) or not all(b in action_structure for b in self.HELD_BLOCKS):
            raise ValueError(
                f"gaze_blind needs an action layout with 'gaze' and 'head' blocks, got {action_structure!r}"
            )
        self.base = base
        self.action_structure = dict(action_structure)
        self.action_dim = sum(action_structure.values())
        self.hold_vergence = bool(hold_vergence)

    @property
    def hold_vergence(self) -> bool:
        return self._hold_vergence

    @hold_vergence.setter
    def hold_vergence(self, value: bool) -> None:
        self._hold_vergence = bool(value)
        blocks = self.HELD_BLOCKS + ((self.VERGENCE_BLOCK,) if self._hold_vergence else ())
        self.held = np.zeros(self.action_dim, dtype=bool)
        start = 0
        for name, size in self.action_structure.items():
            if name in blocks:
                self.held[start : start + size] = True
            start += size

    def reset(self) -> None:
        if hasattr(self.base, "reset"):
            self.base.reset()

    def base_action(self, observation, state=None, episode_start=None, deterministic=True):
        """The base agent's action (a float32 copy of the checked shape) and its state."""
        action, state = self.base.predict(observation, state=state, episode_start=episode_start,
                                          deterministic=deterministic)
        action = np.array(action, dtype=np.float32, copy=True)
        if action.shape[-1] != self.action_dim:
            raise ValueError(f"base agent gave an action of shape {action.shape}, expected (..., {self.action_dim})")
        return action, state

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        action, state = self.base_action(observation, state, episode_start, deterministic)
        action[..., self.held] = 0.0
        return action, state

    def __getattr__(self, name):  # the base agent's plotting state (events, filter, ...)
        if name in ("base", "_hold_vergence", "action_structure"):
            raise AttributeError(name)
        return getattr(self.base, name)


@functools.cache
def _registered_action_structure(env_id: str) -> tuple[tuple[str, int], ...]:
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    env = gym.make(env_id)
    try:
        return tuple(env.unwrapped.action_structure.items())
    finally:
        env.close()


def env_action_structure(env_id: str) -> dict[str, int]:
    """The action blocks of a registered id (its env built once per process)."""
    return dict(_registered_action_structure(env_id.removeprefix("visuomotor_gym:")))


def gaze_blind(agent: Policy, action_structure: dict[str, int], hold_vergence: bool = False) -> GazeBlind:
    """``agent`` with its gaze and head held, and its vergence with ``hold_vergence`` (see :class:`GazeBlind`)."""
    return GazeBlind(agent, action_structure, hold_vergence=hold_vergence)


def has_depth_law(vision) -> bool:
    """Whether an eye with these ``VisionParams`` perceives depth with the depth law (vergence then matters)."""
    return bool(vision is not None and vision.foveated and vision.depth_pedestal_arcmin is not None)


def _registered_depth_law(env_id: str) -> bool:
    from visuomotor_gym.registration import env_vision_params

    return has_depth_law(env_vision_params(env_id.removeprefix("visuomotor_gym:")))


def _gaze_blind(env_id, action_dim, seed, base=None, **kw):
    if kw:
        raise TypeError(f"gaze_blind takes no overrides of its own; put them on the base agent: {sorted(kw)}")
    return GazeBlind(make_agent(base, env_id, action_dim, seed=seed), env_action_structure(env_id),
                     hold_vergence=_registered_depth_law(env_id))


def _fixed_gaze(env_id, action_dim, seed, **kw):
    return GazeBlind(_eyecatch(env_id, action_dim, seed, **kw), env_action_structure(env_id),
                     hold_vergence=_registered_depth_law(env_id))


def _oracle(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.oracle import InterceptOracle

    return InterceptOracle(**kw)


def _eyecatch(env_id, action_dim, seed, **kw):
    import gymnasium as gym

    from visuomotor_gym.baselines.eyecatch import EyecatchAgent

    if (gym.spec(env_id).kwargs or {}).get("n_balls", 1) > 1:
        # One ball at a time, as Eyecatch tracks a single object: the second after the first catch.
        from visuomotor_gym.baselines.belief_mpc.sequential import SequentialEyecatch

        return SequentialEyecatch.for_env(env_id, **kw)
    return _with_env_vision(EyecatchAgent.for_env(env_id, **kw), env_id, kw)


def _belief_mpc(env_id, action_dim, seed, **kw):
    from visuomotor_gym.families import family_for
    from visuomotor_gym.family import resolve

    spec = family_for(env_id).belief_mpc  # which belief MPC plays the family (its record says)
    if spec is None:
        raise ValueError(f"agent 'belief_mpc' does not play {env_id}'s {family_for(env_id).name} family")
    agent = resolve(spec.agent).for_env(env_id, **kw)
    return _with_env_vision(agent, env_id, kw) if spec.env_vision else agent


def _ppo(env_id, action_dim, seed, path=None, **kw):
    if path is None:
        raise ValueError("the ppo agent needs a policy file: ppo:<path to model.zip, run folder or policy .npz>")
    import zipfile

    from visuomotor_gym.baselines.ppo.agent import PPOAgent

    try:
        return PPOAgent(path, env_id=env_id, **kw)
    except FileNotFoundError as exc:
        raise PolicyFileNotFound(str(exc)) from None
    except (zipfile.BadZipFile, KeyError, EOFError, OSError, RuntimeError, UnicodeDecodeError) as exc:
        # A corrupt zip, a zip without SB3's members, a truncated file... (not a user-facing traceback)
        raise PolicyFileError(
            f"cannot load the PPO policy {path!r}: {type(exc).__name__}: {exc} (give a model.zip saved by "
            f"`vmgym train ppo`, its run folder, or a policy .npz written by `vmgym leaderboard submit`)"
        ) from None
    except ValueError as exc:
        raise PolicyFileError(f"cannot load the PPO policy {path!r}: {exc}") from None


register_agent("random", lambda env_id, action_dim, seed, **kw: RandomAgent(action_dim, seed, **kw),
               "uniform random actions", deterministic=False)
register_agent("zero", lambda env_id, action_dim, seed, **kw: ZeroAgent(action_dim, **kw), "all-zero actions")
register_agent("oracle", _oracle, "scripted interception on the true ball state (Oracle env only)")
def _belief_intercept(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.ppo.belief import InterceptBase

    return InterceptBase(env_id, **kw)


register_agent("belief_intercept", _belief_intercept,
               "no learning: closed hand at the Eyecatch filter's interception point, gaze held (PPO's residual base)")
register_agent("ppo", _ppo, "a trained stable-baselines3 PPO/RecurrentPPO policy: ppo:<model.zip or run folder>")
register_agent("eyecatch", _eyecatch, "Eyecatch heuristic (Yeo et al. 2012): Kalman filter, saccades, submovements")
register_agent("belief_mpc", _belief_mpc, "belief-space MPC (Eom et al. 2019): Kalman beliefs, iLQR over gaze, head, hand")
register_agent("gaze_blind", _gaze_blind,
               "gaze_blind:<agent>: that agent with its gaze and head held (its gaze-blind twin)", wraps=True)
register_agent("fixed_gaze", _fixed_gaze,
               "gaze_blind:eyecatch: the Eyecatch filter and hand with gaze and head held (gaze-blind reference)")


def _static_gaze(env_id, action_dim, seed, base=None, **posture):
    from visuomotor_gym.static_gaze import make_static_gaze

    return make_static_gaze(env_id, action_dim, seed, base=base, **posture)


register_agent("static_gaze", _static_gaze,
               "static_gaze:[az=..,el=..,neck_yaw=..,neck_pitch=..,fix=..:]<agent>: that agent with gaze and head "
               "held at one body-frame posture (the searched best one when none is given): its best static twin",
               wraps=True)


def _iwao(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.iwao import IwaoAgent

    return IwaoAgent.for_env(env_id, **kw)


register_agent("iwao", _iwao, "Iwao et al.: head/eye pitch Gaussians per gait cycle toward the next "
               "obstacle, fused percepts, footstep planner (ObstacleWalk); iwao:gaze_blind=true is its gaze-blind twin")


def _faraway(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.faraway import FarawayAgent

    return FarawayAgent.for_env(env_id, **kw)


# Reach family. Its gaze-blind twin is ``faraway:gaze_blind=true`` (gaze, vergence and head held).
register_agent("faraway", _faraway,
               "reach family: saccade to the object, then a reach along Faraway et al.'s (2007) Bézier path")


def _fajen_warren(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.fajen_warren import FajenWarrenAgent

    return FajenWarrenAgent.for_env(env_id, **kw)


# Dodge family. Its gaze-blind twin is ``fajen_warren:gaze_blind=true`` (gaze and head held).
register_agent("fajen_warren", _fajen_warren,
               "dodge family: Fajen & Warren (2003) steering dynamics on filtered pedestrian percepts, gaze to the "
               "highest collision risk (Olivier et al. 2012); fajen_warren:gaze_blind=true is its gaze-blind twin")


def _lookahead(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.lookahead import LookaheadAgent

    return LookaheadAgent.for_env(env_id, **kw)


# Stones family. Its gaze-blind twin is ``lookahead:gaze_blind=true`` (gaze and head held).
register_agent("lookahead", _lookahead,
               "stones family: fixates the stone two steps ahead from the swing start (Patla & Vickers 2003, "
               "Eom 7), fused percepts, footsteps onto the believed stones")


def _eom_brace(env_id, action_dim, seed, **kw):
    from visuomotor_gym.baselines.eom_brace import EomBraceAgent

    return EomBraceAgent.for_env(env_id, **kw)


# Push family. Its gaze-blind twin is ``gaze_blind:eom_brace`` (gaze, vergence and head held).
register_agent("eom_brace", _eom_brace,
               "push family: detects the CoP at the support polygon's edge, saccades to the nearest believed cube "
               "and keeps gaze on it while the hand braces there (Eom et al. 2019, section 7)")
