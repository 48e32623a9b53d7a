"""The throw sampler: exact arrival, seeded, catchable ranges, and a real bounce."""

import gymnasium as gym
import mujoco
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401
from visuomotor_gym.assets import asset_path
from visuomotor_gym.scenarios.throws import ThrowDistribution, launch_velocity, sample_throw


def test_launch_velocity_lands_exactly_in_mujoco():
    """Inverting semi-implicit Euler puts the simulated ball on the arrival point to ~1e-9 m."""
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><option timestep="0.002" integrator="Euler"/><worldbody><body><freejoint/>'
        '<geom size="0.025" contype="0" conaffinity="0"/></body></worldbody></mujoco>'
    )
    data = mujoco.MjData(model)
    rng = np.random.default_rng(1)
    for _ in range(5):
        release = rng.uniform([3, -1, 1], [6, 1, 2])
        arrival = rng.uniform([0.3, -0.4, 0.85], [0.45, -0.1, 1.2])
        n = int(rng.integers(400, 700))
        mujoco.mj_resetData(model, data)
        data.qpos[:3] = release
        data.qvel[:3] = launch_velocity(release, arrival, n, 0.002)
        mujoco.mj_step(model, data, nstep=n)
        assert np.linalg.norm(data.qpos[:3] - arrival) < 1e-9


def test_samples_are_seeded_and_inside_the_ranges():
    dist = ThrowDistribution()
    a = [sample_throw(np.random.default_rng(7), dist, 0.002) for _ in range(2)]
    assert np.array_equal(a[0].release_vel, a[1].release_vel)
    rng = np.random.default_rng(0)
    for _ in range(200):
        t = sample_throw(rng, dist, 0.002)
        assert dist.release_x_m[0] <= t.release_pos[0] <= dist.release_x_m[1]
        assert dist.arrival_z_m[0] <= t.arrival_pos[2] <= dist.arrival_z_m[1]
        assert dist.flight_time_s[0] - 0.002 <= t.flight_time <= dist.flight_time_s[1] + 0.002
        assert t.wall_y is None


def test_bounce_and_plain_throws_share_their_random_draws():
    plain = sample_throw(np.random.default_rng(3), ThrowDistribution(), 0.002, bounce=False)
    bounce = sample_throw(np.random.default_rng(3), ThrowDistribution(), 0.002, bounce=True)
    assert np.array_equal(plain.arrival_pos, bounce.arrival_pos)
    assert plain.flight_time == bounce.flight_time
    assert bounce.wall_y is not None and not np.array_equal(plain.release_vel, bounce.release_vel)


def test_distribution_rejects_bad_ranges():
    with pytest.raises(ValueError, match="release_x_m"):
        ThrowDistribution(release_x_m=(6.0, 3.0))
    with pytest.raises(ValueError, match="flight_time_s"):
        ThrowDistribution(flight_time_s=(0.0, 1.0))


@pytest.mark.parametrize("seed", range(6))
def test_bounce_env_ball_really_bounces_and_comes_back(seed):
    """The invisible wall reverses the lateral velocity mid-flight; the ball still arrives near the
    sampled arrival point (soft contact: within 12 cm)."""
    env = gym.make("EyeCatchBounce-v0")
    _obs, info = env.reset(seed=seed)
    arrival, flight = info["arrival_pos"], info["flight_time"]
    action = np.zeros(9, dtype=np.float32)
    action[:3] = (-1, 1, -1)  # hand out of the way
    action[3] = -1
    vy, best = [], np.inf
    done = False
    while not done:
        _obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        vy.append(info["ball_vel"][1])
        if abs(info["time"] - flight) < 0.011:
            best = min(best, float(np.linalg.norm(info["ball_pos"] - arrival)))
    signs = np.sign(vy)
    assert np.any(signs[1:] != signs[:-1]), "the lateral velocity never reversed: no bounce"
    assert best < 0.12


def test_plain_env_has_no_wall():
    env = gym.make("EyeCatch-v0")
    _, info = env.reset(seed=0)
    assert info["wall_y"] is None
    m = env.unwrapped.model
    wall = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "bounce_wall")
    assert m.geom_contype[wall] == 0
    assert asset_path("catch.xml").is_file()
