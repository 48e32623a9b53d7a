"""Tests of visuomotor_gym.handpath against independent oracles and Faraway et al.'s (2007) printed numbers.

Oracles: ``scipy.interpolate.BPoly`` (an independent Bernstein-polynomial evaluator), a generic
nonlinear least-squares solver (``scipy.optimize.least_squares``) for the fit, ``scipy.stats.beta`` for the
timing profiles, hand-computed control points for Faraway's model, and the centimetre offsets that
Faraway, Reed & Wang (2007, Sec. 4) print for its median 56.7 cm reach.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import interpolate, optimize, stats

from visuomotor_gym import handpath as H

RNG_SEED = 20070402


def bpoly_curve(control_points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Bézier points evaluated by scipy's Bernstein-polynomial class (an independent implementation)."""
    return interpolate.BPoly(control_points[:, None, :], [0.0, 1.0])(t)


def random_controls(rng: np.random.Generator, degree: int) -> np.ndarray:
    return rng.normal(scale=0.3, size=(degree + 1, 3))


# ---------------------------------------------------------------------------------------------------
# Bézier evaluation
# ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 6])
def test_bezier_matches_scipy_bpoly(degree):
    rng = np.random.default_rng(RNG_SEED + degree)
    p = random_controls(rng, degree)
    t = np.linspace(0.0, 1.0, 37)
    np.testing.assert_allclose(H.bezier(p, t), bpoly_curve(p, t), atol=1e-12)
    np.testing.assert_allclose(H.bezier(p, 0.3), bpoly_curve(p, np.array([0.3]))[0], atol=1e-12)
    np.testing.assert_allclose(H.bernstein(degree, t).sum(axis=1), 1.0, atol=1e-12)


def test_bezier_end_points_are_first_and_last_control_points():
    p = random_controls(np.random.default_rng(RNG_SEED), 3)
    np.testing.assert_allclose(H.bezier(p, 0.0), p[0], atol=1e-15)
    np.testing.assert_allclose(H.bezier(p, 1.0), p[-1], atol=1e-15)


def test_degree_elevation_keeps_the_curve():
    p = random_controls(np.random.default_rng(RNG_SEED), 3)
    t = np.linspace(0.0, 1.0, 50)
    q = H.elevate_degree(p)
    assert q.shape == (5, 3)
    np.testing.assert_allclose(H.bezier(q, t), H.bezier(p, t), atol=1e-12)


# ---------------------------------------------------------------------------------------------------
# fitting (Faraway et al. 2007, Sec. 3.2)
# ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_fit_recovers_known_control_points_given_their_parameters(degree):
    rng = np.random.default_rng(RNG_SEED + 10 * degree)
    p = random_controls(rng, degree)
    s = np.r_[0.0, np.sort(rng.uniform(size=30)), 1.0]  # uneven sampling
    z = H.bezier(p, s)
    np.testing.assert_allclose(H.fit_bezier(z, degree, s=s), p, atol=1e-10)


def test_arc_length_fit_is_exact_on_a_uniformly_parameterised_line():
    # collinear, evenly spaced control points: the parameter is proportional to arc length
    p = np.outer(np.linspace(0.0, 1.0, 4), [0.2, -0.3, 0.4]) + [0.1, 0.0, 1.0]
    s = np.r_[0.0, np.sort(np.random.default_rng(RNG_SEED).uniform(size=20)), 1.0]
    np.testing.assert_allclose(H.fit_bezier(H.bezier(p, s)), p, atol=1e-12)


def test_arc_length_parameter_is_relative_cumulative_chord_length():
    z = np.array([[0.0, 0, 0], [3.0, 0, 0], [3.0, 4.0, 0], [3.0, 4.0, 3.0]])
    np.testing.assert_allclose(H.arc_length_parameter(z), [0.0, 0.3, 0.7, 1.0])


def test_a_path_that_rests_at_its_end_still_fits():
    # A hand at rest for the last samples repeats its end point; s must stay within [0, 1] exactly.
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(200):
        z = np.cumsum(rng.uniform(0.0, 0.1, size=(20, 3)) * [0.1, 0.7, 0.3], axis=0)
        z = np.vstack([z, np.repeat(z[-1:], 4, axis=0)])
        s = H.arc_length_parameter(z)
        assert s.max() == 1.0 and np.all(s[-5:] == 1.0)
        H.fit_bezier(z, 3)


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_fit_is_the_least_squares_minimiser(degree):
    # Oracle: a generic nonlinear least-squares solver on SS = sum_i |Z_i - C(s_i)|^2 (Faraway et al. 2007,
    # Sec. 3.2), with the curve evaluated by scipy's BPoly and the end control points pinned to the
    # data's ends.
    rng = np.random.default_rng(RNG_SEED + degree)
    z = np.cumsum(rng.normal(size=(40, 3)), axis=0)
    s = H.arc_length_parameter(z)

    def residuals(x: np.ndarray) -> np.ndarray:
        p = np.vstack([z[0], x.reshape(degree - 1, 3), z[-1]])
        return (bpoly_curve(p, s[1:-1]) - z[1:-1]).ravel()

    oracle = optimize.least_squares(residuals, np.zeros(3 * (degree - 1)), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    p = H.fit_bezier(z, degree)
    np.testing.assert_allclose(p[0], z[0])
    np.testing.assert_allclose(p[-1], z[-1])
    np.testing.assert_allclose(p[1:-1].ravel(), oracle.x, atol=1e-6)  # path scale ~1-5 units
    # Faraway et al.'s normal equations B^T B P = B^T Y hold at the solution
    basis = H.bernstein(degree, s[1:-1])
    y = z[1:-1] - np.outer(basis[:, 0], z[0]) - np.outer(basis[:, -1], z[-1])
    b = basis[:, 1:-1]
    np.testing.assert_allclose(b.T @ b @ p[1:-1], b.T @ y, atol=1e-8 * np.abs(b.T @ y).max())


def test_fit_also_matches_numpy_lstsq_on_the_full_design():
    # A second oracle: unconstrained lstsq over all control points, with the ends pinned by huge weights.
    rng = np.random.default_rng(RNG_SEED)
    z = np.cumsum(rng.normal(size=(25, 3)), axis=0)
    s = H.arc_length_parameter(z)
    w = np.r_[1e7, np.ones(23), 1e7][:, None]
    full = np.linalg.lstsq(w * H.bernstein(3, s), w * z, rcond=None)[0]
    np.testing.assert_allclose(H.fit_bezier(z, 3), full, atol=1e-6)


def test_fit_is_robust_to_uneven_sampling():
    # The same Faraway reach sampled at even, Beta-timed and random instants gives the same fit.
    p0, p3 = np.zeros(3), np.array([0.25, -0.45, 0.2])
    ctrl = H.faraway_control_points(p0, p3)
    rng = np.random.default_rng(RNG_SEED)
    samplings = {
        "even": np.linspace(0.0, 1.0, 50),
        "beta": H.beta_progress(np.linspace(0.0, 1.0, 50)),
        "random": np.r_[0.0, np.sort(rng.uniform(size=48)), 1.0],
        "front-loaded": np.linspace(0.0, 1.0, 50) ** 2,
    }
    fits = {k: H.fit_bezier(H.bezier(ctrl, u)) for k, u in samplings.items()}
    dense = np.linspace(0.0, 1.0, 400)
    for k, f in fits.items():
        # control points agree within 1.5 mm (what is left: denser samples weigh more in the sum)
        assert np.abs(f - fits["even"]).max() < 1.5e-3, k
        # and the fitted curve is the known curve's shape (spatially, within 2 mm)
        assert H.path_distance(H.bezier(f, dense), H.bezier(ctrl, dense), reduce="max") < 2e-3, k
    # evenly spaced parameters (s_i = i / n, which Faraway et al. reject) are not robust: centimetres apart
    even_s = np.linspace(0.0, 1.0, 50)
    fit_even_s = {k: H.fit_bezier(H.bezier(ctrl, u), s=even_s) for k, u in samplings.items()}
    assert np.abs(fit_even_s["front-loaded"] - fit_even_s["even"]).max() > 0.05


def test_fit_error_of_a_known_fit():
    z = np.array([[0.0, 0, 0], [1.0, 1.0, 0], [2.0, 0, 0]])  # the line fit misses the middle point by 1
    p = H.fit_bezier(z, degree=1)
    assert H.fit_error(z, p) == pytest.approx(1.0)


def test_cubic_fit_beats_linear_on_a_curved_path():
    p = np.array([[0.0, 0, 0], [0.1, -0.1, 0.1], [0.3, -0.1, 0.0], [0.4, 0.0, 0.0]])
    z = H.bezier(p, np.linspace(0, 1, 30))
    e1 = H.fit_error(z, H.fit_bezier(z, 1))
    e3 = H.fit_error(z, H.fit_bezier(z, 3))
    assert e3 < 0.1 * e1


# ---------------------------------------------------------------------------------------------------
# timing
# ---------------------------------------------------------------------------------------------------
def test_beta_progress_is_the_scipy_beta_cdf():
    t = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(H.beta_progress(t), stats.beta(1.63, 1.75).cdf(t), atol=1e-12)
    np.testing.assert_allclose(H.beta_progress(t, 2.5, 4.0), stats.beta(2.5, 4.0).cdf(t), atol=1e-12)


def test_beta_peak_time():
    t = np.linspace(0.0, 1.0, 200001)
    numeric = t[np.argmax(stats.beta(1.63, 1.75).pdf(t))]
    peak = H.beta_peak_time(1.63, 1.75)
    assert peak == pytest.approx(numeric, abs=1e-5)
    assert peak == pytest.approx(0.63 / 1.38)
    # Faraway et al. report 0.48 (the median of per-curve peaks); the median-parameter mode is 0.457
    assert abs(peak - 0.48) < 0.03 and peak < 0.5


def test_faraway_path_speed_peaks_at_the_beta_mode():
    path = H.faraway_path(np.zeros(3), np.array([0.3, -0.4, 0.25]), 1001)
    _, t_peak = H.peak_speed(path, 1e-3)
    assert t_peak == pytest.approx(H.beta_peak_time(), abs=2e-3)


def test_minimum_jerk_progress_closed_form_is_the_beta33_cdf():
    t = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(H.minimum_jerk_progress(t), 10 * t**3 - 15 * t**4 + 6 * t**5, atol=1e-14)
    np.testing.assert_allclose(H.minimum_jerk_progress(t), stats.beta(3, 3).cdf(t), atol=1e-12)
    # not Beta(2, 2), as Faraway et al. (2007, Sec. 4) say
    assert np.abs(stats.beta(2, 2).cdf(t) - H.minimum_jerk_progress(t)).max() > 0.05


def test_minimum_jerk_path_is_straight_with_bell_speed():
    start, end = np.array([0.1, 0.2, 0.9]), np.array([0.5, -0.1, 1.2])
    n, duration = 2001, 1.0
    path = H.minimum_jerk_path(start, end, n)
    dist = np.linalg.norm(end - start)
    # straight: every point on the segment
    along = (path - start) @ (end - start) / dist**2
    np.testing.assert_allclose(path, start + np.outer(along, end - start), atol=1e-14)
    vmax, t_peak = H.peak_speed(path, duration / (n - 1))
    assert vmax == pytest.approx(1.875 * dist / duration, rel=1e-5)
    assert t_peak == pytest.approx(0.5, abs=1e-3)
    # zero velocity and acceleration at both ends: first differences vanish to O(dt^3)
    v = np.diff(path, axis=0) / (duration / (n - 1))
    assert np.linalg.norm(v[0]) < 1e-5 and np.linalg.norm(v[-1]) < 1e-5


# ---------------------------------------------------------------------------------------------------
# Faraway's chosen model (Faraway et al. 2007, Sec. 4)
# ---------------------------------------------------------------------------------------------------
def test_faraway_offsets_reproduce_the_papers_centimetres():
    # Faraway et al. (2007): "For the median reach distance of 56.7 cm, this gives offsets of (-1.4, -8.4,
    # 4.3) cm and (-0.8, -7.9, -0.1) cm." The printed means have 3 decimals (+-0.0005 * 56.7 = 0.03 cm) and
    # the cm values 1 decimal (+-0.05 cm), so agreement within 0.08 cm is all the print allows.
    start = np.array([0.1, -0.2, 1.0])
    direction = np.array([0.6, -0.5, -0.2])
    end = start + 0.567 * direction / np.linalg.norm(direction)
    p = H.faraway_control_points(start, end)
    axis = start + np.outer([1 / 3, 2 / 3], end - start)
    body = (p[1:3] - axis) @ H.body_frame().T * 100.0  # cm, rows (lateral, forward, up)
    np.testing.assert_allclose(body[0], [-1.4, -8.4, 4.3], atol=0.08)
    np.testing.assert_allclose(body[1], [-0.8, -7.9, -0.1], atol=0.08)


def test_faraway_control_points_hand_computed():
    # Reach of 0.567 m straight forward (+x) in the world frame (x forward, y left, z up). Lateral is
    # the subject's right = -y, so the paper's lateral -0.025 d is +0.014175 m in y.
    p = H.faraway_control_points(np.zeros(3), np.array([0.567, 0.0, 0.0]))
    expected = [
        [0.0, 0.0, 0.0],
        [0.189 - 0.083916, 0.014175, 0.043659],
        [0.378 - 0.078813, 0.008505, -0.001134],
        [0.567, 0.0, 0.0],
    ]
    np.testing.assert_allclose(p, expected, atol=1e-12)
    left = H.faraway_control_points(np.zeros(3), np.array([0.567, 0.0, 0.0]), hand="left")
    np.testing.assert_allclose(left[:, 1], -p[:, 1], atol=1e-15)
    np.testing.assert_allclose(left[:, [0, 2]], p[:, [0, 2]], atol=1e-15)


def test_body_frame_is_right_handed_for_the_right_hand():
    f = H.body_frame()
    np.testing.assert_allclose(f, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    assert np.linalg.det(f) == pytest.approx(1.0)


def test_faraway_path_ends_timing_and_scale():
    start, end = np.array([0.2, -0.1, 1.0]), np.array([0.5, -0.5, 1.3])
    path = H.faraway_path(start, end, 51)
    assert path.shape == (51, 3)
    np.testing.assert_allclose(path[0], start, atol=1e-12)
    np.testing.assert_allclose(path[-1], end, atol=1e-12)
    # relative arc length at equal time steps follows the Beta CDF
    s = H.arc_length_parameter(H.faraway_path(start, end, 2001))[::40]
    np.testing.assert_allclose(s, H.beta_progress(np.linspace(0, 1, 51)), atol=2e-4)
    # the "parameter" timing puts the curve parameter, not the arc length, on the Beta CDF
    ctrl = H.faraway_control_points(start, end)
    np.testing.assert_allclose(
        H.faraway_path(start, end, 51, progress="parameter"),
        H.bezier(ctrl, H.beta_progress(np.linspace(0, 1, 51))),
    )
    # scale-free: doubling the reach doubles the path about the start
    np.testing.assert_allclose(
        H.faraway_path(start, start + 2 * (end - start), 51) - start, 2 * (path - start), atol=1e-9
    )


def test_faraway_path_rotates_with_the_body():
    # A body turned 90 deg to the left (forward = +y) gives the rotated path.
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    start, end = np.array([0.1, 0.0, 1.0]), np.array([0.5, -0.3, 0.8])
    base = H.faraway_path(start, end, 31)
    turned = H.faraway_path(rot @ start, rot @ end, 31, forward=rot @ [1.0, 0.0, 0.0])
    np.testing.assert_allclose(turned, base @ rot.T, atol=1e-9)


# ---------------------------------------------------------------------------------------------------
# path error and realism
# ---------------------------------------------------------------------------------------------------
def test_path_distance_identity_symmetry_and_known_value():
    rng = np.random.default_rng(RNG_SEED)
    a = np.cumsum(rng.normal(size=(40, 3)), axis=0)
    b = np.cumsum(rng.normal(size=(25, 3)), axis=0)
    for align in ("arc_length", "time"):
        for reduce in ("mean", "max"):
            assert H.path_distance(a, a, align=align, reduce=reduce) == 0.0
            assert H.path_distance(a, b, align=align, reduce=reduce) == H.path_distance(
                b, a, align=align, reduce=reduce
            )
    line = H.straight_path(np.zeros(3), np.array([0.5, 0.0, 0.0]), 11)
    shifted = line + [0.0, 0.05, 0.0]
    assert H.path_distance(line, shifted) == pytest.approx(0.05)
    assert H.path_distance(line, shifted, reduce="max") == pytest.approx(0.05)
    # growing gap f^2 at relative time f on 201 points: mean = (2N + 1) / (6N) with N = 200, max = 1
    f = np.linspace(0.0, 1.0, 201)
    a_line = np.column_stack([f, 0 * f, 0 * f])
    b_line = np.column_stack([f, 0 * f, f**2])
    assert H.path_distance(a_line, b_line, align="time") == pytest.approx(401 / 1200)
    assert H.path_distance(a_line, b_line, align="time", reduce="max") == pytest.approx(1.0)


def test_path_distance_arc_length_ignores_timing_and_time_does_not():
    start, end = np.zeros(3), np.array([0.3, 0.2, 0.1])
    even, jerk = H.straight_path(start, end, 101), H.minimum_jerk_path(start, end, 101)
    assert H.path_distance(even, jerk) < 1e-12
    assert H.path_distance(even, jerk, align="time", reduce="max") > 0.05 * np.linalg.norm(end - start)


def test_realism_of_the_model_path_and_of_a_straight_reach():
    start, end = np.zeros(3), np.array([0.3, -0.4, 0.25])
    model = H.hand_path_realism(H.faraway_path(start, end, 301), dt=0.005)
    assert model.faraway_max < 1e-4
    assert model.curvature_index == pytest.approx(1.0, abs=1e-3)
    assert model.peak_time == pytest.approx(H.beta_peak_time(), abs=5e-3)
    straight = H.hand_path_realism(H.minimum_jerk_path(start, end, 301), dt=0.005)
    assert straight.curvature_index == pytest.approx(0.0, abs=1e-9)
    assert straight.faraway_max == pytest.approx(
        H.path_distance(H.minimum_jerk_path(start, end, 301), H.faraway_path(start, end, 301), reduce="max"),
        rel=1e-3,
    )
    d = np.linalg.norm(end)
    assert straight.faraway_max_at_median_reach == pytest.approx(straight.faraway_max * 0.567 / d)
    assert straight.peak_speed == pytest.approx(1.875 * d / 1.5, rel=1e-3)  # 300 steps of 5 ms
    assert np.isnan(H.hand_path_realism(H.faraway_path(start, end, 31)).peak_speed)


# ---------------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------------
GOOD = np.array([[0.0, 0, 0], [0.1, 0.1, 0], [0.2, 0.1, 0.1], [0.3, 0, 0.1], [0.4, 0, 0]])


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: H.fit_bezier(GOOD[:, :2]), r"points must have shape \(n, 3\)"),
        (lambda: H.fit_bezier(GOOD.ravel()), r"points must have shape \(n, 3\)"),
        (lambda: H.fit_bezier(np.where(GOOD == 0.3, np.nan, GOOD)), "points must be finite"),
        (lambda: H.fit_bezier(GOOD[:3], degree=3), "points needs at least 4 points"),
        (lambda: H.fit_bezier(np.ones((6, 3))), "zero length"),
        (lambda: H.fit_bezier(GOOD, degree=0), "degree must be an integer >= 1"),
        (lambda: H.fit_bezier(GOOD, degree=2.5), "degree must be an integer >= 1"),
        (lambda: H.fit_bezier(GOOD, s=[0, 0.5, 1]), r"s must have shape \(5,\)"),
        (lambda: H.fit_bezier(GOOD, s=[0, 0.6, 0.5, 0.7, 1]), "s must be non-decreasing"),
        (
            lambda: H.fit_bezier(np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]])),
            "do not determine",
        ),
        (lambda: H.bezier(GOOD, 1.5), r"t must lie in \[0, 1\]"),
        (lambda: H.bezier(GOOD[:1], 0.5), "control_points needs at least 2 points"),
        (lambda: H.faraway_path([0, 0, 0], [0, 0, 0], 10), "start and end coincide"),
        (lambda: H.faraway_path([0, 0], [1, 0, 0], 10), r"start must be one 3-D point"),
        (lambda: H.faraway_path([0, 0, np.nan], [1, 0, 0], 10), "start must be finite"),
        (lambda: H.faraway_path([0, 0, 0], [1, 0, 0], 1), "n must be an integer >= 2"),
        (lambda: H.faraway_path([0, 0, 0], [1, 0, 0], 10, hand="both"), "hand must be 'right' or 'left'"),
        (lambda: H.faraway_path([0, 0, 0], [1, 0, 0], 10, progress="time"), "progress must be"),
        (
            lambda: H.faraway_path([0, 0, 0], [1, 0, 0], 10, alpha=-1.0),
            "alpha and beta must be finite and > 0",
        ),
        (
            lambda: H.faraway_path([0, 0, 0], [1, 0, 0], 10, forward=[0, 0, 2]),
            "forward must not be parallel to up",
        ),
        (lambda: H.path_distance(GOOD, GOOD, align="index"), "align must be"),
        (lambda: H.path_distance(GOOD, GOOD, reduce="median"), "reduce must be"),
        (lambda: H.path_distance(GOOD, np.ones((4, 3))), "zero length"),
        (lambda: H.peak_speed(GOOD, 0.0), "dt must be a finite time step > 0"),
        (lambda: H.beta_peak_time(0.9, 2.0), "alpha > 1 and beta > 1"),
        (lambda: H.hand_path_realism(np.vstack([GOOD, GOOD[:1]])), "start and end coincide"),
    ],
)
def test_bad_input_is_refused_with_the_argument_named(call, match):
    with pytest.raises(ValueError, match=match):
        call()
