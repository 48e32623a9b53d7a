"""The gaze-blind reference agents: ``gaze_blind:<agent>`` and ``fixed_gaze`` (= ``gaze_blind:eyecatch``).

Oracles: the action layout of the catch env (gaze and head blocks from ``action_structure``), the
base agent run side by side on the same observations, and the plant's saccade flag.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import GazeBlind, agent_names, is_deterministic, make_agent, parse_agent_spec


def _blocks(env):
    """Index masks of the gaze and head blocks (and the fixation block where the eye has the depth law:
    EyeCatch-v0's human periphery), from the env's own action_structure."""
    from visuomotor_gym.agents import has_depth_law

    blocks = ("gaze", "head") + (("fixation",) if has_depth_law(env.unwrapped.vision_params) else ())
    held = np.zeros(env.action_space.shape[0], dtype=bool)
    start = 0
    for name, size in env.unwrapped.action_structure.items():
        if name in blocks:
            held[start : start + size] = True
        start += size
    return held


def test_names_are_registered_and_parse():
    assert {"fixed_gaze", "gaze_blind"} <= set(agent_names())
    assert parse_agent_spec("gaze_blind:eyecatch") == ("gaze_blind", {"base": "eyecatch"})
    assert parse_agent_spec("gaze_blind:eyecatch:update_period_s=0.3") == (
        "gaze_blind", {"base": "eyecatch:update_period_s=0.3"})
    assert parse_agent_spec("fajen_warren:search_azimuths_deg=45;70,speed=1") == (
        "fajen_warren", {"search_azimuths_deg": (45, 70), "speed": 1})
    assert parse_agent_spec("fajen_warren:los_hypotheses_std=-1.5;") == (
        "fajen_warren", {"los_hypotheses_std": (-1.5,)})
    assert is_deterministic("fixed_gaze") and is_deterministic("gaze_blind:belief_mpc")
    assert not is_deterministic("gaze_blind:random")
    with pytest.raises(ValueError, match="wraps another agent"):
        parse_agent_spec("gaze_blind")
    with pytest.raises(ValueError, match="unknown agent"):
        parse_agent_spec("gaze_blind:nope")


@pytest.mark.parametrize("spec,base_spec", [("fixed_gaze", "eyecatch"), ("gaze_blind:eyecatch", "eyecatch"),
                                            ("gaze_blind:belief_intercept", "belief_intercept"),
                                            ("gaze_blind:random", "random")])
@pytest.mark.parametrize("seed", [0, 3])
def test_only_gaze_and_head_differ_and_the_eye_never_saccades(spec, base_spec, seed):
    env = gym.make("EyeCatch-v0")
    held = _blocks(env)
    assert held.tolist() == [False] * 4 + [True, True, True, True, True]  # gaze 4-5, fixation 6, head 7-8
    blind = make_agent(spec, "EyeCatch-v0", 9, seed=seed)
    base = make_agent(base_spec, "EyeCatch-v0", 9, seed=seed)  # the same agent, fed the same observations
    assert isinstance(blind, GazeBlind)
    obs, info = env.reset(seed=seed)
    blind.reset()
    if hasattr(base, "reset"):
        base.reset()
    steps = differ = 0
    done = False
    while not done:
        a, _ = blind.predict(obs, episode_start=np.array([steps == 0]))
        b, _ = base.predict(obs, episode_start=np.array([steps == 0]))
        assert a.shape == (9,) and a.dtype == np.float32
        np.testing.assert_array_equal(a[held], 0.0)
        np.testing.assert_allclose(a[~held], np.asarray(b, dtype=np.float32)[~held])
        differ += bool(np.any(np.asarray(b)[held] != 0.0))
        obs, _, term, trunc, info = env.step(a)
        done = term or trunc
        steps += 1
        assert not info["saccade_onset"] and not info["in_saccade"]
    assert steps > 20
    if base_spec != "belief_intercept":  # belief_intercept already holds its gaze
        assert differ > 0  # the base agent did want to look around


def test_gaze_stays_where_reset_put_it():
    env = gym.make("EyeCatch-v0")
    agent = make_agent("fixed_gaze", "EyeCatch-v0", 9)
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        agent.reset()
        gaze0 = info["gaze_dir"].copy()
        angles, heads = [], []
        done = False
        while not done:
            a, _ = agent.predict(obs)
            obs, _, term, trunc, info = env.step(a)
            done = term or trunc
            angles.append(np.degrees(np.arccos(np.clip(info["gaze_dir"] @ gaze0, -1, 1))))
            heads.append(np.abs(info["head_qpos"]).max())
        assert max(heads) < np.radians(2.0)  # the neck servo holds the reset pose (arm reaction: < 1 deg)
        assert max(angles) < 2.0  # no pursuit, no saccade: gaze held in the world (VOR)


def test_joint_control_layout_and_bad_layout():
    env = gym.make("EyeCatchPaper-v0", control="joint")  # no depth law: vergence not held
    held = _blocks(env)
    assert np.flatnonzero(held).tolist() == [11, 12, 14, 15]
    blind = GazeBlind(make_agent("random", "EyeCatch-v0", 16, seed=1), env.unwrapped.action_structure)
    a, _ = blind.predict(env.reset(seed=0)[0])
    assert np.all(a[held] == 0.0) and np.any(a[~held] != 0.0)
    with pytest.raises(ValueError, match="'gaze' and 'head' blocks"):
        GazeBlind(make_agent("random", "EyeCatch-v0", 7), {"hand_target": 3, "grasp": 1})


@pytest.mark.parametrize("env_id, base", [("ObstacleWalk-v0", "iwao"), ("ShelfReach-v0", "faraway")])
def test_the_twin_holds_gaze_and_head_in_every_family(env_id, base):
    """The twin reads the env's action_structure: the walk and reach layouts hold their own blocks (and the
    fixation block where the eye has the depth law: both ids' human periphery)."""
    env = gym.make(env_id)
    structure = env.unwrapped.action_structure
    blind = make_agent(f"gaze_blind:{base}", env_id, env.action_space.shape[0])
    vp = env.unwrapped.vision_params
    blocks = ("gaze", "head") + (("fixation",) if vp.foveated and vp.depth_pedestal_arcmin is not None else ())
    assert "fixation" in blocks
    start, held = 0, []
    for name, size in structure.items():
        if name in blocks:
            held += list(range(start, start + size))
        start += size
    assert np.flatnonzero(blind.held).tolist() == held
    obs, _ = env.reset(seed=0)
    for _ in range(30):
        a, _ = blind.predict(obs)
        assert np.all(a[held] == 0.0)
        obs, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            break


def test_bench_accepts_the_twin():
    from visuomotor_gym.bench.evaluate import evaluate

    result = evaluate("fixed_gaze", "EyeCatch-v0", episodes=2, seed=0, workers=1)
    assert result.agent == "fixed_gaze" and result.episodes == 2
    assert all(not tr.saccade_onset.any() for tr in result.traces)


def test_the_twin_holds_vergence_only_when_the_eye_has_the_depth_law():
    """SteppingStones-v0's eye has the depth law (vergence decides depth precision): the twin holds the
    fixation block at 0 too; EyeCatchPaper-v0's has not: the base agent's vergence passes. match_vision
    follows the env's own vision (an override either way)."""
    from visuomotor_gym.agents import match_vision
    from visuomotor_gym.vision.foveation import VisionParams, human_periphery

    def fixation_index(env_id):
        start = 0
        for name, size in gym.make(env_id).unwrapped.action_structure.items():
            if name == "fixation":
                return start
            start += size
        raise AssertionError("no fixation block")

    stones = make_agent("gaze_blind:lookahead", "SteppingStones-v0", 9)
    catch = make_agent("gaze_blind:eyecatch", "EyeCatchPaper-v0", 7)
    assert stones.hold_vergence and not catch.hold_vergence
    assert stones.held[fixation_index("SteppingStones-v0")] and not catch.held[fixation_index("EyeCatchPaper-v0")]
    env = gym.make("SteppingStones-v0")
    obs, _ = env.reset(seed=0)
    base = make_agent("lookahead", "SteppingStones-v0", 9)
    base.reset()
    stones.reset()
    fix = fixation_index("SteppingStones-v0")
    moved = False
    for _ in range(60):
        a, _ = stones.predict(obs)
        b, _ = base.predict(obs)
        assert a[fix] == 0.0
        moved |= b[fix] != 0.0  # the base agent verges on its gaze target: the twin does not
        obs, *_ = env.step(a)
    assert moved
    match_vision(catch, human_periphery())
    assert catch.hold_vergence and catch.held[fixation_index("EyeCatchPaper-v0")]
    assert make_agent("gaze_blind:eyecatch", "EyeCatch-v0", 7).hold_vergence  # EyeCatch-v0's own eye
    match_vision(stones, VisionParams())
    assert not stones.hold_vergence and not stones.held[fixation_index("SteppingStones-v0")]


def test_the_twin_reads_the_action_blocks_of_the_kwargs_registered_now():
    """``registered_kwargs`` can change an id's action blocks (ObstacleWalk's winding walkway: a fourth footstep
    value); the twin made inside it holds the blocks the env has there, not those of an earlier read."""
    from visuomotor_gym.agents import env_action_structure
    from visuomotor_gym.static_gaze import registered_kwargs

    for course, footstep in (("walkway", 3), ("winding", 4), ("walkway", 3)):
        with registered_kwargs("ObstacleWalk-v0", {"course_distribution": course}):
            assert env_action_structure("ObstacleWalk-v0")["footstep"] == footstep
            blind = make_agent("gaze_blind:iwao", "ObstacleWalk-v0", footstep + 5)
            assert np.flatnonzero(blind.held).tolist()[:2] == [footstep, footstep + 1]  # the gaze block
            env = gym.make("ObstacleWalk-v0")
            still = make_agent("static_gaze:az=0,el=-30,neck_yaw=0,neck_pitch=-30,fix=3:iwao", "ObstacleWalk-v0",
                               footstep + 5)
            assert still.predict(env.reset(seed=0)[0])[0].shape == (footstep + 5,)  # the static twin too
            env.close()
