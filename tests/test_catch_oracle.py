"""End-to-end checks of the catch task with the scripted ``InterceptOracle`` on ``EyeCatchOracle-v0``.

They prove that the sampled throws are catchable, that catch detection works (and only with a closed
hand), that a caught ball stays in the hand, and that the throw sampler's arrival point is where the
simulated ball really is at the sampled flight time.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.oracle import InterceptOracle

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.body.seated import HAND_WORKSPACE
from visuomotor_gym.core.frames import SEAT_ORIGIN

ORACLE_ID = "EyeCatchOracle-v0"
GRAVITY = np.array([0.0, 0.0, -9.81])
PHYSICS_DT = 0.002


def run_episode(env, policy, seed: int) -> dict:
    """One episode; returns the outcome and the per-step hand-ball distances."""
    obs, info = env.reset(seed=seed)
    distances = [float(np.linalg.norm(info["hand_pos"] - info["ball_pos"]))]
    ret, caught_steps, steps = 0.0, 0, 0
    while True:
        action, _ = policy.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        steps += 1
        ret += reward
        caught_steps += int(info["caught"])
        distances.append(float(np.linalg.norm(info["hand_pos"] - info["ball_pos"])))
        if terminated or truncated:
            break
    return {
        "success": info["is_success"],
        "missed": info["missed"],
        "diverged": info["physics_diverged"],
        "truncated": truncated,
        "return": ret,
        "caught_steps": caught_steps,
        "min_distance": min(distances),
        "steps": steps,
        "last_info": info,
    }


@pytest.mark.slow
def test_closed_hand_oracle_catches_at_least_95_percent():
    env = gym.make(ORACLE_ID)
    policy = InterceptOracle(grasp_closed=True)
    results = [run_episode(env, policy, seed) for seed in range(200)]
    caught = [r["success"] for r in results]
    failed = [seed for seed, ok in enumerate(caught) if not ok]
    assert sum(caught) >= 190, f"caught {sum(caught)}/200; failed seeds {failed[:20]}"
    assert not any(r["diverged"] for r in results)
    for r in results:
        if r["success"]:
            # sparse reward: exactly +1, on exactly one step, and that step ends the episode
            assert r["return"] == 1.0 and r["caught_steps"] == 1 and not r["truncated"]
            assert not r["missed"]
        else:
            assert r["return"] == 0.0


def test_open_hand_never_catches_but_gets_there():
    env = gym.make(ORACLE_ID)
    policy = InterceptOracle(grasp_closed=False)
    results = [run_episode(env, policy, seed) for seed in range(60)]
    assert not any(r["success"] for r in results), "an open hand caught the ball"
    assert all(r["caught_steps"] == 0 and r["return"] == 0.0 for r in results)
    assert all(r["missed"] for r in results), "episodes should end by a miss"
    # The open hand was really at the ball: the closest sampled hand-ball distance (every 20 ms, the
    # ball moving ~10 cm in between) is within the 6 cm catch radius in most throws.
    closest = np.array([r["min_distance"] for r in results])
    assert np.median(closest) < 0.06, closest
    assert np.mean(closest < 0.10) >= 0.95, closest


def test_caught_ball_stays_in_the_hand():
    env = gym.make(ORACLE_ID)
    u = env.unwrapped
    policy = InterceptOracle(grasp_closed=True)
    lo, hi = HAND_WORKSPACE[:, 0], HAND_WORKSPACE[:, 1]
    checked = 0
    for seed in range(6):
        r = run_episode(env, policy, seed)
        if not r["success"]:
            continue
        checked += 1
        info = r["last_info"]
        start_hand, start_ball = info["hand_pos"].copy(), info["ball_pos"].copy()
        # Hold still for a few steps, then carry the ball to a point lower and nearer the body.
        hold = np.zeros(9, np.float32)
        hold[:3] = 2.0 * (start_hand - SEAT_ORIGIN - lo) / (hi - lo) - 1.0
        hold[3] = 1.0
        carry = hold.copy()
        carry[:3] = 2.0 * (np.array([0.35, -0.3, 0.1]) - lo) / (hi - lo) - 1.0
        distances = []
        for k in range(30):
            _, reward, _, _, step_info = u.step(hold if k < 5 else carry)
            assert not step_info["physics_diverged"]
            assert step_info["is_success"], "the catch was forgotten"
            assert reward == 0.0, "a held ball must not be rewarded as a new catch"
            distances.append(float(np.linalg.norm(step_info["ball_pos"] - step_info["hand_pos"])))
        hand_moved = step_info["hand_pos"] - start_hand
        ball_moved = step_info["ball_pos"] - start_ball
        assert np.linalg.norm(hand_moved) > 0.15, f"the hand did not carry the ball anywhere: {hand_moved}"
        assert max(distances) < u.catch_radius + 0.01, f"seed {seed}: ball left the hand {distances}"
        # (the weld holds the ball where it entered the catch volume, not at its centre)
        assert np.linalg.norm(ball_moved - hand_moved) < 2 * u.catch_radius
    assert checked >= 4


def test_hand_reset_after_a_catch_matches_a_fresh_env():
    """The weld and the model edits of a caught episode do not leak into the next episode."""
    env = gym.make(ORACLE_ID)
    policy = InterceptOracle(grasp_closed=True)
    assert run_episode(env, policy, 0)["success"]
    fresh = gym.make(ORACLE_ID)
    a = run_episode(env, policy, 1)
    b = run_episode(fresh, policy, 1)
    assert a["steps"] == b["steps"] and a["success"] == b["success"]
    assert a["min_distance"] == b["min_distance"]


def test_ball_passes_the_sampled_arrival_point():
    """info["arrival_pos"] is where the simulated ball centre is at t = info["flight_time"].

    Observations come every 20 ms and flight times are multiples of 2 ms: the last recorded state
    before the flight time is propagated ballistically (exactly, as the integrator does) for the
    remaining physics steps; throws whose flight time falls on a control step compare directly.
    """
    env = gym.make(ORACLE_ID)
    away = np.array([-1.0, 1.0, -1.0, -1.0, 0, 0, 0, 0, 0], np.float32)  # hand at the left/back corner, open
    compared, direct = 0, 0
    for seed in range(300):
        if compared >= 20 and direct >= 3:
            break
        _, info = env.reset(seed=seed)
        flight_time, arrival, release_vel = info["flight_time"], info["arrival_pos"], info["release_vel"]
        assert round(flight_time / PHYSICS_DT) * PHYSICS_DT == pytest.approx(flight_time, abs=1e-12)
        on_control_step = abs(flight_time / 0.02 - round(flight_time / 0.02)) < 1e-9
        if compared >= 20 and not on_control_step:
            continue
        last = (info["time"], info["ball_pos"], info["ball_vel"])
        while True:
            _, _, terminated, truncated, info = env.step(away)
            if info["time"] > flight_time + 1e-9:
                break
            last = (info["time"], info["ball_pos"], info["ball_vel"])
            assert not (terminated or truncated), f"seed {seed}: episode ended before the flight time"
        t, p, v = last
        n = round((flight_time - t) / PHYSICS_DT)
        assert 0 <= n < 10
        if on_control_step:
            assert n == 0
            direct += 1
        # The ball is in free flight: the velocity is the launch velocity plus gravity.
        np.testing.assert_allclose(v, release_vel + GRAVITY * t, rtol=0, atol=1e-6, err_msg=f"seed {seed}")
        at_flight_time = p + n * PHYSICS_DT * v + GRAVITY * PHYSICS_DT**2 * n * (n + 1) / 2
        np.testing.assert_allclose(at_flight_time, arrival, rtol=0, atol=1e-3, err_msg=f"seed {seed}")
        compared += 1
    assert compared >= 20 and direct >= 3, (compared, direct)
