"""The evaluator, results JSON, provenance and the ``vmgym bench`` command (visuomotor_gym.bench)."""

from __future__ import annotations

import argparse
import copy
import json
import re
import socket
from dataclasses import fields
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # registers the ids
from visuomotor_gym import agents
from visuomotor_gym.bench import commands
from visuomotor_gym.bench.evaluate import EvalResult, episode_chunks, episode_seeds, evaluate
from visuomotor_gym.bench.provenance import PROVENANCE_FIELDS, git_state, provenance
from visuomotor_gym.bench.results import (
    ResultsError,
    build_results,
    load_results,
    load_schema,
    validate_results,
    write_results,
)
from visuomotor_gym.bench.trace import EpisodeTrace, load_traces, run_episode
from visuomotor_gym.registration import CATCH_ENV_IDS

ORACLE_ENV = "EyeCatchOracle-v0"
TIMING_FIELDS = {"latency_s"}  # wall-clock measurements: the only fields allowed to differ between runs


# ---------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def oracle_run() -> EvalResult:
    """6 oracle episodes in-process (shared by the determinism and results tests)."""
    return evaluate("oracle", ORACLE_ENV, episodes=6, seed=3, workers=1)


@pytest.fixture(scope="module")
def results_obj(oracle_run) -> dict:
    return build_results(oracle_run, f"vmgym bench --agent oracle --env {ORACLE_ENV} --episodes 6 --seed 3")


@pytest.fixture
def results(results_obj) -> dict:
    """A fresh, valid results object a test may tamper with."""
    return copy.deepcopy(results_obj)


def _problems(obj) -> list[str]:
    with pytest.raises(ResultsError) as info:
        validate_results(obj)
    return info.value.problems


# ---------------------------------------------------------------- evaluator


def test_pinned_seeds_and_chunks_do_not_depend_on_workers():
    assert episode_seeds(10, 4) == [10, 11, 12, 13]
    for n in (1, 6, 63, 64, 65, 200, 1000, 5000):
        chunks = episode_chunks(n)
        assert [i for c in chunks for i in c] == list(range(n))  # contiguous, ordered, complete
        assert all(1 <= len(c) <= 16 for c in chunks)
    assert len(episode_chunks(6)) == 6  # small runs spread over every worker


def _assert_same_traces(a: list[EpisodeTrace], b: list[EpisodeTrace]) -> None:
    assert len(a) == len(b)
    for ta, tb in zip(a, b):
        for f in fields(EpisodeTrace):
            if f.name in TIMING_FIELDS or f.name == "extras":
                continue
            va, vb = getattr(ta, f.name), getattr(tb, f.name)
            if f.name == "task":
                assert va.keys() == vb.keys(), f"seed {ta.seed}: task fields differ"
                for k in va:
                    assert np.array_equal(np.asarray(va[k]), np.asarray(vb[k]), equal_nan=np.asarray(va[k]).dtype.kind == "f"), \
                        f"seed {ta.seed}: task field {k} differs"
                continue
            if isinstance(va, np.ndarray):
                assert va.shape == vb.shape and np.array_equal(va, vb, equal_nan=va.dtype.kind == "f"), \
                    f"seed {ta.seed}: {f.name} differs"
            else:
                assert va == vb, f"seed {ta.seed}: {f.name} differs"


def test_results_identical_for_any_worker_count(oracle_run):
    pooled = evaluate("oracle", ORACLE_ENV, episodes=6, seed=3, workers=2)
    assert pooled.workers == 2
    assert [tr.seed for tr in oracle_run.traces] == [tr.seed for tr in pooled.traces] == list(range(3, 9))
    assert [tr.caught for tr in oracle_run.traces] == [tr.caught for tr in pooled.traces]
    assert sum(tr.caught for tr in pooled.traces) >= 5  # the oracle catches (sanity)
    _assert_same_traces(oracle_run.traces, pooled.traces)
    a, b = dict(oracle_run.summary), dict(pooled.summary)
    a.pop("latency_ms"), b.pop("latency_ms")
    assert a == b


def test_seeded_stochastic_agent_is_also_independent_of_workers():
    """The random agent is seeded per chunk and chunks do not depend on workers."""
    one = evaluate("random", ORACLE_ENV, episodes=3, seed=0, workers=1)
    two = evaluate("random", ORACLE_ENV, episodes=3, seed=0, workers=3)
    assert not one.agent_deterministic
    _assert_same_traces(one.traces, two.traces)


def test_keep_traces_false_keeps_the_summary():
    res = evaluate("zero", ORACLE_ENV, episodes=2, seed=0, keep_traces=False, progress=True)
    assert res.traces == [] and res.summary["episodes"] == 2 and res.env_steps > 0
    assert res.seeds == [0, 1] and res.agent_deterministic


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({"env_id": "EyeCatch-v9"}, ValueError, r"unknown env id 'EyeCatch-v9'; known ids: .*EyeCatch-v0"),
        ({"episodes": 0}, ValueError, r"episodes must be >= 1"),
        ({"workers": 0}, ValueError, r"workers must be >= 1"),
        ({"seed": -1}, ValueError, r"seed must be >= 0"),
        ({"episodes": 2.5}, TypeError, r"episodes must be an integer"),
        ({"agent": "nobody"}, ValueError, r"unknown agent 'nobody'; known agents"),
    ],
)
def test_evaluate_rejects_bad_input(kwargs, error, match):
    args = {"agent": "zero", "env_id": ORACLE_ENV, "episodes": 1, "seed": 0, **kwargs}
    with pytest.raises(error, match=match):
        evaluate(**args)


def test_bad_agent_overrides_fail_before_the_pool_starts():
    with pytest.raises(ValueError, match=rf"cannot build agent 'oracle:bogus=1' for {ORACLE_ENV}: .*bogus"):
        evaluate("oracle:bogus=1", ORACLE_ENV, episodes=2, seed=0, workers=2)


def test_evaluate_accepts_the_gym_namespace_prefix():
    assert evaluate("zero", "visuomotor_gym:EyeCatchOracle-v0", 1, 0).env_id == ORACLE_ENV


# ---------------------------------------------------------------- the policy sees observations only


class RecordingPolicy:
    """Wraps a policy; checks and records every ``predict`` call."""

    def __init__(self, inner, obs_shape):
        self.inner, self.obs_shape, self.calls = inner, obs_shape, []

    def predict(self, *args, **kwargs):
        assert len(args) == 1, f"only the observation may be positional, got {len(args)} arguments"
        assert set(kwargs) <= {"state", "episode_start", "deterministic"}, kwargs
        values = (*args, *kwargs.values())
        assert not any(isinstance(v, dict) for v in values), "a dict (info?) reached the policy"
        obs = args[0]
        assert isinstance(obs, np.ndarray), type(obs)
        assert obs.shape == self.obs_shape, obs.shape
        self.calls.append(obs.copy())
        return self.inner.predict(obs, state=kwargs.get("state"), episode_start=kwargs.get("episode_start"),
                                  deterministic=kwargs.get("deterministic", True))


class ObservationLog(gym.Wrapper):
    """Records every observation the environment hands out."""

    def __init__(self, env):
        super().__init__(env)
        self.observations = []

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self.observations.append(np.array(obs))
        return obs, info

    def step(self, action):
        obs, *rest = self.env.step(action)
        self.observations.append(np.array(obs))
        return (obs, *rest)


def test_run_episode_passes_only_the_observation():
    env = ObservationLog(gym.make(ORACLE_ENV))
    shape = env.observation_space.shape
    policy = RecordingPolicy(agents.make_agent("oracle", ORACLE_ENV, env.action_space.shape[0]), shape)
    trace = run_episode(env, policy, seed=5, env_id=ORACLE_ENV, agent="oracle")
    env.close()
    assert len(policy.calls) == trace.steps >= 1
    # exactly the observations the env produced, in order (the last one comes after the final step)
    assert len(env.observations) == trace.steps + 1
    for seen, produced in zip(policy.calls, env.observations[:-1]):
        assert np.array_equal(seen, produced)


def test_evaluator_agents_see_only_observations(monkeypatch):
    made = []

    def factory(env_id, action_dim, seed, **kw):
        env = gym.make(env_id)
        shape = env.observation_space.shape
        env.close()
        made.append(RecordingPolicy(agents.ZeroAgent(action_dim), shape))
        return made[-1]

    monkeypatch.setitem(agents._REGISTRY, "recorder", (factory, "test recorder", True))
    res = evaluate("recorder", ORACLE_ENV, episodes=2, seed=0, workers=1)
    # made[0]: validate_inputs' throwaway agent, which acts once on a throwaway env (the probe)
    assert len(made) >= 2 and len(made[0].calls) == 1
    assert sum(len(p.calls) for p in made[1:]) == res.env_steps


# ---------------------------------------------------------------- results JSON


def test_schema_is_valid_draft_2020_12():
    from jsonschema import Draft202012Validator

    schema = load_schema()
    Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"


def test_results_round_trip(results, tmp_path):
    assert results["schema_version"] == 1 and results["env_id"] == ORACLE_ENV and results["agent"] == "oracle"
    assert results["episodes"] == 6 and results["seed"] == 3
    assert results["seeds"]["first"] == 3 and results["seeds"]["last"] == 8
    assert results["catch_rate"] == results["caught"] / 6
    assert results["agent_deterministic"] is True
    assert results["control_period_ms"] == 20.0
    assert results["real_time"] is (results["latency_ms"]["p95"] < 20.0)
    assert set(results["gaze_realism"]) >= {"score", "components"}
    path = write_results(tmp_path / "r.json", results)
    assert load_results(path) == results
    json.loads(path.read_text())  # plain JSON, no NaN


def test_missing_field_is_named(results):
    del results["caught"]
    del results["provenance"]["git_sha"]
    problems = _problems(results)
    assert "$.caught: missing required field" in problems
    assert "$.provenance.git_sha: missing required field" in problems


def test_wrong_type_is_named(results):
    results["episodes"] = "six"
    results["latency_ms"]["p95"] = "fast"
    problems = _problems(results)
    assert any(p.startswith("$.episodes:") and "not of type 'integer'" in p for p in problems), problems
    assert any(p.startswith("$.latency_ms.p95:") for p in problems), problems


def test_tampered_catch_rate_is_refused(results):
    results["caught"] = results["episodes"] - 1  # the rate no longer matches the count
    problems = _problems(results)
    assert any(p.startswith("$.catch_rate:") and "differs from caught / episodes" in p
               for p in problems), problems


def test_interval_must_contain_the_rate(results):
    results["catch_rate_ci95"] = [0.1, 0.2]
    problems = _problems(results)
    assert any("does not contain catch_rate" in p for p in problems), problems
    results["catch_rate_ci95"] = [0.99, 0.5]
    assert any("is above high" in p for p in _problems(results))


def test_unknown_env_id_is_refused(results):
    results["env_id"] = "EyeCatch-v9"
    (problem,) = _problems(results)
    assert problem.startswith("$.env_id:") and "not a registered environment id" in problem
    assert all(env_id in problem for env_id in CATCH_ENV_IDS)


def test_every_problem_is_reported_at_once(results):
    results["catch_rate"] = 0.5
    results["env_id"] = "Nope-v0"
    results["real_time"] = not results["real_time"]
    results["extra"] = 1
    with pytest.raises(ResultsError) as info:
        validate_results(results)
    paths = {p.split(":")[0] for p in info.value.problems}
    assert {"$.catch_rate", "$.env_id", "$.real_time", "$"} <= paths
    assert f"{len(info.value.problems)} problems" in str(info.value)


def test_nan_is_refused(results):
    results["time_to_catch_s"]["mean"] = float("nan")
    assert any(p.startswith("$.time_to_catch_s.mean:") for p in _problems(results))


def test_malformed_json_file_is_named(tmp_path):
    bad = tmp_path / "broken.json"
    bad.write_text('{"schema_version": 1,,}')
    with pytest.raises(ResultsError, match=r"broken\.json: .*malformed JSON: .*line 1 column"):
        load_results(bad)
    bad.write_text('{"catch_rate": NaN}')
    with pytest.raises(ResultsError, match="NaN is not valid JSON"):
        load_results(bad)


def test_invalid_file_names_the_file(results, tmp_path):
    path = tmp_path / "tampered.json"
    results["catch_rate"] = 0.0
    path.write_text(json.dumps(results))
    with pytest.raises(ResultsError, match=r"tampered\.json: invalid benchmark results"):
        load_results(path)


def test_refuses_to_overwrite_unless_forced(results, tmp_path):
    path = write_results(tmp_path / "r.json", results)
    before = path.read_text()
    changed = dict(results, agent="zero")
    with pytest.raises(FileExistsError, match=r"r\.json already exists; refusing to overwrite"):
        write_results(path, changed)
    assert path.read_text() == before
    write_results(path, changed, force=True)
    assert load_results(path)["agent"] == "zero"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]  # no temporary files left


def test_write_refuses_invalid_results(results, tmp_path):
    results["caught"] = -1
    with pytest.raises(ResultsError):
        write_results(tmp_path / "r.json", results)
    assert not (tmp_path / "r.json").exists()


# ---------------------------------------------------------------- provenance


def test_provenance_fields():
    prov = provenance("vmgym bench --agent oracle")
    assert tuple(prov) == PROVENANCE_FIELDS
    assert prov["command"] == "vmgym bench --agent oracle"
    assert prov["visuomotor_gym"] == visuomotor_gym.__version__
    for key in ("python", "numpy", "mujoco", "gymnasium", "platform", "machine"):
        assert isinstance(prov[key], str) and prov[key], key
    assert re.fullmatch(r"[0-9a-f]{40}|[0-9a-f]{64}|unknown", prov["git_sha"])
    assert prov["git_dirty"] in (True, False, None)
    assert isinstance(prov["cpu_count"], int) and prov["cpu_count"] >= 1
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", prov["timestamp_utc"])
    assert provenance(None)["command"] is None
    host = socket.gethostname()
    if len(host) >= 6:  # short names would match by accident
        assert host not in json.dumps(prov)


def test_provenance_drops_the_home_directory():
    assert provenance(f"vmgym bench --out {Path.home()}/r.json")["command"] == "vmgym bench --out ~/r.json"


def test_git_state_outside_a_repository(tmp_path):
    assert git_state(tmp_path) == ("unknown", None)


# ---------------------------------------------------------------- the bench command


def _bench_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vmgym")
    commands.register(parser.add_subparsers(dest="command", required=True))
    return parser


def test_bench_command_end_to_end(tmp_path, capsys):
    out, npz = tmp_path / "res" / "oracle.json", tmp_path / "oracle.npz"
    argv = ["bench", "--agent", "oracle", "--env", ORACLE_ENV, "--episodes", "4", "--seed", "7",
            "--out", str(out), "--workers", "2", "--traces", str(npz), "--no-progress"]
    args = _bench_parser().parse_args(argv)
    assert args.func(args) == 0
    printed = capsys.readouterr().out
    for text in ("catch rate", "95% CI", "gaze realism", "latency (ms)", "real time", f"wrote {out}"):
        assert text in printed, text
    res = load_results(out)
    assert res["episodes"] == 4
    assert res["seeds"] == {"first": 7, "last": 10, "rule": "episode i uses seed + i"}
    assert res["run"]["workers"] == 2
    assert res["provenance"]["command"] == (
        f"vmgym bench --agent oracle --env {ORACLE_ENV} --episodes 4 --seed 7 --workers 2 "
        "--out oracle.json --traces oracle.npz")
    traces = load_traces(npz)
    assert [tr.seed for tr in traces] == [7, 8, 9, 10]
    assert sum(tr.caught for tr in traces) == res["caught"]

    # a second run refuses to overwrite, before evaluating anything
    before = out.read_text()
    args = _bench_parser().parse_args(argv)
    assert args.func(args) == 2
    assert "already exists; refusing to overwrite it (pass --force" in capsys.readouterr().err
    assert out.read_text() == before


def test_bench_command_bad_arguments(tmp_path, capsys):
    parser = _bench_parser()
    common = ["bench", "--agent", "zero", "--seed", "0", "--out", str(tmp_path / "r.json"), "--no-progress"]
    args = parser.parse_args([*common, "--env", "Nope-v0", "--episodes", "1"])
    assert args.func(args) == 2
    err = capsys.readouterr().err
    assert "unknown env id 'Nope-v0'; known ids:" in err and ORACLE_ENV in err
    assert not (tmp_path / "r.json").exists()
    args = parser.parse_args([*common, "--env", ORACLE_ENV, "--episodes", "0"])
    assert args.func(args) == 2 and "episodes must be >= 1" in capsys.readouterr().err


def test_bench_gaze_gain_plays_the_twin_on_the_same_seeds(tmp_path):
    """`vmgym bench --gaze-gain`: both twins (gaze_blind:<agent>, and static_gaze:<agent> at its searched
    posture, written out) on the same seeds; gain = success - the better twin's."""
    import json
    import subprocess
    import sys

    out = tmp_path / "gain.json"
    proc = subprocess.run(
        [sys.executable, "-m", "visuomotor_gym.cli", "bench", "--agent", "eyecatch", "--env", "EyeCatch-v0",
         "--episodes", "6", "--seed", "0", "--gaze-gain", "--out", str(out), "--no-progress"],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    results = json.loads(out.read_text())
    gain = results["gaze_gain"]
    assert gain["twin_agent"] == "gaze_blind:eyecatch"
    twin = evaluate("gaze_blind:eyecatch", "EyeCatch-v0", 6, 0)
    assert gain["twin_success_rate"] == twin.summary["success_rate"]
    from visuomotor_gym.bench.evaluate import static_twin_spec

    static = static_twin_spec("eyecatch", "EyeCatch-v0")
    assert gain["static_twin_agent"] == static and static.startswith("static_gaze:az=")
    static_run = evaluate(static, "EyeCatch-v0", 6, 0)
    assert gain["static_twin_success_rate"] == static_run.summary["success_rate"]
    best = max(gain["twin_success_rate"], gain["static_twin_success_rate"])
    assert gain["gain"] == pytest.approx(results["success_rate"] - best)
    assert gain["held_difference"] == pytest.approx(results["success_rate"] - gain["twin_success_rate"])
    assert gain["definition"] == "best_twin"
    assert "gaze gain" in proc.stdout and "best static twin" in proc.stdout
    assert "--gaze-gain" in results["provenance"]["command"]
    # a forged gain is refused by the results validator
    from visuomotor_gym.bench.results import ResultsError, validate_results

    results["gaze_gain"]["gain"] = 0.9
    with pytest.raises(ResultsError, match="gain"):
        validate_results(results)


def _gain_results(k_agent=180, k_held=40, k_static=150, n=200):
    """A valid results object of a committed run with a hand-written two-twin gaze_gain block."""
    import json
    from pathlib import Path

    from visuomotor_gym.metrics import wilson_interval

    root = Path(__file__).resolve().parents[1]
    obj = json.loads((root / "docs/reproductions/data/dodge_fajen_warren_200.json").read_text())
    assert obj["episodes"] == n
    ci = lambda k: [float(x) for x in wilson_interval(k, n)]  # noqa: E731
    obj.update(caught=k_agent, catch_rate=k_agent / n, catch_rate_ci95=ci(k_agent), success_rate=k_agent / n,
               success_rate_ci95=ci(k_agent))
    obj["gaze_gain"] = {
        "twin_agent": "gaze_blind:fajen_warren", "twin_successes": k_held, "twin_success_rate": k_held / n,
        "twin_success_rate_ci95": ci(k_held),
        "static_twin_agent": "static_gaze:az=30,el=-5,neck_yaw=0,neck_pitch=0,fix=3:fajen_warren",
        "static_twin_successes": k_static, "static_twin_success_rate": k_static / n,
        "static_twin_success_rate_ci95": ci(k_static), "definition": "best_twin",
        "held_difference": (k_agent - k_held) / n, "gain": (k_agent - max(k_held, k_static)) / n,
    }
    return obj


def test_gaze_gain_is_success_minus_the_better_twin_and_a_forged_claim_is_refused():
    """The gain is success - max(held twin, best static twin); the held-twin difference keeps its own
    name; the validator recomputes both from the twins' counts and refuses any other claim."""
    from visuomotor_gym.bench.results import ResultsError, validate_results

    ok = _gain_results()
    validate_results(ok)
    assert ok["gaze_gain"]["gain"] == pytest.approx(0.15) and ok["gaze_gain"]["held_difference"] == pytest.approx(0.70)
    forged = [
        ("gain", 0.70, "gain"),  # the held-twin difference claimed as the gain
        ("held_difference", 0.5, "held_difference"),
        ("static_twin_success_rate", 0.5, "static_twin_success_rate"),  # not 150/200
        ("definition", "held", "definition"),
    ]
    for key, value, match in forged:
        bad = _gain_results()
        bad["gaze_gain"][key] = value
        with pytest.raises(ResultsError, match=match):
            validate_results(bad)
    # the static twin is the better twin only when it is: with a held twin above it, the gain uses the held one
    flip = _gain_results(k_held=160, k_static=100)
    validate_results(flip)
    assert flip["gaze_gain"]["gain"] == pytest.approx(0.10)
    # a static twin's fields come together
    partial = _gain_results()
    del partial["gaze_gain"]["static_twin_successes"]
    with pytest.raises(ResultsError):
        validate_results(partial)


def test_legacy_held_only_gaze_gain_still_validates():
    """Results written before the static twin existed (committed files) keep validating as 'held'."""
    from visuomotor_gym.bench.results import validate_results

    legacy = _gain_results()
    g = legacy["gaze_gain"]
    for key in ("static_twin_agent", "static_twin_successes", "static_twin_success_rate",
                "static_twin_success_rate_ci95", "held_difference", "definition"):
        del g[key]
    g["gain"] = legacy["success_rate"] - g["twin_success_rate"]
    validate_results(legacy)


def test_static_twin_base_reads_both_spellings():
    from visuomotor_gym.bench.evaluate import static_twin_base

    assert static_twin_base("static_gaze:iwao") == "iwao"
    assert static_twin_base("static_gaze:az=0,el=-20:iwao") == "iwao"
    assert static_twin_base("static_gaze:az=0,el=-20:eyecatch:alpha=1") == "eyecatch:alpha=1"
    assert static_twin_base("gaze_blind:iwao") is None and static_twin_base("iwao") is None


def test_the_twin_of_a_twin_is_refused():
    from visuomotor_gym.bench.evaluate import twin_spec

    assert twin_spec("belief_mpc") == "gaze_blind:belief_mpc"
    for spec in ("fixed_gaze", "gaze_blind:eyecatch"):
        with pytest.raises(ValueError, match="already a gaze-blind agent"):
            twin_spec(spec)
    from visuomotor_gym.bench.evaluate import static_twin_spec

    for spec in ("fixed_gaze", "gaze_blind:eyecatch", "static_gaze:eyecatch"):
        with pytest.raises(ValueError, match="already a twin"):
            static_twin_spec(spec, "EyeCatch-v0")
    with pytest.raises(ValueError):  # no posture was searched for this agent on this id
        static_twin_spec("random", "EyeCatch-v0")


def test_summary_rows_speak_each_familys_terms():
    """A walk result reads 'success rate' and 'distance left', with no throw reaction times; a catch
    result keeps 'catch rate' and its reaction times (same results dict, only the env id differs)."""
    from visuomotor_gym.bench.commands import summary_rows

    base = {"catch_rate": 0.5, "catch_rate_ci95": [0.1, 0.9], "caught": 1, "episodes": 2,
            "gaze_realism": {"score": 0.5, "components": {}}, "latency_ms": {"p50": 1.0, "p95": 2.0, "max": 3.0},
            "real_time": True, "control_period_ms": 20.0,
            "reaction_times_s": {"first_saccade": {"mean": 0.2, "median": 0.2}},
            "time_to_catch_s": {"mean": 1.0, "median": 1.0}, "miss_distance_m": {"mean": 0.3, "median": 0.3},
            "diverged": 0}
    walk = dict(summary_rows({**base, "env_id": "ObstacleWalk-v0"}))
    catch = dict(summary_rows({**base, "env_id": "EyeCatch-v0"}))
    assert "success rate" in walk and "catch rate" not in walk and "distance left, failed walks (m)" in walk
    assert not any(k.startswith("reaction time") for k in walk)
    assert "catch rate" in catch and "reaction time, first saccade (s)" in catch and "miss distance (m)" in catch
