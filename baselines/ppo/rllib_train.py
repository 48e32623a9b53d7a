"""Train PPO with RLlib on any registered id, for users who outgrow one machine.

    pip install 'visuomotor_gym[distributed]' 'ray[rllib]'       # RLlib pins gymnasium 1.2.2: compatible
    python -m visuomotor_gym.baselines.ppo.rllib_train --env EyeCatch-v0 --iterations 200 \\
        --env-runners 8 [--address auto] [--out runs/rllib]

The env is made in each EnvRunner as ``gym.make("visuomotor_gym:<id>", **env_kwargs)``: the
``visuomotor_gym:`` prefix imports the package (registering the ids) in every Ray worker, on any
machine of the cluster that has the package installed. Plain PPO on the raw observation (RLlib's
default MLP): the project's own recipe with belief features is ``vmgym train ppo`` (SB3). The
checkpoint is RLlib's (``Algorithm.save_to_path``); score it with RLlib, the leaderboard takes SB3
policies only.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

DEFAULTS = {  # RLlib's PPO on the new API stack; values as the SB3 recipe where they have a counterpart
    "lr": 3e-4,
    "gamma": 0.99,
    "lambda_": 0.95,
    "clip_param": 0.2,
    "num_epochs": 10,
    "minibatch_size": 512,
    "train_batch_size_per_learner": 4096,
}


def build_config(env_id: str, env_runners: int, envs_per_runner: int, env_kwargs: dict | None = None,
                 **training):
    """The ``PPOConfig`` for ``env_id`` (a registered id, with or without the ``visuomotor_gym:`` prefix)."""
    from ray.rllib.algorithms.ppo import PPOConfig

    from visuomotor_gym.registration import ENV_IDS

    bare = env_id.removeprefix("visuomotor_gym:")
    if bare not in ENV_IDS:
        raise ValueError(f"unknown env id {env_id!r}; known ids: {', '.join(ENV_IDS)}")
    return (
        PPOConfig()
        .environment(f"visuomotor_gym:{bare}", env_config=dict(env_kwargs or {}))
        .env_runners(num_env_runners=env_runners, num_envs_per_env_runner=envs_per_runner)
        .training(**{**DEFAULTS, **training})
        .framework("torch")
    )


def train(env_id: str, iterations: int, env_runners: int = 0, envs_per_runner: int = 1, out: str | None = None,
          address: str | None = None, env_kwargs: dict | None = None, seed: int = 0, **training) -> dict:
    """Run ``iterations`` PPO iterations; returns a summary (and writes a checkpoint to ``out``)."""
    import ray

    if iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    started_here = not ray.is_initialized()
    if started_here:
        ray.init(address=address, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        config = build_config(env_id, env_runners, envs_per_runner, env_kwargs, **training).debugging(seed=seed)
        algo = config.build_algo()
        curve = []
        start = time.perf_counter()
        for i in range(iterations):
            result = algo.train()
            runners = result.get("env_runners", {})
            curve.append({
                "iteration": i + 1,
                "wall_s": round(time.perf_counter() - start, 3),
                "env_steps": int(runners.get("num_env_steps_sampled_lifetime", 0)),
                "episode_return_mean": runners.get("episode_return_mean"),
            })
        summary = {"env_id": env_id, "iterations": iterations, "curve": curve}
        if out is not None:
            path = Path(out).resolve()
            path.mkdir(parents=True, exist_ok=True)
            algo.save_to_path(str(path / "checkpoint"))
            (path / "curve.json").write_text(json.dumps(summary, indent=2) + "\n")
            summary["checkpoint"] = str(path / "checkpoint")
        algo.stop()
        return summary
    finally:
        if started_here:
            ray.shutdown()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env", required=True, help="a registered id (vmgym envs)")
    p.add_argument("--iterations", type=int, default=100)
    p.add_argument("--env-runners", type=int, default=0, help="EnvRunner actors (0: sample in the driver)")
    p.add_argument("--envs-per-runner", type=int, default=1)
    p.add_argument("--address", default=None, help="Ray cluster address (default: start a local one)")
    p.add_argument("--out", default=None, help="folder for the checkpoint and the learning curve")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--train-batch", type=int, default=DEFAULTS["train_batch_size_per_learner"])
    args = p.parse_args(argv)
    try:
        import ray.rllib  # noqa: F401
    except ImportError:
        print("error: RLlib is not installed: pip install 'visuomotor_gym[distributed]' 'ray[rllib]'", file=sys.stderr)
        return 2
    try:
        summary = train(args.env, args.iterations, args.env_runners, args.envs_per_runner, args.out, args.address,
                        seed=args.seed, train_batch_size_per_learner=args.train_batch,
                        minibatch_size=min(DEFAULTS["minibatch_size"], args.train_batch))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for row in summary["curve"]:
        print(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
