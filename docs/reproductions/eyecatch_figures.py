"""Regenerate the figures and measured numbers of docs/reproductions/eyecatch.md.

    python docs/reproductions/eyecatch_figures.py [--episodes 200] [--workers 2]

Runs the common evaluator (pinned seeds 0..N-1, as ``vmgym bench``) and writes, under images/:

* Eyecatch Fig. 3/12-style episode plots (``vmgym plot`` layout) for EyeCatch-v0 seed 0, one caught
  and one missed throw of each paper condition (EyeCatchPaper-v0, EyeCatchPaperPoorVision-v0);
* ``eyecatch_catchup_synchrony.png``: measured over every throw of EyeCatch-v0 and EyeCatchPaper-v0:
  (a) the intervals between consecutive saccade onsets before the ball's apex (Eyecatch Sec. 4.1,
  Fig. 4: ~200 ms), (b) the lag from each saccade onset to the nearest hand-submovement onset
  (the detector of ``visuomotor_gym.metrics.hand``; Eyecatch Sec. 1, Fig. 4: submovements start with
  the catch-up saccades), (c) the saccade rate before and after the apex (Fig. 3: pursuit after it);
* ``eyecatch_bounce_recovery.png``: Bounce catch rate against the time left after the bounce.

and prints the numbers quoted on the page.
"""

from __future__ import annotations

import argparse
import itertools
import os
from pathlib import Path

import numpy as np

os.environ.setdefault("MUJOCO_GL", "egl")

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.metrics import gaze as gaze_metrics
from visuomotor_gym.metrics import hand as hand_metrics
from visuomotor_gym.viz.plots import _new_figure, plot_episode

OUT = Path(__file__).resolve().parent / "images"


def bounce_time(trace) -> float:
    """Time of the wall bounce: the first sign change of the ball's lateral velocity."""
    vy = trace.ball_vel[:, 1]
    flips = np.flatnonzero(np.sign(vy[1:]) != np.sign(vy[:-1]))
    return float(trace.t[flips[0] + 1]) if flips.size else float("nan")


def catchup_measures(traces):
    """Pre-apex inter-saccade intervals, saccade-onset -> nearest hand-onset lags (all saccades),
    and the saccade rates (onsets per second) before / after the apex, pooled over ``traces``."""
    intervals, lags, before, after = [], [], [], []
    for tr in traces:
        onsets = gaze_metrics.saccade_onset_times(tr)
        apex = gaze_metrics.ball_apex_time(tr)
        if onsets.size >= 2 and np.isfinite(apex):
            iv = np.diff(onsets)
            intervals.extend(iv[onsets[:-1] <= apex + 1e-9].tolist())
        hand_on = hand_metrics.hand_submovement_onsets(tr)
        if hand_on.size:
            for s in onsets:
                k = int(np.argmin(np.abs(hand_on - s)))
                lags.append(float(hand_on[k] - s))
        end = float(np.asarray(tr.t)[-1])
        if np.isfinite(apex) and apex < end:
            before.append((np.sum(onsets <= apex), apex))
            after.append((np.sum(onsets > apex), end - apex))
    rate = lambda pairs: sum(n for n, _ in pairs) / max(sum(d for _, d in pairs), 1e-9)  # noqa: E731
    return np.array(intervals), np.array(lags), rate(before), rate(after)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)

    ids = ("EyeCatch-v0", "EyeCatchPaper-v0", "EyeCatchPaperPoorVision-v0", "EyeCatchPoorVision-v0",
           "EyeCatchBounce-v0")
    runs = {e: evaluate("eyecatch", e, args.episodes, 0, workers=args.workers) for e in ids}
    plot_episode(runs["EyeCatch-v0"].traces[0], OUT / "eyecatch_EyeCatch-v0_seed0.png")
    examples = {}
    for e, tag in (("EyeCatchPaper-v0", "Paper"), ("EyeCatchPaperPoorVision-v0", "PaperPoorVision")):
        traces = runs[e].traces
        caught = next((t for t in traces if t.caught), None)
        missed = next((t for t in traces if not t.caught), None)
        for name, tr in (("caught", caught), ("missed", missed)):
            if tr is not None:
                plot_episode(tr, OUT / f"eyecatch_{tag}_{name}_seed{tr.seed}.png")
                examples[f"{tag} {name}"] = tr.seed

    # Catch-up saccades and their synchrony with hand submovements, measured.
    fig = _new_figure((11.0, 3.4))
    axes = fig.subplots(1, 3)
    colours = {"EyeCatch-v0": "#4c72b0", "EyeCatchPaper-v0": "#dd8452"}
    for e, c in colours.items():
        iv, lag, before, after = catchup_measures(runs[e].traces)
        axes[0].hist(iv * 1000, bins=np.arange(0, 620, 20), alpha=0.6, color=c,
                     label=f"{e} (n={iv.size}, median {np.median(iv) * 1000:.0f} ms)")
        axes[1].hist(lag * 1000, bins=np.arange(-200, 220, 20), alpha=0.6, color=c,
                     label=f"{e} (n={lag.size}, median {int(round(np.median(lag) * 1000)):+d} ms)")
        print(f"{e}: pre-apex saccade intervals n={iv.size} median {np.median(iv):.3f} s, "
              f"IQR {np.percentile(iv, 25):.3f}-{np.percentile(iv, 75):.3f} s, "
              f"share in 0.15-0.30 s {np.mean((iv >= 0.15) & (iv <= 0.30)):.2f}")
        print(f"{e}: saccade onset -> nearest hand submovement onset n={lag.size} median {np.median(lag):+.3f} s, "
              f"|lag| <= 60 ms {np.mean(np.abs(lag) <= 0.06):.2f}, <= 100 ms {np.mean(np.abs(lag) <= 0.1):.2f}")
        print(f"{e}: saccades per second before the apex {before:.2f}, after it {after:.2f}")
        short = e[len("EyeCatch"):-len("-v0")] or "default"
        axes[2].bar([f"{short}\nbefore apex", f"{short}\nafter apex"], [before, after], color=c)
    axes[0].axvline(200, color="k", ls=":", lw=1)
    axes[0].set_xlabel("interval between saccade onsets before the apex (ms)")
    axes[0].set_ylabel("count")
    axes[0].set_title("(a) catch-up saccade intervals (paper: ~200 ms)", fontsize=9)
    axes[0].legend(fontsize=7)
    axes[1].axvline(0, color="k", ls=":", lw=1)
    axes[1].set_xlabel("hand submovement onset - saccade onset (ms)")
    axes[1].set_title("(b) saccade -> nearest hand submovement", fontsize=9)
    axes[1].legend(fontsize=7)
    axes[2].set_ylabel("saccades per second")
    axes[2].set_title("(c) saccade rate before / after the apex", fontsize=9)
    axes[2].tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "eyecatch_catchup_synchrony.png", dpi=110)

    bounce = runs["EyeCatchBounce-v0"].traces
    left = np.array([t.flight_time - bounce_time(t) for t in bounce])
    ok = np.array([t.caught for t in bounce])
    edges = np.array([0.0, 0.3, 0.4, 0.5, 0.6, 0.8, 1.2])
    fig = _new_figure((6.0, 3.6))
    ax = fig.add_subplot()
    centres, rates, counts = [], [], []
    for lo, hi in itertools.pairwise(edges):
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
    print(f"examples: {examples}")


if __name__ == "__main__":
    main()
