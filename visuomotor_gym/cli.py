"""``vmgym``: the command line of visuomotor_gym.

    vmgym envs                 list the registered environment ids
    vmgym demo [--episodes N]  run the scripted interception oracle, print a table, write a video
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path


def _cmd_envs(args: argparse.Namespace) -> int:
    from visuomotor_gym.registration import ENV_SPECS

    width = max(len(s.id) for s in ENV_SPECS)
    for spec in ENV_SPECS:
        print(f"{spec.id:<{width}}  {spec.description}  kwargs={spec.kwargs}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    os.environ.setdefault("MUJOCO_GL", "egl")
    import gymnasium as gym
    import numpy as np

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.baselines.oracle import InterceptOracle

    try:
        from rich.console import Console
        from rich.progress import track
        from rich.table import Table
    except ImportError:  # rich is in the viz extra; fall back to plain text
        Console = Table = None

        def track(it, description=""):
            return it

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    policy = InterceptOracle(grasp_closed=True)
    rows = []
    frames: list = []
    env = gym.make(args.env, render_mode="rgb_array", width=320, height=240)
    for ep in track(range(args.episodes), description=f"{args.env}"):
        seed = args.seed + ep
        obs, info = env.reset(seed=seed)
        flight = info["flight_time"]
        record = ep == 0
        done, steps, min_dist = False, 0, np.inf
        while not done:
            if record:
                frames.append(env.render())
            action, _ = policy.predict(obs)
            obs, _, terminated, truncated, info = env.step(action)
            steps += 1
            min_dist = min(min_dist, float(np.linalg.norm(info["hand_pos"] - info["ball_pos"])))
            done = terminated or truncated
        if record:
            frames.append(env.render())
        rows.append((seed, flight, info["is_success"], steps, min_dist))
    env.close()

    caught = sum(r[2] for r in rows)
    if Table is not None:
        table = Table(title=f"{args.env}: scripted interception oracle (true ball state)")
        for col in ("seed", "flight time (s)", "caught", "steps", "closest hand-ball (cm)"):
            table.add_column(col, justify="right")
        for seed, flight, ok, steps, dist in rows:
            table.add_row(str(seed), f"{flight:.2f}", "yes" if ok else "no", str(steps), f"{100 * dist:.1f}")
        Console().print(table)
    else:
        for row in rows:
            print(row)
    print(f"caught {caught}/{len(rows)}")
    written = _write_media(frames, out)
    for path in written:
        print(f"wrote {path}")
    return 0


def _write_media(frames, out: Path) -> list[Path]:
    """Write a 4-frame filmstrip PNG and (with imageio-ffmpeg) an MP4 of the recorded episode."""
    import numpy as np

    try:
        import imageio.v3 as iio
    except ImportError:
        print("imageio is not installed (pip install 'visuomotor_gym[viz]'); no images written")
        return []
    written = []
    picks = np.linspace(0, len(frames) - 1, 4).round().astype(int)
    strip = np.concatenate([frames[i] for i in picks], axis=0)
    png = out / "demo_filmstrip.png"
    iio.imwrite(png, strip)
    written.append(png)
    try:
        mp4 = out / "demo_episode.mp4"
        iio.imwrite(mp4, np.stack(frames), fps=25, codec="libx264")  # 50 Hz episode at half speed
        written.append(mp4)
    except Exception as exc:  # no ffmpeg backend
        print(f"no video written ({exc}); install imageio-ffmpeg")
    return written


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vmgym", description="visuomotor_gym command line")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("envs", help="list the registered environment ids")
    p.set_defaults(func=_cmd_envs)
    p = sub.add_parser("demo", help="run a short demo and write a filmstrip and a video")
    p.add_argument("--env", default="EyeCatchOracle-v0")
    p.add_argument("--episodes", type=int, default=5)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="outputs/demo", help="folder for the images and video")
    p.set_defaults(func=_cmd_demo)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if getattr(args, "episodes", 1) < 1:
        print("--episodes must be >= 1", file=sys.stderr)
        return 2
    return int(args.func(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
