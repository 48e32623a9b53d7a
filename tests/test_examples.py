"""Every script in examples/ runs, with a small budget, as a user runs it (a subprocess from the
repository root), and writes what it says it writes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"


def _run(script: str, *args: str, timeout: int = 180) -> subprocess.CompletedProcess:
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"), "OMP_NUM_THREADS": "1"}
    result = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=REPO, env=env,
                            capture_output=True, text=True, timeout=timeout)
    assert result.returncode == 0, f"{script} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    return result


def test_every_example_is_tested_and_listed():
    scripts = sorted(p.name for p in EXAMPLES.glob("*.py"))
    tested = {"train_tiny_ppo.py", "evaluate_agent.py", "plot_episode.py", "submission_dry_run.py"}
    assert set(scripts) == tested, f"examples without a test here (or tests without a script): {scripts}"
    listing = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    for name in scripts:
        assert f"]({name})" in listing, f"examples/README.md does not list {name}"


def test_evaluate_agent(tmp_path):
    out = _run("evaluate_agent.py", "--episodes", "3", "--out", str(tmp_path)).stdout
    results = json.loads((tmp_path / "results_eyecatch_EyeCatch-v0.json").read_text())
    assert results["episodes"] == 3 and results["agent"] == "eyecatch"
    assert "gaze_gain" in results
    assert "look_straight_ahead on EyeCatch-v0: success 0.0 %" in out


@pytest.mark.slow
def test_plot_episode(tmp_path):
    _run("plot_episode.py", "--seed", "0", "--out", str(tmp_path))
    png = tmp_path / "EyeCatch-v0_eyecatch_seed0.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


@pytest.mark.slow
def test_submission_dry_run(tmp_path):
    scratch = tmp_path / "lb"
    out = _run("submission_dry_run.py", "--episodes", "4", "--workers", "1", "--out", str(scratch)).stdout
    assert "dry run: wrote" in out
    for rel in ("results/my-agent__EyeCatch-v0.json", "results/my-agent__EyeCatch-v0.entry.json",
                "README.md", "index.html"):
        assert (scratch / rel).is_file(), rel
    assert json.loads((scratch / "results/my-agent__EyeCatch-v0.json").read_text())["episodes"] == 4


@pytest.mark.slow
def test_train_tiny_ppo(tmp_path):
    pytest.importorskip("stable_baselines3")
    out = _run("train_tiny_ppo.py", "--timesteps", "1024", "--eval-episodes", "1", "--out", str(tmp_path)).stdout
    assert "trained 1024 steps on EyeCatch-v0" in out
    assert "common evaluator (seeds 0-0): success" in out  # the saved model plays as ppo:<path>
    assert (tmp_path / "ppo_tiny_EyeCatch-v0.zip").is_file()
    assert json.loads((tmp_path / "ppo_tiny_EyeCatch-v0.meta.json").read_text())["algo"] == "PPO"
