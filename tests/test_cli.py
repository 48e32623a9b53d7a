"""The ``vmgym`` command line."""

import subprocess
import sys

import visuomotor_gym
from visuomotor_gym.cli import main


def test_envs_lists_every_registered_id(capsys):
    assert main(["envs"]) == 0
    out = capsys.readouterr().out
    for spec in visuomotor_gym.ENV_SPECS:
        assert spec.id in out


def test_demo_writes_results_a_plot_and_a_video(tmp_path, capsys):
    assert main(["demo", "--episodes", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "catch rate" in out and "(2/2)" in out  # Eyecatch catches seeds 0 and 1
    from visuomotor_gym.bench.results import load_results

    results = load_results(tmp_path / "results.json")  # validates against the schema
    assert results["agent"] == "eyecatch" and results["episodes"] == 2
    png = tmp_path / "episode_seed0.png"
    assert png.stat().st_size > 10_000
    import imageio.v3 as iio

    image = iio.imread(png)
    assert image.ndim == 3 and image.std() > 10  # a real picture, not blank
    assert (tmp_path / "episode_seed0.mp4").stat().st_size > 10_000


def test_agents_lists_the_registry(capsys):
    assert main(["agents"]) == 0
    out = capsys.readouterr().out
    assert "eyecatch" in out and "oracle" in out


def test_console_script_is_installed():
    result = subprocess.run([sys.executable, "-m", "visuomotor_gym.cli", "envs"], capture_output=True, text=True)
    assert result.returncode == 0 and "EyeCatch-v0" in result.stdout


def test_bad_episode_count_is_refused(capsys):
    assert main(["demo", "--episodes", "0"]) == 2
    assert "--episodes" in capsys.readouterr().err
