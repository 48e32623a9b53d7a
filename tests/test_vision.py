"""Tests of the foveated vision noise model (Eyecatch section 3.1, Eq. 1-3) and of what the
EyeCatch environments let the agent see.

Oracles: closed forms written out here from the model's stated constants (1 arcmin lateral
resolution, 5 % depth, Weber 5 % + 0.2 deg/s, E2 = 2 deg, +-60 deg field of view), an orthonormal
line-of-sight basis built independently of the package, and Monte-Carlo statistics of ``sample``.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the environment ids)
from visuomotor_gym.vision import foveation as fov
from visuomotor_gym.vision.foveation import VisionParams

# EyeCatch-v0's eye without the human periphery (the cone field, the acuity law, no crowding, depth law or
# disarray): the closed forms below are those of that eye.
PLAIN_EYE = {"field_shape": "cone", "position_e2_deg": None, "crowding": False, "depth_pedestal_arcmin": None,
             "position_disarray": 0.0, "angular_lateral_noise": False}

DEG = math.pi / 180.0
ARCMIN_RAD = DEG / 60.0  # 2.909e-4 rad
E2 = 2.0 * DEG
FOV_HALF = 60.0 * DEG
SEAT_ORIGIN = np.array([0.0, 0.0, 0.5])


# ------------------------------------------------------------------------------------------------
# Helpers (independent of the package)
# ------------------------------------------------------------------------------------------------
def unit_at(ecc_rad: float, phi_rad: float) -> np.ndarray:
    """Unit vector at angle ``ecc_rad`` from +x, rotated by ``phi_rad`` about +x."""
    return np.array(
        [math.cos(ecc_rad), math.sin(ecc_rad) * math.cos(phi_rad), math.sin(ecc_rad) * math.sin(phi_rad)]
    )


def own_basis(u: np.ndarray) -> np.ndarray:
    """Columns (u, e2, e3): an orthonormal right-handed basis with first axis u (Gram-Schmidt)."""
    u = u / np.linalg.norm(u)
    helper = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e2 = helper - (helper @ u) * u
    e2 /= np.linalg.norm(e2)
    e3 = np.cross(u, e2)
    return np.column_stack([u, e2, e3])


KNEE = 2.5 * DEG  # rad/s: foveal acuity unchanged by image motion up to 2.5 deg/s (Westheimer & McKee 1975)


def expected_stds(d, ecc, retinal_speed, *, scale=1.0, foveated=True, knee=KNEE):
    """Closed-form diagonal of Sigma: (depth, lat, lat, depth rate, lat rate, lat rate).

    The lateral position std grows with the retinal slip above the knee, x max(1, |slip| / knee)
    (foveated eye only; ``knee=math.inf``: the paper's static acuity)."""
    k = scale * ((E2 + ecc) / E2 if foveated else 1.0)
    lat = d * ARCMIN_RAD * (max(1.0, abs(retinal_speed) / knee) if foveated else 1.0)
    lat_rate = d * (0.05 * abs(retinal_speed) + 0.2 * DEG)
    return k * np.array([0.05 * d, lat, lat, 0.1 * d, lat_rate, lat_rate])


def sample(pos, vel, retinal_speed, params, rng):
    """One perceived (position, velocity) of a point the eye sees (inside the field of view)."""
    p, v, visible = fov.perceive(list(map(float, pos)), list(map(float, vel)), retinal_speed, params, rng)
    assert visible, "the test point must be inside the field of view"
    return np.array(p), np.array(v)


def draw(pos, vel, retinal_speed, params, n, seed):
    rng = np.random.default_rng(seed)
    out = np.empty((n, 6))
    for i in range(n):
        p, v = sample(pos, vel, retinal_speed, params, rng)
        out[i, :3] = p
        out[i, 3:] = v
    return out


def blockdiag(r):
    a = np.zeros((6, 6))
    a[:3, :3] = r
    a[3:, 3:] = r
    return a


# ------------------------------------------------------------------------------------------------
# line_of_sight_rotation (Eq. 3)
# ------------------------------------------------------------------------------------------------
def _direction_cases():
    rng = np.random.default_rng(20240601)
    cases = [np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, -1.0])]
    v = rng.standard_normal((300, 3))
    cases += list(v / np.linalg.norm(v, axis=1, keepdims=True))
    for ecc in (1e-12, 1e-9, 1e-6, 1e-3, 0.1):  # near the visual axis
        for phi in rng.uniform(0, 2 * math.pi, 4):
            cases.append(unit_at(ecc, phi))
    for gap in (0.3, 1e-2, 1e-3):  # near-behind (well conditioned)
        for phi in rng.uniform(0, 2 * math.pi, 4):
            cases.append(unit_at(math.pi - gap, phi))
    return cases


def test_line_of_sight_rotation_is_proper_rotation_onto_u():
    for u in _direction_cases():
        r = fov.line_of_sight_rotation(u)
        assert r.shape == (3, 3)
        np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-9, err_msg=f"u={u}")
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-9)
        np.testing.assert_allclose(r @ np.array([1.0, 0.0, 0.0]), u, atol=1e-12, err_msg=f"u={u}")


def test_line_of_sight_rotation_is_the_minimal_rotation_exp_w_theta():
    """Eq. 3: axis w = x_hat x u (fixed by R), angle theta = angle(x_hat, u) (trace 1 + 2 cos)."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        ecc = rng.uniform(1e-3, math.pi - 1e-2)
        u = unit_at(ecc, rng.uniform(0, 2 * math.pi))
        r = fov.line_of_sight_rotation(u)
        w = np.cross([1.0, 0.0, 0.0], u)
        w /= np.linalg.norm(w)
        np.testing.assert_allclose(r @ w, w, atol=1e-10)
        assert np.trace(r) == pytest.approx(1.0 + 2.0 * math.cos(ecc), abs=1e-10)


def test_line_of_sight_rotation_exactly_and_almost_exactly_behind():
    r = fov.line_of_sight_rotation(np.array([-1.0, 0.0, 0.0]))
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-15)
    assert np.linalg.det(r) == pytest.approx(1.0)
    np.testing.assert_allclose(r[:, 0], [-1.0, 0.0, 0.0], atol=1e-15)
    # Within ~1e-6 rad of straight behind the Rodrigues formula is ill-conditioned (1 / (1 + c));
    # the result must still be a rotation (to 1e-4) that maps x within the input's own angle.
    rng = np.random.default_rng(3)
    for gap in (1e-5, 3e-6, 1.5e-6, 1e-7):
        for phi in rng.uniform(0, 2 * math.pi, 20):
            u = unit_at(math.pi - gap, phi)
            r = fov.line_of_sight_rotation(u)
            np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-4)
            assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-4)
            np.testing.assert_allclose(r[:, 0], u, atol=2 * gap)


# ------------------------------------------------------------------------------------------------
# Closed-form standard deviations (Eq. 2) and covariance (Eq. 1)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("d", [0.5, 1.0, 3.0, 6.0])
def test_foveal_standard_deviations_closed_form(d):
    p = VisionParams()
    sig = fov.standard_deviations(d, 0.0, 0.0, p)
    assert sig[1] == pytest.approx(d * 2.908882e-4, rel=1e-6)  # 1 arcmin, small angle
    assert sig[2] == pytest.approx(d * 2.908882e-4, rel=1e-6)
    assert sig[0] == pytest.approx(0.05 * d, rel=1e-12)  # depth: 5 % of depth
    assert sig[3] == pytest.approx(0.1 * d, rel=1e-12)  # depth rate: 0.1/s * depth
    assert sig[4] == pytest.approx(d * 0.2 * DEG, rel=1e-12)  # velocity floor, zero slip
    np.testing.assert_allclose(sig, expected_stds(d, 0.0, 0.0), rtol=1e-12)


@pytest.mark.parametrize("ecc_deg", [0.0, 1.0, 2.0, 5.0, 20.0, 45.0, 59.0])
@pytest.mark.parametrize("d", [1.0, 4.0])
def test_eccentricity_scaling_closed_form(ecc_deg, d):
    p = VisionParams()
    ecc = ecc_deg * DEG
    foveal = fov.standard_deviations(d, 0.0, 0.3, p)
    sig = fov.standard_deviations(d, ecc, 0.3, p)
    factor = (2.0 + ecc_deg) / 2.0
    np.testing.assert_allclose(sig, foveal * factor, rtol=1e-12)
    np.testing.assert_allclose(sig, expected_stds(d, ecc, 0.3), rtol=1e-12)
    assert fov.acuity(ecc, p) == pytest.approx(2.0 / (2.0 + ecc_deg), rel=1e-12)
    if ecc_deg == 2.0:
        assert fov.acuity(ecc, p) == pytest.approx(0.5)  # acuity halves at E2


@pytest.mark.parametrize("retinal_speed", [0.0, 0.1, 1.0, 5.0, -2.0])
def test_velocity_lateral_std_weber_plus_floor(retinal_speed):
    p = VisionParams()
    d = 2.5
    sig = fov.standard_deviations(d, 0.0, retinal_speed, p)
    want = d * (0.05 * abs(retinal_speed) + 0.2 * DEG)
    assert sig[4] == pytest.approx(want, rel=1e-12)
    assert sig[5] == pytest.approx(want, rel=1e-12)
    # the depth terms do not depend on the retinal speed (the lateral position does: see the slip tests)
    np.testing.assert_allclose(sig[[0, 3]], fov.standard_deviations(d, 0.0, 0.0, p)[[0, 3]])


# ------------------------------------------------------------------------------------------------
# Moving-target localisation: lateral position std x max(1, slip / knee)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("slip_deg_s", [0.0, 1.0, 2.5, 2.6, 5.0, 25.0, 100.0, -40.0])
@pytest.mark.parametrize("ecc_deg", [0.0, 10.0])
def test_lateral_position_std_grows_with_retinal_slip(slip_deg_s, ecc_deg):
    p = VisionParams()
    assert p.position_slip_knee_deg_s == 2.5
    d, ecc, slip = 3.0, ecc_deg * DEG, slip_deg_s * DEG
    sig = fov.standard_deviations(d, ecc, slip, p)
    growth = max(1.0, abs(slip_deg_s) / 2.5)
    alpha = E2 / (E2 + ecc)
    assert sig[1] == pytest.approx(d * ARCMIN_RAD * growth / alpha, rel=1e-12)  # small-angle, Eq. 2
    assert sig[2] == pytest.approx(sig[1], rel=1e-15)
    assert fov.slip_factor(slip, p) == pytest.approx(growth, rel=1e-12)
    # the other terms are the paper's, unchanged
    static = fov.standard_deviations(d, ecc, slip, VisionParams(position_slip_knee_deg_s=math.inf))
    np.testing.assert_allclose(sig[[0, 3, 4, 5]], static[[0, 3, 4, 5]], rtol=1e-15)
    np.testing.assert_allclose(sig, expected_stds(d, ecc, slip), rtol=1e-12)
    # 20 arcmin at 50 deg/s, the docstring's example
    assert fov.standard_deviations(1.0, 0.0, 50 * DEG, p)[1] == pytest.approx(20 * ARCMIN_RAD, rel=1e-12)


@pytest.mark.parametrize("slip_deg_s", [0.0, 10.0, 300.0])
def test_paper_vision_and_full_view_have_static_acuity(slip_deg_s):
    slip = slip_deg_s * DEG
    paper = VisionParams(position_slip_knee_deg_s=math.inf)
    full = VisionParams(foveated=False)
    for params, ecc, fov_ed in ((paper, 5 * DEG, True), (full, 30 * DEG, False)):
        sig = fov.standard_deviations(2.0, ecc, slip, params)
        assert sig[1] == pytest.approx(2.0 * ARCMIN_RAD * ((E2 + ecc) / E2 if fov_ed else 1.0), rel=1e-12)
        np.testing.assert_allclose(sig, expected_stds(2.0, ecc, slip, foveated=fov_ed, knee=math.inf), rtol=1e-12)


def test_slip_covariance_and_samples_follow_the_closed_form():
    p = VisionParams()
    pos, vel = np.array([2.0, 0.5, -0.3]), np.array([-4.0, 1.0, 2.0])
    slip = 40 * DEG  # 16 x the knee
    d = float(np.linalg.norm(pos))
    ecc = fov.eccentricity(pos)
    rot = own_basis(pos)
    want = blockdiag(rot) @ np.diag(expected_stds(d, ecc, slip) ** 2) @ blockdiag(rot).T
    np.testing.assert_allclose(fov.covariance(pos, slip, p), want, rtol=1e-9, atol=1e-15)
    x = draw(pos, vel, slip, p, 4000, seed=11)
    lateral = (x[:, :3] - pos) @ rot[:, 1:]  # across the line of sight
    assert np.std(lateral, axis=0) == pytest.approx([expected_stds(d, ecc, slip)[1]] * 2, rel=0.06)


@pytest.mark.parametrize("knee", [0.0, -1.0, float("nan")])
def test_slip_knee_must_be_positive(knee):
    with pytest.raises(ValueError, match="position_slip_knee_deg_s"):
        VisionParams(position_slip_knee_deg_s=knee)


def test_paper_condition_ids_and_agents_use_the_paper_vision():
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.registration import CATCH_ENV_IDS, env_vision_params

    normal = gym.make("EyeCatchPaper-v0").unwrapped.vision_params
    poor = gym.make("EyeCatchPaperPoorVision-v0").unwrapped.vision_params
    assert normal == VisionParams(position_slip_knee_deg_s=math.inf)
    assert poor == VisionParams(position_slip_knee_deg_s=math.inf, noise_scale=10.0)
    for env_id in CATCH_ENV_IDS:  # the brain's model of its eye is the env's eye
        env = gym.make(env_id)
        want = env.unwrapped.vision_params
        if env.unwrapped.vision == "oracle":  # the family's eye (CATCH_VISION), noiseless and unfoveated
            from dataclasses import replace

            from visuomotor_gym.envs.catch import CATCH_VISION

            want = replace(CATCH_VISION, noise_scale=0.0, foveated=False)
        assert env_vision_params(env_id) == want, env_id
        for spec in ("eyecatch", "belief_mpc", "fixed_gaze"):
            if env_id == "EyeCatchTwoBalls-v0":
                continue
            agent = make_agent(spec, env_id, 9)
            assert getattr(agent, "base", agent).vision == want, (spec, env_id)
        env.close()


def test_noise_scale_multiplies_everything():
    base = VisionParams()
    poor = VisionParams(noise_scale=10.0)
    assert base.scaled(10.0) == poor
    for d, ecc, rs in [(1.0, 0.0, 0.0), (3.0, 10 * DEG, 0.5), (6.0, 45 * DEG, 2.0)]:
        np.testing.assert_allclose(
            fov.standard_deviations(d, ecc, rs, poor),
            10.0 * fov.standard_deviations(d, ecc, rs, base),
            rtol=1e-12,
        )
        np.testing.assert_allclose(
            fov.standard_deviations(d, ecc, rs, poor), expected_stds(d, ecc, rs, scale=10.0), rtol=1e-12
        )
    # zero noise: the sample is the truth
    rng = np.random.default_rng(0)
    pos, vel = np.array([2.0, 0.3, -0.1]), np.array([-3.0, 0.2, 1.0])
    p_s, v_s = sample(pos, vel, 0.4, VisionParams(noise_scale=0.0), rng)
    np.testing.assert_array_equal(p_s, pos)
    np.testing.assert_array_equal(v_s, vel)


@pytest.mark.parametrize("ecc_deg", [0.0, 5.0, 30.0, 75.0])
def test_covariance_closed_form_eigenstructure(ecc_deg):
    """A Sigma^2 A^T: eigenvalues are Sigma^2, the depth eigenvector is the line of sight."""
    p = VisionParams()
    d, rs = 3.0, 0.4
    u = unit_at(ecc_deg * DEG, 0.9)
    cov = fov.covariance(d * u, rs, p)
    np.testing.assert_allclose(cov, cov.T, atol=1e-18)
    sig = expected_stds(d, ecc_deg * DEG, rs)
    for block, s in ((cov[:3, :3], sig[:3]), (cov[3:, 3:], sig[3:])):
        w, v = np.linalg.eigh(block)
        np.testing.assert_allclose(np.sort(w), np.sort(s**2), rtol=1e-9)
        top = v[:, np.argmax(w)]
        assert abs(top @ u) == pytest.approx(1.0, abs=1e-12)
        # in an independent line-of-sight basis the block is diagonal
        b = own_basis(u)
        np.testing.assert_allclose(b.T @ block @ b, np.diag(s**2), atol=1e-12 * s.max() ** 2)
    np.testing.assert_allclose(cov[:3, 3:], 0.0, atol=1e-20)  # position/velocity independent
    if ecc_deg == 0.0:
        np.testing.assert_allclose(cov, np.diag(sig**2), rtol=1e-12, atol=1e-20)


# ------------------------------------------------------------------------------------------------
# Monte-Carlo: sample() vs covariance() and vs the closed form
# ------------------------------------------------------------------------------------------------
N_SAMPLES = 20000


@pytest.mark.parametrize("d", [1.0, 3.0, 6.0])
@pytest.mark.parametrize("ecc_deg", [0.0, 5.0, 20.0, 45.0])
def test_sample_statistics_match_covariance(ecc_deg, d):
    p = VisionParams()
    rs = 0.4
    ecc = ecc_deg * DEG
    u = unit_at(ecc, 0.7)
    pos = d * u
    vel = np.array([-4.0, 0.5, 2.0])
    seed = 1000 + int(ecc_deg) * 10 + int(d)
    x = draw(pos, vel, rs, p, N_SAMPLES, seed)
    err = x - np.concatenate([pos, vel])

    cov = fov.covariance(pos, rs, p)
    emp = np.cov(err, rowvar=False)
    sig = expected_stds(d, ecc, rs)

    # unbiased (Eq. 1: mean = truth), per line-of-sight axis
    a = blockdiag(fov.line_of_sight_rotation(u))
    err_los = err @ a  # rows: A^T e
    assert np.all(np.abs(err_los.mean(axis=0)) < 5.0 * sig / math.sqrt(N_SAMPLES))

    # per-axis std in the line-of-sight frame, vs covariance() and vs the closed form
    emp_los = a.T @ emp @ a
    model_los = a.T @ cov @ a
    emp_std = np.sqrt(np.diag(emp_los))
    np.testing.assert_allclose(emp_std, np.sqrt(np.diag(model_los)), rtol=0.04)
    np.testing.assert_allclose(emp_std, sig, rtol=0.04)
    corr = emp_los / np.outer(emp_std, emp_std)
    off = corr - np.diag(np.diag(corr))
    assert np.abs(off).max() < 0.04

    # whole-matrix check: whitening by covariance() leaves the identity
    w, v = np.linalg.eigh(cov)
    inv_sqrt = v @ np.diag(w**-0.5) @ v.T
    np.testing.assert_allclose(inv_sqrt @ emp @ inv_sqrt, np.eye(6), atol=0.05)

    # the largest-variance position axis is the line of sight (depth)
    wp, vp = np.linalg.eigh(emp[:3, :3])
    assert abs(vp[:, -1] @ u) > 1.0 - 1e-4
    assert math.sqrt(wp[-1]) == pytest.approx(sig[0], rel=0.04)


@pytest.mark.parametrize("ecc_deg,d", [(0.0, 1.0), (10.0, 3.0), (40.0, 6.0), (58.0, 2.0)])
def test_sample_statistics_independent_of_covariance(ecc_deg, d):
    """No use of covariance() or line_of_sight_rotation(): own basis, closed-form stds."""
    p = VisionParams()
    rs = 1.2
    ecc = ecc_deg * DEG
    pos = d * unit_at(ecc, -2.1)
    vel = np.array([-6.0, -0.3, 3.0])
    x = draw(pos, vel, rs, p, N_SAMPLES, seed=77 + int(ecc_deg))
    err_p = x[:, :3] - pos
    err_v = x[:, 3:] - vel
    b = own_basis(pos)  # columns: line of sight, two lateral axes
    sig = expected_stds(d, ecc, rs)
    np.testing.assert_allclose((err_p @ b).std(axis=0), sig[:3], rtol=0.04)
    np.testing.assert_allclose((err_v @ b).std(axis=0), sig[3:], rtol=0.04)
    np.testing.assert_allclose(fov.standard_deviations(d, ecc, rs, p), sig, rtol=1e-12)
    # empirical depth axis (largest position spread) is parallel to the position vector
    _w, v = np.linalg.eigh(np.cov(err_p, rowvar=False))
    assert abs(v[:, -1] @ pos / d) > 1.0 - 1e-4
    _w, v = np.linalg.eigh(np.cov(err_v, rowvar=False))
    assert abs(v[:, -1] @ pos / d) > 0.999


def test_sample_spread_grows_with_eccentricity():
    p = VisionParams()
    d = 3.0
    lat_std = []
    for ecc_deg in (0.0, 10.0, 40.0):
        pos = d * unit_at(ecc_deg * DEG, 0.0)
        err = draw(pos, np.zeros(3), 0.0, p, 4000, seed=5)[:, :3] - pos
        lat_std.append((err @ own_basis(pos))[:, 1:].std())
    ratios = np.array(lat_std) / lat_std[0]
    np.testing.assert_allclose(ratios, [1.0, 6.0, 21.0], rtol=0.06)


# ------------------------------------------------------------------------------------------------
# Field of view, acuity without foveation, parameter validation
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "ecc_deg,inside",
    [
        (0.0, True), (10.0, True), (45.0, True), (59.9, True),
        (60.1, False), (90.0, False), (150.0, False), (180.0, False),
    ],
)
def test_field_of_view(ecc_deg, inside):
    for phi in (0.0, 1.0, 2.5, 4.0):
        pos = 2.0 * unit_at(ecc_deg * DEG, phi)
        assert fov.is_in_field_of_view(pos, VisionParams()) is inside
        assert fov.is_in_field_of_view(pos, VisionParams(foveated=False)) is True
    assert fov.eccentricity(2.0 * unit_at(ecc_deg * DEG, 0.3)) == pytest.approx(ecc_deg * DEG, abs=1e-9)


def test_unfoveated_acuity_is_one_everywhere():
    p = VisionParams(foveated=False)
    for ecc_deg in (0.0, 5.0, 60.0, 120.0, 180.0):
        assert fov.acuity(ecc_deg * DEG, p) == 1.0
        np.testing.assert_allclose(
            fov.standard_deviations(3.0, ecc_deg * DEG, 0.2, p), expected_stds(3.0, 0.0, 0.2, foveated=False),
            rtol=1e-12,
        )


def test_perceive_hides_points_outside_field_of_view():
    """``perceive`` (what the env calls): zeros and visible=False beyond 60 deg, else a sample."""
    p = VisionParams()
    vel = np.array([-3.0, 0.2, 1.0])
    for ecc_deg in (61.0, 90.0, 170.0):
        far = 3.0 * unit_at(ecc_deg * DEG, 0.5)
        pos, v, visible = fov.perceive(far, vel, 0.1, p, np.random.default_rng(0))
        assert visible is False
        np.testing.assert_array_equal(pos, 0.0)
        np.testing.assert_array_equal(v, 0.0)
    for ecc_deg in (0.0, 30.0, 59.0):
        truth = 3.0 * unit_at(ecc_deg * DEG, 0.5)
        pos, v, visible = fov.perceive(truth, vel, 0.1, p, np.random.default_rng(1))
        assert visible is True
        # Oracle: truth + A Sigma eps (Eyecatch Eq. 1-3) with the same normal draws.
        eps = np.random.default_rng(1).standard_normal(6)
        d = np.linalg.norm(truth)
        ecc = math.acos(truth[0] / d)
        sig = fov.standard_deviations(d, ecc, 0.1, p)
        rot = fov.line_of_sight_rotation(truth / d)
        ref_pos, ref_v = truth + rot @ (sig[:3] * eps[:3]), np.asarray(vel) + rot @ (sig[3:] * eps[3:])
        np.testing.assert_allclose(pos, ref_pos, rtol=1e-12)
        np.testing.assert_allclose(v, ref_v, rtol=1e-12)
        assert not np.array_equal(pos, truth)  # noisy
    # without foveation everything is seen
    behind = 3.0 * unit_at(120 * DEG, 0.5)
    _, _, visible = fov.perceive(behind, vel, 0.1, VisionParams(foveated=False), np.random.default_rng(2))
    assert visible is True


def test_custom_field_of_view():
    p = VisionParams(field_of_view_deg=30.0)
    assert fov.is_in_field_of_view(unit_at(29.0 * DEG, 0.4), p)
    assert not fov.is_in_field_of_view(unit_at(31.0 * DEG, 0.4), p)


NONNEG_FIELDS = [
    "retinal_position_std_arcmin",
    "retinal_velocity_weber",
    "retinal_velocity_floor_deg_s",
    "depth_std_fraction",
    "depth_rate_std_fraction",
    "noise_scale",
]


@pytest.mark.parametrize("field", NONNEG_FIELDS)
@pytest.mark.parametrize("value", [-1e-9, -1.0, float("nan"), float("inf")])
def test_vision_params_rejects_bad_values(field, value):
    with pytest.raises(ValueError):
        VisionParams(**{field: value})


@pytest.mark.parametrize("field", NONNEG_FIELDS)
def test_vision_params_accepts_zero(field):
    assert getattr(VisionParams(**{field: 0.0}), field) == 0.0


@pytest.mark.parametrize(
    "kwargs",
    [
        {"fovea_e2_deg": 0.0},
        {"fovea_e2_deg": -2.0},
        {"fovea_e2_deg": float("nan")},
        {"fovea_e2_deg": float("inf")},
        {"field_of_view_deg": 0.0},
        {"field_of_view_deg": -10.0},
        {"field_of_view_deg": 180.5},
        {"field_of_view_deg": float("nan")},
    ],
)
def test_vision_params_rejects_bad_geometry(kwargs):
    with pytest.raises(ValueError):
        VisionParams(**kwargs)


def test_env_rejects_bad_vision_params():
    with pytest.raises(ValueError):
        gym.make("EyeCatch-v0", vision_params={"noise_scale": -1.0})
    with pytest.raises(ValueError):
        gym.make("EyeCatch-v0", vision_noise_scale=float("nan"))


# ------------------------------------------------------------------------------------------------
# Environment level
# ------------------------------------------------------------------------------------------------
def _eye_frame(env, obs):
    s = env.unwrapped.layout.slices
    rot = obs[s["eye_rot"]].astype(float).reshape(3, 3)
    eye = obs[s["eye_pos"]].astype(float) + SEAT_ORIGIN
    return rot, eye


def _true_ball_eye(env, obs, info):
    rot, eye = _eye_frame(env, obs)
    return rot.T @ (info["ball_pos"] - eye), rot.T @ info["ball_vel"]


def _action(gaze=(0.0, 0.0), head=(0.0, 0.0)):
    a = np.zeros(9, dtype=np.float32)
    a[4:6] = gaze
    a[7:9] = head
    return a


def test_ball_invisible_outside_field_of_view():
    env = gym.make("EyeCatch-v0", vision_params=PLAIN_EYE)
    s = env.unwrapped.layout.slices
    obs, info = env.reset(seed=1)
    assert obs[s["ball_visible"]][0] == 1.0  # gaze starts on the ball
    assert np.any(obs[s["ball_pos"]] != 0.0)
    n_far = 0
    in_saccade_before = False
    for k in range(40):
        # one 60 deg saccade to the left, then keep turning the head left: the ball leaves the view
        obs, _, term, trunc, info = env.step(_action(gaze=(1.0 if k == 0 else 0.0, 0.0), head=(1.0, 0.0)))
        saccading = info["saccade_onset"] or in_saccade_before
        in_saccade_before = info["in_saccade"]
        ecc = fov.eccentricity(_true_ball_eye(env, obs, info)[0])
        if ecc > FOV_HALF + 0.5 * DEG:
            n_far += not saccading
            assert obs[s["ball_visible"]][0] == 0.0
            assert info["ball_visible"] is False
            np.testing.assert_array_equal(obs[s["ball_pos"]], 0.0)
            np.testing.assert_array_equal(obs[s["ball_vel"]], 0.0)
        assert not (term or trunc)
    assert n_far >= 10, "the scenario should put the ball well outside the field of view"
    env.close()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_visibility_is_field_of_view_and_no_saccade(seed):
    """Random gaze and head actions: visible <=> (within 60 deg and not saccading this step)."""
    env = gym.make("EyeCatch-v0", vision_params=PLAIN_EYE)
    s = env.unwrapped.layout.slices
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    in_saccade_before = False
    counts = {"visible": 0, "out_of_view": 0, "saccade": 0}
    for _ in range(100):
        gaze = rng.uniform(-1, 1, 2) * (rng.random() < 0.3)  # a new gaze request ~30 % of steps
        obs, _, term, trunc, info = env.step(_action(gaze=gaze, head=rng.uniform(-1, 1, 2)))
        saccading = info["saccade_onset"] or in_saccade_before
        in_saccade_before = info["in_saccade"]
        ecc = fov.eccentricity(_true_ball_eye(env, obs, info)[0])
        visible = obs[s["ball_visible"]][0]
        assert visible in (0.0, 1.0)
        assert bool(visible) == info["ball_visible"]
        if abs(ecc - FOV_HALF) < 0.3 * DEG:
            continue  # float32 eye frame: too close to the border to call
        expected = (not saccading) and ecc < FOV_HALF
        assert bool(visible) == expected, (ecc / DEG, saccading)
        if expected:
            counts["visible"] += 1
            assert np.any(obs[s["ball_pos"]] != 0.0)
        else:
            counts["saccade" if saccading else "out_of_view"] += 1
            np.testing.assert_array_equal(obs[s["ball_pos"]], 0.0)
            np.testing.assert_array_equal(obs[s["ball_vel"]], 0.0)
        if term or trunc:
            break
    assert counts["visible"] > 0 and counts["saccade"] > 0
    env.close()


def test_saccadic_blindness():
    env = gym.make("EyeCatch-v0")
    s = env.unwrapped.layout.slices
    obs, info = env.reset(seed=4)
    obs, _, _, _, info = env.step(_action())
    assert obs[s["ball_visible"]][0] == 1.0 and not info["saccade_onset"]
    # 30 deg request: a saccade of 21 + 66 = 87 ms, i.e. in flight during 5 control steps
    obs, _, _, _, info = env.step(_action(gaze=(0.5, 0.0)))
    assert info["saccade_onset"] is True
    assert obs[s["ball_visible"]][0] == 0.0
    np.testing.assert_array_equal(obs[s["ball_pos"]], 0.0)
    np.testing.assert_array_equal(obs[s["ball_vel"]], 0.0)
    assert obs[s["saccade"]][0] == 1.0
    blind = 1
    while info["in_saccade"]:
        obs, _, _, _, info = env.step(_action())
        assert obs[s["ball_visible"]][0] == 0.0
        np.testing.assert_array_equal(obs[s["ball_pos"]], 0.0)
        blind += 1
    assert blind == math.ceil(0.087 / 0.02)  # 5 steps
    # landed 30 deg off the ball: still inside the field of view, so seen again
    obs, _, _, _, info = env.step(_action())
    ecc = fov.eccentricity(_true_ball_eye(env, obs, info)[0])
    assert 15 * DEG < ecc < FOV_HALF
    assert obs[s["ball_visible"]][0] == 1.0
    env.close()


def test_full_view_sees_during_saccades_and_everywhere():
    env = gym.make("EyeCatchFullView-v0")
    s = env.unwrapped.layout.slices
    obs, info = env.reset(seed=1)
    seen_far = 0
    for k in range(40):
        obs, _, _term, _trunc, info = env.step(_action(gaze=(1.0 if k == 0 else 0.0, 0.0), head=(1.0, 0.0)))
        if k == 0:
            assert info["saccade_onset"]
        assert obs[s["ball_visible"]][0] == 1.0
        assert np.any(obs[s["ball_pos"]] != 0.0)
        seen_far += fov.eccentricity(_true_ball_eye(env, obs, info)[0]) > FOV_HALF + DEG
    assert seen_far >= 10
    env.close()


@pytest.mark.parametrize("seed", [0, 5])
def test_oracle_ball_block_is_true_state_in_eye_frame(seed):
    env = gym.make("EyeCatchOracle-v0")
    s = env.unwrapped.layout.slices
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    for k in range(60):
        rot, eye = _eye_frame(env, obs)
        np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-6)
        np.testing.assert_allclose(rot[:, 0], info["gaze_dir"], atol=1e-6)  # column 0 = gaze
        np.testing.assert_allclose(eye, info["eye_pos"], atol=1e-6)  # seat origin (0, 0, 0.5)
        p_true, v_true = _true_ball_eye(env, obs, info)
        np.testing.assert_allclose(obs[s["ball_pos"]], p_true, rtol=1e-5, atol=2e-5)
        np.testing.assert_allclose(obs[s["ball_vel"]], v_true, rtol=1e-5, atol=2e-5)
        assert obs[s["ball_visible"]][0] == 1.0
        # the oracle sees even during saccades and out of view
        gaze = rng.uniform(-1, 1, 2) * (k % 7 == 0)
        obs, _, term, trunc, info = env.step(_action(gaze=gaze, head=rng.uniform(-1, 1, 2)))
        if term or trunc:
            break
    env.close()


def _position_errors(env_id, seeds, gaze_offset):
    """Observed-minus-true ball position, split into depth and lateral parts (world frame)."""
    env = gym.make(env_id)
    s = env.unwrapped.layout.slices
    rows = []
    for seed in seeds:
        obs, info = env.reset(seed=seed)
        for k in range(100):
            obs, _, term, trunc, info = env.step(_action(gaze=gaze_offset if k == 0 else (0.0, 0.0)))
            if obs[s["ball_visible"]][0] == 1.0:
                rot, eye = _eye_frame(env, obs)
                seen = rot @ obs[s["ball_pos"]].astype(float) + eye
                rel = info["ball_pos"] - eye
                d = float(np.linalg.norm(rel))
                u = rel / d
                e = seen - info["ball_pos"]
                depth = float(e @ u)
                lateral = float(np.linalg.norm(e - depth * u))
                rows.append((fov.eccentricity(rot.T @ rel), d, depth, lateral))
            if term or trunc:
                break
    env.close()
    return np.array(rows).T


def test_env_position_noise_matches_model():
    # The paper's static acuity (EyeCatchPaper-v0): the slip term of EyeCatch-v0 is tested below.
    seeds = range(4)
    offset = (0.4, -0.1)  # look ~25 deg away from the ball after the first step
    ecc_f, d_f, depth_f, lat_f = _position_errors("EyeCatchPaper-v0", seeds, offset)
    _ecc_u, d_u, depth_u, lat_u = _position_errors("EyeCatchFullView-v0", seeds, offset)
    assert len(d_f) > 100 and len(d_u) > 100

    # FullView: foveal noise whatever the eccentricity (1 arcmin lateral, 5 % depth)
    z_lat_u = np.sqrt(np.mean((lat_u / (d_u * ARCMIN_RAD)) ** 2) / 2.0)  # 2 lateral axes
    z_depth_u = np.sqrt(np.mean((depth_u / (0.05 * d_u)) ** 2))
    assert 0.8 < z_lat_u < 1.25
    assert 0.8 < z_depth_u < 1.25

    # Foveated: the same, once divided by the acuity alpha(theta) = E2 / (E2 + theta)
    k = (E2 + ecc_f) / E2
    z_lat_f = np.sqrt(np.mean((lat_f / (k * d_f * ARCMIN_RAD)) ** 2) / 2.0)
    z_depth_f = np.sqrt(np.mean((depth_f / (k * 0.05 * d_f)) ** 2))
    assert 0.8 < z_lat_f < 1.25
    assert 0.8 < z_depth_f < 1.25

    # far from the fovea the foveated eye is much worse than the full-view one
    far = ecc_f > 15 * DEG
    assert far.sum() > 50
    ang_f = np.sqrt(np.mean((lat_f[far] / d_f[far]) ** 2))
    ang_u = np.sqrt(np.mean((lat_u / d_u) ** 2))
    assert ang_f > 5.0 * ang_u
    assert ang_u == pytest.approx(math.sqrt(2.0) * ARCMIN_RAD, rel=0.25)


def test_env_lateral_noise_grows_with_retinal_slip():
    """EyeCatch-v0 with the eye held: the lateral error, divided by the closed-form std at the true
    retinal slip (line-of-sight rotation minus the eye's, from ``info``), is a unit normal."""
    env = gym.make("EyeCatch-v0", vision_params=PLAIN_EYE)
    s = env.unwrapped.layout.slices
    z, slips = [], []
    for seed in range(6):
        obs, info = env.reset(seed=seed)
        prev = info
        for _ in range(100):
            obs, _, term, trunc, info = env.step(_action())
            if obs[s["ball_visible"]][0] == 1.0 and not info["in_saccade"]:
                rot, eye = _eye_frame(env, obs)
                rel = info["ball_pos"] - eye
                d = float(np.linalg.norm(rel))
                u = rel / d
                # as the env: ball velocity relative to the moving eye, minus the gaze's own rotation
                rv = info["ball_vel"] - (info["eye_pos"] - prev["eye_pos"]) / env.unwrapped.dt
                w = np.cross(rel, rv) / d**2 - np.cross(prev["gaze_dir"], info["gaze_dir"]) / env.unwrapped.dt
                w -= (w @ u) * u
                slip = float(np.linalg.norm(w))
                ecc = fov.eccentricity(rot.T @ rel)
                e = rot @ obs[s["ball_pos"]].astype(float) + eye - info["ball_pos"]
                lateral = e - (e @ u) * u
                z.append(np.linalg.norm(lateral) / expected_stds(d, ecc, slip)[1])
                slips.append(slip)
            prev = info
            if term or trunc:
                break
    env.close()
    z, slips = np.array(z), np.array(slips)
    fast = slips > 10 * KNEE
    assert len(z) > 200 and fast.sum() > 50  # a held eye sees the ball slip fast
    assert math.sqrt(np.mean(z**2) / 2.0) == pytest.approx(1.0, abs=0.2)  # 2 lateral axes
    assert math.sqrt(np.mean(z[fast] ** 2) / 2.0) == pytest.approx(1.0, abs=0.2)


# ----------------------------------------------------------------------------------------------
# No leak of the ball's true state into the observation
# ----------------------------------------------------------------------------------------------
def _non_ball_blocks(layout, obs, exclude=("ball_pos", "ball_vel", "ball_visible", "eye_rot", "eye_in_head")):
    return {name: obs[s].copy() for name, s in layout.slices.items() if name not in exclude}


def test_reset_observation_depends_on_the_throw_only_through_the_visual_sample():
    """Across throws, every block but the visual sample and the gaze direction (which starts on the
    thrower's hand by design) is identical at reset: no fixation = true distance, no time, no hand."""
    env = gym.make("EyeCatch-v0").unwrapped
    first = None
    for seed in range(12):
        obs, info = env.reset(seed=seed)
        blocks = _non_ball_blocks(env.layout, obs)
        if first is None:
            first = blocks
            continue
        for name, value in blocks.items():
            np.testing.assert_array_equal(value, first[name], err_msg=f"{name} differs between throws at reset")
    distance = np.linalg.norm(info["release_pos"] - info["eye_pos"])
    assert obs[env.layout.slices["fixation"]][0] != pytest.approx(distance, abs=0.05)


def test_fixation_block_follows_the_action_not_the_ball():
    """With the same actions, two different throws give the same fixation trajectory."""
    env = gym.make("EyeCatch-v0").unwrapped
    action = np.zeros(env.action_space.shape, np.float32)
    action[6] = 0.4  # a fixation request
    runs = []
    for seed in (0, 7):
        env.reset(seed=seed)
        runs.append([env.step(action)[0][env.layout.slices["fixation"]][0] for _ in range(20)])
    np.testing.assert_array_equal(runs[0], runs[1])


def test_ball_blocks_carry_nothing_during_saccades_or_out_of_view():
    """Whenever the eye produced no sample (saccade, outside the field of view, before the delay line
    fills), the ball blocks are exactly zero, whatever the ball does."""
    env = gym.make("EyeCatchDelayed-v0").unwrapped
    s = env.layout.slices
    rng = np.random.default_rng(0)
    blind_steps = 0
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        for _ in range(60):
            action = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
            obs, _, terminated, truncated, _info = env.step(action)
            if obs[s["ball_visible"]][0] == 0.0:
                blind_steps += 1
                assert not obs[s["ball_pos"]].any() and not obs[s["ball_vel"]].any()
            if terminated or truncated:
                break
    assert blind_steps > 5  # random gaze makes saccades: the check above ran
