"""The one place that finds MuJoCo XML assets.

The XML lives in the repository's top-level ``envs_assets/`` folder. A wheel installs that folder
as the ``visuomotor_gym.envs_assets`` package, so the same lookup works from a source checkout, an
editable install and an installed wheel.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

ASSETS_ENV_VAR = "VISUOMOTOR_GYM_ASSETS"


def assets_dir() -> Path:
    """Return the directory holding the scene XML files.

    Order: the ``VISUOMOTOR_GYM_ASSETS`` environment variable (for users editing models), the
    installed ``visuomotor_gym.envs_assets`` package, then ``envs_assets/`` beside the package in a
    source checkout.
    """
    override = os.environ.get(ASSETS_ENV_VAR)
    if override:
        path = Path(override)
        if not path.is_dir():
            raise FileNotFoundError(f"{ASSETS_ENV_VAR}={override!r} is not a directory")
        return path
    try:
        installed = resources.files("visuomotor_gym.envs_assets").joinpath("catch.xml")
        if installed.is_file():
            return Path(str(installed)).parent
    except (ModuleNotFoundError, TypeError):
        pass
    source = Path(__file__).resolve().parent.parent / "envs_assets"
    if (source / "catch.xml").is_file():
        return source
    raise FileNotFoundError(
        "visuomotor_gym cannot find its MuJoCo assets (envs_assets/). Reinstall the package, or set "
        f"{ASSETS_ENV_VAR} to the folder holding catch.xml."
    )


def asset_path(name: str) -> Path:
    """Absolute path of one asset file, e.g. ``asset_path("catch.xml")``."""
    path = assets_dir() / name
    if not path.is_file():
        available = sorted(p.name for p in assets_dir().glob("*.xml"))
        raise FileNotFoundError(f"no asset named {name!r}; available: {available}")
    return path
