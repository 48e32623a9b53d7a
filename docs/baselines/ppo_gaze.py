"""What PPO's learned gaze does, against the fixed-gaze base it starts from and the Eyecatch heuristic.

For each agent, 200 pinned throws through the common evaluator, then per throw: the angle between the
line of sight and the true ball (median over the flight), the share of the flight with the ball
within 2 deg and 10 deg of the line of sight, and saccades per throw. Writes a table (markdown, stdout) and a PNG of gaze error against time.

    python docs/baselines/ppo_gaze.py --env EyeCatch-v0 --agents belief_intercept eyecatch ppo:RUN ... \
        --out docs/baselines/images/ppo_gaze_EyeCatch-v0.png
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from visuomotor_gym.bench.evaluate import evaluate


def gaze_error_deg(tr) -> np.ndarray:
    to_ball = tr.ball_pos - tr.eye_pos
    to_ball /= np.linalg.norm(to_ball, axis=1, keepdims=True)
    cos = np.clip(np.sum(to_ball * tr.gaze_dir, axis=1), -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def summarise(result) -> dict:
    med, within2, within10, sacc = [], [], [], []
    for tr in result.traces:
        err = gaze_error_deg(tr)[1:]
        med.append(np.median(err))
        within2.append(np.mean(err < 2.0))
        within10.append(np.mean(err < 10.0))
        sacc.append(int(tr.saccade_onset.sum()))
    return {
        "catch": result.summary["catch_rate"],
        "median gaze error (deg)": float(np.median(med)),
        "ball within 2 deg": float(np.mean(within2)),
        "ball within 10 deg": float(np.mean(within10)),
        "saccades per throw": float(np.mean(sacc)),
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="EyeCatch-v0")
    parser.add_argument("--agents", nargs="+", required=True)
    parser.add_argument("--labels", nargs="*", default=None)
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    labels = args.labels or args.agents
    fig = Figure(figsize=(8, 4), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    rows = []
    for spec, label in zip(args.agents, labels):
        result = evaluate(spec, args.env, args.episodes, 0, workers=args.workers)
        rows.append((label, summarise(result)))
        grid = np.arange(0.0, 1.6, 0.02)
        curves = []
        for tr in result.traces:
            err = gaze_error_deg(tr)
            curves.append(np.interp(grid, tr.t, err, right=np.nan))
        ax.plot(grid, np.nanmedian(np.array(curves), axis=0), label=f"{label} ({result.summary['catch_rate']:.0%})")
    ax.set_xlabel("time since the throw (s)")
    ax.set_ylabel("median angle, line of sight to ball (deg)")
    ax.set_title(f"{args.env}: where the eye looks, {args.episodes} throws")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    keys = list(rows[0][1])
    print("| agent | " + " | ".join(keys) + " |")
    print("|---" * (len(keys) + 1) + "|")
    for label, s in rows:
        print(f"| {label} | " + " | ".join(f"{s[k]:.2f}" if isinstance(s[k], float) else str(s[k]) for k in keys) + " |")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
