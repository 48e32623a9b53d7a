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


def test_demo_writes_a_filmstrip_and_a_video(tmp_path, capsys):
    assert main(["demo", "--episodes", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "caught 1/1" in out  # the oracle catches seed 0
    png = tmp_path / "demo_filmstrip.png"
    assert png.stat().st_size > 10_000
    import imageio.v3 as iio

    strip = iio.imread(png)
    assert strip.ndim == 3 and strip.shape[2] == 3 and strip.std() > 10  # a real picture, not blank
    assert (tmp_path / "demo_episode.mp4").stat().st_size > 10_000


def test_console_script_is_installed():
    result = subprocess.run([sys.executable, "-m", "visuomotor_gym.cli", "envs"], capture_output=True, text=True)
    assert result.returncode == 0 and "EyeCatch-v0" in result.stdout


def test_bad_episode_count_is_refused(capsys):
    assert main(["demo", "--episodes", "0"]) == 2
    assert "--episodes" in capsys.readouterr().err
