"""Leaderboard entries on disk: results file + entry record + policy file, and per-episode outcomes.

An entry named ``<name>`` on ``<env_id>`` (key ``<name>__<env_id>``) is three files under the
leaderboard folder:

* ``results/<key>.json``: the results file of ``vmgym bench`` (validated by
  :func:`visuomotor_gym.bench.results.load_results`; its content is never altered);
* ``results/<key>.entry.json``: the entry record (``entry_schema.json``): the sha256 of the results
  file, the policy file with its format and sha256, and one outcome record per pinned seed
  (seed, caught, diverged, steps, catch time, miss distance, first-saccade time);
* ``agents/<key><suffix>``: the policy file (absent for agents with nothing to configure).

``leaderboard/superseded.json`` (optional, ``superseded_schema.json``) lists entries retired by a
newer version of the same agent (``by``), e.g. because the code they ran moved on: they stay on the
leaderboard, immutable and hash-checked, but are not re-scored and are shown apart. Entries are never
deleted or rewritten. (Which listings a pull request may add: :mod:`.history`.)

**Only regular files are read.** Before anything under the folder is read, every path is checked with
``lstat``: the folder itself, ``results/``, ``agents/`` and every file must be a real folder or a
regular file inside it; a symbolic link (anywhere on the path, absolute or relative) or any other
special file is never followed or read, and is a ``layout`` problem (:attr:`Leaderboard.links`; the
check lets one through only when the base branch already holds the same link, so that a link merged
by mistake never blocks later pull requests; see :mod:`.history`). Files are opened with
``O_NOFOLLOW``.
"""

from __future__ import annotations

import functools
import json
import math
import os
import re
import stat
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from visuomotor_gym.leaderboard.problems import Problem, load_schema, schema_problems

RESULTS_DIR = "results"
AGENTS_DIR = "agents"
RECORD_SUFFIX = ".entry.json"
SUPERSEDED_FILE = "superseded.json"
ENTRY_VERSION = 1
# Matched with fullmatch (``$`` would also match before a trailing newline).
NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")
ENV_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._:-]*")
EPISODE_FIELDS = ("seed", "caught", "diverged", "steps", "catch_time_s", "miss_distance_m", "first_saccade_s")


def entry_key(name: str, env_id: str) -> str:
    return f"{name}__{env_id}"


# File names are <name>__<env_id>.entry.json: 100 characters of name keep them well under the 255
# bytes most file systems allow (modelling choice).
MAX_NAME_LENGTH = 100


def check_name(name: str) -> str:
    """Return ``name`` if it is a valid entry name, else raise ValueError saying why."""
    if isinstance(name, str) and name == "":
        raise ValueError("entry name is empty: give --name a name such as eyecatch-tuned")
    if isinstance(name, str) and len(name) > MAX_NAME_LENGTH:
        raise ValueError(f"entry name is {len(name)} characters long; at most {MAX_NAME_LENGTH} are allowed")
    if not isinstance(name, str) or not NAME_RE.fullmatch(name) or "__" in name:
        raise ValueError(
            f"entry name {name!r} must start with a letter or digit and hold only letters, "
            f"digits, '.', '-' and single '_' (no '__': it separates name and env id)"
        )
    return name


@functools.lru_cache(maxsize=1)
def load_entry_schema() -> dict:
    text = resources.files("visuomotor_gym.leaderboard").joinpath("entry_schema.json").read_text("utf-8")
    return json.loads(text)


def _finite_or_none(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def episode_record(trace) -> dict:
    """The outcome record of one :class:`~visuomotor_gym.bench.trace.EpisodeTrace`."""
    from visuomotor_gym.metrics.gaze import first_saccade_latency
    from visuomotor_gym.metrics.outcome import time_to_catch
    from visuomotor_gym.metrics.summary import episode_miss_distance

    return {
        "seed": int(trace.seed),
        "caught": bool(trace.caught),
        "diverged": bool(trace.diverged),
        "steps": int(trace.steps),
        "catch_time_s": _finite_or_none(time_to_catch(trace)),
        "miss_distance_m": _finite_or_none(episode_miss_distance(trace)),
        "first_saccade_s": _finite_or_none(first_saccade_latency(trace)),
    }


def summary_from_records(records: list[dict]) -> dict:
    """The results fields that per-episode records determine, computed as ``metrics.summarize`` does.

    ``caught``, ``diverged``, ``episodes``, ``time_to_catch_s`` (caught, not diverged),
    ``miss_distance_m`` (not caught, not diverged), ``reaction_times_s.first_saccade`` (not diverged)
    and ``env_steps``.
    """
    from visuomotor_gym.metrics.stats import mean_median
    from visuomotor_gym.metrics.summary import to_json_safe

    def nan(x):
        return float("nan") if x is None else x

    valid = [r for r in records if not r["diverged"]]
    return to_json_safe(
        {
            "episodes": len(records),
            "caught": sum(bool(r["caught"]) for r in records),
            "diverged": sum(bool(r["diverged"]) for r in records),
            "time_to_catch_s": mean_median([nan(r["catch_time_s"]) for r in valid if r["caught"]]),
            "miss_distance_m": mean_median([nan(r["miss_distance_m"]) for r in valid if not r["caught"]]),
            "first_saccade_s": mean_median([nan(r["first_saccade_s"]) for r in valid]),
            "env_steps": sum(int(r["steps"]) for r in records),
        }
    )


def dumps_record(record: dict) -> str:
    """Canonical text of an entry record: 2-space JSON, one line per episode, episodes last."""
    head = {k: v for k, v in record.items() if k != "episodes"}
    text = json.dumps(head, indent=2, allow_nan=False)
    lines = ",\n".join("    " + json.dumps(ep, allow_nan=False) for ep in record["episodes"])
    return text[:-2] + ',\n  "episodes": [\n' + lines + "\n  ]\n}\n"


def record_problems(obj) -> list[str]:
    """Schema problems of an entry record, each with its JSON path."""
    if not isinstance(obj, dict):
        return [f"$: expected a JSON object, got {type(obj).__name__}"]
    return schema_problems(obj, load_entry_schema())


@dataclass
class Entry:
    """One entry as found on disk; ``results`` / ``record`` are None where they failed to load."""

    key: str
    name: str
    env_id: str
    results_path: Path
    record_path: Path
    results: dict | None = None
    record: dict | None = None
    results_bytes: bytes | None = None
    superseded: dict | None = None  # {"reason": ...} when listed in superseded.json

    @property
    def loaded(self) -> bool:
        return self.results is not None and self.record is not None

    @property
    def policy(self) -> dict | None:
        return (self.record or {}).get("policy")


@dataclass
class Leaderboard:
    root: Path
    protocol: object | None  # Protocol, or None when protocol.json is broken
    entries: list[Entry] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)
    superseded: dict[str, dict] = field(default_factory=dict)  # superseded.json's listings
    # Symbolic links and special files found under the folder (never followed or read): the path of
    # each, and its problem (also in ``problems``; the check may excuse one the base already holds).
    links: dict[Path, Problem] = field(default_factory=dict)

    def rel(self, path: Path) -> str:
        """``path`` relative to the leaderboard folder's parent (``leaderboard/results/x.json``)."""
        path = Path(path)
        try:  # the folder resolved, never the file itself (a link is named as the link)
            return str((Path(os.path.realpath(path.parent)) / path.name).relative_to(self.root.resolve().parent))
        except ValueError:
            return str(path)

    @property
    def valid_entries(self) -> list[Entry]:
        return [e for e in self.entries if e.loaded]


def read_regular(path: Path) -> bytes:
    """The bytes of ``path``, which must be a regular file (opened with ``O_NOFOLLOW`` and
    ``O_NONBLOCK``, checked with ``fstat``: a link or a FIFO is refused, never followed or waited on)."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise ValueError(f"cannot open {path.name} as a regular file: {exc.strerror}") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ValueError(f"{path.name} is not a regular file")
        with os.fdopen(os.dup(fd), "rb") as fh:
            return fh.read()
    except OSError as exc:
        raise ValueError(f"cannot read {path.name}: {exc.strerror}") from None
    finally:
        os.close(fd)


def _read_json(path: Path):
    return json.loads(read_regular(path).decode("utf-8"), parse_constant=_reject_constant)


def _kind_of(path: Path) -> str | None:
    """None for a regular file or folder (no link), else what it is: 'a symbolic link to ...', ..."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(mode):
        try:
            target = os.readlink(path)
        except OSError:
            target = "?"
        return f"a symbolic link (to {target!r})"
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None
    return "a special file (not a regular file)"


def _refuse_link(lb: Leaderboard, path: Path, what: str) -> None:
    problem = Problem(
        lb.rel(path),
        "layout",
        f"is {what}: leaderboard files must be regular files inside the leaderboard folder (links are "
        f"never followed); commit the file itself",
    )
    lb.links[path] = problem
    lb.problems.append(problem)


def unsafe_paths(lb: Leaderboard) -> None:
    """Record every link or special file at or under ``lb.root`` (not following any) in ``lb.links``."""
    root = lb.root
    what = _kind_of(root)
    if what is not None:
        _refuse_link(lb, root, what)
        return
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        base = Path(dirpath)
        for n in sorted(dirnames + filenames):
            what = _kind_of(base / n)
            if what is not None:
                _refuse_link(lb, base / n, what)
        dirnames[:] = [d for d in dirnames if (base / d) not in lb.links]


def _reject_constant(name: str):
    raise ValueError(f"{name} is not valid JSON")


def load_leaderboard(root) -> Leaderboard:
    """Find and parse every entry under ``root``; layout, schema and parse problems are collected."""
    from visuomotor_gym.bench.results import ResultsError
    from visuomotor_gym.leaderboard.protocol import ProtocolError, load_protocol

    root = Path(root)
    lb = Leaderboard(root=root, protocol=None)
    if not root.is_dir():
        lb.problems.append(Problem(str(root), "layout", "is not a folder (pass --dir LEADERBOARD)"))
        return lb
    unsafe_paths(lb)  # before anything is read
    if root in lb.links:
        return lb
    if root / "protocol.json" in lb.links:
        lb.problems.append(Problem(lb.rel(root / "protocol.json"), "protocol", "is not a regular file"))
    else:
        try:
            lb.protocol = load_protocol(root)
        except ProtocolError as exc:
            lb.problems.append(Problem(lb.rel(root / "protocol.json"), "protocol", str(exc)))

    results_dir = root / RESULTS_DIR
    files = sorted(p for p in results_dir.iterdir()) if results_dir.is_dir() and results_dir not in lb.links else []
    keys: dict[str, dict[str, Path]] = {}
    for p in files:
        if p in lb.links:
            continue  # a link or special file: refused above, never read
        if not p.is_file() or not p.name.endswith(".json"):
            lb.problems.append(
                Problem(
                    lb.rel(p),
                    "layout",
                    "unexpected file in results/ (only <name>__<env_id>.json "
                    "results files and their .entry.json records belong here)",
                )
            )
            continue
        kind = "record" if p.name.endswith(RECORD_SUFFIX) else "results"
        key = p.name[: -len(RECORD_SUFFIX)] if kind == "record" else p.name[: -len(".json")]
        keys.setdefault(key, {})[kind] = p

    superseded = lb.superseded = _load_superseded(lb)
    for key, paths in sorted(keys.items()):
        parts = key.split("__")
        results_path = paths.get("results", results_dir / f"{key}.json")
        record_path = paths.get("record", results_dir / f"{key}{RECORD_SUFFIX}")
        if len(parts) != 2 or not all(parts) or not NAME_RE.fullmatch(parts[0]) or not ENV_RE.fullmatch(parts[1]):
            lb.problems.append(
                Problem(
                    lb.rel(results_path),
                    "layout",
                    f"file name {key!r} is not <name>__<env_id> (exactly one '__'; the name of letters, "
                    f"digits, '.', '-', '_' starting with a letter or digit; the env id of letters, digits, "
                    f"'.', '-', '_', ':')",
                )
            )
            continue
        entry = Entry(key, parts[0], parts[1], results_path, record_path, superseded=superseded.get(key))
        lb.entries.append(entry)
        if "results" not in paths:
            lb.problems.append(
                Problem(
                    lb.rel(results_path),
                    "layout",
                    f"missing: the entry record {record_path.name} has no results file",
                )
            )
        else:
            try:
                entry.results_bytes = read_regular(results_path)
                entry.results = _parse_results(entry.results_bytes, results_path)
            except ResultsError as exc:
                detail = "; ".join(exc.problems) if exc.problems else str(exc)
                lb.problems.append(Problem(lb.rel(results_path), "results", f"invalid results: {detail}"))
            except ValueError as exc:
                lb.problems.append(Problem(lb.rel(results_path), "layout", str(exc)))
            else:
                bad = _control_characters(entry.results)
                if bad:
                    entry.results = None
                    lb.problems.append(Problem(lb.rel(results_path), "results", bad))
        if "record" not in paths:
            lb.problems.append(
                Problem(
                    lb.rel(record_path),
                    "layout",
                    f"missing: the results file {results_path.name} has no entry record "
                    f"(write entries with `vmgym leaderboard submit`)",
                )
            )
        else:
            try:
                record = _read_json(record_path)
            except ValueError as exc:
                lb.problems.append(Problem(lb.rel(record_path), "record", f"malformed JSON: {exc}"))
            else:
                problems = record_problems(record)
                bad = _control_characters(record)
                if bad:
                    problems.append(bad)
                if problems:
                    lb.problems.append(
                        Problem(lb.rel(record_path), "record", "invalid entry record: " + "; ".join(problems))
                    )
                else:
                    entry.record = record
    for key in sorted(set(superseded) - {e.key for e in lb.entries}):
        lb.problems.append(
            Problem(lb.rel(root / SUPERSEDED_FILE), "layout", f"lists {key!r}, which is no entry")
        )
    return lb


def _parse_results(data: bytes, path: Path) -> dict:
    """``load_results`` on bytes already read (the file is not opened twice)."""
    from visuomotor_gym.bench.results import ResultsError, validate_results

    try:
        obj = json.loads(data.decode("utf-8"), parse_constant=_reject_constant)
    except (UnicodeDecodeError, ValueError) as exc:
        raise ResultsError([f"$: malformed JSON: {exc}"], source=str(path), headline=f"malformed JSON: {exc}") from exc
    validate_results(obj, source=str(path))
    return obj


_CONTROL = re.compile(r"[\x00-\x1f\x7f\u0085\u2028\u2029]")


def _control_characters(obj, path: str = "$") -> str | None:
    """A message naming the first string (value or key) of ``obj`` holding a control character (a
    newline, tab, NUL...), which no field of a results file or entry record needs; None if none."""
    if isinstance(obj, str):
        return (
            f"{path}: {obj[:40]!r} holds a control character (newline, tab...): not allowed in leaderboard files"
            if _CONTROL.search(obj)
            else None
        )
    if isinstance(obj, dict):
        for k, v in obj.items():
            found = _control_characters(k, f"{path} key") or _control_characters(v, f"{path}.{k}")
            if found:
                return found
    if isinstance(obj, list):
        for i, v in enumerate(obj):
            found = _control_characters(v, f"{path}[{i}]")
            if found:
                return found
    return None


def _load_superseded(lb: Leaderboard) -> dict[str, dict]:
    path = lb.root / SUPERSEDED_FILE
    if path in lb.links or not os.path.lexists(path):
        return {}
    try:
        obj = _read_json(path)
    except ValueError as exc:
        lb.problems.append(Problem(lb.rel(path), "layout", f"malformed JSON: {exc}"))
        return {}
    problems = schema_problems(obj, load_schema("superseded_schema.json"))
    if problems:
        lb.problems.append(
            Problem(
                lb.rel(path),
                "layout",
                'expected {"superseded": {"<name>__<env_id>": {"reason": "...", "by": "<name>__<env_id>"}}}: '
                + "; ".join(problems),
            )
        )
        return {}
    bad = _control_characters(obj)
    if bad:
        lb.problems.append(Problem(lb.rel(path), "layout", bad))
        return {}
    return obj["superseded"]
