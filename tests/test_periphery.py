"""Tests of the opt-in human peripheral vision (visuomotor_gym.vision.periphery): the human
field of view, the position law, crowding and the depth law, each against a case computed by hand
here, and their wiring into the retina of a real environment (on either path: the compiled retina
mirrors the Python one bit for bit, tests/test_native.py).

Oracles: the closed forms of the module docstring written out independently (1 arcmin lateral, 5 %
depth, E2 = 2 deg for the acuity law), fields of view 60 up / 75 down / 100 to the side (Spector 1990),
Bouma's b = 0.5.
"""

from __future__ import annotations

import contextlib
import math

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the environment ids)
from visuomotor_gym import _native
from visuomotor_gym.core.retina import PointTarget
from visuomotor_gym.vision import foveation as fov
from visuomotor_gym.vision import periphery
from visuomotor_gym.vision.foveation import VisionParams

DEG = math.pi / 180.0
ARCMIN = DEG / 60.0


def unit(az_deg: float, el_deg: float) -> list[float]:
    """Eye-frame unit vector (x along the visual axis, y left, z up) at azimuth/elevation (degrees)."""
    az, el = az_deg * DEG, el_deg * DEG
    return [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]


def at_ecc(ecc_deg: float, phi_deg: float) -> list[float]:
    """Eye-frame unit vector at eccentricity ``ecc_deg`` and polar angle ``phi_deg`` (0 = left (+y),
    90 = up (+z)) from the visual axis."""
    e, p = ecc_deg * DEG, phi_deg * DEG
    return [math.cos(e), math.sin(e) * math.cos(p), math.sin(e) * math.sin(p)]


# --- 1. field of view ---------------------------------------------------------------------------
HUMAN = VisionParams(field_shape="human")


@pytest.mark.parametrize("phi_deg, limit_deg", [(90.0, 60.0), (-90.0, 75.0), (0.0, 100.0), (180.0, 100.0)])
def test_human_field_meridians_in_and_out(phi_deg, limit_deg):
    # 60 deg up, 75 down, 100 to either side (Spector 1990); 0.1 deg inside is seen, 0.1 outside not
    assert periphery.in_field(*at_ecc(limit_deg - 0.1, phi_deg), HUMAN)
    assert not periphery.in_field(*at_ecc(limit_deg + 0.1, phi_deg), HUMAN)
    assert fov.is_in_field_of_view(np.array(at_ecc(limit_deg - 0.1, phi_deg)), HUMAN)
    assert not fov.is_in_field_of_view(np.array(at_ecc(limit_deg + 0.1, phi_deg)), HUMAN)


@pytest.mark.parametrize("phi_deg, v_deg", [(45.0, 60.0), (-45.0, 75.0), (135.0, 60.0), (-30.0, 75.0)])
def test_human_field_between_meridians_is_the_quadrant_ellipse(phi_deg, v_deg):
    c, s = math.cos(phi_deg * DEG), math.sin(phi_deg * DEG)
    limit = 1.0 / math.sqrt(c * c / 100.0**2 + s * s / v_deg**2)  # degrees, by hand
    u = at_ecc(30.0, phi_deg)
    assert periphery.human_field_limit(u[1], u[2], HUMAN) / DEG == pytest.approx(limit, rel=1e-12)
    assert periphery.in_field(*at_ecc(limit - 0.05, phi_deg), HUMAN)
    assert not periphery.in_field(*at_ecc(limit + 0.05, phi_deg), HUMAN)


def test_human_field_replaces_the_cone_and_perceive_follows_it():
    rng = np.random.default_rng(0)
    cone20 = VisionParams(field_of_view_deg=20.0)
    human20 = VisionParams(field_of_view_deg=20.0, field_shape="human")  # field_of_view_deg then unused
    p = [2.0 * c for c in at_ecc(50.0, -90.0)]  # 50 deg below the fixation point
    assert not fov.perceive(p, [0.0, 0.0, 0.0], 0.0, cone20, rng)[2]
    assert fov.perceive(p, [0.0, 0.0, 0.0], 0.0, human20, rng)[2]
    # the cone's own boundary is unchanged
    assert periphery.in_field(*at_ecc(19.9, 37.0), cone20) and not periphery.in_field(*at_ecc(20.1, 37.0), cone20)
    # no foveation (FullView): everything is in the field
    assert periphery.in_field(-1.0, 0.0, 0.0, VisionParams(field_shape="human", foveated=False))


# --- 2. position law ----------------------------------------------------------------------------
@pytest.mark.parametrize("ecc_factor, expected", [(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)])
def test_position_law_doubles_at_e2_and_triples_at_twice_e2(ecc_factor, expected):
    e2p = 0.7
    vp = VisionParams(position_e2_deg=e2p)
    d, ecc = 2.0, ecc_factor * e2p * DEG
    sd = fov.standard_deviations(d, ecc, 0.0, vp)
    assert sd[1] == pytest.approx(d * ARCMIN * expected, rel=1e-12)  # lateral: 1 arcmin x (1 + theta/E2_pos)
    assert sd[2] == sd[1]
    k = 1.0 + ecc / (2.0 * DEG)  # depth and velocity keep the acuity law (E2 = 2 deg)
    assert sd[0] == pytest.approx(0.05 * d * k, rel=1e-12)
    assert sd[4] == pytest.approx(d * 0.2 * DEG * k, rel=1e-12)


def test_position_law_off_is_the_acuity_law_and_slip_still_multiplies():
    d, ecc = 1.5, 10.0 * DEG
    old = fov.standard_deviations(d, ecc, 0.0, VisionParams())
    assert old[1] == d * ARCMIN * (1.0 + ecc / (2.0 * DEG)) or old[1] == pytest.approx(
        d * ARCMIN * (1.0 + ecc / (2.0 * DEG)), rel=1e-12)
    new = fov.standard_deviations(d, ecc, 10.0 * DEG, VisionParams(position_e2_deg=0.7))  # slip 10 deg/s
    assert new[1] == pytest.approx(d * ARCMIN * (1.0 + 10.0 / 0.7) * 4.0, rel=1e-12)  # x 10/2.5
    # without foveation the law is off
    assert fov.standard_deviations(d, ecc, 0.0, VisionParams(position_e2_deg=0.7, foveated=False))[1] == \
        pytest.approx(d * ARCMIN, rel=1e-12)


# --- 3. crowding --------------------------------------------------------------------------------
CROWD = VisionParams(crowding=True)  # b = 0.5, fovea 0.5 deg exempt


def _groups(dirs, kinds=None, objects=None, params=CROWD):
    n = len(dirs)
    eccs = [math.acos(u[0]) for u in dirs]
    return periphery.crowding_groups(dirs, eccs, kinds or ["k"] * n, objects or [str(i) for i in range(n)], params)


def _sep_deg(u, v) -> float:
    return math.degrees(math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(u, v))))))


def test_crowding_pools_exactly_the_flankers_within_the_critical_spacing():
    # target 10 deg left: critical spacing 5 deg; a flanker 4.9 deg further left (in), one 5.1 deg above
    # the target's direction (5.1 deg of elevation at azimuth 10: ~5.1 deg away, out)
    target, inside, above = unit(10.0, 0.0), unit(14.9, 0.0), unit(10.0, 5.1)
    assert _sep_deg(target, inside) == pytest.approx(4.9, abs=1e-9)
    assert 5.0 < _sep_deg(target, above) < 5.2
    g = _groups([target, inside, above])
    assert g[0] == [[0], [1]]  # the near flanker, not the far one
    # the 14.9-deg flanker (spacing 7.45) is crowded by the target; by the 'above' one if closer than 7.45
    assert g[1] == ([[1], [0], [2]] if _sep_deg(inside, above) < 0.5 * 14.9 else [[1], [0]])
    # 'above' (eccentricity ~11.2 deg, spacing ~5.6) is crowded by the target (5.1 deg) only
    assert math.degrees(math.acos(above[0])) * 0.5 < _sep_deg(above, inside)
    assert g[2] == [[2], [0]]


def test_a_flanker_just_outside_the_critical_spacing_leaves_the_target_untouched():
    for sep, crowded in ((2.999, True), (3.001, False)):  # target at 6 deg: spacing 3 deg
        g = _groups([unit(6.0, 0.0), unit(6.0 + sep, 0.0)])
        assert g[0] == ([[0], [1]] if crowded else [[0]])


def test_crowding_is_asymmetric_and_spares_the_fovea_other_kinds_and_the_same_object():
    # the 4-deg target (spacing 2) is crowded by a flanker 1.5 deg nearer the fovea (2.5 deg: spacing 1.25),
    # which the target does not crowd
    assert _groups([unit(4.0, 0.0), unit(2.5, 0.0)]) == [[[0], [1]], [[1]]]
    # within the 0.5-deg fovea nobody is crowded, even 0.2 deg from a flanker; just outside it (0.6 deg:
    # spacing 0.3) the same pair crowds
    assert _groups([unit(0.4, 0.0), unit(0.6, 0.0)]) == [[[0]], [[1], [0]]]
    # another kind, or another point of the same object, is no flanker
    assert _groups([unit(10.0, 0.0), unit(11.0, 0.0)], kinds=["a", "b"]) == [[[0]], [[1]]]
    assert _groups([unit(10.0, 0.0), unit(11.0, 0.0)], objects=["box", "box"]) == [[[0]], [[1]]]
    # off: nobody is pooled
    assert _groups([unit(10.0, 0.0), unit(11.0, 0.0)], params=VisionParams()) == [[[0]], [[1]]]


def test_a_flanking_object_counts_once_at_the_mean_of_its_flanking_points():
    # target at 10 deg (spacing 5); object B has two points within it (12, 13 deg) and one outside (16)
    dirs = [unit(10.0, 0.0), unit(12.0, 0.0), unit(13.0, 0.0), unit(16.0, 0.0)]
    g = _groups(dirs, objects=["A", "B", "B", "B"])
    assert g[0] == [[0], [1, 2]]
    vecs = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [4.0, 0.0, 0.0], [100.0, 0.0, 0.0]]
    # (target + mean(B's two flanking points)) / 2 = (0 + 3) / 2
    assert periphery.pooled(vecs, g[0]) == [1.5, 0.0, 0.0]


def test_pooled_is_the_mean_of_the_elements():
    vecs = [[1.0, 2.0, 3.0], [3.0, 0.0, -1.0], [5.0, 2.0, 1.0], [100.0, 100.0, 100.0]]
    assert periphery.pooled(vecs, [[0], [1]]) == [2.0, 1.0, 1.0]
    assert periphery.pooled(vecs, [[0], [1, 2]]) == [2.5, 1.5, 1.5]  # (v0 + (v1 + v2) / 2) / 2
    assert periphery.pooled(vecs, [[3]]) == [100.0, 100.0, 100.0]


# --- 4. depth and the vergence distance ---------------------------------------------------------
def test_depth_std_grows_with_the_disparity_pedestal():
    vp = VisionParams(depth_pedestal_arcmin=10.0)
    d_fix = 1.0
    at_fix = fov.standard_deviations(d_fix, 0.0, 0.0, vp, fixation=d_fix)
    assert at_fix[0] == pytest.approx(0.05 * d_fix, rel=1e-12)  # at the vergence distance: 5 % of depth
    # at twice the fixation distance: eta = 0.063 * |1/2 - 1/1| = 0.0315 rad = 108.3 arcmin
    eta_arcmin = 0.063 * 0.5 / ARCMIN
    assert eta_arcmin == pytest.approx(108.29, abs=0.01)
    far = fov.standard_deviations(2.0, 0.0, 0.0, vp, fixation=d_fix)
    assert far[0] == pytest.approx(0.05 * 2.0 * (1.0 + eta_arcmin / 10.0), rel=1e-12)
    assert far[3] == pytest.approx(0.1 * 2.0 * (1.0 + eta_arcmin / 10.0), rel=1e-12)  # depth rate too
    assert far[1] == pytest.approx(2.0 * ARCMIN, rel=1e-12)  # lateral unchanged
    # the pedestal at which the std doubles: eta = eta_2
    d2 = 1.0 / (1.0 / d_fix + 10.0 * ARCMIN / 0.063)
    assert fov.standard_deviations(d2, 0.0, 0.0, vp, fixation=d_fix)[0] == pytest.approx(0.05 * d2 * 2.0, rel=1e-9)
    # off, or with no fixation given: today's law
    assert fov.standard_deviations(2.0, 0.0, 0.0, VisionParams(), fixation=d_fix)[0] == pytest.approx(0.1)
    assert fov.standard_deviations(2.0, 0.0, 0.0, vp)[0] == pytest.approx(0.1)


# --- the parameters -----------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs", [
    {"field_shape": "oval"}, {"field_up_deg": 0.0}, {"field_down_deg": 181.0}, {"field_side_deg": math.nan},
    {"position_e2_deg": 0.0}, {"position_e2_deg": -1.0}, {"position_e2_deg": math.inf}, {"crowding": "yes"},
    {"crowding_bouma": 0.0}, {"crowding_bouma": math.nan}, {"crowding_fovea_deg": -0.1},
    {"depth_pedestal_arcmin": 0.0}, {"interocular_m": 0.0}, {"interocular_m": "0.06"},
])
def test_peripheral_fields_reject_bad_values_naming_the_field(kwargs):
    name = next(iter(kwargs))
    with pytest.raises((ValueError, TypeError), match=f"VisionParams.{name}"):
        VisionParams(**kwargs)


def test_defaults_are_off_and_periphery_on_needs_foveation():
    assert not VisionParams().periphery_on
    for kw in ({"field_shape": "human"}, {"position_e2_deg": 0.7}, {"crowding": True}, {"depth_pedestal_arcmin": 10.0}):
        assert VisionParams(**kw).periphery_on
        assert not VisionParams(**kw, foveated=False).periphery_on


# --- the retina of a real environment -----------------------------------------------------------
ALL_ON = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0}


def _env_eye(vision_params=None, env_id="EyeCatch-v0"):
    env = gym.make(env_id, vision_params=vision_params)
    env.reset(seed=3)
    return env, env.unwrapped


def _placed(u, eye, dist, name, group=None):
    """A PointTarget at ``dist`` m along the eye-frame direction ``u`` of the env's real eye."""
    t = PointTarget(name, group=group)
    r = np.array(eye.rot_flat).reshape(3, 3)
    t.place(*(np.array(eye.pos_list) + dist * (r @ np.array(u))))
    return t


def test_env_defaults_and_options_both_take_the_compiled_retina_when_built():
    env, u = _env_eye()
    assert u.retina._native == _native.enabled()
    env.close()
    env, u = _env_eye(ALL_ON)  # the periphery's retina is compiled too (tests/test_native.py: bit for bit)
    assert u.retina._native == _native.enabled() and u.vision_params.crowding and u.vision_params.position_e2_deg == 0.7
    obs = None
    for _ in range(20):
        obs, *_ = env.step(env.action_space.sample() * 0.0)
    assert np.all(np.isfinite(obs))
    env.close()


def test_env_retina_pools_crowded_targets_and_draws_six_normals_each():
    # noise_scale 0: the percept is exactly the (pooled) point, in the real eye's frame
    env, u = _env_eye({"crowding": True, "noise_scale": 0.0})
    eye, data = u.eye, u.unwrapped.data
    a = _placed(unit(10.0, 0.0), eye, 2.0, "a")
    b = _placed(unit(13.0, 0.0), eye, 2.0, "b", group="b_obj")
    c = _placed(unit(-10.0, 0.0), eye, 2.0, "c")  # 20 deg away: alone
    d = _placed(unit(14.0, 0.0), eye, 2.0, "d", group="b_obj")  # b and d: one object, no mutual crowding
    rng = np.random.default_rng(0)
    out = u.retina._see_all(data, [a, b, c, d], eye, rng)
    pa, pb, pc, pd = (2.0 * np.array(v) for v in (unit(10.0, 0.0), unit(13.0, 0.0), unit(-10.0, 0.0),
                                                  unit(14.0, 0.0)))
    assert all(o[2] for o in out)
    # a (10 deg, spacing 5): b at 3 and d at 4 deg, both points of one object: (a + (b + d) / 2) / 2
    np.testing.assert_allclose(out[0][0], (pa + (pb + pd) / 2.0) / 2.0, atol=1e-9)
    np.testing.assert_allclose(out[1][0], (pa + pb) / 2.0, atol=1e-9)  # b (13 deg, spacing 6.5): a only
    np.testing.assert_allclose(out[2][0], pc, atol=1e-9)  # c: 20 deg from the others
    np.testing.assert_allclose(out[3][0], (pa + pd) / 2.0, atol=1e-9)  # d (14, spacing 7): a at 4, not b
    # one standard_normal(6) per seen target, as without crowding
    ref = np.random.default_rng(0)
    ref.standard_normal(6 * 4)
    assert rng.standard_normal() == ref.standard_normal()
    env.close()


def test_env_retina_position_and_depth_laws_match_the_closed_form():
    env, u = _env_eye({"position_e2_deg": 0.7, "depth_pedestal_arcmin": 20.0})
    eye, data = u.eye, u.unwrapped.data
    eye.fixation = 1.0
    dist, ecc = 2.0, 7.0  # 10 x E2_pos: lateral std 11 arcmin x 2 m; depth x (1 + 108.3 / 20), x 4.5 acuity
    t = _placed(unit(0.0, -ecc), eye, dist, "t")
    rng = np.random.default_rng(1)
    n = 3000
    errs = np.array([np.array(u.retina._see_all(data, [t], eye, rng)[0][0]) for _ in range(n)]) \
        - dist * np.array(unit(0.0, -ecc))
    los = np.array(unit(0.0, -ecc))
    depth = errs @ los
    lateral = errs - np.outer(depth, los)
    lat_sd = np.sqrt(np.mean(np.sum(lateral**2, axis=1)) / 2.0)
    assert lat_sd == pytest.approx(dist * ARCMIN * (1.0 + ecc / 0.7), rel=0.06)
    eta_arcmin = 0.063 * abs(1.0 / dist - 1.0) / ARCMIN
    k = 1.0 + ecc / 2.0
    assert np.std(depth) == pytest.approx(0.05 * dist * k * (1.0 + eta_arcmin / 20.0), rel=0.06)
    # at the vergence distance the depth std is today's
    eye.fixation = dist
    depth0 = np.array([np.array(u.retina._see_all(data, [t], eye, rng)[0][0]) - dist * los for _ in range(n)]) @ los
    assert np.std(depth0) == pytest.approx(0.05 * dist * k, rel=0.06)
    env.close()


def test_walk_env_with_the_human_periphery_runs_and_groups_obstacle_points():
    env = gym.make("ObstacleWalk-v0", vision_params=ALL_ON)
    obs, _ = env.reset(seed=0)
    targets = env.unwrapped.task.all_targets
    assert targets[0].group == targets[3].group != targets[4].group  # 4 points per obstacle
    for _ in range(30):
        obs, _, term, trunc, _ = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        if term or trunc:
            break
    assert np.all(np.isfinite(obs))
    env.close()


@pytest.mark.parametrize("env_id", ["EyeCatchTwoBalls-v0", "SteppingStones-v0", "ObstacleDodge-v0", "ShelfReach-v0"])
def test_every_family_runs_with_the_human_periphery(env_id):
    # distinct objects everywhere (two balls, stones, pedestrians, the shelf object): the percepts are
    # finite, and seeded runs repeat exactly, the Python path's as the compiled one's (when built)
    def run(native=True):
        with contextlib.nullcontext() if native else _native.disabled():
            env = gym.make(env_id, vision_params=ALL_ON)
        assert env.unwrapped.retina._native is (native and _native.enabled())
        obs, _ = env.reset(seed=1)
        rng = np.random.default_rng(5)
        out = [obs]
        for _ in range(25):
            obs, _, term, trunc, _ = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
            out.append(obs)
            if term or trunc:
                break
        env.close()
        return np.array(out)

    a, b = run(), run(native=False)
    assert np.all(np.isfinite(a))
    np.testing.assert_array_equal(a, b)


def test_human_periphery_preset_sets_the_four_mechanisms_and_keeps_the_rest():
    from dataclasses import replace

    from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY, VisionParams, human_periphery

    v = human_periphery()
    assert (v.field_shape, v.position_e2_deg, v.crowding, v.depth_pedestal_arcmin) == ("human", 0.7, True, 10.0)
    assert v.periphery_on
    base = VisionParams(noise_scale=2.0, field_of_view_deg=20.0)
    assert human_periphery(base) == replace(base, **HUMAN_PERIPHERY)
    assert human_periphery(depth_pedestal_arcmin=None).depth_pedestal_arcmin is None
    with pytest.raises(ValueError, match="position_e2_deg"):
        human_periphery(position_e2_deg=-1.0)


# --- 5. positional disarray ---------------------------------------------------------------------
def test_disarray_field_is_unit_variance_fixed_in_place_and_decorrelates_over_one_zone():
    vp = VisionParams(position_e2_deg=0.7, position_disarray=0.5)
    rng = np.random.default_rng(0)
    # places (eccentricity deg, polar deg): a reference at 10 deg; 10 deg again; one Bouma zone
    # (l theta) out in u; a quarter turn in polar angle
    ecc = np.array([10.0, 10.0, 10.0 * math.exp(0.5) + 0.7 * (math.exp(0.5) - 1.0), 10.0]) * DEG
    phi = np.array([30.0, 30.0, 30.0, 120.0]) * DEG
    v = np.array([periphery.DisarrayField(vp, rng).values(ecc, phi) for _ in range(4000)])  # (n, 2, 4)
    assert v.shape == (4000, 2, 4)
    np.testing.assert_allclose(v[:, :, 0].var(axis=0), 1.0, atol=0.08)  # unit variance, each component
    np.testing.assert_array_equal(v[:, :, 0], v[:, :, 1])  # one place, one value
    # squared-exponential correlation: exp(-du^2 / 2 l^2) with du = l (one zone): exp(-1/2) = 0.61
    assert np.corrcoef(v[:, 1, 0], v[:, 1, 2])[0, 1] == pytest.approx(math.exp(-0.5), abs=0.05)
    # a polar step of pi/2 = 3.1 l: exp(-4.9) ~ 0.007 (the integer rounding of m adds a little)
    assert abs(np.corrcoef(v[:, 1, 0], v[:, 1, 3])[0, 1]) < 0.06
    assert abs(np.corrcoef(v[:, 0, 0], v[:, 1, 0])[0, 1]) < 0.06  # components independent


@pytest.mark.parametrize("kwargs", [{"position_disarray": -0.1}, {"position_disarray": 1.5},
                                    {"disarray_length": 0.0}, {"disarray_length": math.nan}])
def test_disarray_fields_reject_bad_values_naming_the_field(kwargs):
    name = next(iter(kwargs))
    with pytest.raises((ValueError, TypeError), match=f"VisionParams.{name}"):
        VisionParams(**kwargs)


def _still_eye_errors(share, n=400, seed=5, ecc=12.0, depth=False):
    """Lateral (or, with ``depth``, depth) errors (m) of ``n`` successive looks of a still eye at a
    still target ``ecc`` deg below its fovea, 2 m away, with ``position_disarray=share``; one episode."""
    env, u = _env_eye({"position_e2_deg": 0.7, "position_disarray": share})
    env.reset(seed=seed)
    eye, data = u.eye, u.unwrapped.data
    direction = np.array(unit(0.0, -ecc))
    t = _placed(direction, eye, 2.0, "t")
    rng = np.random.default_rng(seed)
    errs = np.array([np.array(u.retina._see_all(data, [t], eye, rng)[0][0]) for _ in range(n)]) - 2.0 * direction
    env.close()
    return errs @ direction if depth else errs - np.outer(errs @ direction, direction)


def test_disarray_keeps_each_looks_std_and_a_still_eye_cannot_average_it_away():
    sd = 2.0 * ARCMIN * (1.0 + 12.0 / 0.7)  # the position law's lateral std (closed form)
    off = _still_eye_errors(0.0)
    assert np.sqrt(np.mean(np.sum(off**2, axis=1)) / 2.0) == pytest.approx(sd, rel=0.1)
    assert np.linalg.norm(off.mean(axis=0)) < 0.25 * sd  # independent looks average to ~sd / 20
    # share 0.8: each look still has the law's std across episodes, but within one the looks share
    # a fixed error: 0.8 of the variance the periphery adds, w = 0.8 (1 - 1/f^2), f = 1 + 12/0.7
    w = 0.8 * (1.0 - 1.0 / (1.0 + 12.0 / 0.7) ** 2)
    means, spreads = [], []
    for seed in range(30):
        e = _still_eye_errors(0.8, n=60, seed=seed)
        means.append(e.mean(axis=0))
        spreads.append(np.sqrt(np.mean(np.sum((e - e.mean(axis=0)) ** 2, axis=1)) / 2.0))
    means = np.array(means)
    assert np.sqrt(np.mean(np.sum(means**2, axis=1)) / 2.0) == pytest.approx(math.sqrt(w) * sd, rel=0.3)
    assert np.mean(spreads) == pytest.approx(math.sqrt(1.0 - w) * sd, rel=0.15)  # what a frame adds


def test_disarray_spares_the_fovea_and_depth():
    # at the fovea the position law adds nothing: no fixed part, the looks average out
    fovea = _still_eye_errors(1.0, n=400, ecc=0.0)
    assert np.linalg.norm(fovea.mean(axis=0)) < 0.25 * 2.0 * ARCMIN
    # depth keeps its per-step noise at any eccentricity (the mean of 400 looks ~ std / 20)
    depth = _still_eye_errors(1.0, n=400, ecc=12.0, depth=True)
    assert abs(depth.mean()) < 0.2 * depth.std()


def test_disarray_draws_after_the_scenario_and_only_when_on():
    base = {"position_e2_deg": 0.7}
    envs = [gym.make("SteppingStones-v0", vision_params={**base, "position_disarray": s}) for s in (0.0, 0.8)]
    full = gym.make("SteppingStones-v0", vision="full_view", vision_params={**base, "position_disarray": 0.8})
    courses = []
    for env in envs + [full]:
        env.reset(seed=11)
        courses.append(np.array([t.state(env.unwrapped.data)[0].copy() for t in env.unwrapped.task.all_targets]))
    np.testing.assert_array_equal(courses[0], courses[1])  # one seed, one scenario
    np.testing.assert_array_equal(courses[0], courses[2])
    assert envs[0].unwrapped.retina._disarray is None and envs[1].unwrapped.retina._disarray is not None
    assert full.unwrapped.retina._disarray is None  # FullView sees with the fovea everywhere
    # the field is seeded: the same seed draws the same field
    f1 = envs[1].unwrapped.retina._disarray.w.copy()
    envs[1].reset(seed=11)
    np.testing.assert_array_equal(f1, envs[1].unwrapped.retina._disarray.w)
    for env in envs + [full]:
        env.close()


def test_believed_sigmas_size_the_disarray_for_a_stream_of_looks():
    vp = VisionParams(position_e2_deg=0.7, position_disarray=0.8)
    d, ecc, dt = 3.0, 15.0 * DEG, 0.02
    base = fov._sigmas(d, ecc, 0.0, vp)
    assert fov.believed_sigmas(d, ecc, 0.0, vp) == base  # no dt: the eye's own stds
    assert fov.believed_sigmas(d, ecc, 0.0, VisionParams(position_e2_deg=0.7), None, dt) == \
        fov._sigmas(d, ecc, 0.0, VisionParams(position_e2_deg=0.7))  # no disarray: unchanged
    f = 1.0 + 15.0 / 0.7
    w = 0.8 * (1.0 - 1.0 / f**2)
    # a still image: one second of looks (50) read the same place
    assert fov.disarray_looks(ecc, 0.0, vp, dt) == pytest.approx(50.0)
    still = fov.believed_sigmas(d, ecc, 0.0, vp, None, dt)
    assert still[1] == pytest.approx(base[1] * math.sqrt(1.0 + w * 49.0))
    assert still[0] == base[0] and still[3:] == base[3:]  # depth and rates untouched
    # an image crossing the retina at 20 deg/s leaves the place (0.5 x (15 + 0.7) deg) in 0.39 s
    k = 1.0 + 0.5 * (15.0 + 0.7) / (20.0 * 0.02)
    assert fov.disarray_looks(ecc, 20.0 * DEG, vp, dt) == pytest.approx(k)
    # the covariance agents use carries the same lateral stds
    u = np.array(unit(0.0, -15.0)) * d
    cov = fov.covariance(u, 0.0, vp, dt=dt)
    lat_axis = np.array(unit(0.0, 75.0))  # perpendicular to u, in its vertical plane
    assert float(lat_axis @ cov[:3, :3] @ lat_axis) == pytest.approx(still[1] ** 2, rel=1e-9)
