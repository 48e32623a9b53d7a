"""The git rules of the check: what a pull request may change, measured against a base commit.

* **Entries are immutable.** Every file under ``results/`` and ``agents/`` that exists at the base
  ref must exist in the working tree as the same git object: a regular file (not a link) whose blob
  (``blob <size>\\0<bytes>``, hashed as git hashes it) and mode (644 or 755) are the base's. New files are
  allowed (that is how entries are added); deletions and rewrites are refused. A *symbolic link* on the
  base (mode 120000, never an entry: it is refused at admission, but may have been merged by mistake)
  is compared as a link (its target text, never the file it points to), is not an entry of the base,
  and may be deleted or replaced; while unchanged it is a note, not a problem, so it blocks no later
  pull request.
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
  in the history of the checked tree, and the run's timestamp is not before that commit. For a new
  entry that commit must also *contain what the entry claims to have run* (:func:`claim_problems`):
  the source file of every registered agent of its spec, with the agent's registration, and, for a
  ``ppo:<file>.npz`` spec, that file with exactly the bytes of the entry's policy file. A claim the
  commit does not hold is refused (not shown as "unverified": a page must not depend on git).
* **New protocol rows are full rows** (:func:`protocol_history_problems`): an env id added to
  ``protocol.json`` needs at least as many episodes as the fewest of the base's rows (the protocol's
  own minimum: 200 today), so a new rung cannot be admitted on a handful of episodes.

The base ref is ``--base`` (default: ``origin/main`` if it exists, else ``main``, else ``HEAD``); on a
pull request CI passes the target branch.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
import subprocess
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone
from pathlib import Path

from visuomotor_gym.leaderboard.entries import AGENTS_DIR, RESULTS_DIR, SUPERSEDED_FILE
from visuomotor_gym.leaderboard.problems import Problem

DEFAULT_BASES = ("origin/main", "main", "HEAD")
LINK_MODE = "120000"
REGULAR_MODES = ("100644", "100755")
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
    objects: dict[str, tuple[str, str]] = field(default_factory=dict)  # repo-relative path -> (mode, blob id)

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
            if self.objects.get(name, ("100644", ""))[0] == LINK_MODE:
                continue  # a committed link is never an entry
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
        listing = _git(["ls-tree", "-r", "-z", sha, "--", f"{(prefix / sub).as_posix()}/"], top, binary=True)
        names = []
        for item in listing.split(b"\0"):
            if not item:
                continue
            head, _, name_b = item.partition(b"\t")
            mode, _kind, blob = head.decode("ascii").split(" ")
            name = name_b.decode("utf-8", "surrogateescape")
            out.objects[name] = (mode, blob)
            names.append(name)
        out.files[sub] = sorted(names)
    return out, []


def base_object(b: Base, path: str) -> tuple[str, str] | None:
    """(mode, blob id) of the repo-relative ``path`` at the base (None when absent), for any path."""
    if path in b.objects:
        return b.objects[path]
    try:
        listing = _git(["ls-tree", "-z", b.sha, "--", path], b.top, binary=True)
    except GitError:
        return None
    for item in listing.split(b"\0"):
        head, _, name = item.partition(b"\t")
        if name.decode("utf-8", "surrogateescape") == path:
            mode, _kind, blob = head.decode("ascii").split(" ")
            return mode, blob
    return None


def git_blob_id(data: bytes, like: str) -> str:
    """The id git gives a blob of ``data``, in the hash of the object id ``like`` (40 hex: SHA-1, 64: SHA-256)."""
    h = hashlib.sha1() if len(like) == 40 else hashlib.sha256()
    h.update(b"blob %d\0" % len(data))
    h.update(data)
    return h.hexdigest()


def worktree_object(path: Path, like: str) -> tuple[str, str] | None:
    """(mode, blob id) git would record for ``path`` in the working tree, never following a link;
    None when it is absent; ("?", "") for anything that is neither a regular file nor a link."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(st.st_mode):
        return LINK_MODE, git_blob_id(os.fsencode(os.readlink(path)), like)
    if not stat.S_ISREG(st.st_mode):
        return "?", ""
    from visuomotor_gym.leaderboard.entries import read_regular

    mode = "100755" if st.st_mode & stat.S_IXUSR else "100644"
    return mode, git_blob_id(read_regular(path), like)


def excused_links(b: Base, links: dict) -> tuple[set, list[str]]:
    """The links of ``links`` (path -> problem, from the loader) that the base holds unchanged (the same
    link text): excused (they block no pull request), with a note for each."""
    excused, notes = set(), []
    for path in links:
        path = Path(path)
        try:  # the link itself, not what it points to: resolve its folder only
            name = (Path(os.path.realpath(path.parent)) / path.name).relative_to(b.top)
        except ValueError:
            continue
        name = name.as_posix()
        old = base_object(b, name)
        now = worktree_object(Path(path), b.sha)
        if old is not None and old[0] == LINK_MODE and now == old:
            excused.add(path)
            notes.append(
                f"{name} is a symbolic link committed on {b.ref} ({b.sha[:12]}): ignored (never followed, not an "
                f"entry); delete it in a pull request"
            )
    return excused, notes


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
            old = b.objects.get(name)
            now = worktree_object(current, b.sha) if old is not None else None
            if old is not None and old[0] not in REGULAR_MODES:
                continue  # a link on the base: never an entry; deleting or replacing it is allowed
            if old is not None and now is not None and now[0] == LINK_MODE:
                problems.append(
                    Problem(
                        shown,
                        "history",
                        f"was replaced by a symbolic link, but it is a regular file on {b.ref} ({b.sha[:12]}): "
                        f"existing entries are immutable; restore it with `git checkout {b.ref} -- {name}`",
                    )
                )
                continue
            if now is None or now[0] == "?":
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
            if now[1] != old[1] or now[0] != old[0]:
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
    old_rows = [e for e in old.get("envs") or [] if isinstance(e, dict)]
    counts = [e.get("episodes") for e in old_rows if isinstance(e.get("episodes"), int)]
    if counts:
        minimum = min(counts)
        known = {e.get("env_id") for e in old_rows}
        for e in new.envs:
            if e.env_id not in known and e.episodes < minimum:
                out.append(
                    Problem(
                        where,
                        "history",
                        f"the new env id {e.env_id!r} has {e.episodes} episodes; a new row needs at least the "
                        f"protocol's minimum, {minimum} (the fewest of any row on {b.ref} {b.sha[:12]}), so that "
                        f"its success rates are as precise as the others'",
                    )
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


REGISTRATION = 'register_agent("{name}"'


def _agent_names(spec: str) -> tuple[list[str], str | None]:
    """(registered agent names of ``spec``, wrappers included; the ``path`` argument, if any)."""
    from visuomotor_gym.agents import parse_agent_spec

    names, path = [], None
    while True:
        name, overrides = parse_agent_spec(spec)
        names.append(name)
        if "base" in overrides:
            spec = overrides["base"]
            continue
        path = overrides.get("path")
        return names, path if isinstance(path, str) else None


def claim_problems(root, sha: str, agent: str, policy: bytes | None, where: str) -> list[Problem]:
    """What a new entry claims to have run is in its provenance commit ``sha``:

    * every registered agent of the spec (a wrapper and its base) is registered there
      (``register_agent("<name>"`` in a file of that commit), when the checked repository registers
      agents at all (a repository that holds only a leaderboard folder has nothing to compare);
    * a ``<agent>:<path>`` spec's file (``ppo:<file>.npz``) is in that commit with exactly the bytes
      of the entry's policy file (the policy that was re-scored is the one the commit holds).
    """
    try:
        names, path = _agent_names(agent)
        root = Path(_git(["rev-parse", "--show-toplevel"], Path(root)))  # git grep searches from here
    except (ValueError, GitError):
        return []  # reported by the consistency rule / the history rule
    out = []
    try:
        _git(["grep", "-q", "-F", "-e", "register_agent(", "HEAD", "--"], root)
        registers = True
    except GitError:
        registers = False
    if registers:
        for name in names:
            try:
                _git(["grep", "-q", "-F", "-e", REGISTRATION.format(name=name), sha, "--"], root)
            except GitError:
                out.append(
                    Problem(
                        where,
                        "provenance",
                        f"provenance.git_sha {sha[:12]} does not hold the agent {name!r} (no "
                        f"{REGISTRATION.format(name=name)}...) in that commit): an entry must name the commit "
                        f"whose code it ran",
                    )
                )
    if path is not None:
        try:
            committed = _git(["cat-file", "blob", f"{sha}:{path}"], root, binary=True)
        except GitError:
            committed = None
        if committed is None:
            out.append(
                Problem(
                    where,
                    "provenance",
                    f"the agent spec names {path!r}, which is not a file of commit {sha[:12]} "
                    f"(provenance.git_sha): a new entry's policy must be committed before it is submitted "
                    f"(commit the .npz policy file, then submit ppo:<that file> from a clean checkout)",
                )
            )
        elif policy is not None and committed != policy:
            out.append(
                Problem(
                    where,
                    "provenance",
                    f"the agent spec names {path!r}, but that file in commit {sha[:12]} is not the entry's policy "
                    f"file (sha256 {hashlib.sha256(committed).hexdigest()[:16]}... vs "
                    f"{hashlib.sha256(policy).hexdigest()[:16]}...): the entry claims a policy it did not run",
                )
            )
    return out
