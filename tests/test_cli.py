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


# ---------------------------------------------------------------- bad input: one line, exit 2, nothing run

import zipfile  # noqa: E402

import pytest  # noqa: E402


def _bench(out, agent="zero", env="EyeCatchOracle-v0"):
    return ["bench", "--agent", agent, "--env", env, "--episodes", "1", "--seed", "0", "--out", str(out),
            "--no-progress"]


def _bad_inputs(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    corrupt = tmp_path / "corrupt.zip"
    corrupt.write_bytes(b"PK\x03\x04 not really a zip")
    foreign = tmp_path / "foreign.zip"
    with zipfile.ZipFile(foreign, "w") as zf:
        zf.writestr("readme.txt", "no SB3 data here")
    (tmp_path / "ppo_meta.json").write_text("{}")
    lb = tmp_path / "lb"
    (lb / "results").mkdir(parents=True)
    import shutil
    from pathlib import Path

    shutil.copy(Path(__file__).parents[1] / "leaderboard" / "protocol.json", lb / "protocol.json")
    submit = ["leaderboard", "submit", "--agent", "zero", "--env", "EyeCatchOracle-v0", "--dir", str(lb),
              "--no-progress"]
    ok = tmp_path / "r.json"
    return {
        "out-in-proc": (_bench("/proc/vmgym/r.json"), "cannot write there"),
        "out-under-a-file": (_bench(afile / "r.json"), "is a file, not a folder"),
        "out-onto-a-directory": (_bench(tmp_path), "is a directory"),
        "ppo-missing-zip": (_bench(ok, agent=f"ppo:{tmp_path}/missing.zip"), "no PPO model at"),
        "ppo-corrupt-zip": (_bench(ok, agent=f"ppo:{corrupt}"), "cannot load the PPO policy"),
        "ppo-zip-without-sb3-data": (_bench(ok, agent=f"ppo:{foreign}"), "cannot load the PPO policy"),
        "ppo-path-with-equals": (_bench(ok, agent=f"ppo:{tmp_path}/a=b/model.zip"), "a=b/model.zip"),
        "ppo-without-path": (_bench(ok, agent="ppo:"), "names no file"),
        "unknown-agent": (_bench(ok, agent="nobody"), "unknown agent 'nobody'"),
        "unknown-env": (_bench(ok, env="Nope-v0"), "unknown env id 'Nope-v0'"),
        "submit-empty-name": ([*submit, "--name", ""], "entry name is empty"),
        "submit-300-char-name": ([*submit, "--name", "a" * 300], "at most 100 are allowed"),
        "submit-name-with-double-underscore": ([*submit, "--name", "a__b"], "no '__'"),
        "submit-env-off-protocol": ([*submit[:5], "EyeCatchMoon-v0", *submit[6:]], "has no protocol"),
        "submit-workers-0": ([*submit, "--workers", "0"], "--workers must be >= 1"),
        "check-workers-0": (["leaderboard", "check", "--dir", str(lb), "--workers", "0"], "--workers must be >= 1"),
        "check-missing-dir": (["leaderboard", "check", "--dir", str(tmp_path / "nope")], "is not a folder"),
        "demo-out-in-proc": (["demo", "--out", "/proc/vmgym-demo", "--episodes", "1"], "cannot write there"),
    }


CASES = [
    "out-in-proc", "out-under-a-file", "out-onto-a-directory", "ppo-missing-zip", "ppo-corrupt-zip",
    "ppo-zip-without-sb3-data", "ppo-path-with-equals", "ppo-without-path", "unknown-agent", "unknown-env",
    "submit-empty-name", "submit-300-char-name", "submit-name-with-double-underscore", "submit-env-off-protocol",
    "submit-workers-0", "check-workers-0", "check-missing-dir", "demo-out-in-proc",
]


@pytest.mark.parametrize("case", CASES)
def test_bad_input_gives_one_line_and_status_2_before_any_episode(case, tmp_path, capsys):
    argv, fragment = _bad_inputs(tmp_path)[case]
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert fragment in err, err
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "r.json").exists()  # nothing ran, nothing written
    assert not list((tmp_path / "lb" / "results").iterdir())
