"""The ``vmgym plot`` and ``vmgym record`` subcommands (wired in by :func:`register`).

    vmgym plot   --agent A --env ID [--seed S] --out DIR [--force]      play one episode and plot it
    vmgym plot   --traces FILE.npz [--episode K] --out DIR [--force]    plot a saved episode
    vmgym record --agent A --env ID [--seed S] --out FILE.mp4 [--width W --height H --fps F --stride N]
                 [--camera C] [--quality fast|high] [--force]

``plot`` writes ``DIR/<env>_<agent>_seed<S>.png`` (characters other than letters, digits, ``.``,
``-`` and ``_`` in the agent spec become ``_``); ``record`` writes ``FILE``. Both check their
arguments before any episode is played: an unknown env id or agent, an output that cannot be
written (a folder that cannot be made or written to, such as one under ``/proc``), or an existing
output file without ``--force`` gives one line on stderr and exit status 2. Both print the path
they wrote. This module imports nothing heavy at import time: ``vmgym`` imports it on every call.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from pathlib import Path


def plot_contents() -> dict[str, str]:
    """What ``vmgym plot`` draws for each family (the command's help): family name -> its record's
    ``viz.contents`` (:mod:`visuomotor_gym.viz.plots` and :mod:`visuomotor_gym.viz.family_plots` draw it)."""
    from visuomotor_gym.families import families

    return {f.name: f.viz.contents for f in families() if f.viz is not None}


def __getattr__(name: str):
    """``PLOT_CONTENTS`` (:func:`plot_contents`), for older callers."""
    if name == "PLOT_CONTENTS":
        return plot_contents()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def plot_filename(env_id: str, agent: str, seed: int) -> str:
    """``<env>_<agent>_seed<S>.png`` with file-system-safe characters only."""

    def safe(text: str) -> str:
        return re.sub(r"[^A-Za-z0-9._-]+", "_", str(text)).strip("_") or "x"

    return f"{safe(env_id)}_{safe(agent)}_seed{int(seed)}.png"


def _fail(command: str, message: str) -> int:
    print(f"vmgym {command}: {message}", file=sys.stderr)
    return 2


def writable_folder(folder: Path) -> str | None:
    """None if ``folder`` exists (or can be made) and a file can be created in it; else why not."""
    if folder.exists() and not folder.is_dir():
        return f"{folder} exists and is not a folder"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".vmgym-write-probe-"):
            pass
    except OSError as exc:
        return f"cannot write to {folder} ({exc.strerror or exc})"
    return None


def check_output_file(command: str, path: Path, force: bool) -> str | None:
    """None if ``path`` may be written (its folder is writable; it does not exist, or ``force``)."""
    if path.is_dir():
        return f"--out {path} is a folder; give a file name"
    if path.exists() and not force:
        return f"{path} already exists; refusing to overwrite it (pass --force to replace it)"
    problem = writable_folder(path.parent if str(path.parent) else Path("."))
    return None if problem is None else f"--out {path}: {problem}"


def check_env_and_agent(env_id: str, agent: str) -> str | None:
    """None if ``env_id`` is a registered id and ``agent`` a valid agent spec; else the reason."""
    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.registration import family_of

    try:
        family_of(env_id)
        parse_agent_spec(agent)
    except ValueError as exc:
        return str(exc)
    return None


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
    out_dir = Path(args.out)
    if args.traces is not None:
        if args.agent is not None or args.env is not None:
            return _fail("plot", "give either --traces FILE (with --episode K) or --agent/--env/--seed, not both")
        from visuomotor_gym.bench.trace import load_traces

        try:
            traces = load_traces(args.traces)
        except (OSError, KeyError, ValueError) as exc:
            return _fail("plot", f"cannot read traces from {args.traces}: {exc}")
        if not 0 <= args.episode < len(traces):
            return _fail("plot", f"--episode {args.episode} is out of range; {args.traces} holds "
                                 f"{len(traces)} episode(s) (0..{len(traces) - 1})")
        trace = traces[args.episode]
        target = out_dir / plot_filename(trace.env_id, trace.agent, trace.seed)
        problem = check_output_file("plot", target, args.force)
        if problem:
            return _fail("plot", problem)
    else:
        if args.agent is None or args.env is None:
            return _fail("plot", "give --agent A --env ID [--seed S], or --traces FILE.npz [--episode K]")
        problem = check_env_and_agent(args.env, args.agent)
        target = out_dir / plot_filename(args.env, args.agent, args.seed)
        problem = problem or check_output_file("plot", target, args.force)
        if problem:
            return _fail("plot", problem)
        from gymnasium.error import Error as GymError

        try:
            trace = _play(args.agent, args.env, args.seed)
        except (ValueError, GymError) as exc:  # an agent that refuses this env, a bad override
            return _fail("plot", str(exc))
    from visuomotor_gym.viz.plots import plot_episode

    try:
        path = plot_episode(trace, target)
    except ValueError as exc:  # a trace of no known family
        return _fail("plot", str(exc))
    print(path)
    return 0


def cmd_record(args: argparse.Namespace) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    from visuomotor_gym.viz.video import QUALITIES, VIDEO_SUFFIXES

    out = Path(args.out)
    if out.suffix.lower() not in VIDEO_SUFFIXES:
        return _fail("record", f"--out must end in one of {', '.join(VIDEO_SUFFIXES)}, got {str(out)!r}")
    if not (args.width >= 16 and args.height >= 16 and args.fps >= 1 and (args.stride is None or args.stride >= 1)):
        return _fail("record", f"--width/--height must be >= 16 pixels, --fps and --stride >= 1; got "
                               f"{args.width}x{args.height}, fps {args.fps}, stride {args.stride}")
    if args.quality not in QUALITIES:
        return _fail("record", f"--quality must be one of {QUALITIES}, got {args.quality!r}")
    problem = check_env_and_agent(args.env, args.agent) or check_output_file("record", out, args.force)
    if problem:
        return _fail("record", problem)
    from gymnasium.error import Error as GymError

    from visuomotor_gym.viz.plots import outcome
    from visuomotor_gym.viz.video import record_episode

    try:
        trace = record_episode(args.agent, args.env, args.seed, out, width=args.width, height=args.height,
                               fps=args.fps, camera=args.camera, overlay=not args.no_overlay,
                               overwrite=args.force, stride=args.stride, quality=args.quality)
    except (ValueError, FileExistsError, GymError) as exc:  # bad camera, an agent refusing the env, a race on --out
        return _fail("record", str(exc))
    video = trace.extras["video"]
    w, h = video["frame_size"]
    print(f"{args.env} | {args.agent} | seed {args.seed}: {outcome(trace)}; "
          f"{video['frames']} frames of {w}x{h} at {video['fps']} fps (every {video['stride']} step(s)), "
          f"recorded in {video['seconds']:.1f} s")
    print(out)
    return 0


def register(subparsers) -> None:
    """Add ``plot`` and ``record`` to the ``vmgym`` subparsers (each sets ``func(args) -> int``)."""
    from visuomotor_gym.families import families

    per_family = "\n".join(f"  {family}: {text}" for family, text in plot_contents().items())
    p = subparsers.add_parser(
        "plot",
        help="plot one episode of any family: gaze on the scene, targets, hand or feet, saccades, time series",
        description="Plot one episode to DIR/<env>_<agent>_seed<S>.png: play it (--agent --env --seed) "
        "or read it from a traces file (--traces FILE.npz --episode K). Refuses to overwrite the PNG unless "
        "--force. What the figure shows, per family:\n" + per_family,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--traces", default=None, help="a .npz written by visuomotor_gym.bench.trace.save_traces")
    p.add_argument("--episode", type=int, default=0, help="episode index in --traces (default 0)")
    p.add_argument("--agent", default=None, help="agent spec, e.g. oracle, eyecatch:param=value, iwao, faraway, "
                                                 "lookahead, fajen_warren")
    p.add_argument("--env", default=None, help="environment id, e.g. EyeCatch-v0 or ObstacleWalk-v0")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="outputs/plots", help="folder for the PNG (default outputs/plots)")
    p.add_argument("--force", action="store_true", help="replace the PNG if it exists")
    p.set_defaults(func=cmd_plot)

    p = subparsers.add_parser(
        "record",
        help="record one episode as an MP4 (scene view beside the eye camera)",
        description="Play one episode and write an MP4: a frame after reset and after every --stride-th 20 ms "
        "control step (fps = 50 / stride is real time; at the default 25 fps, catch and reach (stride 1) play at "
        "half speed, the walker families (stride 2) in real time). "
        "Scene view: the fixed scene camera for catch and reach, a camera following the walker for walk, "
        "stones and dodge; the line of sight is drawn in green. Refuses to overwrite --out unless --force.",
    )
    p.add_argument("--agent", required=True, help="agent spec, e.g. oracle or eyecatch:param=value")
    p.add_argument("--env", required=True, help="environment id, e.g. EyeCatch-v0")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True, help="output video, e.g. outputs/episode.mp4")
    p.add_argument("--width", type=int, default=480,
                   help="width of each view (with --camera both the video is twice as wide)")
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--fps", type=int, default=25, help="frames per second (default 25; 50 / stride is real time)")
    p.add_argument("--stride", type=int, default=None,
                   help="render every N-th control step (default: the family's, "
                        + ", ".join(f"{f.name} {f.viz.video_stride}" for f in families() if f.viz is not None) + ")")
    p.add_argument("--camera", default="both",
                   help="both (scene view beside eye, every family), scene, eye, or a family's own MJCF camera "
                        "(catch/reach: over_shoulder; walker families: side, follow; ...); an unknown one is "
                        "refused with the list")
    p.add_argument("--quality", default="fast", choices=("fast", "high"),
                   help="fast (default): no shadows or multisampling; high: the scene's shadows and 4x "
                        "multisampling, ~8x slower in software OpenGL")
    p.add_argument("--no-overlay", action="store_true", help="no text label on the frames")
    p.add_argument("--force", action="store_true", help="replace --out if it exists")
    p.set_defaults(func=cmd_record)
