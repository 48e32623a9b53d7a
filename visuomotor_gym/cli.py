"""``vmgym``: the command line of visuomotor_gym.

    vmgym envs                                   list the registered environment ids
    vmgym agents                                 list the agent names
    vmgym demo [--episodes N] [--out DIR]        Eyecatch on EyeCatch-v0: table, plots, video
    vmgym bench --agent A --env ID --episodes N --seed S --out FILE.json [--workers K]
    vmgym plot  (--agent A --env ID [--seed S] | --traces F.npz [--episode K]) --out DIR
    vmgym record --agent A --env ID [--seed S] --out FILE.mp4 [--force]
    vmgym train ppo --env ID [--timesteps N] [--minutes M] [--recurrent] [...]   (see --help)
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

# Bounds of the counts every subcommand takes, checked before any work or allocation (modelling choices:
# 500 x the leaderboard protocol's 200 episodes; 256 worker processes; seeds of 31 bits, as every
# seeding API takes them). ``--episodes 10**12`` allocated its seed list until the OS killed it.
MAX_EPISODES = 100_000
MAX_WORKERS = 256
MAX_SEED = 2**31 - 1


def argument_problem(args: argparse.Namespace) -> str | None:
    """One line saying what is wrong with the parsed arguments any subcommand shares (counts, seed,
    workers, the env id and whether the agent plays its family), or None. Imports nothing heavy unless
    an agent is named."""
    for name, low, high in (("episodes", 1, MAX_EPISODES), ("workers", 1, MAX_WORKERS), ("seed", 0, MAX_SEED)):
        value = getattr(args, name, None)
        if value is not None and not low <= value <= high:
            return f"--{name} must be in [{low}, {high}], got {value}"
    episodes, seed = getattr(args, "episodes", None), getattr(args, "seed", None)
    if episodes is not None and seed is not None and seed + episodes - 1 > MAX_SEED:
        return f"--seed {seed} + --episodes {episodes} runs past the largest seed, {MAX_SEED}"
    agent, env = getattr(args, "agent", None), getattr(args, "env", None)
    envs = [env] if isinstance(env, str) else list(env or [])
    envs = [e for e in envs if e != "all"]  # leaderboard submit --env all: the protocol's ids
    if agent is not None and envs:
        from visuomotor_gym.agents import check_agent_family
        from visuomotor_gym.registration import ENV_IDS

        try:  # an unknown env id is the subcommand's to refuse (bench: the known ids; submit: the protocol's)
            for env_id in envs:
                if env_id.removeprefix("visuomotor_gym:") in ENV_IDS:
                    check_agent_family(agent, env_id.removeprefix("visuomotor_gym:"))
        except (ValueError, TypeError) as exc:
            return str(exc)
    return None


def _cmd_envs(args: argparse.Namespace) -> int:
    from visuomotor_gym.registration import ENV_SPECS

    width = max(len(s.id) for s in ENV_SPECS)
    for spec in ENV_SPECS:
        print(f"{spec.id:<{width}}  {spec.description}  kwargs={spec.kwargs}")
    return 0


def _cmd_agents(args: argparse.Namespace) -> int:
    from visuomotor_gym.agents import agent_description, agent_names

    for name in agent_names():
        print(f"{name:<10} {agent_description(name)}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    """A few Eyecatch episodes: progress bar, results table, a Fig. 3/4-style plot and a video."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.bench.commands import print_summary
    from visuomotor_gym.bench.evaluate import evaluate, validate_inputs
    from visuomotor_gym.bench.results import build_results, dumps_results
    from visuomotor_gym.viz.plots import plot_episode
    from visuomotor_gym.viz.video import record_episode

    try:  # the agent and the env before anything is written or run
        validate_inputs(args.agent, args.env, args.episodes, args.seed)
    except (ValueError, TypeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".vmgym-write-probe"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:  # before any episode runs
        print(f"error: --out {out}: cannot write there ({exc.strerror or exc})", file=sys.stderr)
        return 2
    command = f"vmgym demo --agent {args.agent} --env {args.env} --episodes {args.episodes} --seed {args.seed}"
    result = evaluate(args.agent, args.env, args.episodes, args.seed, workers=1, progress=True)
    results = build_results(result, command)
    print_summary(results)
    written = [out / "results.json"]
    written[0].write_text(dumps_results(results))
    first = result.traces[0]
    written.append(plot_episode(first, out / f"episode_seed{first.seed}.png"))
    if not args.no_video:
        video = out / f"episode_seed{first.seed}.mp4"
        record_episode(args.agent, args.env, first.seed, video, overwrite=True)
        written.append(video)
    for path in written:
        print(f"wrote {path}")
    return 0


def _cmd_train(args: argparse.Namespace) -> int:
    """Forward to the PPO training script (its own flags; ``vmgym train ppo --help``); a refused argument
    is one line and status 2, before anything is written or trained."""
    from visuomotor_gym.baselines.ppo.train import TrainArgumentError
    from visuomotor_gym.baselines.ppo.train import main as train_ppo

    try:
        train_ppo(args.train_args)
    except TrainArgumentError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


def build_parser() -> argparse.ArgumentParser:
    from visuomotor_gym.bench.commands import register as register_bench
    from visuomotor_gym.viz.commands import register as register_viz

    parser = argparse.ArgumentParser(prog="vmgym", description="visuomotor_gym command line")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("envs", help="list the registered environment ids")
    p.set_defaults(func=_cmd_envs)
    p = sub.add_parser("agents", help="list the agent names")
    p.set_defaults(func=_cmd_agents)
    p = sub.add_parser("demo", help="run the Eyecatch heuristic for a few episodes; write a table, plots and a video")
    p.add_argument("--agent", default="eyecatch")
    p.add_argument("--env", default="EyeCatch-v0")
    p.add_argument("--episodes", type=int, default=5)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="outputs/demo", help="folder for results.json, the plot and the video "
                   "(the demo's own files there are replaced)")
    p.add_argument("--no-video", action="store_true", help="skip the video (rendering is the slow part)")
    p.set_defaults(func=_cmd_demo)
    p = sub.add_parser("train", help="train a learned baseline (ppo: stable-baselines3 PPO / RecurrentPPO)",
                       add_help=False)
    p.add_argument("algo", choices=["ppo"])
    p.add_argument("train_args", nargs=argparse.REMAINDER, help="flags of the training script")
    p.set_defaults(func=_cmd_train)
    register_bench(sub)
    register_viz(sub)
    from visuomotor_gym.leaderboard.commands import register as register_leaderboard
    register_leaderboard(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand. Status 0: done; 2: an argument refused (one line on stderr, before any work:
    argparse's own errors, the checks of :func:`argument_problem` and each subcommand's); 1: the work
    failed (results invalid, a leaderboard rule broken); 130: interrupted."""
    args = build_parser().parse_args(argv)
    try:
        problem = argument_problem(args)
        if problem:
            print(f"error: {problem}", file=sys.stderr)
            return 2
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
