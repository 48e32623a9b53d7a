"""Figures of one episode of the reach, walk, stones and dodge families, from an
:class:`~visuomotor_gym.bench.trace.EpisodeTrace` only (the catch family's are in
:mod:`visuomotor_gym.viz.plots`).

Every figure has the same parts, so a reader learns them once:

* a **scene view** (top view of the floor for the walker families, top and side view of the shelf
  for reach) with the family's targets, the body's path (hand, or pelvis and feet with the
  **footholds**), and the **gaze point**: where the line of sight meets the scene, one dot per 20 ms
  control step **coloured by time** (the colour bar), saccade onsets as black-edged dots;
* a **time-series** column: gaze azimuth and elevation (world frame, azimuth + left of the path's
  +x axis, elevation + up), saccade onsets as dotted vertical lines, and the family's key distances.

**Gaze point** (:func:`gaze_points`): the first hit of the ray ``eye_pos + s * gaze_dir`` (s > 0) on
the floor (z = 0) or, for the walk family, on an obstacle's box (from the trace's ``obstacles``
rows); NaN when the ray leaves the floor beyond ``max_range_m`` (a level gaze). The dodge family
looks at pedestrians at eye height, not at the floor, so its gaze point is the point of the ray at
the distance of the pedestrian nearest the line of sight when that one is within
``DODGE_ON_TARGET_DEG`` of it (:func:`dodge_gaze_points`), else the gaze is drawn as a short ray.

**Footholds** (:func:`footholds`): runs of at least ``FOOTHOLD_MIN_STEPS`` control steps in which a
sole centre (``feet_pos``) is on the ground (z below ``FOOTHOLD_Z_M``) and still (horizontal speed
below ``FOOTHOLD_SPEED_M_S``); each run's mean position is one foothold.

Only trace fields are used, plus two fixed layouts that are not in the trace: the walkway's width
(the walk family's default course, ``CourseDistribution.walkway_width_m``) and the 30 shelf targets
(:data:`visuomotor_gym.tasks.reach.SHELF_LAYOUT`) drawn as context for reach.
"""

from __future__ import annotations

import numpy as np

from visuomotor_gym.bench.trace import EpisodeTrace
from visuomotor_gym.geometry import angles_deg
from visuomotor_gym.viz.plots import (
    GAZE_COLOR,
    HAND_COLOR,
    SACCADE_COLOR,
    _new_figure,
    direction_angles,
    outcome,
    saccade_onset_times,
    tangential_speed,
    unit,
)

TIME_CMAP = "viridis"
BODY_COLOR = "0.25"
LEFT_FOOT_COLOR = "tab:blue"
RIGHT_FOOT_COLOR = "tab:pink"
TARGET_COLOR = "tab:brown"
PEDESTRIAN_COLORS = ("tab:red", "tab:purple", "tab:orange", "tab:cyan", "tab:olive", "tab:pink")

# Foothold detection (display only; modelling choices read off walker episodes: a planted sole sits
# within 1 cm of the floor and moves < 1 cm per 20 ms step, a swing foot lifts > 3 cm within a step).
FOOTHOLD_Z_M = 0.03
FOOTHOLD_SPEED_M_S = 0.5
FOOTHOLD_MIN_STEPS = 3
GAZE_MAX_RANGE_M = 25.0  # gaze points farther than this from the eye are not drawn (a near-level gaze)
DODGE_ON_TARGET_DEG = 10.0  # a pedestrian within this angle of the line of sight counts as looked at
DODGE_HALF_VIEW_M = 9.0  # the dodge top view shows +-9 m about the path (pedestrians start 4-6 m aside)
DODGE_RAY_M = 4.0  # length of the drawn line of sight when no pedestrian is near it
PARKED_Z_M = -1.0  # dodge pedestrians not yet on stage are parked below the floor (z = -5 m)


# ----------------------------------------------------------------------------------------------
# Numeric helpers
# ----------------------------------------------------------------------------------------------
def ray_box_distance(origin: np.ndarray, direction: np.ndarray, lo, hi) -> np.ndarray:
    """Distance along each ray (rows of ``origin``/``direction``) to its entry into the axis-aligned
    box ``[lo, hi]`` (slab method); ``inf`` for a miss or a box behind the ray's origin."""
    o, d = np.asarray(origin, float), np.asarray(direction, float)
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t1, t2 = (lo - o) * inv, (hi - o) * inv
    t1 = np.where(np.isnan(t1), -np.inf, t1)  # a ray parallel to a slab, its origin inside it
    t2 = np.where(np.isnan(t2), np.inf, t2)
    near = np.max(np.minimum(t1, t2), axis=-1)
    far = np.min(np.maximum(t1, t2), axis=-1)
    hit = (far >= np.maximum(near, 0.0)) & (near > 0.0)
    return np.where(hit, near, np.inf)


def floor_distance(origin: np.ndarray, direction: np.ndarray, z: float = 0.0) -> np.ndarray:
    """Distance along each ray to the plane ``z``; ``inf`` where the ray does not go down to it."""
    o, d = np.asarray(origin, float), unit(direction)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (z - o[:, 2]) / d[:, 2]
    return np.where((d[:, 2] < 0) & (s > 0), s, np.inf)


def obstacle_boxes(obstacles) -> list[tuple[np.ndarray, np.ndarray]]:
    """(lo, hi) corners of the walk family's obstacles (rows: x, y, depth, width, height, kind)."""
    boxes = []
    for x, y, depth, width, height, *_ in np.asarray(obstacles, float).reshape(-1, 6).tolist():
        boxes.append((np.array([x - depth / 2, y - width / 2, 0.0]), np.array([x + depth / 2, y + width / 2, height])))
    return boxes


def gaze_points(trace: EpisodeTrace, boxes=(), max_range_m: float = GAZE_MAX_RANGE_M) -> np.ndarray:
    """(T, 3) where the line of sight first meets the floor (z = 0) or one of ``boxes``; NaN rows
    where it meets neither within ``max_range_m`` of the eye."""
    eye, gaze = np.asarray(trace.eye_pos, float), unit(trace.gaze_dir)
    s = floor_distance(eye, gaze)
    for lo, hi in boxes:
        s = np.minimum(s, ray_box_distance(eye, gaze, lo, hi))
    s = np.where(s <= max_range_m, s, np.nan)
    return eye + s[:, None] * gaze


def gaze_angles(trace: EpisodeTrace) -> tuple[np.ndarray, np.ndarray]:
    """World-frame gaze azimuth (deg, + left of +x, unwrapped) and elevation (deg, + up)."""
    az, el = direction_angles(unit(trace.gaze_dir))
    return np.degrees(np.unwrap(np.radians(az))), el


def footholds(trace: EpisodeTrace) -> list[np.ndarray]:
    """Per foot (left, right): (K, 4) rows ``x, y, t_start, t_end`` of its footholds (module docstring)."""
    feet = np.asarray(trace.feet_pos, float)
    t = np.asarray(trace.t, float)
    dt = np.diff(t, prepend=t[0] - trace.dt)
    out = []
    for side in range(feet.shape[1]):
        p = feet[:, side]
        speed = np.zeros(len(p))
        speed[1:] = tangential_speed(p[:, :2], dt[1:])
        planted = (p[:, 2] < FOOTHOLD_Z_M) & (speed < FOOTHOLD_SPEED_M_S)
        rows = []
        k = 0
        while k < len(p):
            if not planted[k]:
                k += 1
                continue
            j = k
            while j + 1 < len(p) and planted[j + 1]:
                j += 1
            if j - k + 1 >= FOOTHOLD_MIN_STEPS:
                xy = p[k : j + 1, :2].mean(axis=0)
                rows.append((xy[0], xy[1], t[k], t[j]))
            k = j + 1
        out.append(np.array(rows, float).reshape(-1, 4))
    return out


def pedestrian_active(trace: EpisodeTrace) -> np.ndarray:
    """(T, N) bool: the dodge pedestrian is on stage (not parked below the floor before its onset)."""
    return np.asarray(trace.pedestrian_pos, float)[:, :, 2] > PARKED_Z_M


def pedestrian_gaze_angles(trace: EpisodeTrace) -> np.ndarray:
    """(T, N) angle (deg) between the line of sight and each pedestrian's seen point; NaN off stage."""
    ped = np.asarray(trace.pedestrian_pos, float)
    eye = np.asarray(trace.eye_pos, float)[:, None, :]
    gaze = np.broadcast_to(unit(trace.gaze_dir)[:, None, :], ped.shape)
    ang = angles_deg(gaze, ped - eye)
    return np.where(pedestrian_active(trace), ang, np.nan)


def pedestrian_distances(trace: EpisodeTrace) -> np.ndarray:
    """(T, N) horizontal distance (m) from the pelvis axis to each pedestrian's axis; NaN off stage."""
    ped = np.asarray(trace.pedestrian_pos, float)[:, :, :2]
    pelvis = np.asarray(trace.pelvis_pos, float)[:, None, :2]
    return np.where(pedestrian_active(trace), np.linalg.norm(ped - pelvis, axis=-1), np.nan)


def dodge_gaze_points(trace: EpisodeTrace) -> tuple[np.ndarray, np.ndarray]:
    """(T, 3) gaze points of the dodge family and (T,) index of the pedestrian looked at (-1: none):
    the point of the ray at that pedestrian's distance from the eye (module docstring)."""
    ang = pedestrian_gaze_angles(trace)
    filled = np.where(np.isnan(ang), np.inf, ang)
    best = np.argmin(filled, axis=1) if filled.shape[1] else np.zeros(len(filled), int)
    on = filled[np.arange(len(filled)), best] <= DODGE_ON_TARGET_DEG if filled.shape[1] else np.zeros(len(filled), bool)
    eye = np.asarray(trace.eye_pos, float)
    ped = np.asarray(trace.pedestrian_pos, float)
    dist = np.linalg.norm(ped[np.arange(len(ped)), best] - eye, axis=1) if ped.shape[1] else np.zeros(len(eye))
    points = eye + dist[:, None] * unit(trace.gaze_dir)
    points[~on] = np.nan
    return points, np.where(on, best, -1)


def nearest_index(points_xy: np.ndarray, centres_xy: np.ndarray, radius: float) -> np.ndarray:
    """Per point, the index of the nearest centre within ``radius`` (m), else -1 (NaN points: -1)."""
    p = np.asarray(points_xy, float)[:, None, :]
    c = np.asarray(centres_xy, float)[None, :, :]
    if c.shape[1] == 0:
        return np.full(len(p), -1)
    d = np.linalg.norm(p - c, axis=-1)
    d = np.where(np.isnan(d), np.inf, d)
    k = np.argmin(d, axis=1)
    return np.where(d[np.arange(len(d)), k] <= radius, k, -1)


def failure_reason(trace: EpisodeTrace) -> str:
    """The family's outcome flags that are set (tripped, fell, collided, panel hit, ...), or ''."""
    flags = [name.replace("_", " ") for name in ("tripped", "misstepped", "off_path", "fell", "collided",
                                                  "panel_hit") if bool(trace.task.get(name, False))]
    return ", ".join(flags)


def title_line(trace: EpisodeTrace) -> str:
    why = failure_reason(trace)
    return (f"{trace.env_id}  |  agent {trace.agent}  |  seed {trace.seed}  |  {outcome(trace).upper()}"
            + (f" ({why})" if why and not trace.success else ""))


# ----------------------------------------------------------------------------------------------
# Shared drawing
# ----------------------------------------------------------------------------------------------
def _time_norm(trace: EpisodeTrace):
    from matplotlib.colors import Normalize

    return Normalize(vmin=float(trace.t[0]), vmax=max(float(trace.t[-1]), float(trace.t[0]) + 1e-6))


def _scatter_gaze(ax, trace: EpisodeTrace, points: np.ndarray, dims=(0, 1), label="gaze point (colour = time)"):
    """Gaze points coloured by time; saccade onsets ringed in black. Returns the scatter (for a colour bar)."""
    ok = ~np.isnan(points[:, 0])
    t = np.asarray(trace.t, float)
    sc = ax.scatter(points[ok, dims[0]], points[ok, dims[1]], c=t[ok], cmap=TIME_CMAP, norm=_time_norm(trace),
                    s=14, lw=0, zorder=5, label=label)
    onset = ok & np.asarray(trace.saccade_onset, bool)
    ax.scatter(points[onset, dims[0]], points[onset, dims[1]], facecolors="none", edgecolors="k", s=40, lw=1.0,
               zorder=6, label="gaze at a saccade onset")
    return sc


def _time_marks(ax, trace: EpisodeTrace, xy: np.ndarray, every_s: float = 1.0, color="k", text=True,
                marker="o", size=18):
    """Small markers on a path every ``every_s`` seconds, coloured by time, labelled with the time."""
    t = np.asarray(trace.t, float)
    ticks = np.arange(np.ceil(t[0] / every_s) * every_s, t[-1] + 1e-9, every_s)
    idx = np.searchsorted(t, ticks - 1e-9)
    idx = idx[idx < len(t)]
    idx = idx[~np.isnan(xy[idx, 0])]
    ax.scatter(xy[idx, 0], xy[idx, 1], c=t[idx], cmap=TIME_CMAP, norm=_time_norm(trace), marker=marker, s=size,
               edgecolors=color, lw=0.8, zorder=7)
    if text:
        for k in idx:
            ax.annotate(f"{t[k]:.0f}s", (xy[k, 0], xy[k, 1]), xytext=(3, 3), textcoords="offset points",
                        fontsize=7, color=color, zorder=8)


def _plot_feet(ax, trace: EpisodeTrace, holds=None):
    feet = np.asarray(trace.feet_pos, float)
    holds = footholds(trace) if holds is None else holds
    for side, (name, color, mk) in enumerate((("left", LEFT_FOOT_COLOR, "^"), ("right", RIGHT_FOOT_COLOR, "v"))):
        ax.plot(feet[:, side, 0], feet[:, side, 1], color=color, lw=0.6, alpha=0.5)
        h = holds[side]
        ax.scatter(h[:, 0], h[:, 1], marker=mk, s=36, color=color, edgecolors="k", lw=0.5, zorder=4,
                   label=f"{name} foothold ({len(h)})")


def _gaze_angle_panel(ax, trace: EpisodeTrace, title: str, extra=None):
    """Gaze azimuth and elevation over time with the saccade onsets; ``extra(ax)`` adds more lines."""
    az, el = gaze_angles(trace)
    t = np.asarray(trace.t, float)
    ax.plot(t, az, color=GAZE_COLOR, lw=1.3, label="gaze azimuth (deg, + left)")
    ax.plot(t, el, color="tab:blue", lw=1.3, label="gaze elevation (deg, + up)")
    if extra is not None:
        extra(ax)
    _onset_lines(ax, trace)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_ylabel("angle (deg)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small", ncols=2)
    ax.set_title(title, fontsize="medium")


def _onset_lines(ax, trace: EpisodeTrace, label: bool = True):
    for i, t0 in enumerate(saccade_onset_times(trace)):
        ax.axvline(t0, color=SACCADE_COLOR, ls=":", lw=0.9, alpha=0.6,
                   label="saccade onset" if (label and i == 0) else None)
    ax.set_xlim(float(trace.t[0]), float(trace.t[-1]) + 0.02)


def _colorbar(fig, sc, ax):
    cb = fig.colorbar(sc, ax=ax, fraction=0.04, pad=0.01)
    cb.set_label("time (s)")
    return cb


# ----------------------------------------------------------------------------------------------
# Walk: obstacles on a walkway
# ----------------------------------------------------------------------------------------------
KIND_NAMES = ("bar", "box", "mat")
KIND_COLORS = ("tab:red", "tab:orange", "0.1")


def _walkway_half_width() -> float:
    from visuomotor_gym.tasks.obstacle_walk import CourseDistribution

    return 0.5 * CourseDistribution().walkway_width_m


def walk_figure(trace: EpisodeTrace):
    """ObstacleWalk: top view (walkway, obstacles by kind, pelvis path, feet and footholds, gaze points
    on the floor or an obstacle, coloured by time), side view (obstacle heights, feet heights), gaze
    angles over time, and the gaze's look-ahead and the distance to the next obstacle over time."""
    from matplotlib.patches import Rectangle

    obstacles = np.asarray(trace.obstacles, float).reshape(-1, 6)
    boxes = obstacle_boxes(obstacles)
    gp = gaze_points(trace, boxes)
    pelvis = np.asarray(trace.pelvis_pos, float)
    t = np.asarray(trace.t, float)
    half = _walkway_half_width()
    length = float(trace.course_length)
    x_hi = max(length, float(np.nanmax(pelvis[:, 0]))) + 1.0

    fig = _new_figure((15, 11))
    grid = fig.add_gridspec(4, 1, height_ratios=(1.3, 0.8, 1.0, 1.0))
    top = fig.add_subplot(grid[0])
    side = fig.add_subplot(grid[1], sharex=top)
    ang = fig.add_subplot(grid[2])
    dist = fig.add_subplot(grid[3], sharex=ang)

    for y in (-half, half):
        top.axhline(y, color="0.4", lw=1.5)
    top.axvline(length, color="tab:green", lw=2.5, label=f"finish ({length:.1f} m)")
    seen_kinds = set()
    for (x, y, depth, width, height, kind) in obstacles.tolist():
        k = int(kind)
        top.add_patch(Rectangle((x - depth / 2, y - width / 2), depth, width, color=KIND_COLORS[k], alpha=0.75,
                                zorder=2, label=f"{KIND_NAMES[k]}" if k not in seen_kinds else None))
        side.add_patch(Rectangle((x - depth / 2, 0.0), depth, max(height, 0.005), color=KIND_COLORS[k], alpha=0.75))
        top.annotate(f"{100 * height:.0f} cm", (x, y + width / 2), xytext=(0, 2), textcoords="offset points",
                     ha="center", fontsize=7)
        seen_kinds.add(k)
    top.plot(pelvis[:, 0], pelvis[:, 1], color=BODY_COLOR, lw=1.2, label="pelvis")
    _plot_feet(top, trace)
    sc = _scatter_gaze(top, trace, gp)
    _time_marks(top, trace, pelvis[:, :2])
    top.set_xlim(-1.0, x_hi)
    top.set_ylim(-half - 1.0, half + 1.0)
    top.set_aspect("equal", adjustable="box")
    top.set_ylabel("y left (m)")
    top.set_title("Top view: walkway edges (gray), obstacles with heights, pelvis path (times in s), "
                  "footholds, gaze on the floor/obstacles", fontsize="medium")
    top.legend(loc="upper left", bbox_to_anchor=(1.06, 1.0), fontsize="small")
    _colorbar(fig, sc, top)

    feet = np.asarray(trace.feet_pos, float)
    side.plot(feet[:, 0, 0], feet[:, 0, 2], color=LEFT_FOOT_COLOR, lw=1.0, label="left sole")
    side.plot(feet[:, 1, 0], feet[:, 1, 2], color=RIGHT_FOOT_COLOR, lw=1.0, label="right sole")
    side.set_ylim(-0.02, max(0.45, float(np.nanmax(feet[:, :, 2])) + 0.05))
    side.set_ylabel("height (m)")
    side.set_xlabel("x along the walkway (m)")
    side.grid(True, alpha=0.3)
    side.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    side.set_title("Side view (height exaggerated): obstacle heights and sole heights", fontsize="medium")

    _gaze_angle_panel(ang, trace, "Gaze over time (world frame: azimuth + left of the walkway's axis)")
    ang.tick_params(labelbottom=False)

    ahead = gp[:, 0] - pelvis[:, 0]
    dist.plot(t, ahead, color=GAZE_COLOR, lw=1.3, label="gaze point ahead of the pelvis (m)")
    far_edges = obstacles[:, 0] + obstacles[:, 2] / 2 if len(obstacles) else np.zeros(0)
    near_edges = obstacles[:, 0] - obstacles[:, 2] / 2 if len(obstacles) else np.zeros(0)
    nxt = np.full(len(t), np.nan)
    for k in range(len(t)):
        ahead_of = near_edges[far_edges > pelvis[k, 0]] - pelvis[k, 0]
        if ahead_of.size:
            nxt[k] = ahead_of[0]
    dist.plot(t, nxt, color="tab:orange", lw=1.3, label="next obstacle's near edge ahead of the pelvis (m)")
    _onset_lines(dist, trace, label=False)
    dist.axhline(0.0, color="0.6", lw=0.6)
    dist.set_xlabel("time (s)")
    dist.set_ylabel("distance (m)")
    dist.grid(True, alpha=0.3)
    dist.legend(loc="best", fontsize="small")
    dist.set_title("Look-ahead: how far ahead the gaze lands, and the next obstacle", fontsize="medium")

    n_sacc = int(np.count_nonzero(trace.saccade_onset[1:]))
    seen = float(np.mean(np.asarray(trace.obstacle_seen, bool))) if "obstacle_seen" in trace.task else float("nan")
    fig.suptitle(f"{title_line(trace)}\n{n_sacc} saccades, median look-ahead {np.nanmedian(ahead):.1f} m, "
                 f"an obstacle seen on {100 * seen:.0f} % of the steps", fontsize="large")
    return fig


# ----------------------------------------------------------------------------------------------
# Stones
# ----------------------------------------------------------------------------------------------
def stones_figure(trace: EpisodeTrace):
    """SteppingStones: top view (stones numbered, the last in green, loose rocks hatched, pelvis path,
    footholds, gaze points on the floor coloured by time), gaze angles over time, and the stone under the gaze
    against the next stone the feet go to, over time."""
    from matplotlib.patches import Circle

    stones = np.asarray(trace.stones, float).reshape(-1, 2)
    radius = float(trace.stone_radius)
    gp = gaze_points(trace)
    pelvis = np.asarray(trace.pelvis_pos, float)
    t = np.asarray(trace.t, float)

    fig = _new_figure((15, 9.5))
    grid = fig.add_gridspec(2, 2, width_ratios=(1.0, 1.1))
    top = fig.add_subplot(grid[:, 0])
    ang = fig.add_subplot(grid[0, 1])
    which = fig.add_subplot(grid[1, 1], sharex=ang)

    heading = np.diff(np.concatenate([[[0.0, 0.0]], stones]), axis=0)
    for i, (x, y) in enumerate(stones.tolist()):
        last = i == len(stones) - 1
        top.add_patch(Circle((x, y), radius, color="tab:green" if last else "0.7", alpha=0.6, zorder=1,
                             label=("last stone (success)" if last else ("stone" if i == 0 else None))))
        h = heading[i] / max(float(np.linalg.norm(heading[i])), 1e-9)
        side = (-1.0 if i % 2 else 1.0) * 1.6 * radius  # numbers beside the path, alternating sides
        top.annotate(str(i), (x - side * h[1], y + side * h[0]), ha="center", va="center", fontsize=9,
                     color="0.15", zorder=9)
    from visuomotor_gym.tasks.stepping_stones import HAZARD_RGBA  # the rocks' colour in the scene

    hazards = np.asarray(getattr(trace, "hazards", np.zeros((0, 2))), float).reshape(-1, 2)
    for i, (x, y) in enumerate(hazards.tolist()):  # the rough course's loose rocks (they never hold a foot)
        top.add_patch(Circle((x, y), float(trace.hazard_radius), facecolor=HAZARD_RGBA[:3], alpha=0.55, zorder=1,
                             hatch="xx", edgecolor="0.25", lw=0.5, label="loose rock (falls)" if i == 0 else None))
    top.plot(pelvis[:, 0], pelvis[:, 1], color=BODY_COLOR, lw=1.2, label="pelvis")
    _plot_feet(top, trace)
    sc = _scatter_gaze(top, trace, gp)
    _time_marks(top, trace, pelvis[:, :2])
    pts = np.concatenate([stones, pelvis[:, :2], np.zeros((1, 2))])
    lo, hi = pts.min(axis=0) - 0.8, pts.max(axis=0) + 0.8
    top.set_xlim(lo[0], hi[0])
    top.set_ylim(lo[1], hi[1])
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x (m)")
    top.set_ylabel("y left (m)")
    top.grid(True, alpha=0.2)
    top.legend(loc="upper left", fontsize="small")
    top.set_title("Top view: stones (numbered), pelvis path (times in s), footholds,\n"
                  "gaze on the floor (colour = time)", fontsize="medium")
    _colorbar(fig, sc, top)

    _gaze_angle_panel(ang, trace, "Gaze over time (world frame)")
    ang.tick_params(labelbottom=False)

    on = nearest_index(gp[:, :2], stones, radius)
    gaze_stone = np.where(on >= 0, on, np.nan)
    which.plot(t, np.asarray(trace.next_stone, float), color=BODY_COLOR, lw=2.0, drawstyle="steps-post",
               label="next stone the feet go to")
    which.plot(t, gaze_stone, color=GAZE_COLOR, lw=0, marker=".", ms=4, label="stone under the gaze")
    _onset_lines(which, trace)
    which.set_ylabel("stone index")
    which.set_xlabel("time (s)")
    which.grid(True, alpha=0.3)
    which.legend(loc="upper left", fontsize="small")
    which.set_title("Which stone the eye is on vs the feet's next stone (looking ahead = red above black)",
                    fontsize="medium")

    n_sacc = int(np.count_nonzero(trace.saccade_onset[1:]))
    lead = gaze_stone - np.asarray(trace.next_stone, float)
    fig.suptitle(f"{title_line(trace)}\n{n_sacc} saccades, gaze on a stone {100 * np.mean(on >= 0):.0f} % of the "
                 f"steps, median lead {np.nanmedian(lead) if np.any(~np.isnan(lead)) else float('nan'):.1f} "
                 "stone(s) ahead of the feet", fontsize="large")
    return fig


# ----------------------------------------------------------------------------------------------
# Dodge
# ----------------------------------------------------------------------------------------------
def dodge_figure(trace: EpisodeTrace):
    """ObstacleDodge: top view (goal line, pelvis and pedestrians' paths with times, the line of sight
    coloured by time: a dot where it meets a pedestrian, else a short ray), the angle between the
    gaze and each pedestrian, and each pedestrian's distance, over time."""
    ped = np.asarray(trace.pedestrian_pos, float)
    active = pedestrian_active(trace)
    pelvis = np.asarray(trace.pelvis_pos, float)
    eye = np.asarray(trace.eye_pos, float)
    t = np.asarray(trace.t, float)
    gp, looked = dodge_gaze_points(trace)
    goal = float(trace.goal_distance)

    fig = _new_figure((15, 10))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.15, 1.0))
    top = fig.add_subplot(grid[:, 0])
    ang = fig.add_subplot(grid[0, 1])
    pang = fig.add_subplot(grid[1, 1], sharex=ang)
    dist = fig.add_subplot(grid[2, 1], sharex=ang)

    top.axvline(goal, color="tab:green", lw=2.5, label=f"goal line ({goal:.1f} m)")
    # Lines of sight with no pedestrian near them: short rays, every 5th step (0.1 s), coloured by time.
    from matplotlib.collections import LineCollection

    free = np.flatnonzero(looked < 0)[::5]
    g = unit(trace.gaze_dir)
    horiz = unit(g[:, :2])
    segs = [np.stack([eye[k, :2], eye[k, :2] + DODGE_RAY_M * horiz[k]]) for k in free]
    if segs:
        lc = LineCollection(segs, cmap=TIME_CMAP, norm=_time_norm(trace), lw=0.8, alpha=0.6,
                            label=f"line of sight, no pedestrian within {DODGE_ON_TARGET_DEG:g} deg ({DODGE_RAY_M:g} m)")
        lc.set_array(t[free])
        top.add_collection(lc)
    top.plot(pelvis[:, 0], pelvis[:, 1], color=BODY_COLOR, lw=2.0, label="walker (pelvis)")
    _time_marks(top, trace, pelvis[:, :2])
    for i in range(ped.shape[1]):
        color = PEDESTRIAN_COLORS[i % len(PEDESTRIAN_COLORS)]
        p = np.where(active[:, i, None], ped[:, i, :2], np.nan)
        veer = bool(np.asarray(trace.task.get("veered", np.zeros(ped.shape[1], bool)))[i])
        top.plot(p[:, 0], p[:, 1], color=color, lw=1.5,
                 label=f"pedestrian {i}" + (" (veered)" if veer else ""))
        _time_marks(top, trace, p, color=color, text=True, size=14)
    sc = _scatter_gaze(top, trace, gp, label="gaze on a pedestrian (colour = time)")
    xs = np.concatenate([pelvis[:, 0], [0.0, goal]])
    top.set_xlim(float(np.min(xs)) - 1.0, float(np.max(xs)) + 1.5)
    top.set_ylim(-DODGE_HALF_VIEW_M, DODGE_HALF_VIEW_M)
    top.set_aspect("equal", adjustable="box")
    top.set_xlabel("x toward the goal (m)")
    top.set_ylabel("y left (m)")
    top.grid(True, alpha=0.2)
    top.legend(loc="upper left", bbox_to_anchor=(0.0, -0.07), fontsize="small", ncols=2)
    top.set_title("Top view: walker and pedestrians (dots every 1 s, times in s),\nwhere the gaze meets a pedestrian",
                  fontsize="medium")
    _colorbar(fig, sc, top)

    _gaze_angle_panel(ang, trace, "Gaze over time (world frame: azimuth + left of the path)")
    ang.tick_params(labelbottom=False)

    pa = pedestrian_gaze_angles(trace)
    pd = pedestrian_distances(trace)
    for i in range(ped.shape[1]):
        color = PEDESTRIAN_COLORS[i % len(PEDESTRIAN_COLORS)]
        pang.plot(t, pa[:, i], color=color, lw=1.3, label=f"pedestrian {i}")
        dist.plot(t, pd[:, i], color=color, lw=1.3, label=f"pedestrian {i}")
    pang.axhline(DODGE_ON_TARGET_DEG, color="0.5", ls="--", lw=0.8, label=f"{DODGE_ON_TARGET_DEG:g} deg")
    pang.set_ylim(0, 60)
    pang.set_ylabel("gaze to pedestrian (deg)")
    pang.grid(True, alpha=0.3)
    pang.legend(loc="upper right", fontsize="small", ncols=3)
    pang.set_title("Angle between the line of sight and each pedestrian (low = looked at)", fontsize="medium")
    pang.tick_params(labelbottom=False)
    _onset_lines(pang, trace, label=False)
    min_gap = float(trace.task.get("min_gap", np.nan))
    dist.set_ylim(0, 10)
    dist.set_ylabel("pelvis to pedestrian (m)")
    dist.set_xlabel("time (s)")
    dist.grid(True, alpha=0.3)
    dist.legend(loc="upper right", fontsize="small", ncols=2)
    dist.set_title("Horizontal distance to each pedestrian (axis to axis)", fontsize="medium")
    _onset_lines(dist, trace, label=False)

    n_sacc = int(np.count_nonzero(trace.saccade_onset[1:]))
    fig.suptitle(f"{title_line(trace)}\n{n_sacc} saccades, a pedestrian within {DODGE_ON_TARGET_DEG:g} deg of the "
                 f"gaze on {100 * np.mean(looked >= 0):.0f} % of the steps, smallest gap {min_gap:.2f} m",
                 fontsize="large")
    return fig


# ----------------------------------------------------------------------------------------------
# Reach
# ----------------------------------------------------------------------------------------------
def reach_figure(trace: EpisodeTrace):
    """ShelfReach: a top view (the shelf targets in gray, the object, the hand path and the gaze point
    at the object's distance, both coloured by time), the visual field seen from the eye (targets,
    object, hand, gaze direction), gaze and object angles over time, and the gaze-object angle,
    hand-object distance and hand speed over time."""
    from visuomotor_gym.tasks.reach import SHELF_LAYOUT

    obj = np.asarray(trace.object_pos, float)
    hand = np.asarray(trace.hand_pos, float)
    eye = np.asarray(trace.eye_pos, float)
    g = unit(trace.gaze_dir)
    t = np.asarray(trace.t, float)
    reach_d = np.linalg.norm(obj[None] - eye, axis=1)
    gp = eye + reach_d[:, None] * g  # the gaze at the object's distance
    shelf = SHELF_LAYOUT.targets()

    fig = _new_figure((15, 10))
    grid = fig.add_gridspec(3, 2, width_ratios=(1.0, 1.15), height_ratios=(1.0, 1.0, 1.0))
    top = fig.add_subplot(grid[0:2, 0])
    side = fig.add_subplot(grid[2, 0])
    ang = fig.add_subplot(grid[0, 1])
    err = fig.add_subplot(grid[1, 1], sharex=ang)
    dist = fig.add_subplot(grid[2, 1], sharex=ang)

    norm = _time_norm(trace)
    # Top view: the 30 targets fall on 6 points (3 towers x 2 depths; levels stack above each other).
    top.scatter(shelf[:, 0], shelf[:, 1], s=60, color="0.8", label="shelf targets (3 towers x 2 depths)", zorder=1)
    top.scatter(obj[0], obj[1], marker="*", s=320, color="gold", edgecolors="k", zorder=8, label="object")
    top.plot(hand[:, 0], hand[:, 1], color=HAND_COLOR, lw=1.0, alpha=0.7)
    top.scatter(hand[:, 0], hand[:, 1], c=t, cmap=TIME_CMAP, norm=norm, s=12, marker="s", zorder=4,
                label="hand (catch site), colour = time")
    top.scatter(eye[0, 0], eye[0, 1], color=GAZE_COLOR, s=40, zorder=6, label="eye")
    top.scatter(0.0, 0.0, marker="+", color="k", s=80, zorder=6, label="seat axis")
    sc = _scatter_gaze(top, trace, gp, label="gaze at the object's distance")
    pts = np.concatenate([shelf[:, :2], hand[:, :2], eye[:1, :2], gp[:, :2]])
    lo, hi = np.nanmin(pts, axis=0) - 0.08, np.nanmax(pts, axis=0) + 0.08
    top.set_xlim(lo[0], hi[0])
    top.set_ylim(lo[1], hi[1])
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x forward (m)")
    top.set_ylabel("y left (m)")
    top.grid(True, alpha=0.2)
    top.legend(loc="center right", fontsize="small", framealpha=0.9)
    top.set_title("Top view: shelf targets, object, hand path and gaze point (colour = time)", fontsize="medium")
    _colorbar(fig, sc, top)

    # The visual field seen from the eye at reset: azimuth reversed so that left is on the left.
    def field(points):
        return direction_angles(unit(np.atleast_2d(points) - eye[0]))

    saz, sel = field(shelf)
    side.scatter(saz, sel, s=18, color="0.75", zorder=1)
    oaz0, oel0 = field(obj)
    side.scatter(oaz0, oel0, marker="*", s=320, color="gold", edgecolors="k", zorder=8)
    haz, hel = field(hand)
    side.plot(haz, hel, color=HAND_COLOR, lw=1.0, alpha=0.7)
    side.scatter(haz, hel, c=t, cmap=TIME_CMAP, norm=norm, s=12, marker="s", zorder=4)
    gaz, gel = direction_angles(g)
    side.plot(gaz, gel, color=GAZE_COLOR, lw=0.6, alpha=0.5)
    _scatter_gaze(side, trace, np.stack([gaz, gel], axis=1))
    side.invert_xaxis()
    side.set_aspect("equal", adjustable="datalim")
    side.set_xlabel("azimuth from the eye (deg, + left; axis reversed)")
    side.set_ylabel("elevation (deg)")
    side.grid(True, alpha=0.3)
    side.set_title("Seen from the eye: shelf targets, object, hand, gaze direction", fontsize="medium")

    obj_dir = unit(obj[None] - eye)
    oaz, oel = direction_angles(obj_dir)

    def object_lines(ax):
        ax.plot(t, oaz, color=GAZE_COLOR, ls="--", lw=1.0, label="object azimuth")
        ax.plot(t, oel, color="tab:blue", ls="--", lw=1.0, label="object elevation")

    _gaze_angle_panel(ang, trace, "Gaze (solid) and object (dashed) directions from the eye, world frame",
                      extra=object_lines)
    ang.tick_params(labelbottom=False)

    e = angles_deg(g, obj_dir)
    err.plot(t, e, color=GAZE_COLOR, lw=1.3, label="gaze to object (deg)")
    _onset_lines(err, trace)
    err.set_ylabel("angle (deg)")
    err.grid(True, alpha=0.3)
    err.legend(loc="best", fontsize="small")
    err.set_title("Angle between the line of sight and the object", fontsize="medium")
    err.tick_params(labelbottom=False)

    hd = np.linalg.norm(hand - obj[None], axis=1)
    dist.plot(t, hd, color=HAND_COLOR, lw=1.5, label="hand to object (m)")
    right = dist.twinx()
    hs = tangential_speed(hand, np.diff(t)) if len(t) > 1 else np.zeros(0)
    right.plot(0.5 * (t[1:] + t[:-1]), hs, color="0.4", lw=1.0, ls="--", label="hand speed (m/s)")
    right.set_ylabel("hand speed (m/s)", color="0.4")
    _onset_lines(dist, trace, label=False)
    dist.set_ylabel("distance (m)", color=HAND_COLOR)
    dist.set_xlabel("time (s)")
    dist.grid(True, alpha=0.3)
    h1, l1 = dist.get_legend_handles_labels()
    h2, l2 = right.get_legend_handles_labels()
    dist.legend(h1 + h2, l1 + l2, loc="center left", fontsize="small")
    dist.set_title("Hand to object and hand speed", fontsize="medium")

    from visuomotor_gym.tasks.reach import ShelfLayout

    tower, level, depth = ShelfLayout.describe(int(trace.target_index))
    n_sacc = int(np.count_nonzero(trace.saccade_onset[1:]))
    fig.suptitle(f"{title_line(trace)}\nobject at target {int(trace.target_index)} (tower {tower}, level {level}, "
                 f"{'far' if depth else 'near'}), {n_sacc} saccades, closest hand-object {100 * np.min(hd):.1f} cm, "
                 f"final gaze-object angle {e[-1]:.1f} deg", fontsize="large")
    return fig


def __getattr__(name: str):
    """``FIGURES``: family name -> figure function, from the records' ``viz.figure`` (for older callers;
    the records are the one place a family's figure is named)."""
    if name == "FIGURES":
        from visuomotor_gym.families import families
        from visuomotor_gym.family import resolve

        return {f.name: resolve(f.viz.figure) for f in families() if f.viz is not None}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

