"""Hand-path toolkit: Bézier fitting and the Faraway, Reed & Wang (2007) reach model.

Faraway, Reed & Wang (*Modelling three-dimensional trajectories by using Bézier curves with
application to hand motion*, JRSS C 2007) describe a wrist path from a home shelf to a target shelf as
a cubic Bézier curve, fitted by least squares with an arc-length parameterisation (Sec. 3.2), and
predicts new reaches with a "null axis model with distance scaling" (Sec. 4): the two interior control
points sit at fixed offsets, proportional to the reach length, from the points one third and two thirds
of the way along the start-end axis. Progress along the path in time follows a Beta(1.63, 1.75)
relative-speed profile.

What is here
------------
- :func:`bernstein`, :func:`bezier`: the curve, Faraway et al. (2007) Sec. 3.1 (Eq. for ``B_i^d``
  and ``C(t)``).
- :func:`arc_length_parameter`, :func:`fit_bezier`, :func:`fit_error`: the fit of Sec. 3.2 and the
  "maximum error" of Sec. 4 (Table 1).
- :func:`beta_progress`, :func:`beta_peak_time`, :func:`minimum_jerk_progress`: timing profiles.
- :func:`body_frame`, :func:`faraway_control_points`, :func:`faraway_path`: the chosen model.
- :func:`straight_path`, :func:`minimum_jerk_path`: the straight-line and Flash & Hogan (1985)
  references. Flash & Hogan's *via-point* variant is not built.
- :func:`resample`, :func:`path_distance`: path-error measures at equal arc length or equal time.
- :func:`peak_speed`, :func:`hand_path_realism`: plain measures of a recorded hand path for the
  evaluator.

Axis convention (the paper leaves it implicit)
----------------------------------------------
The offsets are read in a *body* frame whose rows are (lateral, forward, up), not in a frame attached
to the start-end axis. Sourced: Sec. 5 says the model "operates in a co-ordinate system that is defined
by a global vertical and a 'forward' direction that is defined by the initial posture", and Sec. 4
describes Y1 = (-0.025, -0.148, 0.077) as "to the rear and above the corresponding axis point" and
Y2 = (-0.015, -0.139, -0.002) as "mostly to the rear": so the second component is forward (negative =
towards the body) and the third is up. Our choice: the first component is lateral with **positive to
the subject's right** (the reaching hand's side), which makes (lateral, forward, up) a right-handed
triad (lateral = forward x up). The paper does not state this sign; it only moves the path 1.4 cm
sideways at a 56.7 cm reach. For a left hand the lateral sign is reversed (``hand="left"``), as the
paper's Sec. 5 suggests but did not test. The default ``forward=(1, 0, 0)``, ``up=(0, 0, 1)`` is this
package's MuJoCo world frame (x forward, y left, z up), so the paper's lateral axis is world -y.

Reach length ``d``: the paper scales by "d_a, the distance between P_0 and P_1", but converts the means
to centimetres with "the median reach distance of 56.7 cm" and argues the scaling makes short reaches
close to straight, so ``d`` is read as the start-end distance ``|P_3 - P_0|`` (P_1 is taken as a typo).

Timing (which quantity follows the Beta CDF)
--------------------------------------------
Faraway et al. (2007) fit each curve with its parameter set to the relative arc length of the data (Sec. 3.2,
``s_i``) and fits a Beta distribution to those ``s_i`` as "the relative speed profile" (Sec. 4): the Beta
CDF of relative time is the fraction of the *path length* covered. :func:`faraway_path` keeps that
meaning by default (``progress="arc_length"``): the point at relative time ``tau`` is where the relative
arc length of the predicted curve equals ``F(tau)``, so the hand's tangential speed is the Beta density
times ``length / duration`` and peaks at the Beta mode (0.457) for every target. The alternative,
``progress="parameter"``, evaluates ``C(F(tau))``: the literal inverse of the fitting step (the mean
control points average fitted curves at equal parameter, and in each fit the parameter stood for the
data's arc length). The geometric path is the same; the timing is not: the Bézier parameter of the
model's curve is far from its arc length, so the two place the hand up to 3 cm (56.7 cm reach to the
right-front) to 6 cm (straight-forward reach) apart at the same time, and under ``"parameter"`` the
speed peak moves with the target direction (0.37 to 0.61 of the reach in our checks), which
contradicts the measured near-symmetric profile. Faraway et al. (2007, Sec. 5) weigh spatial error
above timing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

# Faraway et al. (2007), Sec. 4 ("The observed means for the distance-scaled control points offset from the
# axis points"), dimensionless (metres of offset per metre of reach), rows (lateral, forward, up).
FARAWAY_Y1 = (-0.025, -0.148, 0.077)
FARAWAY_Y2 = (-0.015, -0.139, -0.002)
# Faraway et al. (2007), Sec. 4: median ML estimates of the Beta relative-speed profile.
FARAWAY_ALPHA = 1.63
FARAWAY_BETA = 1.75
# Faraway et al. (2007), Sec. 4: the median reach distance, at which the offsets are quoted in cm.
FARAWAY_MEDIAN_REACH_M = 0.567
# Flash & Hogan (1985) minimum-jerk progress 10t^3 - 15t^4 + 6t^5 has speed 30 t^2 (1 - t)^2, the
# Beta(3, 3) density. (Faraway et al. 2007, Sec. 4, call it "a beta density with alpha = 2 and beta = 2"; that
# is a slip: Beta(2, 2) has density 6 t (1 - t).)
MINIMUM_JERK_ALPHA = 3.0
MINIMUM_JERK_BETA = 3.0

_ARC_GRID = 4097  # samples of a Bézier used to tabulate its arc length (chord error ~1e-8 relative)

Hand = Literal["right", "left"]
Progress = Literal["arc_length", "parameter"]
Align = Literal["arc_length", "time"]
Reduce = Literal["mean", "max"]


# ---------------------------------------------------------------------------------------------------
# input checks
# ---------------------------------------------------------------------------------------------------
def _points(x: ArrayLike, name: str, min_points: int = 2) -> np.ndarray:
    """``x`` as a finite float array of shape (n, 3) with n >= ``min_points``, or a ValueError."""
    a = np.asarray(x, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3) (one 3-D point per row), got shape {a.shape}")
    if a.shape[0] < min_points:
        raise ValueError(f"{name} needs at least {min_points} points, got {a.shape[0]}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    return a


def _point(x: ArrayLike, name: str) -> np.ndarray:
    """``x`` as a finite float array of shape (3,), or a ValueError."""
    a = np.asarray(x, dtype=float)
    if a.shape != (3,):
        raise ValueError(f"{name} must be one 3-D point, shape (3,), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (no NaN or inf), got {a.tolist()}")
    return a


def _unit_interval(t: ArrayLike, name: str) -> np.ndarray:
    """``t`` as a finite float array with every value in [0, 1], or a ValueError."""
    a = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (no NaN or inf)")
    if a.size and (a.min() < 0.0 or a.max() > 1.0):
        raise ValueError(f"{name} must lie in [0, 1], got values in [{a.min():g}, {a.max():g}]")
    return a


def _count(n: int, name: str, minimum: int = 2) -> int:
    """``n`` as an int >= ``minimum``, or a ValueError."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {n!r}")
    return int(n)


def _shape_params(alpha: float, beta: float) -> tuple[float, float]:
    a, b = float(alpha), float(beta)
    if not (math.isfinite(a) and a > 0 and math.isfinite(b) and b > 0):
        raise ValueError(f"alpha and beta must be finite and > 0, got alpha={alpha!r}, beta={beta!r}")
    return a, b


def _reach(start: ArrayLike, end: ArrayLike) -> tuple[np.ndarray, np.ndarray, float]:
    p0, p3 = _point(start, "start"), _point(end, "end")
    d = float(np.linalg.norm(p3 - p0))
    if d == 0.0:
        raise ValueError("start and end coincide: the reach length is 0, a reach needs start != end")
    return p0, p3, d


# ---------------------------------------------------------------------------------------------------
# Bézier curves (Faraway et al. 2007, Sec. 3.1)
# ---------------------------------------------------------------------------------------------------
def bernstein(degree: int, t: ArrayLike) -> np.ndarray:
    """Bernstein basis ``B_i^d(t) = C(d, i) t^i (1 - t)^(d - i)`` (Faraway et al. 2007, Sec. 3.1),
    shape (len(t), d + 1).

    Parameters
    ----------
    degree : int
        Curve degree ``d >= 1``.
    t : array_like
        Parameter values in [0, 1], any shape (flattened).
    """
    d = _count(degree, "degree", minimum=1)
    t = _unit_interval(t, "t").reshape(-1, 1)
    i = np.arange(d + 1)
    binom = np.array([math.comb(d, k) for k in i], dtype=float)
    return binom * t**i * (1.0 - t) ** (d - i)


def bezier(control_points: ArrayLike, t: ArrayLike) -> np.ndarray:
    """Points of the Bézier curve ``C(t) = sum_i P_i B_i^d(t)`` (Faraway et al. 2007, Sec. 3.1).

    Parameters
    ----------
    control_points : array_like, shape (d + 1, 3)
        ``P_0 .. P_d``; at least 2 (a line segment).
    t : float or array_like
        Parameter value(s) in [0, 1].

    Returns
    -------
    numpy.ndarray
        Shape (3,) for a scalar ``t``, else (len(t), 3).
    """
    p = _points(control_points, "control_points", min_points=2)
    scalar = np.ndim(t) == 0
    c = bernstein(p.shape[0] - 1, t) @ p
    return c[0] if scalar else c


def elevate_degree(control_points: ArrayLike) -> np.ndarray:
    """Control points of the same curve at degree ``d + 1``: ``Q_i = i/(d+1) P_{i-1} + (1 - i/(d+1)) P_i``."""
    p = _points(control_points, "control_points", min_points=2)
    d = p.shape[0] - 1
    i = np.arange(1, d + 1)[:, None] / (d + 1)
    inner = i * p[:-1] + (1.0 - i) * p[1:]
    return np.vstack([p[0], inner, p[-1]])


# ---------------------------------------------------------------------------------------------------
# fitting (Faraway et al. 2007, Sec. 3.2) and the fit error (Sec. 4, Table 1)
# ---------------------------------------------------------------------------------------------------
def arc_length_parameter(points: ArrayLike) -> np.ndarray:
    """Relative arc length ``s_i = sum_{j<=i} a_j / sum_j a_j``, ``a_j = |Z_j - Z_{j-1}|``
    (Faraway et al. 2007, Sec. 3.2).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The path ``Z_0 .. Z_{n-1}``; at least 2 points and a positive length.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Non-decreasing, from 0 to 1.
    """
    z = _points(points, "points", min_points=2)
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(z, axis=0), axis=1))])
    if cum[-1] == 0.0:
        raise ValueError("points has zero length (all points equal): arc length cannot parameterise it")
    # divide by the running sum's own last value (not a separately rounded total), so repeated points at
    # the end give exactly 1, never 1 + 1 ulp
    return np.minimum(cum / cum[-1], 1.0)


def fit_bezier(points: ArrayLike, degree: int = 3, s: ArrayLike | None = None) -> np.ndarray:
    """Least-squares Bézier fit with the end points fixed to the path's ends (Faraway et al. 2007, Sec. 3.2).

    With the default arc-length parameter the fit recovers a curve's *shape*, not its control points:
    a cubic's parameter is not its arc length, so points sampled on a known cubic give back a curve
    within ~1 mm of it whose control points can differ by centimetres (4 cm for Faraway's 56.7 cm
    reach). Pass the known parameters as ``s`` to recover control points exactly.

    Minimises ``SS = sum_{i=1}^{n-1} |Z_i - C(s_i)|^2`` over the interior control points with
    ``P_0 = Z_0`` and ``P_d = Z_n``. Faraway et al. solve the normal equations ``B^T B P = B^T Y`` with
    ``B_ij = B_j^d(s_i)`` (j = 1 .. d-1) and ``Y_i = Z_i - B_0^d(s_i) Z_0 - B_d^d(s_i) Z_n``; the same
    minimiser is computed here by ``numpy.linalg.lstsq``, which is better conditioned.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The observed path, in time order; ``n >= degree + 1`` and a positive length.
    degree : int
        Curve degree ``d >= 1`` (Faraway et al. choose 3). Degree 1 is the straight line between the ends.
    s : array_like, shape (n,), optional
        Curve parameter of each point, non-decreasing from 0 to 1. Default: the relative arc length
        :func:`arc_length_parameter` (Faraway et al.'s choice). Pass e.g. a Beta CDF of relative time for the
        paper's speed-profile variants, or the known parameters to recover a known curve exactly.

    Returns
    -------
    numpy.ndarray, shape (degree + 1, 3)
        Control points ``P_0 .. P_d``.
    """
    d = _count(degree, "degree", minimum=1)
    z = _points(points, "points", min_points=d + 1)
    if s is None:
        s = arc_length_parameter(z)
    else:
        s = _unit_interval(s, "s")
        if s.shape != (z.shape[0],):
            raise ValueError(f"s must have shape ({z.shape[0]},) (one value per point), got {s.shape}")
        if np.any(np.diff(s) < 0) or s[0] != 0.0 or s[-1] != 1.0:
            raise ValueError("s must be non-decreasing, start at 0 and end at 1")
        if np.all(z == z[0]):
            raise ValueError("points has zero length (all points equal): there is no path to fit")
    p = np.empty((d + 1, 3))
    p[0], p[d] = z[0], z[-1]
    if d == 1:
        return p
    basis = bernstein(d, s[1:-1])
    y = z[1:-1] - np.outer(basis[:, 0], z[0]) - np.outer(basis[:, d], z[-1])
    b = basis[:, 1:d]
    if np.linalg.matrix_rank(b) < d - 1:
        raise ValueError(
            f"the interior points do not determine a degree-{d} curve: need at least {d - 1} interior "
            f"points with distinct parameter values s in (0, 1) (repeated points give repeated s)"
        )
    p[1:d] = np.linalg.lstsq(b, y, rcond=None)[0]
    return p


def fit_error(points: ArrayLike, control_points: ArrayLike, s: ArrayLike | None = None) -> float:
    """Maximum error ``max_i |Z_i - C(s_i)|`` of a fitted curve (Faraway et al. 2007, Sec. 4, the
    Table 1 measure).

    ``s`` defaults to the relative arc length of ``points`` (as in :func:`fit_bezier`).
    """
    z = _points(points, "points", min_points=2)
    s = arc_length_parameter(z) if s is None else _unit_interval(s, "s")
    if s.shape != (z.shape[0],):
        raise ValueError(f"s must have shape ({z.shape[0]},) (one value per point), got {s.shape}")
    return float(np.linalg.norm(z - bezier(control_points, s), axis=1).max())


# ---------------------------------------------------------------------------------------------------
# timing profiles
# ---------------------------------------------------------------------------------------------------
def beta_progress(tau: ArrayLike, alpha: float = FARAWAY_ALPHA, beta: float = FARAWAY_BETA) -> np.ndarray:
    """Relative progress at relative time ``tau``: the Beta(alpha, beta) CDF (Faraway et al. 2007, Sec. 4).

    The relative speed is the Beta density; Faraway's median fit is Beta(1.63, 1.75).
    """
    a, b = _shape_params(alpha, beta)
    return special.betainc(a, b, _unit_interval(tau, "tau"))


def beta_peak_time(alpha: float = FARAWAY_ALPHA, beta: float = FARAWAY_BETA) -> float:
    """Relative time of peak speed: the Beta mode ``(alpha - 1) / (alpha + beta - 2)`` (alpha, beta > 1).

    For Beta(1.63, 1.75) this is 0.457. Faraway et al. report 0.48 as the *median over curves* of each
    curve's peak, which need not equal the mode of the median parameters.
    """
    a, b = _shape_params(alpha, beta)
    if a <= 1.0 or b <= 1.0:
        raise ValueError(f"the speed peak is interior only for alpha > 1 and beta > 1, got {a}, {b}")
    return (a - 1.0) / (a + b - 2.0)


def minimum_jerk_progress(tau: ArrayLike) -> np.ndarray:
    """Flash & Hogan (1985) minimum-jerk progress ``10 t^3 - 15 t^4 + 6 t^5`` (the Beta(3, 3) CDF)."""
    t = _unit_interval(tau, "tau")
    return t**3 * (10.0 - 15.0 * t + 6.0 * t**2)


# ---------------------------------------------------------------------------------------------------
# reference paths
# ---------------------------------------------------------------------------------------------------
def _relative_times(n: int) -> np.ndarray:
    return np.linspace(0.0, 1.0, _count(n, "n"))


def straight_path(start: ArrayLike, end: ArrayLike, n: int, progress: ArrayLike | None = None) -> np.ndarray:
    """Points on the segment start -> end at relative progress ``progress`` (default: even), shape (n, 3)."""
    p0, p3, _ = _reach(start, end)
    f = _relative_times(n) if progress is None else _unit_interval(progress, "progress")
    if f.shape != (n,):
        raise ValueError(f"progress must have shape ({n},), got {f.shape}")
    return p0 + np.outer(f, p3 - p0)


def minimum_jerk_path(start: ArrayLike, end: ArrayLike, n: int) -> np.ndarray:
    """Flash & Hogan (1985) point-to-point path at ``n`` equal time steps, shape (n, 3).

    A straight line with progress ``10 t^3 - 15 t^4 + 6 t^5``: zero velocity and acceleration at both
    ends, peak speed ``1.875 d / T`` at mid time. The via-point variant is not built.
    """
    return straight_path(start, end, n, minimum_jerk_progress(_relative_times(n)))


def body_frame(
    forward: ArrayLike = (1.0, 0.0, 0.0), up: ArrayLike = (0.0, 0.0, 1.0), hand: Hand = "right"
) -> np.ndarray:
    """Rows (lateral, forward, up) of the paper's body frame, in world coordinates, shape (3, 3).

    ``up`` is normalised; ``forward`` is made orthogonal to it (its horizontal part). Lateral points to
    the subject's right for ``hand="right"`` (``forward x up``) and to the left for ``hand="left"``: the
    paper's lateral offsets are then towards the reaching hand's side when positive.
    """
    f, u = _point(forward, "forward"), _point(up, "up")
    nu = float(np.linalg.norm(u))
    if nu == 0.0:
        raise ValueError("up must be a non-zero vector")
    u = u / nu
    f = f - np.dot(f, u) * u
    nf = float(np.linalg.norm(f))
    if nf < 1e-9:
        raise ValueError("forward must not be parallel to up")
    f = f / nf
    if hand not in ("right", "left"):
        raise ValueError(f"hand must be 'right' or 'left', got {hand!r}")
    lateral = np.cross(f, u) if hand == "right" else np.cross(u, f)
    return np.vstack([lateral, f, u])


def faraway_control_points(
    start: ArrayLike,
    end: ArrayLike,
    *,
    forward: ArrayLike = (1.0, 0.0, 0.0),
    up: ArrayLike = (0.0, 0.0, 1.0),
    hand: Hand = "right",
    y1: Sequence[float] = FARAWAY_Y1,
    y2: Sequence[float] = FARAWAY_Y2,
) -> np.ndarray:
    """Control points of Faraway's chosen model, the null axis model with distance scaling, shape (4, 3).

    ``P_0 = start``, ``P_3 = end``, axis points ``A_i = P_0 + (i/3)(P_3 - P_0)`` (Faraway et al. 2007, Sec.
    3.3, Fig. 5) and ``P_i = A_i + d * Y_i`` with ``d = |P_3 - P_0|`` and ``Y_i`` in the body frame of
    :func:`body_frame` (Faraway et al. 2007, Sec. 4; see the module docstring for the axis convention).
    """
    p0, p3, d = _reach(start, end)
    frame = body_frame(forward, up, hand)
    offsets = np.array([_point(y1, "y1"), _point(y2, "y2")]) @ frame  # body -> world
    axis = p0 + np.outer([1.0 / 3.0, 2.0 / 3.0], p3 - p0)
    return np.vstack([p0, axis + d * offsets, p3])


def _arc_length_table(control_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(parameter grid, relative arc length) of a Bézier, tabulated densely by chords."""
    u = np.linspace(0.0, 1.0, _ARC_GRID)
    c = bezier(control_points, u)
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
    return u, cum / cum[-1]


def bezier_at_arc_length(control_points: ArrayLike, fraction: ArrayLike) -> np.ndarray:
    """Points of a Bézier at relative arc length ``fraction`` (in [0, 1]), shape (len(fraction), 3)."""
    p = _points(control_points, "control_points", min_points=2)
    f = _unit_interval(fraction, "fraction")
    if np.all(p == p[0]):
        raise ValueError("control_points describe a zero-length curve")
    u, s = _arc_length_table(p)
    return bezier(p, np.clip(np.interp(f, s, u), 0.0, 1.0))


def faraway_path(
    start: ArrayLike,
    end: ArrayLike,
    n: int,
    *,
    forward: ArrayLike = (1.0, 0.0, 0.0),
    up: ArrayLike = (0.0, 0.0, 1.0),
    hand: Hand = "right",
    alpha: float = FARAWAY_ALPHA,
    beta: float = FARAWAY_BETA,
    progress: Progress = "arc_length",
) -> np.ndarray:
    """Faraway's predicted hand path at ``n`` equal time steps from ``start`` to ``end``, shape (n, 3).

    The curve is :func:`faraway_control_points`; the point at relative time ``tau_k = k / (n - 1)`` is at
    relative arc length ``F(tau_k)`` (``progress="arc_length"``, default) or curve parameter ``F(tau_k)``
    (``progress="parameter"``), ``F`` the Beta(alpha, beta) CDF (Faraway et al. 2007, Sec. 4). Units follow
    the inputs (the model is scale-free).

    Parameters
    ----------
    start, end : array_like, shape (3,)
        Hand position at the start and end of the reach; must differ.
    n : int
        Number of samples, >= 2 (the first is ``start``, the last ``end``).
    forward, up : array_like, shape (3,)
        The subject's forward and vertical directions in world coordinates (default: this package's
        world frame, x forward, z up).
    hand : {"right", "left"}
        Reaching hand; "left" mirrors the lateral offsets.
    alpha, beta : float
        Beta speed-profile shape; (3, 3) gives the minimum-jerk progress.
    progress : {"arc_length", "parameter"}
        What the Beta CDF sets: relative arc length of the curve, or its Bézier parameter.
    """
    p = faraway_control_points(start, end, forward=forward, up=up, hand=hand)
    f = beta_progress(_relative_times(n), alpha, beta)
    if progress == "arc_length":
        return bezier_at_arc_length(p, f)
    if progress == "parameter":
        return bezier(p, f)
    raise ValueError(f"progress must be 'arc_length' or 'parameter', got {progress!r}")


# ---------------------------------------------------------------------------------------------------
# path error
# ---------------------------------------------------------------------------------------------------
def resample(path: ArrayLike, n: int, align: Align = "arc_length") -> np.ndarray:
    """``path`` resampled to ``n`` points at equal relative arc length or equal relative time, (n, 3).

    ``align="time"`` assumes the rows of ``path`` are equally spaced in time and interpolates linearly
    between them; ``"arc_length"`` interpolates along the polyline at equal fractions of its length.
    """
    z = _points(path, "path", min_points=2)
    n = _count(n, "n")
    if align == "arc_length":
        x = arc_length_parameter(z)
    elif align == "time":
        x = np.linspace(0.0, 1.0, z.shape[0])
    else:
        raise ValueError(f"align must be 'arc_length' or 'time', got {align!r}")
    q = np.linspace(0.0, 1.0, n)
    return np.column_stack([np.interp(q, x, z[:, k]) for k in range(3)])


def path_distance(
    a: ArrayLike,
    b: ArrayLike,
    *,
    align: Align = "arc_length",
    reduce: Reduce = "mean",
    n: int = 201,
) -> float:
    """Distance between two paths compared point by point at equal relative arc length (or time).

    Both are resampled by :func:`resample` to ``n`` points and the Euclidean distances are averaged
    (``reduce="mean"``) or maximised (``"max"``). ``align="time", reduce="max"`` is Faraway et al.'s
    prediction and replicate error ("maximum distance ... over relative time", Sec. 4); its tables
    report the median of this over reaches. Symmetric in ``a`` and ``b``; 0 for identical paths.
    """
    ra, rb = resample(a, n, align), resample(b, n, align)
    dist = np.linalg.norm(ra - rb, axis=1)
    if reduce == "mean":
        return float(dist.mean())
    if reduce == "max":
        return float(dist.max())
    raise ValueError(f"reduce must be 'mean' or 'max', got {reduce!r}")


# ---------------------------------------------------------------------------------------------------
# realism measures of a recorded hand path
# ---------------------------------------------------------------------------------------------------
def peak_speed(path: ArrayLike, dt: float) -> tuple[float, float]:
    """(peak tangential speed, its relative time) of a path sampled every ``dt`` seconds.

    Speed per step ``|p[k+1] - p[k]| / dt``, as in :func:`visuomotor_gym.metrics.hand.hand_speed`; the
    relative time is the step's midpoint over the path's duration.
    """
    z = _points(path, "path", min_points=2)
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite time step > 0 (seconds), got {dt!r}")
    v = np.linalg.norm(np.diff(z, axis=0), axis=1) / dt
    k = int(np.argmax(v))
    return float(v[k]), (k + 0.5) / (z.shape[0] - 1)


@dataclass(frozen=True)
class HandPathRealism:
    """Measures of one reach against Faraway's predicted path (lengths in the path's units, e.g. m).

    Attributes
    ----------
    reach_length : float
        ``|end - start|``.
    faraway_max, faraway_mean : float
        Max / mean distance to :func:`faraway_path` between the same ends, at equal relative arc length.
    straight_max : float
        Max distance to the straight segment at equal relative arc length.
    faraway_max_at_median_reach : float
        ``faraway_max`` scaled to Faraway et al.'s median 56.7 cm reach (``* 0.567 m / reach_length``, with
        lengths in metres), comparable with the paper's cm figures.
    curvature_index : float
        Least-squares coefficient ``k`` of the path's deviation from the straight segment on the Faraway
        path's deviation (both at equal relative arc length): 0 = straight, 1 = Faraway's mean curvature.
    peak_speed : float
        Peak tangential speed (units per second); NaN when ``dt`` was not given.
    peak_time : float
        Relative time of the peak speed (Faraway: Beta mode 0.457); NaN when ``dt`` was not given.
    """

    reach_length: float
    faraway_max: float
    faraway_mean: float
    straight_max: float
    faraway_max_at_median_reach: float
    curvature_index: float
    peak_speed: float
    peak_time: float


def hand_path_realism(
    path: ArrayLike,
    dt: float | None = None,
    *,
    forward: ArrayLike = (1.0, 0.0, 0.0),
    up: ArrayLike = (0.0, 0.0, 1.0),
    hand: Hand = "right",
    n: int = 201,
) -> HandPathRealism:
    """Spatial realism measures of a recorded reach from ``path[0]`` to ``path[-1]`` (lengths in metres).

    The comparison is spatial (equal relative arc length), as Faraway et al. (2007, Sec. 5) weigh spatial
    error above timing; the timing enters only through ``peak_speed``/``peak_time``. Reading: Faraway et al.'s
    8.0 cm (chosen model) and 12.6 cm (Flash-Hogan) are errors *against human reaches*, not distances to the
    model's path - a straight reach of 56.7 cm is only ~6 cm from Faraway's path. Use
    ``curvature_index`` (and ``faraway_max`` over many reaches) to tell straight from human-like paths;
    ``docs/reproductions/faraway.md`` gives their spread on synthetic human-like reaches.
    """
    z = _points(path, "path", min_points=2)
    p0, p3, d = _reach(z[0], z[-1])
    pred = faraway_path(p0, p3, n, forward=forward, up=up, hand=hand)
    line = straight_path(p0, p3, n)
    rz, rf = resample(z, n), resample(pred, n)
    dev, dev_f = rz - line, rf - line
    if dt is None:
        vmax, tpeak = float("nan"), float("nan")
    else:
        vmax, tpeak = peak_speed(z, dt)
    far_max = float(np.linalg.norm(rz - rf, axis=1).max())
    return HandPathRealism(
        reach_length=d,
        faraway_max=far_max,
        faraway_mean=float(np.linalg.norm(rz - rf, axis=1).mean()),
        straight_max=float(np.linalg.norm(dev, axis=1).max()),
        faraway_max_at_median_reach=far_max * FARAWAY_MEDIAN_REACH_M / d,
        curvature_index=float(np.sum(dev * dev_f) / np.sum(dev_f * dev_f)),
        peak_speed=vmax,
        peak_time=tpeak,
    )
