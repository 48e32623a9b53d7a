"""``vmgym leaderboard submit``: play the standard protocol and write an entry (never over an old one).

For each env id: evaluate the agent on the protocol's pinned seeds (:func:`visuomotor_gym.bench.
evaluate.evaluate`, the evaluator of ``vmgym bench``), write the results file, the policy file and
the entry record with the per-episode outcomes, then rebuild the pages and run the entry's own
checks (re-scoring included) so a submitter sees a refusal before CI does.

``from_results`` attaches a results file produced earlier by ``vmgym bench`` on the protocol: the
protocol is played again (the per-episode outcomes are needed) and every score field of the file must
come out identical; the file is then kept byte for byte (its own provenance and timing survive).
"""

from __future__ import annotations

import hashlib
import shlex
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from visuomotor_gym.leaderboard.entries import (
    AGENTS_DIR,
    ENTRY_VERSION,
    RECORD_SUFFIX,
    RESULTS_DIR,
    check_name,
    dumps_record,
    entry_key,
    episode_record,
)

# Fields of a results file that measure the machine rather than the agent's play.
MACHINE_FIELDS = ("latency_ms", "real_time", "run", "provenance")


class SubmitError(RuntimeError):
    """The submission is refused (existing entry, off-protocol results, unknown env id...)."""


@dataclass
class Submission:
    key: str
    written: list[Path] = field(default_factory=list)
    kept: list[Path] = field(default_factory=list)  # files that were already there, byte-identical


def submit_command(agent: str, env_id: str, name: str, workers: int) -> str:
    return shlex.join(
        [
            "vmgym",
            "leaderboard",
            "submit",
            "--agent",
            agent,
            "--env",
            env_id,
            "--name",
            name,
            "--workers",
            str(workers),
        ]
    )


def default_name(agent: str) -> str:
    from visuomotor_gym.agents import parse_agent_spec

    name, overrides = parse_agent_spec(agent)
    if overrides:
        raise SubmitError(
            f"agent {agent!r} has overrides: give the entry its own --name (e.g. {name}-tuned), so "
            f"it is not mistaken for the default {name!r}"
        )
    return name


def _score_differences(stored: dict, fresh: dict) -> list[str]:
    out = []
    for k in sorted(set(stored) | set(fresh)):
        if k in MACHINE_FIELDS:
            continue
        if stored.get(k) != fresh.get(k):
            out.append(f"{k}: file {stored.get(k)!r}, re-run {fresh.get(k)!r}")
    return out


def submit_one(
    root,
    agent: str,
    env_id: str,
    name: str | None = None,
    workers: int = 1,
    from_results=None,
    progress: bool = False,
) -> Submission:
    """Write the entry ``<name>__<env_id>`` under the leaderboard folder ``root`` (see module doc)."""
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.bench.evaluate import evaluate, validate_inputs
    from visuomotor_gym.bench.results import build_results, load_results, write_results
    from visuomotor_gym.leaderboard.policies import format_for_agent, sha256_bytes
    from visuomotor_gym.leaderboard.protocol import load_protocol

    root = Path(root)
    protocol = load_protocol(root)
    proto = protocol.for_env(env_id)
    if proto is None:
        raise SubmitError(
            f"env id {env_id!r} has no protocol in {root / 'protocol.json'}; the leaderboard "
            f"accepts {', '.join(protocol.env_ids)}"
        )
    name = check_name(name if name is not None else default_name(agent))
    key = entry_key(name, env_id)
    results_path = root / RESULTS_DIR / f"{key}.json"
    record_path = root / RESULTS_DIR / f"{key}{RECORD_SUFFIX}"
    attaching_in_place = from_results is not None and Path(from_results).resolve() == results_path.resolve()
    if record_path.exists() or (results_path.exists() and not attaching_in_place):
        raise SubmitError(
            f"entry {key} exists ({results_path.name}): entries are immutable; submit under another --name"
        )
    try:
        validate_inputs(agent, env_id, proto.episodes, proto.seed, workers)
    except (TypeError, ValueError, OSError) as exc:
        raise SubmitError(str(exc)) from exc
    # The policy file before any episode runs (ppo: converted to the pickle-free ppo-npz and proven
    # to give the SB3 model's actions), so a bad one is refused at once.
    fmt0 = format_for_agent(parse_agent_spec(agent)[0])
    policy_data = None
    if fmt0 is not None:
        try:
            policy_data = fmt0.export(agent, env_id)
        except (OSError, ValueError, TypeError, KeyError) as exc:
            raise SubmitError(f"cannot write the {fmt0.name} policy file of {agent!r}: {exc}") from exc

    stored = None
    if from_results is not None:
        stored = load_results(from_results)
        theirs = (stored["agent"], stored["env_id"], stored["episodes"], stored["seed"])
        ours = (agent, env_id, proto.episodes, proto.seed)
        if theirs != ours:
            raise SubmitError(
                f"{from_results} is agent/env/episodes/seed {theirs}, but the submission is {ours} "
                f"(the protocol)"
            )

    result = evaluate(
        agent, env_id, proto.episodes, proto.seed, workers=workers, keep_traces=True, progress=progress
    )
    fresh = build_results(result, submit_command(agent, env_id, name, workers))
    if stored is not None:
        diffs = _score_differences(stored, fresh)
        if diffs:
            raise SubmitError(f"{from_results} does not reproduce on the protocol: " + "; ".join(diffs))

    sub = Submission(key)
    agent_name, _ = parse_agent_spec(agent)
    fmt = format_for_agent(agent_name)
    policy = None
    if fmt is not None:
        data = policy_data
        policy_path = root / AGENTS_DIR / f"{key}{fmt.suffix}"
        if policy_path.exists():
            if policy_path.read_bytes() != data:
                raise SubmitError(f"{policy_path} exists with other content: entries are immutable")
            sub.kept.append(policy_path)
        else:
            policy_path.parent.mkdir(parents=True, exist_ok=True)
            policy_path.write_bytes(data)
            sub.written.append(policy_path)
        policy = {
            "file": f"{AGENTS_DIR}/{policy_path.name}",
            "format": fmt.name,
            "sha256": sha256_bytes(data),
        }

    if stored is not None:
        if Path(from_results).resolve() != results_path.resolve():
            results_path.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(from_results, results_path)
            sub.written.append(results_path)
        else:
            sub.kept.append(results_path)
    else:
        write_results(results_path, fresh)
        sub.written.append(results_path)

    record = {
        "entry_version": ENTRY_VERSION,
        "name": name,
        "env_id": env_id,
        "agent": agent,
        "results": {
            "file": f"{RESULTS_DIR}/{results_path.name}",
            "sha256": hashlib.sha256(results_path.read_bytes()).hexdigest(),
        },
        "policy": policy,
        "episodes": [episode_record(tr) for tr in result.traces],
    }
    with open(record_path, "x", encoding="utf-8") as fh:
        fh.write(dumps_record(record))
    sub.written.append(record_path)
    return sub
