"""The built wheel is self-contained: installed on its own (not the editable checkout), it imports,
finds its MuJoCo assets and runs ``EyeCatch-v0``.

The wheel is built from a *copy* of the source tree, so the shared checkout gets no ``build/`` or
``*.egg-info`` from the test. Building uses the current environment (``--no-isolation``): CI has no
network for an isolated build environment.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parent.parent
IGNORE = shutil.ignore_patterns(
    ".git", ".venv", "venv", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache", ".ruff_cache",
    "runs", "outputs", "tests", "*.mp4", "*.pyc",
)


def _run(cmd, **kwargs) -> subprocess.CompletedProcess:
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, (
        f"{cmd} failed ({result.returncode}):\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
    )
    return result


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("wheel")
    src = root / "src"
    shutil.copytree(REPO, src, ignore=IGNORE)
    out = root / "dist"
    try:
        import build  # noqa: F401

        # --skip-dependency-check: setuptools>=70.1 builds wheels by itself; build-system.requires
        # also names "wheel", which the dev environment need not have.
        cmd = [sys.executable, "-m", "build", "--wheel", "--no-isolation", "--skip-dependency-check"]
        cmd += ["-o", str(out)]
    except ImportError:
        cmd = [sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "--no-build-isolation", "-w", str(out)]
    _run(cmd, cwd=src)
    wheels = list(out.glob("visuomotor_gym-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="module")
def site(wheel, tmp_path_factory) -> Path:
    target = tmp_path_factory.mktemp("install") / "site"
    pip = [sys.executable, "-m", "pip", "install", "--no-deps", "--no-index", "--target", str(target)]
    _run([*pip, str(wheel)], cwd=target.parent)
    return target


def _run_installed(site: Path, code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    """Run ``code`` with only the installed wheel on the path, from a directory outside the repo."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VISUOMOTOR_GYM_ASSETS")}
    env["PYTHONPATH"] = str(site)
    env.setdefault("MUJOCO_GL", "egl")
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], cwd=tmp_path, env=env, capture_output=True, text=True,
        timeout=300,
    )


def test_wheel_contains_assets_and_baselines(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "visuomotor_gym/envs_assets/catch.xml" in names
    common = sorted(p.name for p in (REPO / "envs_assets" / "common").glob("*.xml"))
    assert common, "no common/*.xml in the checkout"
    for name in common:
        assert f"visuomotor_gym/envs_assets/common/{name}" in names
    for path in (REPO / "envs_assets").glob("*.xml"):
        assert f"visuomotor_gym/envs_assets/{path.name}" in names
    assert "visuomotor_gym/baselines/__init__.py" in names
    assert "visuomotor_gym/baselines/oracle.py" in names
    # every module of the package (new subpackages must be listed in pyproject's packages)
    for path in (REPO / "visuomotor_gym").rglob("*.py"):
        rel = path.relative_to(REPO).as_posix()
        if "__pycache__" not in rel:
            assert rel in names, f"{rel} is missing from the wheel"
    for path in (REPO / "baselines").glob("*.py"):
        assert f"visuomotor_gym/baselines/{path.name}" in names
    # what the documented commands need (README "From a wheel"): the committed policies and the
    # rl_zoo3 hyperparameters; the typing marker and the licence
    for path in (REPO / "baselines" / "ppo" / "policies").glob("*.npz"):
        assert f"visuomotor_gym/baselines/ppo/policies/{path.name}" in names
    assert "visuomotor_gym/baselines/ppo/rl_zoo3.yml" in names
    assert "visuomotor_gym/py.typed" in names
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names), "LICENSE is not in the wheel"
    # the repository-level folders are installed inside the package, not as top-level packages
    assert not any(n.startswith(("envs_assets/", "baselines/", "tests/")) for n in names)


def test_installed_wheel_imports_from_site(site, tmp_path):
    result = _run_installed(site, """
        import json, sys
        import visuomotor_gym
        import visuomotor_gym.baselines.oracle as oracle
        print(json.dumps({"file": visuomotor_gym.__file__, "oracle": oracle.__file__}))
    """, tmp_path)
    assert result.returncode == 0, result.stderr
    paths = json.loads(result.stdout.strip().splitlines()[-1])
    for path in paths.values():
        assert Path(path).resolve().is_relative_to(site.resolve()), f"imported {path}, not the wheel"


def test_installed_wheel_runs_eyecatch(site, tmp_path):
    result = _run_installed(site, """
        import json, sys
        import numpy as np
        import gymnasium as gym
        import visuomotor_gym
        from visuomotor_gym import assets
        from visuomotor_gym.baselines.oracle import InterceptOracle

        env = gym.make("EyeCatch-v0")
        obs, info = env.reset(seed=0)
        for _ in range(5):
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert obs.shape == (57,) and np.all(np.isfinite(obs))
        oracle_env = gym.make("visuomotor_gym:EyeCatchOracle-v0")
        o, _ = oracle_env.reset(seed=0)
        oracle_env.step(InterceptOracle().predict(o)[0])
        modules = {k: getattr(m, "__file__", None) for k, m in sys.modules.items()
                   if k.startswith("visuomotor_gym")}
        print(json.dumps({"assets": str(assets.assets_dir()), "modules": modules}))
    """, tmp_path)
    assert result.returncode == 0, result.stderr[-4000:]
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert Path(report["assets"]).resolve().is_relative_to(site.resolve()), report["assets"]
    for name, path in report["modules"].items():
        if path is not None:
            assert Path(path).resolve().is_relative_to(site.resolve()), f"{name} came from {path}"


def test_installed_console_scripts_resolve(site, tmp_path):
    entry_points = next(site.glob("visuomotor_gym-*.dist-info")) / "entry_points.txt"
    if not entry_points.exists():
        pytest.skip("the wheel declares no entry points")
    result = _run_installed(site, """
        import importlib, json
        from importlib.metadata import distribution
        scripts = [ep for ep in distribution("visuomotor_gym").entry_points if ep.group == "console_scripts"]
        print(json.dumps({ep.name: callable(ep.load()) for ep in scripts}))
    """, tmp_path)
    assert result.returncode == 0, result.stderr[-4000:]
    scripts = json.loads(result.stdout.strip().splitlines()[-1])
    assert scripts and all(scripts.values()), scripts


def test_installed_wheel_finds_the_committed_policy(site, tmp_path):
    """The README's way to the committed policies from a wheel, and the policy file is the clone's."""
    result = _run_installed(site, """
        import hashlib, json, pathlib
        import visuomotor_gym.baselines.ppo as p
        path = pathlib.Path(p.__file__).parent / "policies" / "ppo-gated__EyeCatch-v0.npz"
        print(json.dumps({"path": str(path), "sha": hashlib.sha256(path.read_bytes()).hexdigest()}))
    """, tmp_path)
    assert result.returncode == 0, result.stderr[-4000:]
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert Path(report["path"]).resolve().is_relative_to(site.resolve())
    import hashlib

    committed = REPO / "baselines" / "ppo" / "policies" / "ppo-gated__EyeCatch-v0.npz"
    assert report["sha"] == hashlib.sha256(committed.read_bytes()).hexdigest()


def test_installed_vmgym_envs_lists_the_registry(site, tmp_path):
    import visuomotor_gym

    script = site / "bin" / "vmgym"
    if not script.exists():
        pytest.skip("the wheel installs no vmgym script")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    result = subprocess.run([sys.executable, str(script), "envs"], cwd=tmp_path, env=env, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-4000:]
    for spec in visuomotor_gym.ENV_SPECS:
        assert spec.id in result.stdout
