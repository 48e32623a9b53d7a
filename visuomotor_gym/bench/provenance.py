"""Where a result came from: software versions, git commit, platform, time and command.

No personal data: no hostname, user name or home-directory paths (a command line that mentions the
home directory has it replaced by ``~``).
"""

from __future__ import annotations

import os
import platform
import subprocess
from datetime import datetime, timezone
from pathlib import Path

PROVENANCE_FIELDS = (
    "visuomotor_gym",
    "python",
    "numpy",
    "mujoco",
    "gymnasium",
    "git_sha",
    "git_dirty",
    "platform",
    "machine",
    "cpu_count",
    "timestamp_utc",
    "command",
)


def _git(args: list[str], cwd: Path) -> str | None:
    """Output of ``git <args>`` in ``cwd``, or None when git is missing or fails."""
    try:
        out = subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, timeout=10,
                             check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def git_state(package_dir: Path | None = None) -> tuple[str, bool | None]:
    """``(sha, dirty)`` of the repository this package is checked out in; ``("unknown", None)`` else.

    The package counts as "in git" only when its ``__init__.py`` is tracked: a wheel installed into a
    virtual environment that happens to sit inside some repository is not that repository's code.
    ``dirty`` is True when tracked files differ from HEAD or untracked, non-ignored files exist,
    outside ``leaderboard/`` (leaderboard data is not code: a submission writes its files there while
    it evaluates the next env id).
    """
    if package_dir is None:
        package_dir = Path(__file__).resolve().parents[1]
    if _git(["ls-files", "--error-unmatch", "__init__.py"], package_dir) is None:
        return "unknown", None
    sha = _git(["rev-parse", "HEAD"], package_dir)
    if not sha:
        return "unknown", None
    status = _git(["status", "--porcelain", "--", ":(top)", ":(top,exclude)leaderboard"], package_dir)
    return sha, (None if status is None else bool(status))


def _scrub(command: str | None) -> str | None:
    if command is None:
        return None
    home = os.path.expanduser("~")
    if home and home not in ("/", "~"):
        command = command.replace(home, "~")
    return command


def _version(module: str) -> str:
    try:
        mod = __import__(module)
    except ImportError:
        return "not installed"
    return str(getattr(mod, "__version__", "unknown"))


def cpu_count() -> int:
    """CPUs this process may run on (the affinity mask where the OS has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def provenance(command: str | None) -> dict:
    """Versions, git commit, platform and time of this run, plus the ``command`` that produced it."""
    import visuomotor_gym

    sha, dirty = git_state()
    return {
        "visuomotor_gym": visuomotor_gym.__version__,
        "python": platform.python_version(),
        "numpy": _version("numpy"),
        "mujoco": _version("mujoco"),
        "gymnasium": _version("gymnasium"),
        "git_sha": sha,
        "git_dirty": dirty,
        "platform": platform.platform(),
        "machine": platform.machine(),
        "cpu_count": cpu_count(),
        "timestamp_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": _scrub(command),
    }


def report_benchmark(result: dict, json_path: str | None = None) -> dict:
    """Print a benchmark's result as JSON and, with ``json_path``, also write it there; return it."""
    import json

    print(json.dumps(result, indent=2))
    if json_path:
        with open(json_path, "w") as f:
            json.dump(result, f, indent=2)
    return result
