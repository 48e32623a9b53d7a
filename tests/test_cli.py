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


def _bench(out, agent="zero", env="EyeCatchOracle-v0", episodes="1", seed="0"):
    return ["bench", "--agent", agent, "--env", env, "--episodes", episodes, "--seed", seed, "--out", str(out),
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
        "submit-workers-0": ([*submit, "--workers", "0"], "--workers must be in [1, 256]"),
        "check-workers-0": (["leaderboard", "check", "--dir", str(lb), "--workers", "0"], "--workers must be in [1, 256]"),
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


# ------------------------------------ every refusal one line and status 2, before any work or allocation

PPO_CATCH_NPZ = "leaderboard/agents/ppo-intercept-v2__EyeCatch-v0.npz"


def _more_bad_inputs(tmp_path):
    import shutil
    from pathlib import Path

    repo = Path(__file__).parents[1]
    lb = tmp_path / "lb"
    (lb / "results").mkdir(parents=True, exist_ok=True)
    shutil.copy(repo / "leaderboard" / "protocol.json", lb / "protocol.json")
    (lb / "results" / "zero__EyeCatchOracle-v0.entry.json").write_text("{}")  # an entry that exists
    afile = tmp_path / "afile"
    afile.write_text("x")
    (tmp_path / "runs" / "EyeCatchOracle-v0" / "same").mkdir(parents=True)
    ok = tmp_path / "r.json"
    submit = ["leaderboard", "submit", "--env", "EyeCatchOracle-v0", "--dir", str(lb), "--no-progress"]
    train = ["train", "ppo", "--out", str(tmp_path / "runs"), "--no-progress-bar"]
    ppo = f"ppo:{repo / PPO_CATCH_NPZ}"
    return {
        "bench-agent-of-another-family": (_bench(ok, agent="iwao", env="EyeCatch-v0"),
                                          "agent 'iwao' plays the walk family"),
        "bench-twin-of-another-family": (_bench(ok, agent="gaze_blind:faraway", env="ObstacleWalk-v0"),
                                         "agent 'faraway' plays the reach family"),
        "bench-policy-of-another-family": (_bench(ok, agent=ppo, env="ObstacleWalk-v0"),
                                           "cannot act on ObstacleWalk-v0 (walk family)"),
        "demo-agent-of-another-family": (["demo", "--agent", "iwao", "--episodes", "1", "--out", str(tmp_path / "d")],
                                         "agent 'iwao' plays the walk family"),
        "plot-agent-of-another-family": (["plot", "--agent", "lookahead", "--env", "EyeCatch-v0", "--out",
                                          str(tmp_path / "p")], "agent 'lookahead' plays the stones family"),
        "record-agent-of-another-family": (["record", "--agent", "fajen_warren", "--env", "ShelfReach-v0", "--out",
                                            str(tmp_path / "v.mp4")], "not ShelfReach-v0's reach family"),
        "submit-agent-of-another-family": ([*submit, "--agent", "iwao"], "agent 'iwao' plays the walk family"),
        "bench-workers-100000": ([*_bench(ok), "--workers", "100000"], "--workers must be in [1, 256]"),
        "bench-seed-negative": (_bench(ok, seed="-1"), "--seed must be in [0, 2147483647]"),
        "bench-seed-2**32": (_bench(ok, seed=str(2**32)), "--seed must be in [0, 2147483647]"),
        "bench-seeds-past-the-last": (_bench(ok, episodes="100", seed=str(2**31 - 50)), "runs past the largest seed"),
        "bench-out-exists": (_bench(afile), "already exists; refusing to overwrite it (pass --force"),
        "plot-seed-negative": (["plot", "--agent", "zero", "--env", "EyeCatch-v0", "--seed", "-1", "--out",
                                str(tmp_path / "p")], "--seed must be in [0, 2147483647]"),
        "submit-workers-1000": ([*submit, "--agent", "zero", "--workers", "1000"], "--workers must be in [1, 256]"),
        "submit-existing-entry": ([*submit, "--agent", "zero"], "entries are immutable"),
        "build-missing-dir": (["leaderboard", "build", "--dir", str(tmp_path / "nope")], "is not a folder"),
        "train-unknown-env": ([*train, "--env", "Nope-v0"], "--env: unknown env id 'Nope-v0'"),
        "train-negative-timesteps": ([*train, "--timesteps", "-5"], "--timesteps must be in [1, 10000000000], got -5"),
        "train-nan-minutes": ([*train, "--minutes", "nan"], "--minutes must be in [0, 10080]"),
        "train-negative-seed": ([*train, "--seed", "-2"], "--seed must be in [0, 2147483647]"),
        "train-bad-belief": ([*train, "--belief", "maybe"], "--belief must be one of"),
        "train-bad-hand-action": ([*train, "--hand-action", "grab"], "--hand-action must be one of"),
        "train-bad-set": ([*train, "--set", "nope=1"], "--set 'nope=1': expected key=value"),
        "train-bad-n-envs": ([*train, "--set", "n_envs=0"], "n_envs must be an integer in [1, 256]"),
        "train-missing-hyperparams": ([*train, "--hyperparams", str(tmp_path / "none.yml")], "is not a file"),
        "train-out-under-a-file": (["train", "ppo", "--out", str(afile / "runs")], "is a file, not a folder"),
        "train-out-in-proc": (["train", "ppo", "--out", "/proc/vmgym-runs"], "cannot write in /proc"),
        "train-existing-run": ([*train, "--run-name", "same"], "already exists: pick another --run-name"),
        "train-run-name-a-path": ([*train, "--run-name", "../x"], "--run-name must be a folder name"),
    }


MORE_CASES = [
    "bench-agent-of-another-family", "bench-twin-of-another-family", "bench-policy-of-another-family",
    "demo-agent-of-another-family", "plot-agent-of-another-family", "record-agent-of-another-family",
    "submit-agent-of-another-family", "bench-workers-100000", "bench-seed-negative", "bench-seed-2**32",
    "bench-seeds-past-the-last", "bench-out-exists", "plot-seed-negative", "submit-workers-1000",
    "submit-existing-entry", "build-missing-dir", "train-unknown-env", "train-negative-timesteps",
    "train-nan-minutes", "train-negative-seed", "train-bad-belief", "train-bad-hand-action", "train-bad-set",
    "train-bad-n-envs", "train-missing-hyperparams", "train-out-under-a-file", "train-out-in-proc",
    "train-existing-run", "train-run-name-a-path",
]


def _listing(root):
    return sorted(str(p) for p in root.rglob("*"))


@pytest.mark.parametrize("case", MORE_CASES)
def test_refusal_is_one_line_and_status_2_before_any_work(case, tmp_path, capsys):
    argv, fragment = _more_bad_inputs(tmp_path)[case]
    before = _listing(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err, err
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert _listing(tmp_path) == before  # nothing written: no results, run folder, entry, plot or video


def test_every_case_of_the_table_runs():
    import pathlib
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        assert set(_more_bad_inputs(pathlib.Path(d))) == set(MORE_CASES)


@pytest.mark.parametrize("argv", [
    ["bench", "--agent", "zero", "--env", "EyeCatch-v0", "--episodes", str(10**12), "--seed", "0", "--out", "r.json"],
    ["demo", "--episodes", str(10**12), "--no-video", "--out", "demo"],
])
def test_a_huge_episode_count_is_refused_before_any_allocation(argv, tmp_path):
    """In a subprocess capped at 2 GiB of address space: the old behaviour (a list of 10**12 seeds) dies
    there instead of taking the machine's memory."""
    import resource

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    result = subprocess.run([sys.executable, "-m", "visuomotor_gym.cli", *argv], capture_output=True, text=True,
                            cwd=tmp_path, preexec_fn=cap, timeout=120, check=False)
    err = result.stderr.strip()
    assert result.returncode == 2 and err == "error: --episodes must be in [1, 100000], got 1000000000000", err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [["bench", "--episodes", "x"], ["nope"], ["train"], ["leaderboard", "check", "--workers", "x"]])
def test_argparse_refusals_exit_2_too(argv, capsys):
    with pytest.raises(SystemExit) as excinfo:
        main(argv)
    assert excinfo.value.code == 2
    assert "Traceback" not in capsys.readouterr().err
