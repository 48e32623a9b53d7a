"""Policy files: the exact configuration of an entry's agent, hashed into its entry record.

A *policy format* turns an agent spec into the bytes of a small file (``export``) and that file back
into a policy (``load``). ``vmgym leaderboard submit`` writes ``leaderboard/agents/<entry><suffix>``
with ``export``; ``vmgym leaderboard check`` verifies the file's sha256, verifies that the entry's
agent spec still exports to exactly these bytes (the spec is reproducible from the file), and
re-scores the entry with the policy ``load`` builds from the file.

Formats register with :func:`register_policy_format` (one current format per agent name):

* ``eyecatch-params``: every :class:`~visuomotor_gym.baselines.eyecatch.EyecatchParams` field,
  resolved for the env id (JSON);
* ``belief-mpc-params``: every :class:`~visuomotor_gym.baselines.belief_mpc.agent.BeliefMPCParams`
  field, resolved for the env id (JSON);
* ``ppo-npz``: a trained PPO actor as ``.npy`` arrays plus a JSON record of its architecture and
  normalisation (:func:`visuomotor_gym.baselines.ppo.agent.pack_npz`), converted from the SB3 model at
  submit time. Loading it unpickles nothing and never calls ``torch.load``.

**No policy file is ever unpickled by the check.** Every format's ``load`` reads JSON and plain
``.npy`` arrays (``allow_pickle=False``) only, and checks every value's type. The retired format
``sb3-ppo-zip`` (an SB3 zip: loading it runs cloudpickle on its ``data`` member, so a crafted file runs
code) has no loader: entries that carry it are kept, hash-checked and shown only while superseded
(``superseded.json``); a current entry with it is refused.

Agents without a format (``oracle``, ``zero``, ``random``, ``belief_intercept``: nothing to configure)
have no policy file and are re-scored from their spec with :func:`visuomotor_gym.agents.make_agent`.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Callable
from dataclasses import dataclass

from visuomotor_gym.agents import Policy


@dataclass(frozen=True)
class PolicyFormat:
    name: str  # recorded in the entry, e.g. "eyecatch-params"
    agent: str  # the agent name it serves
    suffix: str  # file name suffix, e.g. ".json" or ".zip"
    export: Callable[[str, str], bytes]  # (agent spec, env id) -> file bytes
    load: Callable[[bytes, str], Policy]  # (file bytes, env id) -> a fresh policy
    # True: the file is a pure function of the spec, and ``check`` verifies that the spec still exports
    # to it (a changed agent is caught). False for trained artifacts: the spec names a training run
    # that need not exist where the check runs; the hashed file *is* the policy, and re-scoring it
    # is the check.
    reexport: bool = True
    # Why the format may no longer be loaded (None: current). A retired format's ``load`` is never
    # called; its entries are only accepted while superseded.
    retired: str | None = None
    # (committed bytes, fresh export, env id) -> True when a committed file that differs from the fresh
    # export still describes the same policy (None: only identical bytes do); see _belief_mpc_same.
    same_policy: Callable[[bytes, bytes, str], bool] | None = None


_FORMATS: dict[str, PolicyFormat] = {}


def register_policy_format(fmt: PolicyFormat) -> None:
    """Register ``fmt`` (replacing a format of the same name)."""
    _FORMATS[fmt.name] = fmt


def policy_format(name: str) -> PolicyFormat | None:
    return _FORMATS.get(name)


def format_for_agent(agent_name: str) -> PolicyFormat | None:
    """The current format serving ``agent_name`` (None: the agent has no policy file)."""
    for fmt in _FORMATS.values():
        if fmt.agent == agent_name and fmt.retired is None:
            return fmt
    return None


def _typed_params(params, cls, what: str, fill_defaults: bool = False) -> dict:
    """``params`` checked against the dataclass ``cls``: exactly its fields, each value of its default's
    JSON type (bool, int, float (an int is accepted), str; a tuple of numbers from a JSON list of numbers,
    returned as a tuple). Raises ValueError naming the field. ``fill_defaults``: a field the file lacks
    takes the dataclass default (a file written before the field existed; the format's ``same_policy``
    check has made sure that default is what the spec resolves today)."""
    from dataclasses import MISSING, fields

    known = {f.name: f for f in fields(cls)}
    if fill_defaults and isinstance(params, dict):
        for name, f in known.items():
            if name not in params and f.default is not MISSING:
                params = {**params, name: list(f.default) if isinstance(f.default, tuple) else f.default}
    if not isinstance(params, dict) or set(params) != set(known):
        missing = sorted(set(known) - set(params or {})) if isinstance(params, dict) else sorted(known)
        unknown = sorted(set(params or {}) - set(known)) if isinstance(params, dict) else []
        raise ValueError(f"params must hold exactly the {what} fields (missing {missing}, unknown {unknown})")
    for name, f in known.items():
        default = f.default if f.default is not MISSING else None
        value = params[name]
        if isinstance(default, bool):
            ok = isinstance(value, bool)
        elif isinstance(default, int):
            ok = isinstance(value, int) and not isinstance(value, bool)
        elif isinstance(default, float):
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        elif isinstance(default, str):
            ok = isinstance(value, str)
        elif isinstance(default, tuple):
            ok = isinstance(value, list) and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value
            )
            if ok:
                params = {**params, name: tuple(value)}
        else:
            ok = value is None or isinstance(value, (bool, int, float, str))
        if not ok:
            raise ValueError(f"params.{name} must be {type(default).__name__}, got {value!r}")
    return params


def _read_json_policy(data: bytes, fmt: str, env_id: str) -> dict:
    try:
        obj = json.loads(data.decode("utf-8"), parse_constant=_reject_constant)
    except (UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"not a {fmt} policy file: {exc}") from None
    if not isinstance(obj, dict) or obj.get("format") != fmt or obj.get("format_version") != 1:
        raise ValueError(f"not a {fmt} v1 policy file")
    allowed = {"format", "format_version", "agent", "env_id", "note", "params"}
    if set(obj) != allowed:
        raise ValueError(f"a {fmt} policy file holds exactly the keys {sorted(allowed)}, got {sorted(obj)}")
    if obj.get("env_id") != env_id:
        raise ValueError(f"the policy file is for {obj.get('env_id')!r}, not {env_id!r}")
    return obj


def _reject_constant(name: str):
    raise ValueError(f"{name} is not valid JSON")


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# ------------------------------------------------------------------ eyecatch-params

EYECATCH_FORMAT = "eyecatch-params"
# What the file means. Files written before the loader gave the agent its env's eye carry the first note:
# they load the same agent wherever the env's eye is the one the params imply (:func:`_eyecatch_same`).
EYECATCH_NOTE = ("Every EyecatchParams field as EyecatchAgent.for_env(env_id, **overrides) resolves it; the policy "
                 "is EyecatchAgent(EyecatchParams(**params)) with the env's eye, as the spec in 'agent' builds it "
                 "(visuomotor_gym.agents.match_vision(agent, agent_eye(env_id, overrides))).")
EYECATCH_NOTE_BEFORE_EYE = ("Every EyecatchParams field as EyecatchAgent.for_env(env_id, **overrides) resolves it; "
                            "the policy is EyecatchAgent(EyecatchParams(**params)).")


def _eyecatch_export(spec: str, env_id: str) -> bytes:
    from dataclasses import asdict

    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.baselines.eyecatch import EyecatchAgent

    name, overrides = parse_agent_spec(spec)
    if name != "eyecatch":
        raise ValueError(f"the {EYECATCH_FORMAT} format serves the eyecatch agent, not {name!r}")
    import visuomotor_gym  # noqa: F401  (registers the ids for gym.spec)

    params = EyecatchAgent.for_env(env_id, **overrides).params
    obj = {
        "format": EYECATCH_FORMAT,
        "format_version": 1,
        "agent": spec,
        "env_id": env_id,
        "note": EYECATCH_NOTE,
        "params": asdict(params),
    }
    return (json.dumps(obj, indent=2, allow_nan=False) + "\n").encode("utf-8")


def _eyecatch_load(data: bytes, env_id: str) -> Policy:
    from visuomotor_gym.baselines.eyecatch import EyecatchAgent, EyecatchParams

    obj = _read_json_policy(data, EYECATCH_FORMAT, env_id)
    params = _typed_params(obj["params"], EyecatchParams, "EyecatchParams", fill_defaults=True)
    agent = EyecatchAgent(EyecatchParams(**params))
    eye = _eyecatch_env_eye(obj["agent"], env_id)
    if eye is not None:
        # every constant of the env's eye (the human periphery, the paper conditions' vision_params), as
        # the spec path gives it (agents._with_env_vision): the replayed policy is the one that was scored
        from visuomotor_gym.agents import match_vision

        match_vision(agent, eye)
    return agent


def _eyecatch_env_eye(spec, env_id: str):
    """The ``VisionParams`` the agent spec ``spec`` models on ``env_id`` (None when the spec overrides the
    eye it assumes, :func:`visuomotor_gym.registration.agent_eye`)."""
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.registration import agent_eye

    if not isinstance(spec, str):
        raise ValueError(f"agent must be an agent spec string, got {spec!r}")
    name, overrides = parse_agent_spec(spec)
    if name != "eyecatch":
        raise ValueError(f"the {EYECATCH_FORMAT} format serves the eyecatch agent, not {name!r}")
    return agent_eye(env_id, overrides)


def _eyecatch_same(committed: bytes, fresh: bytes, env_id: str) -> bool:
    """A committed Eyecatch file written before some parameters existed (``periphery_model``) is the same
    policy when the fresh export adds only fields at their default (:func:`_same_but_defaults`); one written
    before the loader gave the agent its env's eye (:data:`EYECATCH_NOTE_BEFORE_EYE`) is the same policy
    where that eye is the one its params build alone."""
    from visuomotor_gym.baselines.eyecatch import EyecatchAgent, EyecatchParams

    old = json.loads(committed)
    if isinstance(old, dict) and old.get("note") == EYECATCH_NOTE_BEFORE_EYE:
        # written before the loader gave the agent its env's eye: the same policy only where that eye is
        # the one the params alone build (EyecatchAgent's own VisionParams from noise scale and foveation)
        params = _typed_params(old.get("params"), EyecatchParams, "EyecatchParams", fill_defaults=True)
        eye = _eyecatch_env_eye(old.get("agent"), env_id)
        if eye is not None and eye != EyecatchAgent(EyecatchParams(**params)).vision:
            return False
        committed = (json.dumps({**old, "note": EYECATCH_NOTE}, indent=2, allow_nan=False) + "\n").encode("utf-8")
        if committed == fresh:
            return True
    return _same_but_defaults(committed, fresh, EyecatchParams)


register_policy_format(PolicyFormat(EYECATCH_FORMAT, "eyecatch", ".json", _eyecatch_export, _eyecatch_load,
                                    same_policy=_eyecatch_same))


# ------------------------------------------------------------------ belief-mpc-params

BELIEF_MPC_FORMAT = "belief-mpc-params"


def _belief_mpc_classes(env_id: str) -> tuple[type, type, str | None]:
    """(agent class, params class, how its note names the env's VisionParams, None when the agent takes
    none) of the belief_mpc agent on ``env_id``'s family, from the family record's ``belief_mpc``
    (:class:`visuomotor_gym.family.BeliefMPC`; the note's name is fixed by committed entries: the check
    compares re-exported bytes)."""
    import visuomotor_gym  # noqa: F401  (registers the ids for gym.spec)
    from visuomotor_gym.families import family_for
    from visuomotor_gym.family import resolve

    record = family_for(env_id)
    if record.belief_mpc is None:
        raise ValueError(f"the {BELIEF_MPC_FORMAT} format serves families the belief_mpc agent plays, "
                         f"not {env_id}'s {record.name} family")
    spec = record.belief_mpc
    return resolve(spec.agent), resolve(spec.params), spec.vision_note


def _belief_mpc_export(spec: str, env_id: str) -> bytes:
    from dataclasses import asdict

    from visuomotor_gym.agents import parse_agent_spec

    name, overrides = parse_agent_spec(spec)
    if name != "belief_mpc":
        raise ValueError(f"the {BELIEF_MPC_FORMAT} format serves the belief_mpc agent, not {name!r}")
    agent_cls, params_cls, vision = _belief_mpc_classes(env_id)
    params = asdict(agent_cls.for_env(env_id, **overrides).params)
    a, p = agent_cls.__name__, params_cls.__name__
    note = f"Every {p} field as {a}.for_env(env_id, **overrides) resolves it; the policy is {a}({p}(**params)"
    note += f", vision={vision}(env_id))." if vision else ")."
    obj = {
        "format": BELIEF_MPC_FORMAT,
        "format_version": 1,
        "agent": spec,
        "env_id": env_id,
        "note": note,
        "params": params,
    }
    return (json.dumps(obj, indent=2, allow_nan=False) + "\n").encode("utf-8")


def _belief_mpc_load(data: bytes, env_id: str) -> Policy:
    from visuomotor_gym.registration import env_vision_params

    obj = _read_json_policy(data, BELIEF_MPC_FORMAT, env_id)
    agent_cls, params_cls, vision = _belief_mpc_classes(env_id)
    params = params_cls(**_typed_params(obj["params"], params_cls, params_cls.__name__, fill_defaults=True))
    if vision:
        return agent_cls(params, vision=env_vision_params(env_id))
    agent = agent_cls(params)
    agent.env_id = env_id  # as for_env sets it (the catch planner builds its Eyecatch perception for this id)
    from visuomotor_gym.families import family_for

    if family_for(env_id).belief_mpc.env_vision:
        # every constant of the env's eye, as the spec path gives it (agents._with_env_vision): the human
        # periphery of EyeCatch-v0 is more than the noise scale and foveation the params carry
        from visuomotor_gym.agents import _with_env_vision, parse_agent_spec

        if not isinstance(obj.get("agent"), str):
            raise ValueError(f"agent must be an agent spec string, got {obj.get('agent')!r}")
        _with_env_vision(agent, env_id, parse_agent_spec(obj["agent"])[1])
    return agent


def _belief_mpc_same(committed: bytes, fresh: bytes, env_id: str) -> bool:
    """A committed belief-MPC file written before some parameters existed is the same policy as the
    fresh export when the fresh export has exactly the committed file's fields and values plus fields
    that sit at the params dataclass's default: :func:`_belief_mpc_load` fills a missing field with
    that default, so loading the committed file builds the agent the spec builds today. (A field added
    with a default that changes behaviour is still caught: the re-score replays the committed file.)"""
    _, params_cls, _ = _belief_mpc_classes(env_id)
    return _same_but_defaults(committed, fresh, params_cls)


def _same_but_defaults(committed: bytes, fresh: bytes, params_cls: type) -> bool:
    """The rule of :func:`_belief_mpc_same` for any params dataclass: the fresh export is the committed file
    plus fields at ``params_cls``'s defaults (the loader fills a missing field with its default)."""
    from dataclasses import MISSING, fields

    old, new = json.loads(committed), json.loads(fresh)
    if not (isinstance(old.get("params"), dict) and isinstance(new.get("params"), dict)):
        return False
    added = set(new["params"]) - set(old["params"])
    if not added or set(old["params"]) - set(new["params"]):
        return False
    defaults = {}
    for f in fields(params_cls):
        if f.default is not MISSING:
            defaults[f.name] = f.default
        elif f.default_factory is not MISSING:
            defaults[f.name] = f.default_factory()
    for name in added:
        if name not in defaults or json.loads(json.dumps(defaults[name])) != new["params"][name]:
            return False
    trimmed = {**new, "params": {k: v for k, v in new["params"].items() if k not in added}}
    return (json.dumps(trimmed, indent=2, allow_nan=False) + "\n").encode("utf-8") == committed


register_policy_format(
    PolicyFormat(BELIEF_MPC_FORMAT, "belief_mpc", ".json", _belief_mpc_export, _belief_mpc_load,
                 same_policy=_belief_mpc_same)
)


# ------------------------------------------------------------------ ppo-npz (and the retired sb3-ppo-zip)

PPO_FORMAT = "ppo-npz"
RETIRED_PPO_FORMAT = "sb3-ppo-zip"


def _ppo_export(spec: str, env_id: str) -> bytes:
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.baselines.ppo.agent import pack_npz

    name, overrides = parse_agent_spec(spec)
    if name != "ppo" or set(overrides) != {"path"}:
        raise ValueError(f"the {PPO_FORMAT} format serves ppo:<run folder, model zip or .npz>, not {spec!r}")
    return pack_npz(overrides["path"])


def _ppo_load(data: bytes, env_id: str) -> Policy:
    from visuomotor_gym.baselines.ppo.agent import PPOAgent

    return PPOAgent.from_npz(data, env_id)


register_policy_format(PolicyFormat(PPO_FORMAT, "ppo", ".npz", _ppo_export, _ppo_load, reexport=False))


def _retired(*_args):
    raise ValueError(f"the {RETIRED_PPO_FORMAT} format is retired: loading an SB3 zip unpickles it")


register_policy_format(
    PolicyFormat(
        RETIRED_PPO_FORMAT,
        "ppo",
        ".zip",
        _retired,
        _retired,
        reexport=False,
        retired="an SB3 zip cannot be loaded without unpickling (cloudpickle runs code from its data "
        f"member); re-submit the policy, which writes the pickle-free {PPO_FORMAT} format",
    )
)
