"""Policy files: the exact configuration of an entry's agent, hashed into its entry record.

A *policy format* turns an agent spec into the bytes of a small file (``export``) and that file back
into a policy (``load``). ``vmgym leaderboard submit`` writes ``leaderboard/agents/<entry><suffix>``
with ``export``; ``vmgym leaderboard check`` verifies the file's sha256, verifies that the entry's
agent spec still exports to exactly these bytes (the spec is reproducible from the file), and
re-scores the entry with the policy ``load`` builds from the file.

Formats register with :func:`register_policy_format` (one per agent name): ``eyecatch-params``
here (every :class:`~visuomotor_gym.baselines.eyecatch.EyecatchParams` field, resolved for the env
id) and ``sb3-ppo-zip`` (a packed stable-baselines3 PPO/RecurrentPPO ``.zip`` with its
``ppo_meta.json`` inside, from ``ppo:<run folder or zip>``). Agents without a
format (``oracle``, ``zero``, ``random``: nothing to configure) have no policy file and are re-scored
from their spec with :func:`visuomotor_gym.agents.make_agent`.
"""

from __future__ import annotations

import hashlib
import json
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


_FORMATS: dict[str, PolicyFormat] = {}


def register_policy_format(fmt: PolicyFormat) -> None:
    """Register ``fmt`` (replacing a format of the same name)."""
    _FORMATS[fmt.name] = fmt


def policy_format(name: str) -> PolicyFormat | None:
    return _FORMATS.get(name)


def format_for_agent(agent_name: str) -> PolicyFormat | None:
    """The format serving ``agent_name`` (None: the agent has no policy file)."""
    for fmt in _FORMATS.values():
        if fmt.agent == agent_name:
            return fmt
    return None


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# ------------------------------------------------------------------ eyecatch-params

EYECATCH_FORMAT = "eyecatch-params"


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
        "note": "Every EyecatchParams field as EyecatchAgent.for_env(env_id, **overrides) resolves it; "
        "the policy is EyecatchAgent(EyecatchParams(**params)).",
        "params": asdict(params),
    }
    return (json.dumps(obj, indent=2, allow_nan=False) + "\n").encode("utf-8")


def _eyecatch_load(data: bytes, env_id: str) -> Policy:
    from dataclasses import fields

    from visuomotor_gym.baselines.eyecatch import EyecatchAgent, EyecatchParams

    obj = json.loads(data.decode("utf-8"))
    if not isinstance(obj, dict) or obj.get("format") != EYECATCH_FORMAT or obj.get("format_version") != 1:
        raise ValueError(f"not an {EYECATCH_FORMAT} v1 policy file")
    if obj.get("env_id") != env_id:
        raise ValueError(f"the policy file is for {obj.get('env_id')!r}, not {env_id!r}")
    params = obj.get("params")
    known = {f.name for f in fields(EyecatchParams)}
    if not isinstance(params, dict) or set(params) != known:
        missing = sorted(known - set(params or {}))
        unknown = sorted(set(params or {}) - known)
        raise ValueError(
            f"params must hold exactly the EyecatchParams fields (missing {missing}, unknown {unknown})"
        )
    return EyecatchAgent(EyecatchParams(**params))


register_policy_format(PolicyFormat(EYECATCH_FORMAT, "eyecatch", ".json", _eyecatch_export, _eyecatch_load))


# ------------------------------------------------------------------ sb3-ppo-zip

PPO_FORMAT = "sb3-ppo-zip"


def _ppo_export(spec: str, env_id: str) -> bytes:
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.baselines.ppo.agent import pack_policy

    name, overrides = parse_agent_spec(spec)
    if name != "ppo" or set(overrides) != {"path"}:
        raise ValueError(f"the {PPO_FORMAT} format serves ppo:<run folder or model zip>, not {spec!r}")
    return pack_policy(overrides["path"])


def _ppo_load(data: bytes, env_id: str) -> Policy:
    from visuomotor_gym.baselines.ppo.agent import PPOAgent

    return PPOAgent.from_bytes(data, env_id)


register_policy_format(PolicyFormat(PPO_FORMAT, "ppo", ".zip", _ppo_export, _ppo_load, reexport=False))
