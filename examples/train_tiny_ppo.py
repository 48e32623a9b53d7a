"""Train a tiny stable-baselines3 PPO on EyeCatch-v0 for a few thousand steps, then evaluate it.

The saved model gets a ``<name>.meta.json`` beside it (what ``ppo:<path>`` needs besides the zip:
the algorithm, and that it saw the raw observation), so the common evaluator (``vmgym bench --agent
ppo:<path>``) plays it too. A smoke run of plain SB3 on the raw observation (it learns nothing useful in 4k steps; the project's
recipe with belief features is `vmgym train ppo --env EyeCatch-v0`, docs: baselines/ppo.md).
Needs the rl extra (install CPU PyTorch first, README "Installation").

    python examples/train_tiny_ppo.py [--env EyeCatch-v0] [--timesteps 4096] [--subproc] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path


def main(argv=None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="EyeCatch-v0", help="any registered id (vmgym envs)")
    parser.add_argument("--timesteps", type=int, default=4096, help="environment transitions to train on")
    parser.add_argument("--n-envs", type=int, default=2)
    parser.add_argument("--subproc", action="store_true", help="one process per env (SubprocVecEnv)")
    parser.add_argument("--eval-episodes", type=int, default=3)
    parser.add_argument("--out", default="outputs/examples", help="folder for the saved model")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")

    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    torch.set_num_threads(1)  # small MLPs train faster on one thread (README, Training)
    # "visuomotor_gym:<id>" makes Gymnasium import the package first, so the id is known in subprocess
    # workers too; a bare "EyeCatch-v0" there dies with only ConnectionResetError in this process.
    env_id = f"visuomotor_gym:{args.env}"
    venv = make_vec_env(env_id, n_envs=args.n_envs, seed=0,
                        vec_env_cls=SubprocVecEnv if args.subproc else DummyVecEnv)
    model = PPO("MlpPolicy", venv, n_steps=512, batch_size=256, n_epochs=2, seed=0, device="cpu", verbose=0)
    model.learn(total_timesteps=args.timesteps)
    venv.close()

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"ppo_tiny_{args.env}.zip"
    model.save(path)
    # The meta `ppo:<path>` reads (baselines/ppo/agent.py): plain SB3 on the raw observation, no
    # belief features, the env's own hand action, no observation normalisation.
    meta = {"algo": "PPO", "env_id": args.env, "belief": False, "hand_action": "absolute"}
    path.with_suffix(".meta.json").write_text(json.dumps(meta, indent=2) + "\n")

    eval_env = make_vec_env(env_id, n_envs=1, seed=1000)
    mean, std = evaluate_policy(model, eval_env, n_eval_episodes=args.eval_episodes, deterministic=True)
    eval_env.close()
    print(f"trained {model.num_timesteps} steps on {args.env}; SB3 evaluate_policy return over "
          f"{args.eval_episodes} episodes: {mean:.3f} +- {std:.3f}; saved {path}")

    from visuomotor_gym.bench.evaluate import evaluate

    result = evaluate(f"ppo:{path}", args.env, episodes=args.eval_episodes, seed=0)
    print(f"common evaluator (seeds 0-{args.eval_episodes - 1}): success {100 * result.summary['success_rate']:.1f} %;"
          f" the same as: vmgym bench --agent ppo:{path} --env {args.env} --episodes {args.eval_episodes} --seed 0")
    return path


if __name__ == "__main__":
    main()
