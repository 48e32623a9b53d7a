"""Existing entries are immutable: compare the working tree with a base commit in git.

Every file under ``results/`` and ``agents/`` of the leaderboard that exists at the base ref must
exist, byte for byte, in the working tree. New files are allowed (that is how entries are added);
deletions and rewrites are refused. The base ref is ``--base`` (default: ``origin/main`` if it
exists, else ``main``, else ``HEAD``); on a pull request CI passes the target branch.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from visuomotor_gym.leaderboard.entries import AGENTS_DIR, RESULTS_DIR
from visuomotor_gym.leaderboard.problems import Problem

DEFAULT_BASES = ("origin/main", "main", "HEAD")
IMMUTABLE_DIRS = (RESULTS_DIR, AGENTS_DIR)


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


def history_problems(root, base: str | None, rel) -> tuple[list[Problem], str]:
    """Problems of the leaderboard at ``root`` against ``base``, and a one-line note on what was compared.

    ``rel(path)`` formats a path for messages.
    """
    root = Path(root).resolve()
    where = rel(root)
    try:
        top = Path(_git(["rev-parse", "--show-toplevel"], root)).resolve()
    except GitError:
        return [
            Problem(
                where,
                "history",
                "is not inside a git repository, so deleted or rewritten entries "
                "cannot be detected (run the check in a clone, or pass --base none "
                "to skip this rule)",
            )
        ], ""
    try:
        ref = resolve_base(root, base)
        sha = _git(["rev-parse", f"{ref}^{{commit}}"], root)
    except GitError as exc:
        return [Problem(where, "history", str(exc))], ""
    prefix = root.relative_to(top)
    problems = []
    compared = 0
    for sub in IMMUTABLE_DIRS:
        listing = _git(
            ["ls-tree", "-r", "-z", "--name-only", sha, "--", f"{(prefix / sub).as_posix()}/"],
            top,
            binary=True,
        )
        for name in sorted(n.decode("utf-8") for n in listing.split(b"\0") if n):
            compared += 1
            current = top / name
            shown = rel(current)
            if not current.is_file():
                problems.append(
                    Problem(
                        shown,
                        "history",
                        f"was deleted, but it exists on {ref} "
                        f"({sha[:12]}): existing entries are immutable; restore it with "
                        f"`git checkout {ref} -- {name}` (to retire an entry, list it in "
                        f"superseded.json instead)",
                    )
                )
                continue
            before = _git(["cat-file", "blob", f"{sha}:{name}"], top, binary=True)
            if current.read_bytes() != before:
                problems.append(
                    Problem(
                        shown,
                        "history",
                        f"was rewritten: it differs from its version on {ref} "
                        f"({sha[:12]}); existing entries are immutable (submit a new entry under "
                        f"another name instead), restore it with `git checkout {ref} -- {name}`",
                    )
                )
    return problems, f"{compared} committed file(s) compared with {ref} ({sha[:12]})"
