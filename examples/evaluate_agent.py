"""Evaluate agents with the common evaluator (what `vmgym bench` and the leaderboard use).

Plays a built-in agent and its gaze-blind twin on the same pinned seeds (episode i uses seed + i),
prints the success rates, the gaze gain and the gaze realism, and writes a results file validated
against the results schema. Then registers a custom agent (any object with SB3's `predict`) and
evaluates it the same way.

    python examples/evaluate_agent.py [--agent eyecatch] [--env EyeCatch-v0] [--episodes 10] [--out DIR]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np


class LookStraightAhead:
    """A custom agent: hand and gaze held at the action's centre (the evaluator only needs `predict`)."""

    def __init__(self, action_dim: int):
        self.action_dim = action_dim

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return np.zeros(self.action_dim, dtype=np.float32), state


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--agent", default="eyecatch", help="agent spec (vmgym agents)")
    parser.add_argument("--env", default="EyeCatch-v0", help="registered id (vmgym envs)")
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0, help="first seed")
    parser.add_argument("--workers", type=int, default=1, help="processes (1: this one)")
    parser.add_argument("--out", default="outputs/examples", help="folder for the results file")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")

    from visuomotor_gym.agents import register_agent
    from visuomotor_gym.bench.evaluate import evaluate, twin_spec
    from visuomotor_gym.bench.results import build_results, write_results

    run = evaluate(args.agent, args.env, episodes=args.episodes, seed=args.seed, workers=args.workers)
    twin = evaluate(twin_spec(args.agent), args.env, episodes=args.episodes, seed=args.seed, workers=args.workers)
    results = build_results(run, command=f"examples/evaluate_agent.py --agent {args.agent} --env {args.env}",
                            twin_result=twin)
    out = Path(args.out) / f"results_{args.agent.replace(':', '_')}_{args.env}.json"
    write_results(out, results, force=True)
    realism = results["gaze_realism"]["score"]
    print(f"{args.agent} on {args.env}, seeds {args.seed}-{args.seed + args.episodes - 1}: success "
          f"{100 * results['success_rate']:.1f} % (95 % CI {100 * results['success_rate_ci95'][0]:.1f}-"
          f"{100 * results['success_rate_ci95'][1]:.1f}), gaze-blind twin {100 * twin.summary['success_rate']:.1f} %, "
          f"gaze realism {realism:.3f}; results: {out}")

    # A custom agent: register a factory, then use its name anywhere an agent spec goes (in this
    # process: workers=1, or a module that registers it on import).
    register_agent("look_straight_ahead", lambda env_id, action_dim, seed, **kw: LookStraightAhead(action_dim),
                   "hand and gaze held at the centre")
    custom = evaluate("look_straight_ahead", args.env, episodes=args.episodes, seed=args.seed, workers=1)
    print(f"look_straight_ahead on {args.env}: success {100 * custom.summary['success_rate']:.1f} %")
    return results


if __name__ == "__main__":
    main()
