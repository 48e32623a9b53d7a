"""The standard protocol of the leaderboard (``leaderboard/protocol.json``) and the re-score sample.

The protocol fixes, per env id, the number of episodes and the first seed (episode ``i`` uses
``seed + i``, as in ``vmgym bench``), and how many of those pinned seeds ``vmgym leaderboard check``
re-plays for each entry, with the tolerances for the float outcomes it compares.

The order of ``envs`` is the observability ladder the pages plot along; the pages depend on the
protocol and the results only (never on the env registry), so registering a new env id does not
make the committed pages stale.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from visuomotor_gym.leaderboard.problems import load_schema, schema_problems

PROTOCOL_FILE = "protocol.json"
PROTOCOL_SCHEMA = "protocol_schema.json"
PROTOCOL_VERSION = 1


class ProtocolError(ValueError):
    """``protocol.json`` is missing or malformed."""


@dataclass(frozen=True)
class EnvProtocol:
    env_id: str
    episodes: int
    seed: int
    sees: str = ""  # what the agent sees (shown on the pages)

    @property
    def seeds(self) -> list[int]:
        return [self.seed + i for i in range(self.episodes)]


@dataclass(frozen=True)
class Protocol:
    envs: tuple[EnvProtocol, ...]
    rescore_sample: int
    time_tolerance_s: float
    distance_tolerance_m: float
    description: str = ""

    @property
    def env_ids(self) -> tuple[str, ...]:
        return tuple(e.env_id for e in self.envs)

    def for_env(self, env_id: str) -> EnvProtocol | None:
        for e in self.envs:
            if e.env_id == env_id:
                return e
        return None


def _int(obj: dict, key: str, where: str, minimum: int) -> int:
    value = obj.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ProtocolError(f"{where}.{key} must be an integer >= {minimum}, got {value!r}")
    return value


def _num(obj: dict, key: str, where: str) -> float:
    value = obj.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
        raise ProtocolError(f"{where}.{key} must be a number >= 0, got {value!r}")
    return float(value)


def _reject_constant(name: str):
    raise ValueError(f"{name} is not valid JSON")


def read_protocol_json(text: str):
    """Parse protocol.json text (NaN / Infinity refused)."""
    return json.loads(text, parse_constant=_reject_constant)


def load_protocol(leaderboard_dir) -> Protocol:
    """Read and check ``<leaderboard_dir>/protocol.json``; raises :class:`ProtocolError`."""
    path = Path(leaderboard_dir) / PROTOCOL_FILE
    try:
        obj = read_protocol_json(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ProtocolError(f"{path} is missing: the leaderboard has no protocol") from None
    except ValueError as exc:
        raise ProtocolError(f"{path}: malformed JSON: {exc}") from exc
    if not isinstance(obj, dict):
        raise ProtocolError(f"{path}: expected a JSON object")
    problems = schema_problems(obj, load_schema(PROTOCOL_SCHEMA))
    if problems:
        raise ProtocolError(f"{path}: " + "; ".join(problems))
    if obj.get("protocol_version") != PROTOCOL_VERSION:
        raise ProtocolError(
            f"{path}: protocol_version must be {PROTOCOL_VERSION}, got {obj.get('protocol_version')!r}"
        )
    envs = obj.get("envs")
    if not isinstance(envs, list) or not envs:
        raise ProtocolError(f"{path}: envs must be a non-empty list")
    out, seen = [], set()
    for i, e in enumerate(envs):
        where = f"envs[{i}]"
        if not isinstance(e, dict) or not isinstance(e.get("env_id"), str):
            raise ProtocolError(f"{path}: {where} must be an object with a string env_id")
        if e["env_id"] in seen:
            raise ProtocolError(f"{path}: {where}: env id {e['env_id']!r} appears twice")
        seen.add(e["env_id"])
        out.append(
            EnvProtocol(
                e["env_id"], _int(e, "episodes", where, 1), _int(e, "seed", where, 0), str(e.get("sees", ""))
            )
        )
    rescore = obj.get("rescore")
    if not isinstance(rescore, dict) or not isinstance(rescore.get("tolerance"), dict):
        raise ProtocolError(f"{path}: rescore must be an object with sample and tolerance")
    return Protocol(
        envs=tuple(out),
        rescore_sample=_int(rescore, "sample", "rescore", 1),
        time_tolerance_s=_num(rescore["tolerance"], "time_s", "rescore.tolerance"),
        distance_tolerance_m=_num(rescore["tolerance"], "distance_m", "rescore.tolerance"),
        description=str(obj.get("description", "")),
    )


def sample_seeds(seeds: list[int], k: int, key: str) -> list[int]:
    """``k`` of ``seeds``: one from each of ``k`` equal contiguous strata, spread over the whole run.

    The position inside stratum ``j`` is ``sha256(f"{key}:{j}") mod len(stratum)``: deterministic for
    a given ``key``, so anyone re-running the check re-plays the same seeds. The check uses it for
    *existing* entries only, keyed by the base commit and the entry (``"<base sha>:<entry key>"``),
    which exist before any pull request and are not in the submitter's hands; a new entry is
    re-scored on every pinned seed. (It was keyed by the sha256 of the results file, which the
    submitter writes: a forger could vary a float until the sample fell on honest seeds.)
    ``k >= len(seeds)`` gives every seed.
    """
    n = len(seeds)
    if k >= n:
        return list(seeds)
    out = []
    for j in range(k):
        lo, hi = (j * n) // k, ((j + 1) * n) // k
        digest = hashlib.sha256(f"{key}:{j}".encode()).digest()
        out.append(seeds[lo + int.from_bytes(digest[:8], "big") % (hi - lo)])
    return out
