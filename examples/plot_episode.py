"""Play one episode and plot it: gaze against the target, saccades, hand or feet (the viz extra).

The same figure as `vmgym plot --agent eyecatch --env EyeCatch-v0 --seed 0`; here step by step, from
the episode's trace (`visuomotor_gym.bench.trace`: everything the evaluator records per step).

    python examples/plot_episode.py [--agent eyecatch] [--env EyeCatch-v0] [--seed 0] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path


def main(argv=None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--agent", default="eyecatch", help="agent spec (vmgym agents)")
    parser.add_argument("--env", default="EyeCatch-v0", help="registered id (vmgym envs)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="outputs/examples", help="folder for the PNG")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")

    import gymnasium as gym

    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.viz.plots import plot_episode

    env = gym.make(args.env)
    try:
        agent = make_agent(args.agent, args.env, env.action_space.shape[0], seed=args.seed)
        trace = run_episode(env, agent, args.seed, args.env, args.agent)
    finally:
        env.close()
    print(f"{args.agent} on {args.env} seed {args.seed}: {trace.steps} steps, success {trace.caught}")
    out = Path(args.out) / f"{args.env}_{args.agent}_seed{args.seed}.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    path = plot_episode(trace, out)
    print(f"wrote {path}")
    return Path(path)


if __name__ == "__main__":
    main()
