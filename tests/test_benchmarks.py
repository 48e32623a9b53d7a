"""Tiny-budget smoke runs of every benchmark script (their numbers are reported, not asserted)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_env_throughput_runs_and_reports_a_ratio(tmp_path):
    result = load("env_throughput").main(["--steps", "60", "--repeats", "1", "--json", str(tmp_path / "r.json")])
    assert result["ratio_env_over_raw"] > 0 and (tmp_path / "r.json").exists()
    assert result["substeps_per_control_step"] == 10


def test_eyecatch_speed_runs_and_reports_ratios():
    result = load("eyecatch_speed").main(["--episodes", "3", "--workers", "1"])
    assert result["catch_rate"] == 1.0
    assert 0 < result["latency_p95_over_control_period"] < 1
    assert result["eval_wall_over_zero_agent"] > 0
