"""The figure of one PushRecovery episode, from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace` only:
a view of the wall from the body (x along the wall, z up) with the cubes' faces, the hand's path and the
gaze direction's crossing of the wall plane (coloured by time); and over time the gaze angle to the
nearest cube face, the hand's distance to it and the centre of pressure's lateral position, the push
marked."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from visuomotor_gym.geometry import angles_deg


def push_figure(trace) -> Figure:
    t = np.asarray(trace.t, dtype=float)
    hand = np.asarray(trace.hand_pos, dtype=float)
    faces = np.asarray(trace.block_faces, dtype=float).reshape(-1, 3)
    halves = np.asarray(trace.block_half_sizes, dtype=float).reshape(-1)
    eye = np.asarray(trace.eye_pos, dtype=float)
    gaze = np.asarray(trace.gaze_dir, dtype=float)
    fig = Figure(figsize=(11, 4.5), dpi=100)
    ax = fig.add_subplot(1, 2, 1)
    for (x, _y, z), h in zip(faces, halves):
        ax.add_patch(__import__("matplotlib.patches", fromlist=["Rectangle"]).Rectangle(
            (x - h, z - h), 2 * h, 2 * h, facecolor="#c89e5c", edgecolor="k", alpha=0.8))
    ax.plot(hand[:, 0], hand[:, 2], "-", color="tab:red", label="hand")
    y_wall = float(np.median(faces[:, 1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (y_wall - eye[:, 1]) / gaze[:, 1]
    ok = np.isfinite(s) & (s > 0) & (s < 5)
    pts = eye + s[:, None] * gaze
    sc = ax.scatter(pts[ok, 0], pts[ok, 2], c=t[ok], s=10, cmap="viridis", label="gaze on the wall plane")
    fig.colorbar(sc, ax=ax, label="time (s)")
    ax.set_xlim(-1.2, 1.4)
    ax.set_ylim(0.6, 1.9)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the wall (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("the wall seen from the body")
    ax.legend(loc="lower left", fontsize=8)
    ax2 = fig.add_subplot(1, 2, 2)
    d = np.linalg.norm(hand[:, None, :] - faces[None, :, :], axis=2)
    near = np.argmin(d, axis=1)
    ang = angles_deg(gaze, faces[near] - eye)
    ax2.plot(t, ang, label="gaze to nearest face (deg)")
    ax2.plot(t, 100 * d[np.arange(len(t)), near], label="hand to nearest face (cm)")
    cop = np.asarray(getattr(trace, "cop", np.zeros((len(t), 3))), dtype=float)
    ax2.plot(t, 100 * cop[:, 1], label="CoP y (cm)")
    ax2.axvline(float(trace.push_time), color="k", ls="--", label="shove onset")
    ax2.set_xlabel("time (s)")
    ax2.legend(fontsize=8)
    ax2.set_title("upright" if bool(trace.success) else "fell")
    fig.tight_layout()
    return fig
