"""Eyecatch-style figures of one episode, drawn from an :class:`~visuomotor_gym.bench.trace.EpisodeTrace`.

The figures follow Yeo et al. 2012 (Eyecatch):

* :func:`plot_gaze_vs_ball`: azimuth and elevation of the gaze and of the ball over time (Fig. 3 and
  its simulated counterpart Fig. 12, unrolled in time): catch-up saccades (shaded) while the ball
  rises, smooth pursuit after the apex (vertical line);
* :func:`plot_gaze_path`: the same angles as a path in the visual field, the layout of Fig. 3/12;
* :func:`plot_tangential_velocities`: hand speed (m/s) and eye speed (deg/s) with the saccade onsets
  as dotted lines (Fig. 4: hand submovements synchronised with saccades);
* :func:`plot_paths_3d`: ball and hand paths in 3-D;
* :func:`plot_episode`: all of these in one PNG.

**Reference frame of the angles** (Fig. 3: "a reference frame fixed at the initial position of the
eye"): axes fixed for the whole episode, ``x`` = the initial forward axis of the head projected on
the horizontal plane, ``z`` = world up, ``y = z x x`` (left). Azimuth is the angle about ``z``,
**positive to the left** (the env's convention,
:func:`visuomotor_gym.oculomotor.plant.angles_from_direction`); elevation is positive up. The gaze
angles are those of the world line of sight ``gaze_dir``. The ball angles are those of the true
ball seen **from the current eye position** by default (``origin="eye"``), so that a gaze exactly
on the ball gives identical angles; ``origin="initial"`` uses the eye position at reset instead, as
in the paper (the two differ by the parallax of the eye moving with head and torso by a few cm:
about a degree before the apex for the oracle, up to ~10 degrees in the last steps, ball within 0.5 m).

**Speeds** come from successive 50 Hz rows (one control step, ``dt`` = 20 ms): the eye speed is the
great-circle angle between successive ``gaze_dir`` divided by the step, the hand speed is the
distance between successive ``hand_pos`` divided by the step; both are step means, plotted at the
step midpoints, so a 40 ms saccade of 800 deg/s peak shows as a step mean of a few hundred deg/s.
Saccades are resolved to the control step: step ``k`` (from ``t[k-1]`` to ``t[k]``) counts as
saccadic when a saccade started at its start (``saccade_onset[k]``) or was still in flight at its
start (``in_saccade[k-1]``).

Figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas, not ``pyplot``: no
global figure state and no backend switch for the caller. Every ``plot_*`` function accepts an
existing ``ax`` (from ``pyplot`` or elsewhere) and returns the axes it drew on.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from visuomotor_gym.bench.trace import EpisodeTrace
from visuomotor_gym.geometry import angles_deg

BALL_COLOR = "0.45"
GAZE_COLOR = "tab:red"
HAND_COLOR = "tab:green"
EYE_SPEED_COLOR = "tab:red"
APEX_COLOR = "tab:blue"
CATCH_COLOR = "black"
SACCADE_COLOR = "tab:orange"

ORIGINS = ("eye", "initial")


# ----------------------------------------------------------------------------------------------
# Numeric helpers (pure numpy; tested against closed forms)
# ----------------------------------------------------------------------------------------------
def unit(vectors) -> np.ndarray:
    """Rows scaled to unit length (zero rows stay zero)."""
    v = np.asarray(vectors, dtype=float)
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, n, out=np.zeros_like(v), where=n > 0)


def direction_angles(directions, frame: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (about z, + left) and elevation (+ up), in degrees, of direction vectors.

    ``frame`` (3 x 3, rows = the frame's x, y, z axes in world coordinates) expresses the directions
    in that frame first; ``None`` uses the world axes (x forward, y left, z up).
    """
    d = np.asarray(directions, dtype=float)
    if frame is not None:
        d = d @ np.asarray(frame, dtype=float).T
    az = np.degrees(np.arctan2(d[..., 1], d[..., 0]))
    el = np.degrees(np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1])))
    return az, el


def angular_speed_deg_s(directions, dt) -> np.ndarray:
    """Mean angular speed (deg/s) between successive direction rows: ``angle(d[k-1], d[k]) / dt``.

    ``dt`` is a scalar or one value per interval (length ``len(directions) - 1``).
    """
    d = np.asarray(directions, dtype=float)
    return angles_deg(d[:-1], d[1:]) / np.asarray(dt, dtype=float)


def tangential_speed(positions, dt) -> np.ndarray:
    """Mean speed between successive position rows: ``|p[k] - p[k-1]| / dt`` (units of p per s)."""
    p = np.asarray(positions, dtype=float)
    return np.linalg.norm(np.diff(p, axis=0), axis=-1) / np.asarray(dt, dtype=float)


def reference_frame(trace: EpisodeTrace) -> np.ndarray:
    """Rows x, y, z (world coordinates) of the Fig. 3 frame: initial head forward made horizontal, z up."""
    up = np.array([0.0, 0.0, 1.0])
    for candidate in (trace.head_dir[0], trace.gaze_dir[0], np.array([1.0, 0.0, 0.0])):
        forward = np.asarray(candidate, dtype=float) * np.array([1.0, 1.0, 0.0])
        if np.linalg.norm(forward) > 1e-6:
            break
    x = forward / np.linalg.norm(forward)
    y = np.cross(up, x)
    return np.stack([x, y, up])


def gaze_ball_angles(trace: EpisodeTrace, origin: str = "eye") -> dict[str, np.ndarray]:
    """The data of Fig. 3/12: gaze and ball azimuth/elevation (deg) per row, in :func:`reference_frame`.

    ``origin="eye"``: the ball direction from the eye position of each row (default; a foveated ball
    gives the gaze angles exactly); ``"initial"``: from the eye position at reset (the paper's frame).
    Returns ``t``, ``gaze_az``, ``gaze_el``, ``ball_az``, ``ball_el`` and ``error_deg`` (the angle
    between the line of sight and the ball, frame-independent). Azimuths are unwrapped over time.
    """
    if origin not in ORIGINS:
        raise ValueError(f"origin must be one of {ORIGINS}, got {origin!r}")
    frame = reference_frame(trace)
    eye = trace.eye_pos if origin == "eye" else trace.eye_pos[:1]
    ball_dir = unit(trace.ball_pos - eye)
    gaze = unit(trace.gaze_dir)
    gaze_az, gaze_el = direction_angles(gaze, frame)
    ball_az, ball_el = direction_angles(ball_dir, frame)
    return {
        "t": np.asarray(trace.t, dtype=float),
        "gaze_az": np.degrees(np.unwrap(np.radians(gaze_az))),
        "gaze_el": gaze_el,
        "ball_az": np.degrees(np.unwrap(np.radians(ball_az))),
        "ball_el": ball_el,
        "error_deg": angles_deg(gaze, ball_dir),
    }


def velocity_profiles(trace: EpisodeTrace) -> dict[str, np.ndarray]:
    """The data of Fig. 4: step midpoints ``t``, ``hand_speed`` (m/s) and ``eye_speed`` (deg/s)."""
    t = np.asarray(trace.t, dtype=float)
    dt = np.diff(t)
    return {
        "t": 0.5 * (t[1:] + t[:-1]),
        "hand_speed": tangential_speed(trace.hand_pos, dt),
        "eye_speed": angular_speed_deg_s(trace.gaze_dir, dt),
    }


def saccade_steps(trace: EpisodeTrace) -> np.ndarray:
    """Bool per row: step k (``t[k-1]`` .. ``t[k]``) had a saccade in flight during some part of it."""
    onset = np.asarray(trace.saccade_onset, dtype=bool)
    flying = np.asarray(trace.in_saccade, dtype=bool)
    steps = np.zeros(len(onset), dtype=bool)
    steps[1:] = onset[1:] | flying[:-1]
    return steps


def saccade_intervals(trace: EpisodeTrace) -> list[tuple[float, float]]:
    """(start, end) times (s) of the saccades, to the control step (consecutive steps merged)."""
    t = np.asarray(trace.t, dtype=float)
    intervals: list[tuple[float, float]] = []
    for k in np.flatnonzero(saccade_steps(trace)):
        start, end = float(t[k - 1]), float(t[k])
        if intervals and abs(intervals[-1][1] - start) < 1e-9:
            intervals[-1] = (intervals[-1][0], end)
        else:
            intervals.append((start, end))
    return intervals


def saccade_onset_times(trace: EpisodeTrace) -> np.ndarray:
    """Onset time (s) of every saccade: the start ``t[k-1]`` of each step k with ``saccade_onset[k]``."""
    t = np.asarray(trace.t, dtype=float)
    k = np.flatnonzero(np.asarray(trace.saccade_onset, dtype=bool)[1:]) + 1
    return t[k - 1]


def apex_time(trace: EpisodeTrace) -> float:
    """Time (s) of the ball's apex: the first + to - zero crossing of the vertical ball velocity,
    linearly interpolated between rows (exact for ballistic flight); the time of the highest row if
    the velocity never crosses zero (e.g. a ball thrown downward)."""
    t = np.asarray(trace.t, dtype=float)
    vz = np.asarray(trace.ball_vel, dtype=float)[:, 2]
    k = np.flatnonzero((vz[:-1] > 0) & (vz[1:] <= 0))
    if k.size:
        k = int(k[0])
        frac = vz[k] / (vz[k] - vz[k + 1])
        return float(t[k] + frac * (t[k + 1] - t[k]))
    return float(t[int(np.argmax(trace.ball_pos[:, 2]))])


def outcome(trace: EpisodeTrace) -> str:
    """One word (and the time of success): how the episode ended, in its family's words (the record's
    ``viz.outcome_words``; a trace of an unregistered id is read with the default family's)."""
    from visuomotor_gym.families import default_family, family_for

    try:
        record = family_for(str(trace.env_id))
    except ValueError:  # a synthetic or unregistered trace: the default (catch) family's words
        record = default_family()
    viz = record.viz
    success, failure = viz.outcome_words if viz is not None else ("succeeded", "failed")
    failure_field = viz.failure_field if viz is not None else None
    if trace.success:
        return f"{success} at {float(trace.t[-1]):.2f} s"
    if trace.diverged:
        return "physics diverged"
    if getattr(trace, failure_field, False) if failure_field is not None else not trace.truncated:
        return failure
    if trace.truncated:
        return "truncated (time limit)"
    return "ended"


def _end_time(trace: EpisodeTrace) -> float:
    return float(trace.t[-1])


# ----------------------------------------------------------------------------------------------
# Figures
# ----------------------------------------------------------------------------------------------
def _new_figure(figsize):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _mark_events(ax, trace: EpisodeTrace, *, saccades: str = "span", labels: bool = True) -> None:
    """Saccades (shaded spans or dotted onset lines), the apex and the catch/end as vertical lines."""
    if saccades == "span":
        for i, (t0, t1) in enumerate(saccade_intervals(trace)):
            ax.axvspan(t0, t1, color=SACCADE_COLOR, alpha=0.25, lw=0,
                       label="saccade" if (labels and i == 0) else None)
    else:
        for i, t0 in enumerate(saccade_onset_times(trace)):
            ax.axvline(t0, color=SACCADE_COLOR, ls=":", lw=1.5,
                       label="saccade onset" if (labels and i == 0) else None)
    ax.axvline(apex_time(trace), color=APEX_COLOR, ls="--", lw=1.2, label="ball apex" if labels else None)
    if trace.caught:
        ax.axvline(trace.catch_time, color=CATCH_COLOR, ls="-", lw=1.2, label="ball caught" if labels else None)
    else:
        ax.axvline(_end_time(trace), color=CATCH_COLOR, ls=(0, (1, 3)), lw=1.2,
                   label="episode end (no catch)" if labels else None)
    ax.set_xlim(float(trace.t[0]), _end_time(trace) + 0.02)


def plot_gaze_vs_ball(trace: EpisodeTrace, ax=None, origin: str = "eye"):
    """Eyecatch Fig. 3/12 over time: gaze (red) and ball (gray) azimuth and elevation in degrees.

    ``ax``: ``None`` (a new figure with two stacked axes, azimuth above elevation), a pair of axes
    (azimuth, elevation), or one axes (azimuth solid, elevation dashed). Saccades are shaded, the
    ball apex and the catch (or the episode end) are vertical lines. The frame and ``origin`` are
    those of :func:`gaze_ball_angles`. Returns the axes drawn on (a list, or the single axes).
    """
    a = gaze_ball_angles(trace, origin=origin)
    t = a["t"]
    if ax is None:
        fig = _new_figure((7.5, 5.5))
        axes = list(fig.subplots(2, 1, sharex=True))
    elif isinstance(ax, (Sequence, np.ndarray)):
        axes = list(ax)
        if len(axes) != 2:
            raise ValueError("ax must be one Axes or a pair (azimuth, elevation)")
    else:
        axes = [ax]
    if len(axes) == 2:
        panels = [(axes[0], "az", "-", "azimuth (deg, + left)"),
                  (axes[1], "el", "-", "elevation (deg, + up)")]
    else:
        panels = [(axes[0], "az", "-", None), (axes[0], "el", "--", None)]
    for i, (axis, key, ls, ylabel) in enumerate(panels):
        suffix = "" if len(axes) == 2 else (" azimuth" if key == "az" else " elevation")
        axis.plot(t, a["ball_" + key], color=BALL_COLOR, ls=ls, lw=2.0, marker=".", ms=3,
                  label=("ball (true, from the eye)" if origin == "eye" else "ball (from the initial eye)")
                  + suffix)
        axis.plot(t, a["gaze_" + key], color=GAZE_COLOR, ls=ls, lw=1.2, marker=".", ms=4,
                  label="gaze" + suffix)
        if i == 0 or len(axes) == 2:
            _mark_events(axis, trace, labels=(i == 0))
        if ylabel:
            axis.set_ylabel(ylabel)
        axis.grid(True, alpha=0.3)
    if len(axes) == 1:
        axes[0].set_ylabel("angle (deg): azimuth (+ left) solid, elevation (+ up) dashed")
    axes[-1].set_xlabel("time since release (s)")
    axes[0].legend(loc="best", fontsize="small", ncols=2)
    axes[0].set_title("Gaze vs ball (Eyecatch Fig. 3/12): frame fixed at the initial head pose",
                      fontsize="medium")
    return axes if len(axes) == 2 else axes[0]


def plot_gaze_path(trace: EpisodeTrace, ax=None, origin: str = "eye"):
    """The layout of Eyecatch Fig. 3/12: ball (gray) and gaze (red dots, one per 20 ms) as paths in the
    visual field, azimuth against elevation, seen from the catcher (azimuth axis reversed, so left is
    on the left). Saccadic steps are drawn as orange segments, the apex as a circle on the ball path.
    Returns the axes."""
    a = gaze_ball_angles(trace, origin=origin)
    if ax is None:
        ax = _new_figure((5.5, 5)).subplots()
    ax.plot(a["ball_az"], a["ball_el"], color=BALL_COLOR, lw=2.0, marker=".", ms=3, label="ball")
    ax.plot(a["gaze_az"], a["gaze_el"], color=GAZE_COLOR, lw=0.6, ls="-", alpha=0.6)
    ax.plot(a["gaze_az"], a["gaze_el"], color=GAZE_COLOR, lw=0, marker=".", ms=5, label="gaze (every 20 ms)")
    for i, k in enumerate(np.flatnonzero(saccade_steps(trace))):
        ax.plot(a["gaze_az"][k - 1 : k + 1], a["gaze_el"][k - 1 : k + 1], color=SACCADE_COLOR, lw=2.5,
                label="saccadic step" if i == 0 else None)
    t_apex = apex_time(trace)
    ax.plot(np.interp(t_apex, a["t"], a["ball_az"]), np.interp(t_apex, a["t"], a["ball_el"]), "o", ms=11,
            mfc="none", mec=APEX_COLOR, mew=2, label="ball apex")
    ax.plot(a["ball_az"][0], a["ball_el"][0], "s", color="k", ms=6, label="release")
    if trace.caught:
        ax.plot(a["ball_az"][-1], a["ball_el"][-1], "*", color=CATCH_COLOR, ms=12, label="ball caught")
    ax.set_xlabel("azimuth (deg, + left; axis reversed)")
    ax.set_ylabel("elevation (deg)")
    if not ax.xaxis_inverted():
        ax.invert_xaxis()
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.09), fontsize="small", ncols=3)
    ax.set_title("Visual field, as seen by the catcher (Eyecatch Fig. 3/12 layout)", fontsize="medium")
    return ax


def plot_tangential_velocities(trace: EpisodeTrace, ax=None):
    """Eyecatch Fig. 4: hand tangential speed (green, m/s, left axis) and eye angular speed (red,
    deg/s, right axis) per control step, saccade onsets as dotted vertical lines, apex and catch
    marked. Returns ``(ax, ax_right)``."""
    v = velocity_profiles(trace)
    if ax is None:
        ax = _new_figure((7.5, 3.5)).subplots()
    right = ax.twinx()
    h_hand = ax.plot(v["t"], v["hand_speed"], color=HAND_COLOR, lw=2.0, marker=".", ms=4,
                     label="hand speed (m/s)")
    h_eye = right.plot(v["t"], v["eye_speed"], color=EYE_SPEED_COLOR, lw=1.2, marker=".", ms=4,
                       label="eye speed (deg/s)")
    _mark_events(ax, trace, saccades="lines")
    ax.set_xlabel("time since release (s)")
    ax.set_ylabel("hand tangential speed (m/s)", color=HAND_COLOR)
    right.set_ylabel("eye angular speed (deg/s)", color=EYE_SPEED_COLOR)
    ax.tick_params(axis="y", colors=HAND_COLOR)
    right.tick_params(axis="y", colors=EYE_SPEED_COLOR)
    ax.set_ylim(bottom=0, top=max(0.1, 1.1 * float(np.nanmax(v["hand_speed"], initial=0.0))))
    right.set_ylim(bottom=0, top=max(10.0, 1.1 * float(np.nanmax(v["eye_speed"], initial=0.0))))
    ax.grid(True, alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    ax.legend(h_hand + h_eye + handles[1:], [h.get_label() for h in h_hand + h_eye] + labels[1:],
              loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize="small", ncols=5)
    ax.set_title("Tangential velocity of hand and eye (Eyecatch Fig. 4), 20 ms step means", fontsize="medium")
    return ax, right


def plot_paths_3d(trace: EpisodeTrace, ax=None, zoom: float = 1.0):
    """3-D ball path (gray) and hand path (green), world frame (x forward, y left, z up), with the
    release point, the sampled arrival point, the eye and the catch (or the last ball position)
    marked. Axes are scaled to the data's proportions (each side at least a quarter of the longest,
    so a flat path stays readable); ``zoom`` enlarges the box inside its axes. Returns the 3-D axes."""
    from matplotlib.ticker import MaxNLocator

    if ax is None:
        ax = _new_figure((6, 5)).add_subplot(projection="3d")
    ball, hand = np.asarray(trace.ball_pos), np.asarray(trace.hand_pos)
    ax.plot(*ball.T, color=BALL_COLOR, lw=2.0, marker=".", ms=3, label="ball")
    ax.plot(*hand.T, color=HAND_COLOR, lw=2.5, label="hand (catch site)")
    ax.scatter(*np.asarray(trace.release_pos), color="k", marker="s", s=30, label="release")
    ax.scatter(*np.asarray(trace.arrival_pos), color=APEX_COLOR, marker="x", s=50, label="sampled arrival")
    ax.scatter(*trace.eye_pos[0], color=GAZE_COLOR, marker="o", s=25, label="eye")
    if trace.caught:
        ax.scatter(*ball[-1], color=CATCH_COLOR, marker="*", s=120, label="ball caught")
    else:
        ax.scatter(*ball[-1], color=CATCH_COLOR, marker="X", s=60, label="ball at the end")
    pts = np.concatenate([ball, hand, trace.eye_pos[:1], np.asarray(trace.arrival_pos)[None]])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 0.25 * float(np.max(hi - lo)) + 1e-3)
    mid = 0.5 * (lo + hi)
    ax.set_xlim(mid[0] - 0.55 * span[0], mid[0] + 0.55 * span[0])
    ax.set_ylim(mid[1] - 0.55 * span[1], mid[1] + 0.55 * span[1])
    ax.set_zlim(max(0.0, mid[2] - 0.55 * span[2]), mid[2] + 0.55 * span[2])
    ax.set_box_aspect(tuple(span), zoom=zoom)
    ax.set_xlabel("x forward (m)")
    ax.set_ylabel("y left (m)")
    ax.set_zlabel("z up (m)")
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(nbins=4 if axis is ax.xaxis else 3))
    ax.view_init(elev=18, azim=-125)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, 1.0), fontsize="small", ncols=3)
    ax.set_title("Ball and hand paths", fontsize="medium")
    return ax


def episode_summary(trace: EpisodeTrace) -> str:
    """One line of numbers for a figure title."""
    a = gaze_ball_angles(trace)
    closest = float(np.min(np.linalg.norm(trace.ball_pos - trace.hand_pos, axis=1)))
    n_sacc = int(np.count_nonzero(trace.saccade_onset[1:]))
    return (f"flight time {trace.flight_time:.2f} s, {n_sacc} saccades, apex at {apex_time(trace):.2f} s, "
            f"median gaze-ball angle {float(np.median(a['error_deg'])):.1f} deg, "
            f"closest hand-ball {100 * closest:.1f} cm")


def trace_family(trace: EpisodeTrace) -> str:
    """The family of a trace: from its registered env id, else from the task fields it holds (the
    records' ``viz.trace_field``)."""
    return _trace_record(trace).name


def _trace_record(trace: EpisodeTrace):
    from visuomotor_gym.families import families, family_for

    try:
        return family_for(str(trace.env_id))
    except ValueError:
        markers = [f for f in families() if f.viz is not None]
        for record in markers:
            if record.viz.trace_field in trace.task:
                return record
    raise ValueError(f"cannot tell the family of the trace of {trace.env_id!r}: not a registered id and none of "
                     f"the fields {[f.viz.trace_field for f in markers]} in its task fields {sorted(trace.task)}")


def __getattr__(name: str):
    """``FAMILIES``: the names of the families with a figure, from the records (for older callers)."""
    if name == "FAMILIES":
        from visuomotor_gym.families import families

        return tuple(f.name for f in families() if f.viz is not None)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def catch_figure(trace: EpisodeTrace, origin: str = "eye"):
    """The catch family's figure: gaze vs ball over time (azimuth, elevation), hand and eye speeds,
    the visual-field path and the 3-D paths, titled with env id, agent, seed and outcome."""
    fig = _new_figure((15, 11.5))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.4, 1.0), height_ratios=(1.0, 1.0, 1.2))
    ax_az = fig.add_subplot(grid[0, 0])
    ax_el = fig.add_subplot(grid[1, 0], sharex=ax_az)
    ax_vel = fig.add_subplot(grid[2, 0], sharex=ax_az)
    ax_path = fig.add_subplot(grid[0:2, 1])
    ax_3d = fig.add_subplot(grid[2, 1], projection="3d")
    plot_gaze_vs_ball(trace, ax=(ax_az, ax_el), origin=origin)
    ax_az.tick_params(labelbottom=False)
    ax_az.set_xlabel("")
    plot_tangential_velocities(trace, ax=ax_vel)
    plot_gaze_path(trace, ax=ax_path, origin=origin)
    plot_paths_3d(trace, ax=ax_3d, zoom=1.25)
    ok = "CAUGHT" if trace.caught else outcome(trace).upper()
    fig.suptitle(f"{trace.env_id}  |  agent {trace.agent}  |  seed {trace.seed}  |  {ok}"
                 + (f" at {trace.catch_time:.2f} s" if trace.caught else "")
                 + f"\n{episode_summary(trace)}", fontsize="large")
    return fig


def episode_figure(trace: EpisodeTrace, origin: str = "eye"):
    """The figure of one episode for its family (:func:`trace_family`): the function its record names
    (``viz.figure``: :func:`catch_figure`, or the reach/walk/stones/dodge figures of
    :mod:`visuomotor_gym.viz.family_plots`). ``origin`` is passed to a figure function that takes it
    (the catch family's, see :func:`gaze_ball_angles`). Returns a matplotlib ``Figure`` (Agg canvas)."""
    import inspect

    from visuomotor_gym.family import resolve

    record = _trace_record(trace)
    if record.viz is None:
        raise ValueError(f"the {record.name} family declares no figure (its Family record has no viz)")
    figure = resolve(record.viz.figure)
    if "origin" in inspect.signature(figure).parameters:
        return figure(trace, origin=origin)
    return figure(trace)


def save_figure(fig, path, dpi: int = 100) -> Path:
    """Write ``fig`` to ``path`` (PNG) at ``dpi``, making the parent folder; returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    return path


def plot_episode(trace: EpisodeTrace, path, dpi: int | None = None, origin: str = "eye") -> Path:
    """Write :func:`episode_figure` of ``trace`` to ``path`` (PNG) at ``dpi`` (default: the family
    record's ``viz.dpi``: 110 for catch, 100 for the other families' larger figures). Creates the
    parent folder; overwrites ``path``. Returns the path written."""
    if dpi is None:
        record = _trace_record(trace)
        dpi = record.viz.dpi if record.viz is not None else 100
    return save_figure(episode_figure(trace, origin=origin), path, dpi)
