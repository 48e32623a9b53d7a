"""Cartesian hand control: the hand reaches reachable targets and respects the 2 m/s cap."""

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401
from visuomotor_gym.body.seated import HAND_WORKSPACE
from visuomotor_gym.core.frames import SEAT_ORIGIN


def to_action(point_world):
    lo, hi = HAND_WORKSPACE[:, 0], HAND_WORKSPACE[:, 1]
    return 2.0 * (np.asarray(point_world) - SEAT_ORIGIN - lo) / (hi - lo) - 1.0


@pytest.mark.parametrize(
    "target", [(0.35, -0.25, 1.0), (0.45, -0.1, 1.15), (0.3, -0.4, 0.9), (0.4, -0.2, 0.85)]
)
def test_hand_reaches_targets_in_the_catch_region(target):
    env = gym.make("EyeCatchOracle-v0").unwrapped
    env.reset(seed=0)
    # the ball flies away; we only look at the hand
    action = np.zeros(9, dtype=np.float32)
    action[:3] = to_action(target)
    speeds, pos = [], None
    for _ in range(40):  # 0.8 s
        obs, *_ = env.step(action)
        s = env.layout.slices
        speeds.append(np.linalg.norm(obs[s["hand_vel"]]))
        pos = obs[s["hand_pos"]] + SEAT_ORIGIN
    assert np.linalg.norm(pos - np.array(target)) < 0.02, pos
    # The reference moves at <= 2 m/s; the servo may overshoot that a little, never by much.
    assert max(speeds) < 2.4


def test_joint_control_drives_joints_to_setpoints():
    env = gym.make("EyeCatchOracle-v0", control="joint").unwrapped
    env.reset(seed=0)
    action = np.zeros(16, dtype=np.float32)
    ranges = env.body.joint_range
    goal = ranges[:, 0] + 0.5 * (ranges[:, 1] - ranges[:, 0])  # action 0 -> mid-range
    for _ in range(60):
        obs, *_ = env.step(action)
    q = obs[env.layout.slices["body_qpos"]]
    assert np.max(np.abs(q - goal)) < np.radians(4)


def test_action_encoder_neck_ranges_match_the_model():
    """``envs.actions.NECK_RANGE_DEG`` (used by the agents) agrees with the MJCF neck joints."""
    from visuomotor_gym.envs.actions import NECK_RANGE_DEG, hand_action

    env = gym.make("EyeCatch-v0").unwrapped
    np.testing.assert_allclose(np.radians(NECK_RANGE_DEG), env.head.range, atol=1e-9)
    a = hand_action([0.4, -0.2, 1.0], True, head=(np.radians(40.0), np.radians(-25.0)))
    assert a[3] == 1.0 and a[7] == pytest.approx(0.5) and a[8] == pytest.approx(-0.5)  # -25 of -50 deg
    np.testing.assert_allclose(a[:3], to_action([0.4, -0.2, 1.0]), atol=1e-6)
