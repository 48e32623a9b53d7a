"""The RLlib training entry point (``visuomotor_gym.baselines.ppo.rllib_train``): a tiny real run.

Needs RLlib (``ray[rllib]``, which pins gymnasium 1.2.2) and torch: CI runs it in the Ray venv
(``make test-ray``), where ``VMGYM_REQUIRE_RAY=1`` turns a missing RLlib into a failure.
"""

from __future__ import annotations

import json
import os

import pytest

if os.environ.get("VMGYM_REQUIRE_RAY") == "1":
    import ray.rllib  # noqa: F401
else:
    pytest.importorskip("ray.rllib")

from visuomotor_gym.baselines.ppo.rllib_train import build_config, main, train

pytestmark = pytest.mark.ray


def test_tiny_rllib_ppo_run_trains_and_checkpoints(tmp_path):
    summary = train("EyeCatch-v0", 2, env_runners=0, out=str(tmp_path / "run"), seed=0,
                    train_batch_size_per_learner=256, minibatch_size=64, num_epochs=1)
    curve = summary["curve"]
    assert [row["iteration"] for row in curve] == [1, 2]
    assert curve[1]["env_steps"] > curve[0]["env_steps"] >= 256  # it sampled the env
    assert (tmp_path / "run" / "checkpoint").is_dir()
    assert json.loads((tmp_path / "run" / "curve.json").read_text())["env_id"] == "EyeCatch-v0"


def test_every_registered_id_builds_a_config_and_unknown_ids_are_refused():
    from visuomotor_gym.registration import ENV_IDS

    for env_id in ENV_IDS:
        assert build_config(env_id, 0, 1).env == f"visuomotor_gym:{env_id}"
    with pytest.raises(ValueError, match="unknown env id"):
        build_config("CartPole-v1", 0, 1)
    assert main(["--env", "NoSuch-v0", "--iterations", "1"]) == 2
