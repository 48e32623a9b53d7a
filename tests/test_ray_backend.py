"""``evaluate(..., backend="ray")`` / ``vmgym bench --backend ray``: the same per-seed outcomes as the
local process pool, on a small local Ray cluster.

Ray is an optional extra (``visuomotor_gym[distributed]``): the main venv has no Ray and skips this
module; CI runs it in a second venv with the extra (``make test-ray``), where
``VMGYM_REQUIRE_RAY=1`` turns the skip into a failure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

if os.environ.get("VMGYM_REQUIRE_RAY") == "1":
    import ray  # must be importable where CI asks for it
else:
    ray = pytest.importorskip("ray")

from visuomotor_gym.bench.evaluate import evaluate

pytestmark = pytest.mark.ray
AGENT, ENV, EPISODES, SEED = "eyecatch", "EyeCatch-v0", 8, 5


@pytest.fixture(scope="module")
def local_cluster():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield
    ray.shutdown()


def _outcomes(result):
    return [(tr.seed, tr.success, tr.steps, tr.diverged) for tr in result.traces]


def test_ray_backend_gives_the_local_pools_per_seed_outcomes(local_cluster):
    local = evaluate(AGENT, ENV, EPISODES, SEED, workers=2)
    on_ray = evaluate(AGENT, ENV, EPISODES, SEED, backend="ray")
    assert _outcomes(local) == _outcomes(on_ray)
    for a, b in zip(local.traces, on_ray.traces):  # whole traces, not only outcomes
        np.testing.assert_array_equal(a.gaze_dir, b.gaze_dir)
        np.testing.assert_array_equal(a.action[1:], b.action[1:])
    assert on_ray.summary["catch_rate"] == local.summary["catch_rate"]


def test_bad_backend_arguments_are_refused():
    with pytest.raises(ValueError, match="backend"):
        evaluate(AGENT, ENV, 1, 0, backend="dask")
    with pytest.raises(ValueError, match="address"):
        evaluate(AGENT, ENV, 1, 0, address="auto")


def test_cli_bench_with_the_ray_backend(tmp_path):
    out = tmp_path / "ray.json"
    proc = subprocess.run(
        [sys.executable, "-m", "visuomotor_gym.cli", "bench", "--agent", AGENT, "--env", ENV, "--episodes", "4",
         "--seed", "0", "--backend", "ray", "--out", str(out), "--no-progress"],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    results = json.loads(out.read_text())
    assert results["episodes"] == 4 and "--backend ray" in results["provenance"]["command"]
