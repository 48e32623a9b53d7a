"""Regenerate the figures of docs/reproductions/eyecatch.md.

    python docs/reproductions/eyecatch_figures.py [--episodes 200]

Runs the common evaluator (same pinned seeds as the leaderboard entries: 0..N-1) and writes:
episode plots (Eyecatch Fig. 3/4 style) for typical throws, and the Bounce recovery curve (catch
rate against the time left between the bounce and the ball's arrival).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

os.environ.setdefault("MUJOCO_GL", "egl")

from visuomotor_gym.bench.evaluate import evaluate  # noqa: E402
from visuomotor_gym.viz.plots import _new_figure, plot_episode  # noqa: E402

OUT = Path(__file__).resolve().parent / "images"


def bounce_time(trace) -> float:
    """Time of the wall bounce: the first sign change of the ball's lateral velocity."""
    vy = trace.ball_vel[:, 1]
    flips = np.flatnonzero(np.sign(vy[1:]) != np.sign(vy[:-1]))
    return float(trace.t[flips[0] + 1]) if flips.size else float("nan")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)

    runs = {e: evaluate("eyecatch", e, args.episodes, 0, workers=args.workers)
            for e in ("EyeCatch-v0", "EyeCatchPoorVision-v0", "EyeCatchBounce-v0")}
    plot_episode(runs["EyeCatch-v0"].traces[0], OUT / "eyecatch_EyeCatch-v0_seed0.png")
    poor = runs["EyeCatchPoorVision-v0"].traces
    caught = next(t for t in poor if t.caught)
    missed = next(t for t in poor if not t.caught)
    plot_episode(caught, OUT / f"eyecatch_PoorVision_caught_seed{caught.seed}.png")
    plot_episode(missed, OUT / f"eyecatch_PoorVision_missed_seed{missed.seed}.png")

    bounce = runs["EyeCatchBounce-v0"].traces
    left = np.array([t.flight_time - bounce_time(t) for t in bounce])
    ok = np.array([t.caught for t in bounce])
    recovered = next(t for t, l in zip(bounce, left) if t.caught and l > 0.5)
    plot_episode(recovered, OUT / f"eyecatch_Bounce_recovered_seed{recovered.seed}.png")
    edges = np.array([0.0, 0.3, 0.4, 0.5, 0.6, 0.8, 1.2])
    fig = _new_figure((6.0, 3.6))
    ax = fig.add_subplot()
    centres, rates, counts = [], [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (left >= lo) & (left < hi)
        if m.sum():
            centres.append(0.5 * (lo + hi))
            rates.append(ok[m].mean())
            counts.append(int(m.sum()))
    ax.bar(centres, rates, width=np.diff(edges)[: len(centres)] * 0.9, color="#4c72b0")
    for c, r, n in zip(centres, rates, counts):
        ax.text(c, r + 0.02, f"n={n}", ha="center", fontsize=8)
    ax.set_xlabel("time from the bounce to the ball's arrival (s)")
    ax.set_ylabel("catch rate")
    ax.set_ylim(0, 1.1)
    ax.set_title(f"EyeCatchBounce-v0, {args.episodes} throws: recovery needs time")
    fig.savefig(OUT / "eyecatch_bounce_recovery.png", dpi=110)
    for e, r in runs.items():
        print(f"{e}: catch rate {r.summary['catch_rate']:.3f}")
    for c, rate, n in zip(centres, rates, counts):
        print(f"bounce-to-arrival ~{c:.2f} s: {rate:.2f} (n={n})")
    late = left >= 0.6
    print(f"bounce-to-arrival >= 0.6 s: {ok[late].mean():.3f} ({ok[late].sum()}/{late.sum()})")
    print(f"examples: PoorVision caught seed {caught.seed}, missed seed {missed.seed}; Bounce seed {recovered.seed}")


if __name__ == "__main__":
    main()
