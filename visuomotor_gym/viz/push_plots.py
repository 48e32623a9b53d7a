"""The figure of one PushRecovery episode, from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace`
only, with the parts of every family's figure (:mod:`visuomotor_gym.viz.family_plots`):

* **the wall seen from the body** (x along the wall, z up): the cubes' faces (the one the hand first
  touched outlined), the hand's path and the **gaze point**, where the line of sight crosses the plane of
  the faces, coloured by time, saccade onsets ringed;
* **gaze over time**: the angle between the line of sight and each cube's face centre (the nearest one
  to the line of sight in black), saccade onsets dotted, the push's onset dashed;
* **hand and centre of pressure**: the active hand's distance to the nearest face, and the centre of
  pressure's lateral position with the outer edge of the foot on the wall's side (the right foot's at
  -0.205 m, the stance of ``body.standing``; the left foot's at +0.205 m for a wall on the left), hand
  contacts shaded.
"""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Rectangle

from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.viz.family_plots import _colorbar, _onset_lines, _scatter_gaze, title_line
from visuomotor_gym.viz.plots import HAND_COLOR, _new_figure, unit

RIGHT_FOOT_EDGE_M = -0.205  # the right sole's outer edge, stance frame (body/standing.py's stance)


def push_figure(trace):
    t = np.asarray(trace.t, dtype=float)
    hand = np.asarray(trace.hand_pos, dtype=float)
    task = trace.task
    faces = np.asarray(task["block_faces"], dtype=float).reshape(-1, 3)
    halves = np.asarray(task["block_half_sizes"], dtype=float).reshape(-1)
    eye = np.asarray(trace.eye_pos, dtype=float)
    gaze = unit(trace.gaze_dir)
    push_t = float(task["push_time"])
    touching = np.asarray(task.get("hand_on_block", np.zeros(len(t), bool)), dtype=bool)
    cop = np.asarray(task.get("cop", np.zeros((len(t), 3))), dtype=float)
    left = int(task.get("wall_side", -1)) > 0  # the wall (and the push) on the body's left
    edge, foot = (-RIGHT_FOOT_EDGE_M, "left") if left else (RIGHT_FOOT_EDGE_M, "right")

    fig = _new_figure((15, 10))
    grid = fig.add_gridspec(2, 2, width_ratios=(1.1, 1.0))
    wall = fig.add_subplot(grid[:, 0])
    ang = fig.add_subplot(grid[0, 1])
    bal = fig.add_subplot(grid[1, 1], sharex=ang)

    first = int(np.argmin(np.linalg.norm(faces - hand[np.flatnonzero(touching)[0]], axis=1))) if touching.any() else -1
    # loose cubes (PushRecovery's eleventh pass: they give way, told apart only by central vision); none before it
    loose = np.zeros(len(faces), bool)
    given = np.asarray(task.get("block_loose", loose), dtype=bool).reshape(-1)
    n = min(len(given), len(faces))
    loose[:n] = given[:n]
    labelled = set()  # one legend entry per kind
    for k, ((x, _y, z), h) in enumerate(zip(faces, halves)):
        kind = "loose cube (gives way)" if loose[k] else "cube face"
        wall.add_patch(Rectangle((x - h, z - h), 2 * h, 2 * h, facecolor="#ead9b8" if loose[k] else "#c89e5c",
                                 alpha=0.8, hatch="///" if loose[k] else None,
                                 edgecolor="k" if k == first else "0.4", lw=2.5 if k == first else 0.8,
                                 label=None if kind in labelled else kind))
        labelled.add(kind)
        wall.text(x, z, str(k), ha="center", va="center", fontsize="small", color="0.2", clip_on=True)
    wall.plot(hand[:, 0], hand[:, 2], color=HAND_COLOR, lw=1.5, label="hand (palm centre)")
    y_wall = float(np.median(faces[:, 1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (y_wall - eye[:, 1]) / gaze[:, 1]
    points = eye + s[:, None] * gaze
    points[~(np.isfinite(s) & (s > 0) & (s < 5))] = np.nan
    sc = _scatter_gaze(wall, trace, points, dims=(0, 2))
    _colorbar(fig, sc, wall)
    wall.set_xlim(-0.8, 1.8)
    wall.set_ylim(0.5, 1.9)
    wall.set_aspect("equal")
    wall.set_xlabel("x along the wall (m)")
    wall.set_ylabel("height (m)")
    wall.set_title("The wall seen from the body (gaze where it crosses the faces' plane)")
    wall.legend(loc="lower right", fontsize="small")

    angles = np.stack([angles_deg(gaze, f - eye) for f in faces], axis=1)
    for k in range(len(faces)):
        ang.plot(t, angles[:, k], lw=0.8, alpha=0.6, ls="--" if loose[k] else "-",
                 label=f"cube {k}" + (" (loose)" if loose[k] else ""))
    ang.plot(t, angles.min(axis=1), color="k", lw=2, label="nearest cube")
    _onset_lines(ang, trace)
    ang.axvline(push_t, color="k", ls="--", label="shove onset")
    ang.set_ylim(0, 120)
    ang.set_ylabel("line of sight to face centre (deg)")
    ang.set_title("Gaze over time: angle to each cube")
    ang.legend(fontsize="x-small", ncol=3)

    d = np.linalg.norm(hand[:, None, :] - faces[None, :, :], axis=2).min(axis=1)
    bal.plot(t, 100 * d, color=HAND_COLOR, label="hand to nearest face (cm)")
    bal.plot(t, 100 * cop[:, 1], color="tab:purple", label="centre of pressure y (cm)")
    bal.axhline(100 * edge, color="tab:purple", ls=":", label=f"{foot} foot's outer edge")
    for i in np.flatnonzero(touching):
        bal.axvspan(t[i] - float(trace.dt), t[i], color="tab:green", alpha=0.2, lw=0)
    bal.axvline(push_t, color="k", ls="--")
    bal.set_xlabel("time (s)")
    bal.set_title("Hand and centre of pressure (green: hand on a cube)")
    bal.legend(fontsize="small")
    n_sacc = int(np.count_nonzero(trace.saccade_onset))
    fig.suptitle(f"{title_line(trace)}\n{n_sacc} saccades, hand on a cube on {100 * np.mean(touching):.0f} % of "
                 "the steps", fontsize="large")
    return fig
