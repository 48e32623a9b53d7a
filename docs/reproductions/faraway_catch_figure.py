"""The catch hand-path figure of docs/reproductions/faraway.md ("Catch hand paths").

Reads the per-episode traces that ``vmgym bench ... --traces FILE.npz`` wrote, one file per agent, and
draws, for each agent, the transports (movement onset to arrival at the interception point,
:func:`visuomotor_gym.metrics.catch_handpath.catch_reach_segment`) of its first ``--paths`` episodes
against ``faraway_path`` between the same ends (side and front views), and the distribution of the
per-episode distance to Faraway's path (scaled to 56.7 cm) of every episode.

    python docs/reproductions/faraway_catch_figure.py eyecatch=eyecatch.npz belief_mpc=belief.npz
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from visuomotor_gym import handpath
from visuomotor_gym.bench.trace import load_traces
from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.metrics import catch_handpath as C

OUT = Path(__file__).parent / "images" / "faraway_catch_paths.png"


def print_stats(label: str, traces, measures) -> None:
    """The page's per-episode spread: quantiles of the distance and curvature index, the shares under
    8.0 and over 12.6 cm, and the transport's path length over its start-end distance."""
    d = np.array([m["faraway_distance_cm"] for m in measures])
    k = np.array([m["curvature_index"] for m in measures])
    ok = np.isfinite(d)
    ratio, ball_ecc, point_ecc = [], [], []
    for tr, good in zip(traces, ok):
        if good:
            onset, arrival, end = C.catch_reach_segment(tr)
            hand, gaze, eye = (np.asarray(x) for x in (tr.hand_pos, tr.gaze_dir, tr.eye_pos))
            p = hand[onset : arrival + 1]
            ratio.append(np.linalg.norm(np.diff(p, axis=0), axis=1).sum() / np.linalg.norm(p[-1] - p[0]))
            ball_ecc.append(angles_deg(gaze[end], np.asarray(tr.ball_pos)[end] - eye[end]))
            point_ecc.append(angles_deg(gaze[: end + 1], hand[end] - eye[: end + 1]).min())
    q = [10, 25, 50, 75, 90]
    print(f"{label}: {int(ok.sum())} transports")
    print(f"  distance (cm) quantiles {q}: {np.round(np.percentile(d[ok], q), 1).tolist()}; "
          f"share <= 8.0 cm {np.mean(d[ok] <= C.HUMAN_LIKE_MAX_CM):.2f}, > 12.6 cm {np.mean(d[ok] > C.UNLIKE_REACH_MIN_CM):.2f}")
    print(f"  curvature index quantiles: {np.round(np.percentile(k[ok], q), 2).tolist()}")
    print(f"  path length / start-end distance: median {np.median(ratio):.2f}, "
          f"IQR {np.percentile(ratio, 25):.2f}-{np.percentile(ratio, 75):.2f}")
    print(f"  gaze to ball at the catch / closest approach (deg) quantiles {q}: "
          f"{np.round(np.percentile(ball_ecc, q), 1).tolist()}")
    print(f"  closest gaze to the interception point (deg), median {np.median(point_ecc):.1f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", help="LABEL=TRACES.npz, one per agent")
    ap.add_argument("--paths", type=int, default=12, help="transports drawn per agent")
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args()
    runs = [r.split("=", 1) for r in args.runs]
    fig, axes = plt.subplots(len(runs), 3, figsize=(13, 4.3 * len(runs)), squeeze=False)
    for row, (label, path) in enumerate(runs):
        traces = [tr for tr in load_traces(path) if not tr.diverged]
        side, front, hist = axes[row]
        drawn = 0
        for tr in traces:
            seg = C.catch_reach_segment(tr)
            if seg is None or drawn >= args.paths:
                continue
            p = np.asarray(tr.hand_pos)[seg[0] : seg[1] + 1]
            if np.linalg.norm(p[-1] - p[0]) < C.MIN_REACH_M:
                continue
            f = handpath.faraway_path(p[0], p[-1], 60)
            for ax, (i, j) in ((side, (0, 2)), (front, (1, 2))):
                (line,) = ax.plot(p[:, i], p[:, j], lw=1.1)
                ax.plot(f[:, i], f[:, j], "--", lw=0.8, color=line.get_color())
                ax.plot(p[-1, i], p[-1, j], "o", ms=3, color=line.get_color())
            drawn += 1
        side.set(title="side view (solid: recorded; dashed: faraway_path)", xlabel="x forward (m)",
                 ylabel=f"{label}\nz up (m)", aspect="equal")
        front.set(title="front view", xlabel="y left (m)", ylabel="z up (m)", aspect="equal")
        measures = [C.catch_hand_path_measures(tr) for tr in traces]
        d = np.array([m["faraway_distance_cm"] for m in measures])
        d = d[np.isfinite(d)]
        print_stats(label, traces, measures)
        hist.hist(np.minimum(d, 100.0), bins=np.arange(0, 102.5, 2.5), color="0.5")
        for x, name, height in ((C.HUMAN_LIKE_MAX_CM, "8.0", 0.95), (C.UNLIKE_REACH_MIN_CM, "12.6", 0.85)):
            hist.axvline(x, color="k", lw=0.8, ls=":")
            hist.text(x, hist.get_ylim()[1] * height, f" {name}", fontsize=8, va="top")
        hist.axvline(np.median(d), color="C3", lw=1.2)
        hist.set(title=f"{d.size} transports; red: median {np.median(d):.1f} cm",
                 xlabel="distance to faraway_path at 56.7 cm scale (cm; > 100 at 100)", ylabel="episodes")
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=70)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
