"""Tests of the oculomotor plant (saccades, pursuit, refractory period) and of the
vestibulo-ocular reflex in the EyeCatch environment.

The plant is driven directly with ``record=True``, ``dt = 0.02`` and 10 substeps, and judged on its
500 Hz trace against closed forms: main sequence D = 21 ms + 2.2 ms/deg * A (stretched so the
minimum-jerk peak 1.875 A / D stays <= 800 deg/s), s(u) = 10u^3 - 15u^4 + 6u^5 along the great
circle, 200 ms between saccade onsets; pursuit driven by the request stream's motion with the
sourced onset latency, gain (Schalen 1980), acceleration bound and 100 deg/s cap, and refused
saccades never executed as pursuit.
"""

from __future__ import annotations

import itertools
import math

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the environment ids)
from visuomotor_gym.oculomotor.plant import (
    OculomotorParams,
    OculomotorPlant,
    angles_from_direction,
    direction_from_angles,
)

DEG = math.pi / 180.0
DT = 0.02
N_SUB = 10
H = DT / N_SUB  # 2 ms substep
X = np.array([1.0, 0.0, 0.0])


def ang(a, b) -> float:
    """Angle between two unit vectors (independent of the package's helper)."""
    a = np.asarray(a, float) / np.linalg.norm(a)
    b = np.asarray(b, float) / np.linalg.norm(b)
    return math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))


def main_sequence(amp_deg: float) -> float:
    return 0.021 + 0.0022 * amp_deg


def expected_duration(amp_deg: float) -> float:
    return max(main_sequence(amp_deg), 1.875 * amp_deg / 800.0)


def mj(u):
    return 10 * u**3 - 15 * u**4 + 6 * u**5


def new_plant(params=None, gaze=X):
    plant = OculomotorPlant(params, record=True)
    plant.reset(np.asarray(gaze, float), time=0.0)
    return plant


def run(plant, targets):
    """Step the plant once per target; return the PlantStep results."""
    return [plant.step(np.asarray(t, float), DT, N_SUB) for t in targets]


def trace_speeds(plant):
    """Finite-difference angular speeds (rad/s) between consecutive trace samples, at midpoints."""
    t, g = plant.trace()
    dt = np.diff(t)
    d_ang = np.array([ang(g[i], g[i + 1]) for i in range(len(g) - 1)])
    return 0.5 * (t[1:] + t[:-1]), d_ang / dt


def saccade_target(amp_deg: float) -> np.ndarray:
    return direction_from_angles(amp_deg * DEG, 0.0)


def single_saccade(amp_deg: float, target=None):
    plant = new_plant()
    target = saccade_target(amp_deg) if target is None else target
    n_steps = int(math.ceil(expected_duration(amp_deg) / DT)) + 2
    steps = run(plant, [target] * n_steps)
    return plant, steps


# ------------------------------------------------------------------------------------------------
# Saccades
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("amp_deg", [5.0, 10.0, 20.0, 40.0, 80.0])
def test_saccade_duration_follows_main_sequence(amp_deg):
    plant, steps = single_saccade(amp_deg)
    assert steps[0].saccade_started and steps[0].saccading
    assert not any(s.saccade_started for s in steps[1:])
    assert len(plant.saccades) == 1
    sac = plant.saccades[0]
    assert sac.onset == 0.0
    assert sac.amplitude == pytest.approx(amp_deg * DEG, rel=1e-12)
    assert sac.duration == pytest.approx(main_sequence(amp_deg), rel=1e-12)

    t, g = plant.trace()
    assert np.allclose(np.diff(t), H)  # 500 Hz trace
    start, end = X, saccade_target(amp_deg)
    moved = np.array([ang(start, gi) for gi in g]) > 1e-12
    onset_measured = t[np.argmax(moved) - 1]  # last sample still at the start
    assert onset_measured == pytest.approx(0.0, abs=1e-12)
    at_end = np.array([ang(end, gi) for gi in g]) < 1e-9
    first = int(np.argmax(at_end))
    assert at_end[first:].all()  # stays landed
    measured = t[first] - onset_measured
    assert abs(measured - main_sequence(amp_deg)) <= H + 1e-9
    # and it is not already there one substep before the main-sequence duration is over
    assert measured >= main_sequence(amp_deg) - H - 1e-9
    # the in-flight flags agree with the duration
    n_in_flight = sum(s.saccading for s in steps)
    assert n_in_flight == math.ceil(main_sequence(amp_deg) / DT - 1e-9)


@pytest.mark.parametrize("amp_deg", [5.0, 10.0, 20.0, 40.0, 80.0, 120.0, 150.0, 170.0, 179.0])
def test_saccade_peak_speed(amp_deg):
    plant, _ = single_saccade(amp_deg)
    _, speed = trace_speeds(plant)
    peak = speed.max() / DEG
    assert peak <= 800.0 * (1 + 1e-9)
    want = 1.875 * amp_deg / expected_duration(amp_deg)
    assert want <= 800.0 + 1e-9
    assert peak == pytest.approx(want, rel=0.02)
    assert plant.saccades[0].duration == pytest.approx(expected_duration(amp_deg), rel=1e-12)
    if amp_deg >= 170.0:  # main sequence alone would exceed 800 deg/s: the cap binds
        assert 1.875 * amp_deg / main_sequence(amp_deg) > 800.0
        assert peak == pytest.approx(800.0, rel=0.005)


@pytest.mark.parametrize("amp_deg", [10.0, 40.0, 120.0])
def test_saccade_profile_is_minimum_jerk_along_great_circle(amp_deg):
    target = direction_from_angles(amp_deg * 0.6 * DEG, -amp_deg * 0.3 * DEG)  # oblique
    amp = ang(X, target)
    plant, steps = single_saccade(amp / DEG, target=target)
    sac = plant.saccades[0]
    t, g = plant.trace()
    normal = np.cross(X, target)
    normal /= np.linalg.norm(normal)
    in_flight = (t >= sac.onset) & (t <= sac.onset + sac.duration)
    assert in_flight.sum() >= 10
    for ti, gi in zip(t[in_flight], g[in_flight]):
        u = (ti - sac.onset) / sac.duration
        assert abs(np.linalg.norm(gi) - 1.0) < 1e-12
        assert abs(gi @ normal) < 1e-12  # on the great circle
        assert ang(X, gi) == pytest.approx(amp * mj(u), abs=1e-9)
        assert ang(gi, target) == pytest.approx(amp * (1.0 - mj(u)), abs=1e-9)
    assert sum(s.saccading for s in steps) == math.ceil(sac.duration / DT - 1e-9)
    # Eq. 15: the reported angular velocity at each step end is the minimum-jerk speed
    plant2 = new_plant()
    for k in range(int(math.ceil(sac.duration / DT))):
        plant2.step(target, DT, N_SUB)
        u = min((k + 1) * DT / sac.duration, 1.0)
        w = plant2.angular_velocity
        speed = amp * 30 * u**2 * (1 - u) ** 2 / sac.duration
        assert np.linalg.norm(w) == pytest.approx(speed, rel=1e-9, abs=1e-12)
        if speed > 0:
            np.testing.assert_allclose(w / np.linalg.norm(w), normal, atol=1e-12)


def test_saccade_is_ballistic():
    first = saccade_target(30.0)  # D = 87 ms
    second = direction_from_angles(-20.0 * DEG, 25.0 * DEG)
    plant = new_plant()
    steps = run(plant, [first] + [second] * 20)
    sac = plant.saccades[0]
    assert sac.duration == pytest.approx(0.087)
    np.testing.assert_allclose(sac.end, first, atol=1e-15)
    t, g = plant.trace()
    landing = int(np.argmax(t >= sac.onset + sac.duration - 1e-12))
    assert ang(g[landing], first) < 1e-9  # lands where it was aimed at onset
    normal = np.cross(X, first)
    normal /= np.linalg.norm(normal)
    for gi in g[: landing + 1]:
        assert abs(gi @ normal) < 1e-12  # never deviated toward the new target in flight
    # the new target is taken up only after landing, by a saccade when the refractory period ends
    assert [s.saccade_started for s in steps].count(True) == 2
    assert plant.saccades[1].onset == pytest.approx(0.2, abs=1e-9)
    np.testing.assert_allclose(plant.saccades[1].start, g[int(round(0.2 / H))], atol=1e-15)


def test_near_antipodal_saccade_stays_on_the_unit_sphere():
    """1e-6 rad short of straight behind: still a clean minimum-jerk half turn."""
    target = direction_from_angles(math.pi - 1e-6, 0.0)
    plant, _ = single_saccade(180.0, target=target)
    _, g = plant.trace()
    assert np.all(np.isfinite(g))
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=1e-8)
    assert ang(plant.gaze, target) < 1e-9


@pytest.mark.parametrize("target", [np.array([-1.0, 0.0, 0.0]), direction_from_angles(math.pi, 0.0)])
def test_antipodal_saccade_is_well_defined(target):
    plant = new_plant()
    prev_angle = 0.0
    for _ in range(int(math.ceil(expected_duration(180.0) / DT)) + 1):
        plant.step(target, DT, N_SUB)
        assert np.all(np.isfinite(plant.gaze))
        assert np.linalg.norm(plant.gaze) == pytest.approx(1.0, abs=1e-9)
        angle = ang(X, plant.gaze)
        assert angle >= prev_angle - 1e-9  # moves monotonically away from the start
        prev_angle = angle
    _, g = plant.trace()
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=1e-9)
    assert ang(plant.gaze, target) < 1e-9


def test_saccade_threshold():
    for amp_deg, expect in [(2.9, False), (3.1, True), (10.0, True)]:
        plant = new_plant()
        (step,) = run(plant, [saccade_target(amp_deg)])
        assert step.saccade_started is expect
        assert (len(plant.saccades) == 1) is expect


def test_refractory_period_between_onsets_and_no_pursuit_meanwhile():
    """Alternating 50 deg jumps every control step: onsets >= 200 ms apart, and the refused jumps
    are not carried out as pursuit (they are position steps, not target motion): the eye is still."""
    left, right = saccade_target(25.0), saccade_target(-25.0)
    plant = new_plant()
    steps = run(plant, [left if k % 2 == 0 else right for k in range(60)])
    onsets = np.array([s.onset for s in plant.saccades])
    assert len(onsets) >= 5
    gaps = np.diff(onsets)
    assert np.all(gaps >= 0.2 - 1e-9), gaps
    assert np.all(gaps <= 0.2 + DT + 1e-9), gaps  # and it fires again as soon as allowed
    started = [k for k, s in enumerate(steps) if s.saccade_started]
    np.testing.assert_allclose(np.array(started) * DT, onsets, atol=1e-9)
    mid, speed = trace_speeds(plant)
    in_sac = saccade_mask(plant, mid, margin=H)  # (a landing falls between two substeps)
    assert (~in_sac).sum() > 100
    assert speed[~in_sac].max() < 1e-9
    deferred = [k for k, s in enumerate(steps) if s.saccade_deferred]
    assert deferred and not set(deferred) & set(started)


def test_zero_refractory_allows_back_to_back_saccades():
    plant = new_plant(OculomotorParams(saccade_refractory_s=0.0))
    run(plant, [saccade_target(10.0)] * 3 + [saccade_target(-10.0)] * 4)
    onsets = [s.onset for s in plant.saccades]
    # 10 deg lasts 43 ms: landed by the end of step 3 (60 ms), re-fires at 60 ms
    assert onsets == pytest.approx([0.0, 0.06])


# ------------------------------------------------------------------------------------------------
# Pursuit
# ------------------------------------------------------------------------------------------------
P = OculomotorParams()
LATENCY = P.pursuit_latency_s
ACCEL = P.pursuit_accel_max_deg_s2 * DEG


def ramp(speed_deg_s, start_s=0.0, elevation_deg_s=0.0):
    """Request stream of a target still until ``start_s``, then moving at constant angular speed."""
    def at(k):
        t = max(k * DT - start_s, 0.0)
        return direction_from_angles(speed_deg_s * DEG * t, elevation_deg_s * DEG * t)
    return at


def horizontal_kinematics(plant):
    """(substep times, azimuth velocity, azimuth acceleration) of the trace, in rad, s."""
    t, g = plant.trace()
    az = np.unwrap([angles_from_direction(x)[0] for x in g])
    vel = np.diff(az) / np.diff(t)
    acc = np.diff(vel) / np.diff(t)[1:]
    return t, vel, acc


def saccade_mask(plant, times, margin=0.0):
    mask = np.zeros_like(times, dtype=bool)
    for sac in plant.saccades:
        mask |= (times > sac.onset - 1e-12) & (times < sac.onset + sac.duration + margin)
    return mask


def test_pursuit_gain_follows_schalen_1980():
    """0.98 at 10 deg/s falling to 0.75 at 60 deg/s (Schalen 1980), linear in between, capped at 100."""
    assert P.pursuit_gain(10.0) == pytest.approx(0.98)
    assert P.pursuit_gain(60.0) == pytest.approx(0.75)
    assert P.pursuit_gain(30.0) == pytest.approx(0.98 - 0.23 * 20 / 50)
    assert P.pursuit_gain(2.0) == pytest.approx(0.98) and P.pursuit_gain(90.0) == pytest.approx(0.75)
    speeds = np.linspace(0, 200, 401)
    gains = [P.pursuit_gain(s) for s in speeds]
    assert np.all(np.diff(gains) <= 1e-12) and all(g < 1.0 for g in gains)
    assert max(P.pursuit_velocity(s) for s in speeds) == pytest.approx(100.0)


@pytest.mark.parametrize("speed_deg_s,gain", [(10.0, 0.98), (30.0, 0.888), (60.0, 0.75)])
def test_steady_state_pursuit_gain(speed_deg_s, gain):
    """Desaccaded eye velocity once pursuit has settled: the sourced gain times the target speed
    (catch-up saccades may interrupt it; the pursuit velocity persists through them)."""
    plant = new_plant()
    target = ramp(speed_deg_s)
    run(plant, [target(k) for k in range(1, 60)])  # 1.2 s
    t, vel, _ = horizontal_kinematics(plant)
    mid = t[1:]
    settled = (mid > 0.6) & ~saccade_mask(plant, mid, margin=2 * H)
    assert settled.sum() > 100
    np.testing.assert_allclose(vel[settled] / DEG, gain * speed_deg_s, rtol=1e-6)
    if speed_deg_s >= 60.0:  # the eye falls behind by (1 - gain) * speed: catch-up saccades
        assert len(plant.saccades) >= 2
    else:
        assert ang(plant.gaze, target(59)) < 3.0 * DEG + 1e-9


@pytest.mark.parametrize("latency", [None, 0.1])
def test_pursuit_onset_latency(latency):
    """The eye stays still for the onset latency after the request stream starts to move."""
    params = OculomotorParams() if latency is None else OculomotorParams(pursuit_latency_s=latency)
    plant = new_plant(params)
    start = 0.1  # the request at step k = 6 (t = 0.12 s) is the first that moved
    target = ramp(10.0, start_s=start)
    run(plant, [target(k) for k in range(30)])
    revealed = 6 * DT
    t, g = plant.trace()
    moved = np.array([ang(X, x) for x in g])
    still = t <= revealed + params.pursuit_latency_s + 1e-9
    assert moved[still].max() < 1e-12
    assert moved[t >= revealed + params.pursuit_latency_s + H - 1e-9].min() > 0.0
    assert plant.saccades == []


@pytest.mark.parametrize("accel", [None, 300.0])
def test_pursuit_acceleration_is_bounded(accel):
    """A step-ramp at 60 deg/s: the eye accelerates at the bound (Robinson 1965: ~130 ms per velocity
    transition at 100 deg/s) until it reaches the gain-scaled speed; never faster."""
    params = OculomotorParams() if accel is None else OculomotorParams(pursuit_accel_max_deg_s2=accel)
    plant = new_plant(params)
    target = ramp(60.0)
    run(plant, [target(k) for k in range(1, 30)])
    t, vel, acc = horizontal_kinematics(plant)
    mid = t[1:-1]
    pursuit = ~saccade_mask(plant, mid, margin=2 * H) & ~saccade_mask(plant, mid - H, margin=2 * H)
    a_max = params.pursuit_accel_max_deg_s2 * DEG
    assert np.abs(acc[pursuit]).max() <= a_max * (1 + 1e-6)
    assert np.abs(acc[pursuit]).max() == pytest.approx(a_max, rel=1e-6)  # the bound is reached
    # time to reach 0.75 * 60 deg/s from rest: 45 / a_max after the latency
    v_final = 0.75 * 60.0 * DEG
    reached = mid[(vel[1:] >= v_final * (1 - 1e-9)) & pursuit]
    assert reached.min() == pytest.approx(DT + params.pursuit_latency_s + v_final / a_max, abs=2 * H)


def test_refused_saccade_waits_static_target_not_reached_by_pursuit():
    """The refractory loophole: a static 12 deg target inside the refractory period is not pursued;
    it is reached only by the saccade that starts when the generator recharges (flag on)."""
    plant = new_plant()
    first = saccade_target(5.0)
    run(plant, [first] * 3)  # a 5 deg saccade at t = 0 (32 ms), refractory until 200 ms
    landing = plant.gaze.copy()
    far = direction_from_angles(17.0 * DEG, 0.0)  # 12 deg from the landing point, static
    for _k in range(3, 10):  # steps starting at 60 ... 180 ms
        s = plant.step(far, DT, N_SUB)
        assert s.saccade_deferred and not s.saccade_started and not s.saccading
        assert ang(landing, plant.gaze) < 1e-12  # not moved: no pursuit of a static target
    s = plant.step(far, DT, N_SUB)  # t = 200 ms: the saccade generator is recharged
    assert s.saccade_started and not s.saccade_deferred
    assert plant.saccades[-1].onset == pytest.approx(0.2)
    run(plant, [far] * 4)
    assert ang(plant.gaze, far) < 1e-9
    # with saccades impossible (refractory longer than the run), the eye never gets there
    plant = new_plant(OculomotorParams(saccade_refractory_s=10.0))
    run(plant, [first] * 3)
    landing = plant.gaze.copy()
    steps = run(plant, [far] * 6)  # 120 ms
    assert not any(s.saccade_started or s.saccading for s in steps)
    assert ang(landing, plant.gaze) < 1e-12


@pytest.mark.parametrize("amp_deg", [0.5, 2.0, 2.9])
def test_static_sub_threshold_offset_is_not_pursued(amp_deg):
    """Pursuit needs target motion: a still request below the saccade threshold moves nothing."""
    plant = new_plant()
    steps = run(plant, [direction_from_angles(0.0, amp_deg * DEG)] * 20)
    assert ang(X, plant.gaze) < 1e-12
    assert plant.saccades == [] and not any(s.saccade_deferred for s in steps)


def test_refused_saccades_never_move_the_eye_faster_than_pursuit():
    """A random request stream (jumps, ramps, holds): outside saccades the eye never exceeds the
    pursuit speed cap nor the acceleration bound, whatever was refused."""
    rng = np.random.default_rng(3)
    plant = new_plant()
    az = el = 0.0
    for _k in range(300):
        r = rng.random()
        if r < 0.15:
            az, el = az + rng.normal(0, 20) * DEG, el + rng.normal(0, 10) * DEG  # jump
        elif r < 0.8:
            az, el = az + rng.normal(0, 2.0) * DEG, el + rng.normal(0, 1.0) * DEG  # fast motion
        plant.step(direction_from_angles(az, max(min(el, 1.2), -1.2)), DT, N_SUB)
    t, g = plant.trace()
    speeds = np.array([ang(g[i], g[i + 1]) for i in range(len(g) - 1)]) / H
    mid = t[1:]
    free = ~saccade_mask(plant, mid, margin=H)
    assert free.sum() > 1000 and len(plant.saccades) > 5
    assert speeds[free].max() <= 100 * DEG * (1 + 1e-6)
    assert speeds[free].max() > 50 * DEG  # the stream did drive pursuit


def test_pursuit_velocity_persists_through_a_catch_up_saccade():
    plant = new_plant()
    target = ramp(60.0)
    run(plant, [target(k) for k in range(1, 60)])
    t, vel, _ = horizontal_kinematics(plant)
    sac = next(s for s in plant.saccades if s.onset > 0.5)
    before = vel[(t[1:] > sac.onset - 4 * H) & (t[1:] <= sac.onset)]
    after = vel[(t[1:] > sac.onset + sac.duration + H) & (t[1:] < sac.onset + sac.duration + 5 * H)]
    np.testing.assert_allclose(before / DEG, 45.0, rtol=1e-6)
    np.testing.assert_allclose(after / DEG, 45.0, rtol=1e-6)


def test_pursuit_is_deterministic():
    def go():
        plant = new_plant()
        rng = np.random.default_rng(0)
        out = []
        for k in range(80):
            plant.step(direction_from_angles(0.9 * k * DT + 0.05 * rng.standard_normal(), 0.0), DT, N_SUB)
            out.append(plant.gaze.copy())
        return np.array(out)
    np.testing.assert_array_equal(go(), go())


def test_fast_target_outruns_pursuit_and_triggers_catch_up_saccades():
    """A 140 deg/s target (2.8 deg per step) is below the threshold per step, but the lag grows."""
    plant = new_plant()
    for k in range(1, 60):
        plant.step(direction_from_angles(140.0 * DEG * k * DT, 0.0), DT, N_SUB)
    assert len(plant.saccades) >= 2
    for sac in plant.saccades:
        assert sac.amplitude > 3.0 * DEG
    onsets = np.array([s.onset for s in plant.saccades])
    assert np.all(np.diff(onsets) >= 0.2 - 1e-9)
    mid, speed = trace_speeds(plant)
    in_sac = np.zeros_like(mid, dtype=bool)
    for sac in plant.saccades:
        in_sac |= (mid > sac.onset) & (mid < sac.onset + sac.duration)
    assert speed[~in_sac].max() <= 100 * DEG * (1 + 1e-9)


def test_saccade_endpoint_noise_is_proportional_to_amplitude():
    params = OculomotorParams(saccade_endpoint_noise=0.1)
    rng = np.random.default_rng(11)
    amp_deg = 20.0
    target = direction_from_angles(amp_deg * DEG, 10.0 * DEG)
    start = direction_from_angles(0.0, 10.0 * DEG)
    errs = []
    plant = OculomotorPlant(params)
    for _ in range(1000):
        plant.reset(start)
        plant.step(target, DT, N_SUB, rng)
        errs.append(ang(plant.saccades[0].end, target))
    errs = np.array(errs)
    # two independent angular offsets of std 0.1 * A: E[err^2] = 2 (0.1 A)^2
    ratio = np.mean(errs**2) / (2 * (0.1 * amp_deg * DEG) ** 2)
    assert ratio == pytest.approx(1.0, abs=0.15)
    # without an rng (or with zero noise) it lands exactly
    plant.reset(start)
    plant.step(target, DT, N_SUB)
    assert ang(plant.saccades[0].end, target) < 1e-12


def test_trace_needs_record():
    plant = OculomotorPlant()
    with pytest.raises(RuntimeError):
        plant.trace()


# ------------------------------------------------------------------------------------------------
# Parameters
# ------------------------------------------------------------------------------------------------
POSITIVE = [
    "saccade_threshold_deg",
    "main_sequence_slope_s_per_deg",
    "saccade_peak_deg_s",
    "pursuit_max_deg_s",
    "pursuit_accel_max_deg_s2",
    "vergence_max_diopter_s",
    "head_max_deg_s",
]
NONNEG = ["saccade_refractory_s", "main_sequence_intercept_s", "saccade_endpoint_noise", "pursuit_latency_s"]


@pytest.mark.parametrize("points", [(), ((10.0, 0.9), (5.0, 0.8)), ((10.0, 0.0),), ((10.0, float("nan")),)])
def test_oculomotor_params_rejects_bad_gain_points(points):
    with pytest.raises(ValueError):
        OculomotorParams(pursuit_gain_points=points)


@pytest.mark.parametrize("field", POSITIVE)
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), float("inf")])
def test_oculomotor_params_rejects_non_positive(field, value):
    with pytest.raises(ValueError):
        OculomotorParams(**{field: value})


@pytest.mark.parametrize("field", NONNEG)
@pytest.mark.parametrize("value", [-1e-6, float("nan"), float("inf")])
def test_oculomotor_params_rejects_negative(field, value):
    with pytest.raises(ValueError):
        OculomotorParams(**{field: value})


@pytest.mark.parametrize("field", NONNEG)
def test_oculomotor_params_accepts_zero(field):
    assert getattr(OculomotorParams(**{field: 0.0}), field) == 0.0


def test_env_rejects_bad_oculomotor_params():
    with pytest.raises(ValueError):
        gym.make("EyeCatch-v0", oculomotor_params={"pursuit_max_deg_s": -5.0})
    with pytest.raises(TypeError):
        gym.make("EyeCatch-v0", oculomotor_params={"no_such_field": 1.0})


def test_saccade_duration_closed_form():
    p = OculomotorParams()
    for amp_deg in (0.0, 1.0, 10.0, 100.0, 146.0, 147.0, 180.0):
        assert p.saccade_duration(amp_deg * DEG) == pytest.approx(expected_duration(amp_deg), rel=1e-12)
    slow = OculomotorParams(saccade_peak_deg_s=300.0)
    assert slow.saccade_duration(40 * DEG) == pytest.approx(1.875 * 40 / 300.0)


# ------------------------------------------------------------------------------------------------
# Vestibulo-ocular reflex in the environment
# ------------------------------------------------------------------------------------------------
AZ_LIM = 44.2 * DEG
EL_LIM = (-47.1 * DEG, 27.7 * DEG)


def _head_action(yaw, pitch=0.0):
    a = np.zeros(9, dtype=np.float32)  # gaze change 0: hold gaze fixed in the world
    a[7], a[8] = yaw, pitch
    return a


def _run_head(seed, actions):
    env = gym.make("EyeCatch-v0")
    s = env.unwrapped.layout.slices
    obs, info = env.reset(seed=seed)

    def row():
        # (world gaze, eye-in-head (az, el), eye frame, neck (yaw, pitch), body joints)
        return (
            info["gaze_dir"].copy(),
            obs[s["eye_in_head"]].astype(float),
            obs[s["eye_rot"]].astype(float).reshape(3, 3),
            obs[s["head_qpos"]].astype(float),
            obs[s["body_qpos"]].astype(float),
        )

    rows = [row()]
    for a in actions:
        obs, _, term, trunc, info = env.step(a)
        assert not info["saccade_onset"]
        rows.append(row())
        if term or trunc:
            break
    env.close()
    return rows


def _clamped(eye_in_head, tol=1e-4):
    az, el = eye_in_head
    return abs(abs(az) - AZ_LIM) < tol or abs(el - EL_LIM[0]) < tol or abs(el - EL_LIM[1]) < tol


@pytest.mark.parametrize("seed,yaw", [(0, 0.5), (2, -0.5), (3, 0.3)])
def test_vor_holds_gaze_while_head_turns(seed, yaw):
    rows = _run_head(seed, [_head_action(yaw)] * 10)
    g0, e0, _, h0, b0 = rows[0]
    unclamped = [r for r in rows[1:] if not _clamped(r[1], tol=0.3 * DEG)]
    assert len(unclamped) >= 6
    for g, e, rot, h, b in unclamped:
        assert ang(g, g0) < 1e-9  # world gaze fixed
        np.testing.assert_allclose(rot[:, 0], g, atol=1e-6)
        # the eye counter-rotates by the head's (and torso's) yaw
        assert (e[0] - e0[0]) == pytest.approx(-((h[0] - h0[0]) + (b[0] - b0[0])), abs=1.0 * DEG)
    g, e, _, h, b = unclamped[-1]
    assert abs(e[0] - e0[0]) > 15 * DEG  # the eye really moved in the head
    assert np.sign(e[0] - e0[0]) == -np.sign(yaw)


# Head pitch action -1 turns the head 50 deg down, so the eye must look up past its +27.7 deg limit;
# yaw +-1 turns the head 80 deg, past the eye's +-44.2 deg azimuth range.
@pytest.mark.parametrize("seed,head", [(0, (1.0, 0.0)), (1, (-1.0, 0.0)), (2, (0.0, -1.0)), (4, (0.0, -1.0))])
def test_vor_range_clamp_carries_gaze_with_head(seed, head):
    rows = _run_head(seed, [_head_action(*head)] * 30)
    clamped_seen = False
    for prev, cur in itertools.pairwise(rows):
        g_prev, g, e, rot = prev[0], cur[0], cur[1], cur[2]
        az, el = e
        assert -AZ_LIM - 1e-6 <= az <= AZ_LIM + 1e-6
        assert EL_LIM[0] - 1e-6 <= el <= EL_LIM[1] + 1e-6
        np.testing.assert_allclose(rot[:, 0], g, atol=1e-6)  # plant gaze = where the eye points
        if _clamped(e):
            clamped_seen = True
        else:
            assert ang(g, g_prev) < 1e-9  # inside the range the VOR holds gaze exactly
    assert clamped_seen
    g0, g_end = rows[0][0], rows[-1][0]
    assert ang(g0, g_end) > 10 * DEG  # once clamped, the gaze was carried with the head
    if head[0] != 0.0:
        # while clamped in azimuth, the world gaze azimuth follows head + torso yaw
        idx = [i for i, r in enumerate(rows) if abs(abs(r[1][0]) - AZ_LIM) < 1e-4]
        i0, i1 = idx[0], idx[-1]
        assert i1 - i0 >= 5
        d_gaze = angles_from_direction(rows[i1][0])[0] - angles_from_direction(rows[i0][0])[0]
        d_head = (rows[i1][3][0] - rows[i0][3][0]) + (rows[i1][4][0] - rows[i0][4][0])
        assert abs(d_head) > 10 * DEG
        assert d_gaze == pytest.approx(d_head, abs=1.5 * DEG)


def test_saccade_history_is_bounded_unless_recording():
    """An env stepped without end (after termination) must not grow the plant without bound."""
    from visuomotor_gym.oculomotor.plant import SACCADE_HISTORY

    plant = OculomotorPlant(OculomotorParams())
    plant.reset(direction_from_angles(0.0, 0.0), time=0.0)
    rng = np.random.default_rng(0)
    for k in range(6000):  # a 10 deg jump every 0.3 s: one saccade per 15 steps
        az = math.radians(10.0 * ((k // 15) % 2))
        plant.step(direction_from_angles(az, 0.0), 0.02, 10, rng)
    assert len(plant.saccades) == SACCADE_HISTORY
    recording = OculomotorPlant(OculomotorParams(), record=True)
    recording.reset(direction_from_angles(0.0, 0.0), time=0.0)
    for k in range(6000):
        az = math.radians(10.0 * ((k // 15) % 2))
        recording.step(direction_from_angles(az, 0.0), 0.02, 10, rng)
    assert len(recording.saccades) > SACCADE_HISTORY  # everything kept, with the trace
