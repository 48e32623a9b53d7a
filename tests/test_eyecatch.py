"""The Eyecatch baseline: its Kalman filter against filterpy, its pieces, and its catching."""

import gymnasium as gym
import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import make_agent
from visuomotor_gym.baselines.eyecatch import BallKalmanFilter, EyecatchAgent, EyecatchParams, KalmanParams
from visuomotor_gym.baselines.eyecatch.agent import _Superposition
from visuomotor_gym.bench.trace import run_episode
from visuomotor_gym.vision import foveation
from visuomotor_gym.vision.foveation import VisionParams


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


@pytest.mark.parametrize("process_noise", [0.0, 0.5])
def test_filter_matches_filterpy_on_identical_inputs(process_noise):
    """Eq. 4-14 against filterpy's KalmanFilter (the reset disabled: filterpy has none)."""
    rng = np.random.default_rng(0)
    dt = 0.02
    ours = BallKalmanFilter(dt, KalmanParams(reset_mahalanobis=1e12, process_noise_acc_m_s2=process_noise,
                                             measurement_floor_m=0.0))
    ref = KalmanFilter(dim_x=6, dim_z=6)
    ref.F = ours.F.copy()
    ref.B = ours.b.reshape(6, 1)
    ref.Q = ours.Q.copy()
    ref.x = ours.x.reshape(6, 1).copy()
    ref.P = ours.P.copy()
    vision = VisionParams()
    truth = np.array([4.0, 0.5, 1.5, -5.0, -0.3, 4.0])
    for k in range(40):
        if k:
            ours.predict()
            ref.predict(u=np.array([[1.0]]))
            truth = ours.F @ truth + ours.b
        rot = random_rotation(rng) if k % 7 == 0 else np.eye(3)
        eye = rng.normal(0, 0.1, 3) + np.array([0.1, 0.0, 1.1])
        H, h = BallKalmanFilter.observation_model(rot, eye)
        z_true = H @ truth + h
        R = foveation.covariance(z_true[:3], 0.3, vision)
        z = z_true + rng.multivariate_normal(np.zeros(6), R + 1e-12 * np.eye(6))
        ours.update(z, R, rot, eye)
        ref.H = H
        ref.update((z - h).reshape(6, 1), R=R)  # filterpy has no offset h: move it to z
        np.testing.assert_allclose(ours.x, ref.x.ravel(), rtol=1e-8, atol=1e-9)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-6, atol=1e-12)


def test_gravity_model_is_exact_for_ballistic_flight():
    f = BallKalmanFilter(0.02)
    f.x = np.array([0.0, 0.0, 1.0, 3.0, 0.0, 4.0])
    for _ in range(25):
        f.predict()
    t = 0.5
    np.testing.assert_allclose(f.x[:3], [3.0 * t, 0.0, 1.0 + 4.0 * t - 0.5 * 9.81 * t * t], atol=1e-12)
    np.testing.assert_allclose(f.extrapolate(0.1)[0], f.trajectory(np.array([0.1]))[0])


def test_adaptive_reset_after_a_sudden_change():
    """A confident filter meeting an impossible innovation resets P (Eyecatch 3.2)."""
    f = BallKalmanFilter(0.02)
    rot, eye = np.eye(3), np.zeros(3)
    R = np.eye(6) * 1e-4
    x = np.array([3.0, 0.0, 1.5, -4.0, 0.0, 3.0])
    for k in range(30):
        if k:
            f.predict()
            x = f.F @ x + f.b
        f.update(np.concatenate([x[:3], x[3:]]), R, rot, eye)
    assert f.resets == 0
    f.predict()
    bounced = f.F @ x + f.b
    bounced[4] = 4.0  # the lateral velocity flipped sign off a wall
    maha = f.update(bounced, R, rot, eye)
    assert maha > f.params.reset_mahalanobis and f.resets == 1
    assert abs(f.x[4] - 4.0) < 0.1  # the post-reset estimate follows the new course


def test_submovements_superpose_from_the_previous_destination():
    """Eq. 16: b_i is new destination minus previous destination; min-jerk profile; speed cap."""
    s = _Superposition(np.zeros(3))
    s.add(0.0, 0.4, np.array([0.3, 0.0, 0.0]))
    s.add(0.2, 0.4, np.array([0.3, 0.2, 0.0]))  # redirected mid-way
    np.testing.assert_allclose(s.position(10.0), [0.3, 0.2, 0.0])
    np.testing.assert_allclose(s.position(0.2), [0.3 * 0.5, 0.0, 0.0], atol=1e-12)  # min-jerk midpoint
    capped = _Superposition(np.zeros(3))
    capped.add(0.0, 0.4, np.array([2.0, 0.0, 0.0]), max_speed=2.0)
    assert capped.destination[0] == pytest.approx(2.0 * 0.4 / 1.875)  # peak speed exactly 2 m/s


def test_parameters_are_named_and_validated():
    with pytest.raises(TypeError, match="unknown Eyecatch parameter"):
        make_agent("eyecatch:nope=1", "EyeCatch-v0", 9)
    with pytest.raises(ValueError, match="hand_max_speed_m_s"):
        EyecatchParams(hand_max_speed_m_s=-1.0)
    agent = make_agent("eyecatch:hand_submovement_s=0.3", "EyeCatch-v0", 9)
    assert agent.params.hand_submovement_s == 0.3


def test_for_env_matches_the_vision_of_the_env():
    assert EyecatchAgent.for_env("EyeCatchPoorVision-v0").vision.noise_scale == 10.0
    assert EyecatchAgent.for_env("EyeCatchFullView-v0").vision.foveated is False
    assert EyecatchAgent.for_env("EyeCatchDelayed-v0").delay_steps == 5
    assert EyecatchAgent.for_env("EyeCatchOracle-v0").vision.noise_scale == 0.0


@pytest.mark.parametrize("env_id, seeds, minimum", [("EyeCatch-v0", range(20), 18), ("EyeCatchFullView-v0", range(10), 9)])
def test_catches_through_the_eye(env_id, seeds, minimum):
    env = gym.make(env_id)
    agent = make_agent("eyecatch", env_id, 9)
    traces = [run_episode(env, agent, s, env_id, "eyecatch") for s in seeds]
    assert sum(t.caught for t in traces) >= minimum
    # It looks where the ball is: median gaze-ball angle under 2 deg while the ball is in flight.
    angles = []
    for t in traces:
        rel = t.ball_pos - t.eye_pos
        cos = np.einsum("ij,ij->i", rel, t.gaze_dir) / np.linalg.norm(rel, axis=1)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1)))[: len(cos) * 3 // 4])
    assert np.median(np.concatenate(angles)) < 2.0
    # Hand speed stays human (<= 2 m/s reference, servo overshoot allowed).
    speeds = np.concatenate([np.linalg.norm(np.diff(t.hand_pos, axis=0), axis=1) / t.dt for t in traces])
    assert speeds.max() < 2.5


def test_predict_is_deterministic_and_resets_on_episode_start():
    env = gym.make("EyeCatch-v0")
    a = make_agent("eyecatch", "EyeCatch-v0", 9)
    t1 = run_episode(env, a, 3, "EyeCatch-v0", "eyecatch")
    t2 = run_episode(env, a, 3, "EyeCatch-v0", "eyecatch")  # same agent object, reused
    np.testing.assert_array_equal(t1.action[1:], t2.action[1:])
    with pytest.raises(ValueError, match="flat EyeCatch observation"):
        a.predict(np.zeros(5))


def test_first_saccade_waits_for_a_reliable_estimate():
    """The first saccade is suppressed until the retinal uncertainty is low (Eyecatch 4.1): with an
    unreachable threshold the eye only pursues; with the default it saccades once released."""
    env = gym.make("EyeCatch-v0")
    never = make_agent("eyecatch:first_saccade_retinal_std_deg=1e-6", "EyeCatch-v0", 9)
    t = run_episode(env, never, 0, "EyeCatch-v0", "eyecatch")
    assert not never.first_saccade_released
    assert not t.saccade_onset.any()
    default = make_agent("eyecatch", "EyeCatch-v0", 9)
    t = run_episode(env, default, 0, "EyeCatch-v0", "eyecatch")
    assert default.first_saccade_released and t.saccade_onset.any()


def _angles_deg(a, b):
    return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)))


def test_head_pursues_with_the_eye():
    """Eyecatch 4.2: the head adds the eye's pursuit velocity. With the first saccade never released
    (so no visuomotor update, hence no head saccade), only head pursuit moves the head: it carries the
    eye along, which stays near the head's axis (not at its +27.7 deg elevation limit) and on the ball."""
    env = gym.make("EyeCatch-v0")
    spec = "eyecatch:first_saccade_retinal_std_deg=1e-6"
    for seed in (0, 1):
        still = run_episode(env, make_agent(spec + ",head_pursuit_gain=0", "EyeCatch-v0", 9), seed, "EyeCatch-v0", "x")
        pursuing = run_episode(env, make_agent(spec, "EyeCatch-v0", 9), seed, "EyeCatch-v0", "x")
        for t in (still, pursuing):
            assert not t.saccade_onset.any()
        n = min(len(still.t), len(pursuing.t)) * 2 // 3  # the flight before the hand region
        head_turn = lambda t: _angles_deg(np.repeat(t.head_dir[:1], n, axis=0), t.head_dir[:n]).max()
        eye_in_head = lambda t: _angles_deg(t.gaze_dir[:n], t.head_dir[:n]).max()
        assert head_turn(still) < 0.5
        assert head_turn(pursuing) > 15.0
        assert eye_in_head(pursuing) < 0.6 * eye_in_head(still)
        rel = pursuing.ball_pos[:n] - pursuing.eye_pos[:n]
        rel /= np.linalg.norm(rel, axis=1, keepdims=True)
        assert np.median(_angles_deg(pursuing.gaze_dir[:n], rel)) < 1.0
