"""The walker baselines model the eye they see with, the human periphery included.

iwao's obstacle memory and lookahead's stone memory weight every sample with the env's own
``VisionParams`` (``agents.match_vision``, called by ``make_agent``, reaches them); the belief-MPC
planners of the dodge and stones families predict what they will see with the env's field shape and
position law (``baselines/belief_mpc/field.py``), each checked against a hand-computed case.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.belief_mpc.field import field_limit, field_limit_eye, position_e2_rad
from visuomotor_gym.baselines.belief_mpc.stone_belief import plane_variance

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import make_agent, match_vision
from visuomotor_gym.vision import periphery
from visuomotor_gym.vision.foveation import ARCMIN, DEG, VisionParams

HUMAN = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0}


def _inner(policy):
    while hasattr(policy, "base"):
        policy = policy.base
    return policy


# The walk family's 20 deg cone without the periphery (ObstacleWalk's default; SteppingStones' first definition).
CONE = {"field_shape": "cone", "field_of_view_deg": 20.0, "position_e2_deg": None, "crowding": False,
        "depth_pedestal_arcmin": None}


@pytest.mark.parametrize("env_id, agent, memory", [("ObstacleWalk-v0", "iwao", "memory"),
                                                    ("SteppingStones-v0", "lookahead", "memory"),
                                                    ("SteppingStones-v0", "belief_mpc", "memory")])
@pytest.mark.parametrize("spec", ["{}", "gaze_blind:{}"])
def test_the_memory_weights_samples_with_the_env_vision(env_id, agent, memory, spec):
    from visuomotor_gym.registration import env_vision_params

    registered = env_vision_params(env_id)
    # an env whose eye is not the registered id's: the periphery where the id has the cone, and back
    other = HUMAN if registered.field_shape == "cone" else CONE
    env = gym.make(env_id, vision_params=dict(other))
    try:
        policy = make_agent(spec.format(agent), env_id, int(env.action_space.shape[0]))
        inner = _inner(policy)
        assert getattr(inner, memory).vision == registered  # make_agent gives the registered id's vision
        match_vision(policy, env.unwrapped.vision_params)
        seen = getattr(inner, memory).vision
        assert seen is inner.vision is env.unwrapped.vision_params
        assert {k: getattr(seen, k) for k in other} == other
    finally:
        env.close()


def test_iwao_for_env_keeps_vision_overrides():
    from visuomotor_gym.baselines.iwao.agent import IwaoAgent

    agent = IwaoAgent.for_env("ObstacleWalk-v0", vision_noise_scale=3.0, foveated=False)
    assert agent.memory.vision.noise_scale == 3.0 and agent.memory.vision.foveated is False
    assert IwaoAgent.for_env("ObstacleWalk-v0").memory.vision.field_of_view_deg == 20.0


def test_field_limit_of_the_cone_is_its_half_angle():
    v = VisionParams(field_of_view_deg=20.0)
    assert field_limit(np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), v) == 20.0 * DEG


def test_field_limit_of_the_human_field_by_hand():
    v = VisionParams(field_shape="human")
    g = np.array([1.0, 0.0, 0.0])  # gaze along x: the eye frame is the path frame
    up, down, left = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0])
    assert field_limit(g, up, v) == pytest.approx(60.0 * DEG)
    assert field_limit(g, down, v) == pytest.approx(75.0 * DEG)
    assert field_limit(g, left, v) == pytest.approx(100.0 * DEG)
    assert field_limit(g, -left, v) == pytest.approx(100.0 * DEG)
    # 45 deg up-left: 1 / sqrt(0.5 / S^2 + 0.5 / V^2), S = 100 deg, V = 60 deg
    diag = np.array([0.0, 1.0, 1.0]) / math.sqrt(2.0)
    expected = 1.0 / math.sqrt(0.5 / (100.0 * DEG) ** 2 + 0.5 / (60.0 * DEG) ** 2)
    assert field_limit(g, diag, v) == pytest.approx(expected)
    # the same geometry seen with the gaze turned 90 deg left (yaw): left is then -x
    g2 = np.array([0.0, 1.0, 0.0])
    assert field_limit(g2, np.array([-1.0, 0.0, 0.0]), v) == pytest.approx(100.0 * DEG)
    assert field_limit(g2, down, v) == pytest.approx(75.0 * DEG)


def test_field_limit_eye_matches_the_retina_law():
    v = VisionParams(field_shape="human")
    rng = np.random.default_rng(0)
    for uy, uz in rng.uniform(-1.0, 1.0, size=(50, 2)):
        assert float(field_limit_eye(uy, uz, v)) == pytest.approx(periphery.human_field_limit(uy, uz, v), rel=1e-12)
    assert float(field_limit_eye(0.0, 0.0, v)) == pytest.approx(100.0 * DEG)


def test_plane_variance_follows_the_position_law_and_the_field():
    d, th, slip, dep = 2.0, 5.0 * DEG, 0.0, 0.5
    for e2_deg, vision in ((2.0, VisionParams()), (0.7, VisionParams(position_e2_deg=0.7))):
        assert position_e2_rad(vision) == pytest.approx(e2_deg * DEG)
        s = d * ARCMIN * (1.0 + math.sqrt(th * th + (0.2 * DEG) ** 2) / (e2_deg * DEG))
        expected = 0.5 * s * s * (1.0 + 1.0 / dep**2) + 1e-6  # + FLOOR_M2 (1 mm std)
        assert float(plane_variance(d, th, slip, dep, vision)) == pytest.approx(expected, rel=1e-6, abs=1e-12)
    # beyond the limit: nothing seen; the default limit is the cone
    assert math.isinf(float(plane_variance(d, 25.0 * DEG, slip, dep, VisionParams(field_of_view_deg=20.0))))
    assert math.isfinite(float(plane_variance(d, 25.0 * DEG, slip, dep, VisionParams(field_of_view_deg=20.0),
                                              limit=60.0 * DEG)))


def test_dodge_planner_models_the_env_vision():
    env_id = "ObstacleDodge-v0"
    env = gym.make(env_id, vision_params=CONE)  # the walk family's cone over the family's eye
    try:
        policy = make_agent("belief_mpc", env_id, int(env.action_space.shape[0]))
        assert policy.plan_vision.field_shape == "human"  # the registered id's eye (DODGE_VISION)
        match_vision(policy, env.unwrapped.vision_params)
        assert policy.plan_vision.field_of_view_deg == 20.0 and policy.plan_vision.field_shape == "cone"
        env.close()
        env = gym.make(env_id, vision_params=dict(HUMAN))
        before = policy.noise
        match_vision(policy, env.unwrapped.vision_params)
        assert policy.plan_vision is policy.vision is env.unwrapped.vision_params
        assert policy.plan_vision.field_shape == "human"
        assert policy.noise is not before
    finally:
        env.close()


def test_iwao_verges_on_its_gaze_target_only_under_the_depth_law():
    """Without the depth law the fixation action stays 0 (iwao v0); with it, it asks for a vergence
    distance on the ground ahead (the fixated point: 1.8-8 m for the walkway's eye 1.6 m up), never the
    action 0's 1.4 m."""
    from visuomotor_gym.baselines.iwao.agent import _LOG_FIX

    lo, hi = _LOG_FIX
    for fields, check in (({}, lambda a: a == 0.0),
                          ({"depth_pedestal_arcmin": 10.0},
                           lambda a: 1.8 <= math.exp(lo + (a + 1.0) * 0.5 * (hi - lo)) <= 8.0)):
        env = gym.make("ObstacleWalk-v0", vision_params=fields) if fields else gym.make("ObstacleWalk-v0")
        try:
            policy = make_agent("iwao", "ObstacleWalk-v0", int(env.action_space.shape[0]))
            match_vision(policy, env.unwrapped.vision_params)
            fix = env.unwrapped.action_structure  # the fixation action's index in the flat action
            index = sum(n for name, n in list(fix.items())[:list(fix).index("fixation")])
            obs, _ = env.reset(seed=0)
            for _ in range(40):
                action, _ = policy.predict(obs)
                assert check(float(action[index])), (fields, float(action[index]))
                obs, _, terminated, truncated, _ = env.step(action)
                assert not (terminated or truncated)
        finally:
            env.close()


def test_crowded_flags_only_targets_within_the_critical_spacing():
    """Target at 10 deg: a flanker of another object 4.9 deg away crowds it (b theta = 5 deg), one at
    5.1 deg does not, a point of the same object never does; a target inside the 0.5 deg fovea is never
    crowded; without crowding in the vision model nothing is flagged."""
    from visuomotor_gym.baselines.crowding import crowd_std, crowded

    def at(az_deg):
        return (math.cos(az_deg * DEG), math.sin(az_deg * DEG), 0.0)

    v = VisionParams(crowding=True)
    assert crowded([at(10.0), at(14.9)], [1, 2], v) == {0, 1}  # 4.9 < 0.5 x 14.9 too
    assert 0 not in crowded([at(10.0), at(15.1)], [1, 2], v)
    assert crowded([at(10.0), at(14.9)], [1, 1], v) == set()
    assert 0 not in crowded([at(0.3), at(0.35)], [1, 2], v)
    assert crowded([at(10.0), at(14.9)], [1, 2], VisionParams()) == set()
    assert crowd_std(2.0, 10.0 * DEG, v) == pytest.approx(0.5 * 0.5 * 10.0 * DEG * 2.0)


def _first_saccade_time(disarray: float, seed: int = 16, spec: str = "eyecatch") -> float:
    env = gym.make("EyeCatch-v0", vision_params={**HUMAN, "position_disarray": disarray})
    policy = make_agent(spec, "EyeCatch-v0", int(env.action_space.shape[0]), seed=seed)
    match_vision(policy, env.unwrapped.vision_params)
    agent = _inner(policy)
    obs, _ = env.reset(seed=seed)
    for _ in range(40):
        obs, *_ = env.step(policy.predict(obs)[0])
        if agent.first_saccade_released:
            break
    env.close()
    return next(t for t, e in agent.events if e == "first-saccade")


def test_eyecatch_under_the_human_periphery_saccades_at_the_latency():
    # seed 16, all four + disarray 0.8: the ball's believed retinal std never meets the 3 deg criterion
    # (the old agent waited for its 0.5 s deadline); with the throw expected the first saccade goes at the
    # saccadic latency (0.18 s), and the agent without its periphery model still waits
    assert _first_saccade_time(0.8) == pytest.approx(0.18, abs=0.011)
    assert _first_saccade_time(0.8, spec="eyecatch:periphery_model=False") == pytest.approx(0.5, abs=0.011)

# --- eyecatch's model of the human periphery (baselines/eyecatch/agent.py, 5-7) -------------------------
def _eyecatch(vision_params=None, spec="eyecatch"):
    agent = _inner(make_agent(spec, "EyeCatch-v0", 9))
    if vision_params is not None:
        agent.vision = VisionParams(**vision_params)
    return agent


def test_throw_prior_matches_its_monte_carlo():
    """The closed-form moments of the expected throw against 400k draws of the same generative model."""
    from visuomotor_gym.baselines.eyecatch.agent import throw_prior

    from visuomotor_gym.scenarios.throws import GRAVITY, ThrowDistribution

    mean0, cov0 = np.array([4.5, 0.3, 1.6]), np.diag([1.0, 0.09, 0.09])
    mean, cov = throw_prior(mean0, cov0)
    rng = np.random.default_rng(0)
    n, d = 400_000, ThrowDistribution()
    p0 = rng.multivariate_normal(mean0, cov0, n)
    lo = np.array([d.arrival_x_m[0], d.arrival_y_m[0], d.arrival_z_m[0]])
    hi = np.array([d.arrival_x_m[1], d.arrival_y_m[1], d.arrival_z_m[1]])
    arrival = lo + (hi - lo) * rng.random((n, 3))
    flight = d.flight_time_s[0] + (d.flight_time_s[1] - d.flight_time_s[0]) * rng.random((n, 1))
    samples = np.hstack([p0, (arrival - p0) / flight - 0.5 * GRAVITY * flight])
    np.testing.assert_allclose(mean, samples.mean(axis=0), atol=0.01)
    np.testing.assert_allclose(cov, np.cov(samples.T), atol=0.02)
    # by hand: the mean velocity of a throw from 4.5 m to the region's centre (0.375, -0.25, 1.025)
    inv_t = math.log(1.4 / 0.8) / 0.6
    np.testing.assert_allclose(mean[3:], [(0.375 - 4.5) * inv_t, (-0.25 - 0.3) * inv_t,
                                          (1.025 - 1.6) * inv_t + 0.5 * 9.81 * 1.1], atol=1e-9)
    assert np.diag(cov)[3:].max() < 2.0  # far below the uninformative 100 m^2/s^2


def test_eyecatch_expects_the_throw_only_under_the_human_periphery():
    rot, eye = np.eye(3), np.array([0.1, -0.2, 1.2])
    plain = _eyecatch({})  # an eye without the human periphery
    plain._set_thrower_prior(rot, eye)
    np.testing.assert_allclose(np.diag(plain.filter.P)[3:], [100.0] * 3)  # the paper agent: uninformative
    for spec, expects in (("eyecatch", True), ("eyecatch:periphery_model=False", False)):
        agent = _eyecatch({**HUMAN, "position_disarray": 0.8}, spec)
        agent._set_thrower_prior(rot, eye)
        np.testing.assert_allclose(agent.filter.x[:3], eye + [4.5, 0.0, 0.0])
        assert (np.diag(agent.filter.P)[3:].max() < 2.0) == expects
        assert (agent.filter.x[3] < -2.0) == expects  # toward the catcher


def test_eyecatch_noise_point_at_the_rms_eccentricity_under_the_periphery():
    """A sample on the fovea is not taken for a foveal ball: the noise is evaluated in the prior's polar
    direction at sqrt(theta_p^2 + 2 sigma_theta^2), whatever the sample's own direction."""
    agent = _eyecatch({**HUMAN, "position_disarray": 0.8})
    rot, eye = np.eye(3), np.zeros(3)
    theta = 5.0 * DEG
    agent.filter.x = np.array([3.0 * math.cos(theta), 0.0, 3.0 * math.sin(theta), 0.0, 0.0, 0.0])
    lat = (0.03 * 3.0) ** 2  # 1.72 deg of lateral std per axis at 3 m
    u = agent.filter.x[:3] / 3.0
    agent.filter.P = np.zeros((6, 6))
    agent.filter.P[:3, :3] = 0.04 * np.outer(u, u) + lat * (np.eye(3) - np.outer(u, u))
    agent.filter.initialised = True
    point = agent._noise_point(np.array([2.0, 0.0, 0.0]), rot, eye)  # the sample: on the fovea, too near
    d = math.sqrt(9.0 + 0.04)
    assert np.linalg.norm(point) == pytest.approx(d)
    var = lat / (9.0 + 0.04)
    expected = math.sqrt(theta**2 + 2.0 * var)
    assert math.acos(point[0] / d) == pytest.approx(expected, rel=1e-9)
    assert point[1] == pytest.approx(0.0, abs=1e-12) and point[2] > 0  # the prior's polar direction


def test_eyecatch_rms_pedestal_and_retinal_speed():
    agent = _eyecatch({**HUMAN, "position_disarray": 0.8})
    eye = np.zeros(3)
    agent.filter.x = np.array([2.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    agent.filter.P = np.diag([0.1**2, 1e-4, 1e-4, 1.0, 0.25, 0.25])
    agent.filter.initialised = True
    # verged on the estimate (2 m): the gap is the depth std over d^2 alone, 0.1 / 4 diopters
    fix = agent._pedestal_fixation(np.array([2.0, 0.0, 0.0]), 2.0, eye)
    assert 1.0 / fix - 1.0 / 2.0 == pytest.approx(0.1 / 4.0)
    # and it adds in quadrature to the vergence's own gap (verged at 4 m: 0.25 D)
    fix = agent._pedestal_fixation(np.array([2.0, 0.0, 0.0]), 4.0, eye)
    assert 1.0 / fix - 1.0 / 2.0 == pytest.approx(math.hypot(0.25, 0.025))
    # RMS retinal speed: a still ball with 0.5 m/s of velocity std on each lateral axis at 2 m
    speed = agent._expected_retinal_speed(np.array([2.0, 0.0, 0.0]), np.zeros(3), np.diag([1.0, 0.25, 0.25]),
                                          np.zeros(3))
    assert speed == pytest.approx(math.sqrt(0.5) / 2.0)
