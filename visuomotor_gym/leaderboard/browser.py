"""Headless Chromium: a screenshot and a DOM dump of the leaderboard page (tests and docs).

The browser is ``$VMGYM_BROWSER`` or the first of ``chromium``, ``chromium-browser``,
``google-chrome``, ``google-chrome-stable`` on the PATH (Debian: ``apt-get install chromium``). Each call
uses a fresh, throw-away profile, no network services and no sandbox (CI containers run as root).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-dev-shm-usage",
    "--hide-scrollbars",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--no-default-browser-check",
    "--mute-audio",
)


def find_browser() -> str | None:
    """Path of a headless-capable Chromium, or None."""
    env = os.environ.get("VMGYM_BROWSER")
    if env:
        return shutil.which(env) or (env if Path(env).is_file() else None)
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


def _run(args: list[str], timeout: float) -> subprocess.CompletedProcess:
    browser = find_browser()
    if browser is None:
        raise FileNotFoundError("no Chromium found (apt-get install chromium, or set VMGYM_BROWSER)")
    with tempfile.TemporaryDirectory(prefix="vmgym-chromium-") as profile:
        cmd = [browser, *FLAGS, f"--user-data-dir={profile}", *args]
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({out.returncode}): {out.stderr[-2000:]}")
    return out


def screenshot(page, png, width: int = 1200, height: int = 1600, timeout: float = 90.0) -> Path:
    """Render ``page`` (an HTML file) at ``width`` x ``height`` CSS pixels into ``png``."""
    page, png = Path(page).resolve(), Path(png).resolve()
    png.parent.mkdir(parents=True, exist_ok=True)
    if png.exists():
        png.unlink()
    _run([f"--screenshot={png}", f"--window-size={width},{height}", page.as_uri()], timeout)
    if not png.is_file():
        raise RuntimeError(f"the browser wrote no screenshot to {png}")
    return png


def dump_dom(page, timeout: float = 90.0, budget_ms: int = 5000, width: int = 1200, height: int = 1600) -> str:
    """The DOM of ``page`` after it loaded and its scripts ran, serialised as HTML; laid out in a window of
    ``width`` x ``height`` CSS pixels (the size :func:`screenshot` uses), so scripts measure that layout."""
    page = Path(page).resolve()
    args = [f"--window-size={width},{height}", f"--virtual-time-budget={budget_ms}", "--dump-dom", page.as_uri()]
    return _run(args, timeout).stdout
