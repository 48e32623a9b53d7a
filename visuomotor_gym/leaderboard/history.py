"""The git rules of the check: what a pull request may change, measured against a base commit.

* **Entries are immutable.** Every file under ``results/`` and ``agents/`` that exists at the base
  ref must exist, byte for byte, in the working tree. New files are allowed (that is how entries are
  added); deletions and rewrites are refused.
* **New or existing.** An entry whose results file exists at the base was admitted there; any other
  entry is *new* and gets the admission rules of the check (every pinned seed re-scored, the summary
  recomputed, provenance verified). The re-score sample of existing entries is drawn from the base
  commit's sha, which exists before the pull request.
* **protocol.json cannot be weakened for existing entries** (:func:`protocol_history_problems`): no
  env id removed, no change of its episodes or first seed, no smaller re-score sample, no larger
  tolerance, no other protocol version.
* **superseded.json is append-only** (:func:`superseded_history_problems`): a listing on the base is
  kept with its reason and ``by``; a new listing may only name an entry that exists on the base (a new
  entry cannot arrive superseded, which would hide it from re-scoring).
* **Provenance names a real commit** (:func:`commit_problems`): the results' ``git_sha`` is a commit
  in the history of the checked tree, and the run's timestamp is not before that commit.

The base ref is ``--base`` (default: ``origin/main`` if it exists, else ``main``, else ``HEAD``); on a
pull request CI passes the target branch.
"""

from __future__ import annotations

import json
import subprocess
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone
from pathlib import Path

from visuomotor_gym.leaderboard.entries import AGENTS_DIR, RESULTS_DIR, SUPERSEDED_FILE
from visuomotor_gym.leaderboard.problems import Problem

DEFAULT_BASES = ("origin/main", "main", "HEAD")
IMMUTABLE_DIRS = (RESULTS_DIR, AGENTS_DIR)
PROTOCOL_FILE = "protocol.json"
# A run's timestamp may precede its commit's committer date by this much (clock skew between the
# machine that committed and the one that ran; modelling choice, the same day of slack the future
# check allows).
CLOCK_SKEW = timedelta(days=1)


class GitError(RuntimeError):
    pass


def _git(args: list[str], cwd: Path, binary: bool = False):
    try:
        out = subprocess.run(["git", *args], cwd=cwd, capture_output=True, timeout=60, check=False)
    except (OSError, subprocess.SubprocessError) as exc:
        raise GitError(f"cannot run git: {exc}") from exc
    if out.returncode != 0:
        raise GitError(out.stderr.decode("utf-8", "replace").strip() or f"git {' '.join(args)} failed")
    return out.stdout if binary else out.stdout.decode("utf-8", "replace").strip()


def _ref_exists(ref: str, cwd: Path) -> bool:
    try:
        _git(["rev-parse", "--verify", "--quiet", f"{ref}^{{commit}}"], cwd)
        return True
    except GitError:
        return False


def resolve_base(root: Path, base: str | None) -> str:
    """The base ref to compare with: ``base``, or the first of :data:`DEFAULT_BASES` that exists."""
    if base not in (None, "", "auto"):
        if not _ref_exists(base, root):
            raise GitError(
                f"base ref {base!r} not found (fetch it, e.g. `git fetch origin main`, or pass "
                f"--base none to skip the history check)"
            )
        return base
    for candidate in DEFAULT_BASES:
        if _ref_exists(candidate, root):
            return candidate
    raise GitError("no base ref: none of origin/main, main, HEAD exists (an empty repository?)")


@dataclass
class Base:
    """The leaderboard folder as it is at the base commit."""

    ref: str
    sha: str
    top: Path  # the repository's top level
    prefix: Path  # the leaderboard folder relative to ``top``
    files: dict[str, list[str]] = field(default_factory=dict)  # sub folder -> repo-relative paths

    def blob(self, name: str) -> bytes:
        return _git(["cat-file", "blob", f"{self.sha}:{name}"], self.top, binary=True)

    def json(self, leaf: str):
        """A JSON file of the leaderboard folder at the base (None when absent or unreadable)."""
        try:
            return json.loads(self.blob((self.prefix / leaf).as_posix()).decode("utf-8"))
        except (GitError, ValueError, UnicodeDecodeError):
            return None

    @property
    def entry_keys(self) -> set[str]:
        """Keys of the entries whose results file exists at the base."""
        out = set()
        for name in self.files.get(RESULTS_DIR, []):
            leaf = name.rsplit("/", 1)[-1]
            if leaf.endswith(".json") and not leaf.endswith(".entry.json"):
                out.add(leaf[: -len(".json")])
        return out


def load_base(root, base: str | None, rel) -> tuple[Base | None, list[Problem]]:
    """The :class:`Base` of the leaderboard at ``root``, or None and the problem saying why."""
    root = Path(root).resolve()
    where = rel(root)
    try:
        top = Path(_git(["rev-parse", "--show-toplevel"], root)).resolve()
    except GitError:
        return None, [
            Problem(
                where,
                "history",
                "is not inside a git repository, so deleted or rewritten entries "
                "cannot be detected (run the check in a clone, or pass --base none "
                "to skip this rule)",
            )
        ]
    try:
        ref = resolve_base(root, base)
        sha = _git(["rev-parse", f"{ref}^{{commit}}"], root)
    except GitError as exc:
        return None, [Problem(where, "history", str(exc))]
    prefix = root.relative_to(top)
    out = Base(ref, sha, top, prefix)
    for sub in IMMUTABLE_DIRS:
        listing = _git(
            ["ls-tree", "-r", "-z", "--name-only", sha, "--", f"{(prefix / sub).as_posix()}/"], top, binary=True
        )
        out.files[sub] = sorted(n.decode("utf-8") for n in listing.split(b"\0") if n)
    return out, []


def history_problems(root, base: str | None, rel) -> tuple[list[Problem], str]:
    """Deleted or rewritten entry files of the leaderboard at ``root`` against ``base``, and a one-line
    note on what was compared. ``rel(path)`` formats a path for messages."""
    b, problems = load_base(root, base, rel)
    if b is None:
        return problems, ""
    return immutability_problems(b, rel), f"{sum(len(v) for v in b.files.values())} committed file(s) compared with {b.ref} ({b.sha[:12]})"


def immutability_problems(b: Base, rel) -> list[Problem]:
    problems = []
    for sub in IMMUTABLE_DIRS:
        for name in b.files.get(sub, []):
            current = b.top / name
            shown = rel(current)
            if not current.is_file():
                problems.append(
                    Problem(
                        shown,
                        "history",
                        f"was deleted, but it exists on {b.ref} "
                        f"({b.sha[:12]}): existing entries are immutable; restore it with "
                        f"`git checkout {b.ref} -- {name}` (to retire an entry, list it in "
                        f"superseded.json instead)",
                    )
                )
                continue
            if current.read_bytes() != b.blob(name):
                problems.append(
                    Problem(
                        shown,
                        "history",
                        f"was rewritten: it differs from its version on {b.ref} "
                        f"({b.sha[:12]}); existing entries are immutable (submit a new entry under "
                        f"another name instead), restore it with `git checkout {b.ref} -- {name}`",
                    )
                )
    return problems


def protocol_history_problems(b: Base, lb) -> list[Problem]:
    """protocol.json may grow and tighten, never weaken for what exists on the base."""
    old = b.json(PROTOCOL_FILE)
    if not isinstance(old, dict) or lb.protocol is None:
        return []  # no protocol on the base (a new leaderboard), or the current one is broken (reported)
    where = lb.rel(lb.root / PROTOCOL_FILE)
    new = lb.protocol
    out = []

    def add(msg):
        out.append(
            Problem(
                where,
                "history",
                f"{msg} (on {b.ref} {b.sha[:12]}): the protocol cannot be weakened or changed for "
                f"existing entries; add a new env id instead",
            )
        )

    if old.get("protocol_version") != 1:
        add(f"protocol_version was {old.get('protocol_version')!r}")
    for e in old.get("envs") or []:
        if not isinstance(e, dict):
            continue
        now = new.for_env(e.get("env_id"))
        if now is None:
            add(f"env id {e.get('env_id')!r} was removed")
        elif (now.episodes, now.seed) != (e.get("episodes"), e.get("seed")):
            add(
                f"{now.env_id}: episodes/seed changed from {e.get('episodes')}/{e.get('seed')} to "
                f"{now.episodes}/{now.seed}"
            )
    rescore = old.get("rescore") if isinstance(old.get("rescore"), dict) else {}
    sample = rescore.get("sample")
    if isinstance(sample, int) and new.rescore_sample < sample:
        add(f"rescore.sample was lowered from {sample} to {new.rescore_sample}")
    tol = rescore.get("tolerance") if isinstance(rescore.get("tolerance"), dict) else {}
    for key, value in (("time_s", new.time_tolerance_s), ("distance_m", new.distance_tolerance_m)):
        before = tol.get(key)
        if isinstance(before, (int, float)) and value > before:
            add(f"rescore.tolerance.{key} was raised from {before} to {value}")
    return out


def superseded_history_problems(b: Base, lb) -> list[Problem]:
    """superseded.json is append-only, and only entries admitted on the base may be listed."""
    old = b.json(SUPERSEDED_FILE)
    old_items = old.get("superseded", {}) if isinstance(old, dict) else {}
    if not isinstance(old_items, dict):
        old_items = {}
    where = lb.rel(lb.root / SUPERSEDED_FILE)
    now = lb.superseded
    existing = b.entry_keys
    out = []
    for key, listing in sorted(old_items.items()):
        if not isinstance(listing, dict):
            continue
        cur = now.get(key)
        if cur is None:
            out.append(
                Problem(
                    where,
                    "history",
                    f"the listing of {key!r} was removed, but it exists on {b.ref} ({b.sha[:12]}): "
                    f"superseded.json is append-only (an entry, once superseded, stays so)",
                )
            )
            continue
        if cur.get("reason") != listing.get("reason"):
            out.append(
                Problem(where, "history", f"the reason of {key!r} changed from its version on {b.ref}: listings are immutable")
            )
        if "by" in listing and cur.get("by") != listing.get("by"):
            out.append(
                Problem(
                    where,
                    "history",
                    f"{key!r} was superseded by {listing.get('by')!r} on {b.ref}, now by {cur.get('by')!r}: "
                    f"listings are immutable",
                )
            )
    for key in sorted(set(now) - set(old_items)):
        if key not in existing:
            out.append(
                Problem(
                    where,
                    "history",
                    f"lists {key!r}, which is not an entry on {b.ref} ({b.sha[:12]}): a new entry cannot "
                    f"arrive superseded (superseded entries are not re-scored, so this would hide it "
                    f"from re-scoring); submit it as a current entry",
                )
            )
    return out


def commit_problems(root, sha: str, timestamp_utc: str, where: str) -> list[Problem]:
    """``sha`` is a commit in the history of the tree checked out at ``root`` (HEAD), and the run's
    ``timestamp_utc`` is not more than :data:`CLOCK_SKEW` before that commit's committer date."""
    root = Path(root)
    try:
        _git(["cat-file", "-e", f"{sha}^{{commit}}"], root)
    except GitError:
        return [
            Problem(
                where,
                "provenance",
                f"provenance.git_sha {sha} is not a commit of this repository: an entry must name the "
                f"commit it ran at (push that commit with the entry)",
            )
        ]
    try:
        _git(["merge-base", "--is-ancestor", sha, "HEAD"], root)
    except GitError:
        return [
            Problem(
                where,
                "provenance",
                f"provenance.git_sha {sha[:12]} is not in the history of the checked tree (HEAD): an "
                f"entry must be produced by code this branch contains",
            )
        ]
    try:
        committed = datetime.fromtimestamp(int(_git(["show", "-s", "--format=%ct", sha], root)), timezone.utc)
        stamp = datetime.strptime(timestamp_utc[:19], "%Y-%m-%dT%H:%M:%S").replace(tzinfo=timezone.utc)
    except (GitError, ValueError) as exc:
        return [Problem(where, "provenance", f"cannot compare the timestamp with commit {sha[:12]}: {exc}")]
    if stamp < committed - CLOCK_SKEW:
        return [
            Problem(
                where,
                "provenance",
                f"provenance.timestamp_utc {timestamp_utc} is before commit {sha[:12]} was made "
                f"({committed:%Y-%m-%dT%H:%M:%SZ}): a run cannot precede the code it ran",
            )
        ]
    return []
