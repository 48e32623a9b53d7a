"""The ``vmgym plot`` and ``vmgym record`` subcommands (wired in by :func:`register`).

    vmgym plot   --agent A --env ID [--seed S] --out DIR           play one episode and plot it
    vmgym plot   --traces FILE.npz [--episode K] --out DIR         plot a saved episode
    vmgym record --agent A --env ID [--seed S] --out FILE.mp4 [--width W --height H --fps F] [--force]

``plot`` writes ``DIR/<env>_<agent>_seed<S>.png`` (characters other than letters, digits, ``.``,
``-`` and ``_`` in the agent spec become ``_``) and overwrites it; ``record`` refuses to replace an
existing video unless ``--force``. Both print the path they wrote. This module imports nothing
heavy at import time: ``vmgym`` imports it on every call.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path


def plot_filename(env_id: str, agent: str, seed: int) -> str:
    """``<env>_<agent>_seed<S>.png`` with file-system-safe characters only."""

    def safe(text: str) -> str:
        return re.sub(r"[^A-Za-z0-9._-]+", "_", str(text)).strip("_") or "x"

    return f"{safe(env_id)}_{safe(agent)}_seed{int(seed)}.png"


def _play(agent: str, env_id: str, seed: int):
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    env = gym.make(env_id)
    try:
        policy = make_agent(agent, env_id, env.action_space.shape[0], seed=seed)
        return run_episode(env, policy, seed, env_id, agent)
    finally:
        env.close()


def cmd_plot(args: argparse.Namespace) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    if args.traces is not None:
        if args.agent is not None or args.env is not None:
            print("vmgym plot: give either --traces FILE (with --episode K) or --agent/--env/--seed, "
                  "not both", file=sys.stderr)
            return 2
        from visuomotor_gym.bench.trace import load_traces

        try:
            traces = load_traces(args.traces)
        except (OSError, KeyError, ValueError) as exc:
            print(f"vmgym plot: cannot read traces from {args.traces}: {exc}", file=sys.stderr)
            return 2
        if not 0 <= args.episode < len(traces):
            print(f"vmgym plot: --episode {args.episode} is out of range; {args.traces} holds "
                  f"{len(traces)} episode(s) (0..{len(traces) - 1})", file=sys.stderr)
            return 2
        trace = traces[args.episode]
    else:
        if args.agent is None or args.env is None:
            print("vmgym plot: give --agent A --env ID [--seed S], or --traces FILE.npz [--episode K]",
                  file=sys.stderr)
            return 2
        from gymnasium.error import Error as GymError

        try:
            trace = _play(args.agent, args.env, args.seed)
        except (ValueError, GymError) as exc:  # unknown agent or env id, bad override
            print(f"vmgym plot: {exc}", file=sys.stderr)
            return 2
    from visuomotor_gym.viz.plots import plot_episode

    path = plot_episode(trace, Path(args.out) / plot_filename(trace.env_id, trace.agent, trace.seed))
    print(path)
    return 0


def cmd_record(args: argparse.Namespace) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    out = Path(args.out)
    if out.exists() and not args.force:
        print(f"vmgym record: {out} already exists; refusing to overwrite it (pass --force to replace it)",
              file=sys.stderr)
        return 1
    from gymnasium.error import Error as GymError

    from visuomotor_gym.viz.plots import outcome
    from visuomotor_gym.viz.video import record_episode

    try:
        trace = record_episode(args.agent, args.env, args.seed, out, width=args.width, height=args.height,
                               fps=args.fps, camera=args.camera, overlay=not args.no_overlay,
                               overwrite=args.force)
    except (ValueError, FileExistsError, GymError) as exc:  # bad size/agent/env id, a race on --out
        print(f"vmgym record: {exc}", file=sys.stderr)
        return 2
    video = trace.extras["video"]
    w, h = video["frame_size"]
    print(f"{args.env} | {args.agent} | seed {args.seed}: {outcome(trace)}; "
          f"{video['frames']} frames of {w}x{h} at {video['fps']} fps")
    print(out)
    return 0


def register(subparsers) -> None:
    """Add ``plot`` and ``record`` to the ``vmgym`` subparsers (each sets ``func(args) -> int``)."""
    p = subparsers.add_parser(
        "plot",
        help="plot one episode: gaze vs ball (Eyecatch Fig. 3), hand/eye speed (Fig. 4), 3-D paths",
        description="Plot one episode to DIR/<env>_<agent>_seed<S>.png: play it (--agent --env --seed) "
        "or read it from a traces file (--traces FILE.npz --episode K).",
    )
    p.add_argument("--traces", default=None, help="a .npz written by visuomotor_gym.bench.trace.save_traces")
    p.add_argument("--episode", type=int, default=0, help="episode index in --traces (default 0)")
    p.add_argument("--agent", default=None, help="agent spec, e.g. oracle or eyecatch:param=value")
    p.add_argument("--env", default=None, help="environment id, e.g. EyeCatch-v0")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="outputs/plots", help="folder for the PNG (default outputs/plots)")
    p.set_defaults(func=cmd_plot)

    p = subparsers.add_parser(
        "record",
        help="record one episode as an MP4 (scene camera beside the eye camera)",
        description="Play one episode and write an MP4, one frame per 20 ms control step "
        "(--fps 50 is real time, the default 25 half speed). Refuses to overwrite --out unless --force.",
    )
    p.add_argument("--agent", required=True, help="agent spec, e.g. oracle or eyecatch:param=value")
    p.add_argument("--env", required=True, help="environment id, e.g. EyeCatch-v0")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True, help="output video, e.g. outputs/episode.mp4")
    p.add_argument("--width", type=int, default=480,
                   help="width of each camera image (with --camera both the video is twice as wide)")
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--fps", type=int, default=25, help="frames per second (50 = real time; default 25)")
    p.add_argument("--camera", default="both",
                   help="the env's render_camera: both (scene beside eye, every family), scene, eye, or a "
                        "family's own (catch/reach: over_shoulder; walk: side, follow; ...); the env refuses "
                        "an unknown one and lists its cameras")
    p.add_argument("--no-overlay", action="store_true", help="no text label on the frames")
    p.add_argument("--force", action="store_true", help="replace --out if it exists")
    p.set_defaults(func=cmd_record)
