"""The static twin (``static_gaze:<posture>:<agent>``): blind, holds its posture, parses, searches."""

from __future__ import annotations

import json
import math
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import tomllib
from setuptools import find_packages

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import GazeBlind, is_deterministic, make_agent, match_vision, parse_agent_spec
from visuomotor_gym.static_gaze import (
    DEAD_BAND_DEG,
    POSTURE_KEYS,
    Posture,
    StaticGaze,
    load_postures,
    main,
    resolve_spec,
    searched_posture,
    static_gaze_spec,
    update_postures,
)

REPO = Path(__file__).resolve().parents[1]
# Every family's foveated id and a baseline of it (the cheap one).
FAMILIES = (("EyeCatch-v0", "eyecatch"), ("ShelfReach-v0", "faraway"), ("ObstacleWalk-v0", "iwao"),
            ("SteppingStones-v0", "lookahead"), ("ObstacleDodge-v0", "fajen_warren"))
POSTURE = "az=20,el=-25,neck_yaw=10,neck_pitch=-20,fix=3"
POSTURE_BLOCKS = ("gaze", "fixation", "head")


def _unit(az_deg, el_deg):
    a, e = math.radians(az_deg), math.radians(el_deg)
    return np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])


def _blocks(structure):
    out, start = {}, 0
    for name, size in structure.items():
        out[name] = slice(start, start + size)
        start += size
    return out


@pytest.mark.parametrize("env_id,base", FAMILIES)
def test_blind_to_every_percept(env_id, base):
    """Zeroing every visual sample (the task's percept blocks), or randomising every block but the eye
    pose, leaves the gaze, fixation and head actions unchanged, step by step, on every family."""
    env = gym.make(env_id)
    u = env.unwrapped
    n = env.action_space.shape[0]
    spec = f"static_gaze:{POSTURE}:{base}"
    seen, zeroed, noise = (make_agent(s, env_id, n, seed=0) for s in (spec, spec, f"static_gaze:{POSTURE}:zero"))
    percepts = [u.layout.slices[b.name] for b in u.task.leading_blocks]
    assert percepts, "no percept blocks found"
    rot = u.layout.slices["eye_rot"]
    act = _blocks(u.action_structure)
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=3)
    moved = 0
    want = _unit(20.0, -25.0)
    errors, heads = [], []
    for k in range(40):
        a, _ = seen.predict(obs)
        blind = obs.copy()
        for s in percepts:
            blind[s] = 0.0
        b, _ = zeroed.predict(blind)
        scrambled = rng.normal(0.0, 5.0, obs.shape).astype(np.float32)
        scrambled[rot] = obs[rot]
        c, _ = noise.predict(scrambled)
        for block in POSTURE_BLOCKS:
            np.testing.assert_array_equal(a[act[block]], b[act[block]], err_msg=block)
            np.testing.assert_array_equal(a[act[block]], c[act[block]], err_msg=block)
        moved += bool(np.any(a[act["gaze"]] != 0.0))
        obs, _, terminated, truncated, _ = env.step(a)
        if k >= 15:  # after the first saccades and the neck's move: the eye is at the posture, every family
            gaze = obs[rot].reshape(3, 3)[:, 0]
            errors.append(math.degrees(math.acos(min(1.0, float(gaze @ want)))))
            heads.append(np.degrees(obs[u.layout.slices["head_qpos"]]))
        if terminated or truncated:
            break
    assert moved >= 1  # the posture was reached by at least one saccade (the gaze request is not constant)
    assert errors and np.mean(errors) < DEAD_BAND_DEG, errors
    np.testing.assert_allclose(np.mean(heads, axis=0), [10.0, -20.0], atol=2.0)
    env.close()


@pytest.mark.parametrize("env_id,base,posture,steps", [
    ("EyeCatch-v0", "eyecatch", Posture(-9.0, 35.0, -9.0, 20.0), 60),  # seated: the seat frame
    ("ObstacleWalk-v0", "iwao", Posture(15.0, -25.0, 10.0, -20.0), 300),  # walker: the pelvis heading
])
def test_eye_reaches_and_holds_the_posture(env_id, base, posture, steps):
    env = gym.make(env_id)
    u = env.unwrapped
    agent = make_agent(static_gaze_spec(posture, base), env_id, env.action_space.shape[0], seed=0)
    want = _unit(posture.az, posture.el)
    obs, _ = env.reset(seed=1)
    start_error = math.degrees(math.acos(obs[u.layout.slices["eye_rot"]].reshape(3, 3)[:, 0] @ want))
    assert start_error > 10.0  # reset put the eye elsewhere: the test sees it move there
    errors, heads, fixations, saccades = [], [], [], 0
    for k in range(steps):
        a, _ = agent.predict(obs)
        obs, _, terminated, truncated, info = env.step(a)
        saccades += info["saccade_onset"]
        if k >= 15:  # 0.3 s: the first saccades and the neck (300 deg/s) are done
            gaze = obs[u.layout.slices["eye_rot"]].reshape(3, 3)[:, 0]
            errors.append(math.degrees(math.acos(min(1.0, float(gaze @ want)))))
            heads.append(np.degrees(obs[u.layout.slices["head_qpos"]]))
            fixations.append(float(obs[u.layout.slices["fixation"]][0]))
        if terminated or truncated:
            break
    assert len(errors) > 30
    assert max(errors) < DEAD_BAND_DEG + 1.0, max(errors)
    np.testing.assert_allclose(np.mean(heads, axis=0), [posture.neck_yaw, posture.neck_pitch], atol=1.5)
    np.testing.assert_allclose(fixations, posture.fix, rtol=1e-3)
    assert saccades <= 3 + len(errors) // 50  # held, not re-aimed every step
    env.close()


def test_gaze_blind_does_not_hold_that_posture():
    """The check above can fail: the held twin (gaze 0 from reset) is not at the posture."""
    env = gym.make("EyeCatch-v0")
    u = env.unwrapped
    agent = make_agent("gaze_blind:eyecatch", "EyeCatch-v0", env.action_space.shape[0])
    obs, _ = env.reset(seed=1)
    for _ in range(30):
        obs, *_ = env.step(agent.predict(obs)[0])
    gaze = obs[u.layout.slices["eye_rot"]].reshape(3, 3)[:, 0]
    assert math.degrees(math.acos(float(gaze @ _unit(-9.0, 35.0)))) > 10.0
    env.close()


def test_spec_round_trip_and_wrapping():
    posture = Posture(-9.5, 35.0, -10.0, 20.0, 1.5)
    spec = static_gaze_spec(posture, "eyecatch:max_submovements=3")
    name, overrides = parse_agent_spec(spec)
    assert name == "static_gaze" and overrides["base"] == "eyecatch:max_submovements=3"
    assert Posture(**{k: float(overrides[k]) for k in POSTURE_KEYS}) == posture
    agent = make_agent("static_gaze:az=-9.5,el=35,neck_yaw=-10,neck_pitch=20,fix=1.5:eyecatch", "EyeCatch-v0", 9)
    assert isinstance(agent, StaticGaze) and isinstance(agent, GazeBlind) and agent.posture == posture
    assert resolve_spec("static_gaze:az=-9.5,el=35,neck_yaw=-10,neck_pitch=20,fix=1.5:eyecatch",
                        "EyeCatch-v0") == static_gaze_spec(posture, "eyecatch")
    # the head action maps the neck's angles as core/head.py does: +-1 at the range ends (-80..80, -50..40)
    np.testing.assert_allclose(agent._head_action, [-10 / 80, 20 / 40])
    assert is_deterministic("static_gaze:az=0,el=0:eyecatch")
    assert not is_deterministic("static_gaze:az=0,el=0:random")
    assert parse_agent_spec("gaze_blind:eyecatch")[1] == {"base": "eyecatch"}  # the other wrapper unchanged
    # match_vision sees through it to the base agent's vision model
    from visuomotor_gym.registration import env_vision_params

    vision = env_vision_params("EyeCatchPoorVision-v0")
    match_vision(agent, vision)
    assert agent.base.vision is vision


@pytest.mark.parametrize("spec,needle", [
    ("static_gaze:az=0,el=80:eyecatch", "el=80.0 is outside the line of sight's elevation"),
    ("static_gaze:az=0,el=nan:eyecatch", "el must be a finite number"),
    ("static_gaze:az=0,el=0,neck_yaw=90:eyecatch", "neck_yaw=90.0 is outside the neck's yaw range [-80, 80]"),
    ("static_gaze:az=60,el=0:eyecatch", "outside the eye's range"),  # the neck straight: the eye can't
    ("static_gaze:az=0,el=0,fix=50:eyecatch", "fix=50.0 is outside the fixation range"),
    ("static_gaze:az=0,el=0,pitch=3:eyecatch", "unknown key(s) ['pitch']"),
    ("static_gaze:el=0:eyecatch", "['az'] missing"),
    ("static_gaze:az=0,el=up:eyecatch", "el must be a number"),
    ("static_gaze:random", "no searched posture for agent 'random' on EyeCatch-v0"),
])
def test_bad_postures_are_refused(spec, needle):
    with pytest.raises(ValueError) as err:
        make_agent(spec, "EyeCatch-v0", 9)
    assert needle in str(err.value)


def test_spec_errors_without_a_base():
    with pytest.raises(ValueError, match="wraps another agent"):
        parse_agent_spec("static_gaze:az=0,el=0")
    with pytest.raises(ValueError, match="unknown agent"):
        parse_agent_spec("static_gaze:az=0,el=0:nobody")


def test_searched_posture_lookup(tmp_path):
    path = tmp_path / "postures.json"
    record = {"env_id": "EyeCatch-v0", "agent": "eyecatch",
              "chosen": {"az": -10.0, "el": 35.0, "neck_yaw": -10.0, "neck_pitch": 35.0, "fix": 2.0,
                         "successes": 30, "episodes": 40}}
    update_postures(record, path=path)
    other = {**record, "env_id": "ObstacleWalk-v0", "agent": "iwao",
             "chosen": {**record["chosen"], "el": -20.0, "neck_pitch": -20.0}}
    update_postures(other, path=path)
    update_postures({**record, "chosen": {**record["chosen"], "az": -5.0}}, path=path)  # replaces only its own
    table = load_postures(path)
    assert table["ObstacleWalk-v0"]["iwao"]["el"] == -20.0
    assert searched_posture("EyeCatch-v0", "eyecatch", path=path) == Posture(-5.0, 35.0, -10.0, 35.0, 2.0)
    with pytest.raises(ValueError, match="no searched posture"):
        searched_posture("EyeCatch-v0", "belief_mpc", path=path)


def test_committed_postures_build_agents():
    table = load_postures()
    for env_id, agents in table.items():
        env = gym.make(env_id)
        for base, entry in agents.items():
            agent = make_agent(f"static_gaze:{base}", env_id, env.action_space.shape[0])
            assert [getattr(agent.posture, k) for k in POSTURE_KEYS] == [entry[k] for k in POSTURE_KEYS]
        env.close()


def test_postures_file_is_package_data():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    # setup.py finds the packages (find_packages under visuomotor_gym/): data/ must be one of them
    assert "visuomotor_gym.data" in find_packages(str(REPO), include=["visuomotor_gym", "visuomotor_gym.*"])
    assert "*.json" in project["package-data"]["visuomotor_gym.data"]
    assert (REPO / "visuomotor_gym" / "data" / "static_postures.json").exists()


def test_search_on_a_tiny_grid_replays(tmp_path):
    out = tmp_path / "search.json"
    assert main(["search", "--env", "EyeCatch-v0", "--agent", "eyecatch", "--out", str(out), "--quiet",
                 "--postures", "0,20,0,20;-10,30,-10,30", "--coarse-episodes", "2", "--final-episodes", "2"]) == 0
    record = json.loads(out.read_text())
    for key in ("env_id", "agent", "chosen", "design_seeds", "stages", "rules", "postures", "wall_time_s",
                "provenance"):
        assert key in record, key
    assert record["design_seeds"]["first"] == 100000 and record["design_seeds"]["last"] == 100001
    assert {p["episodes"] for p in record["postures"]} == {2} and len(record["postures"]) == 2
    assert record["provenance"]["visuomotor_gym"] and "git_sha" in record["provenance"]
    assert record["provenance"]["command"].startswith("python -m visuomotor_gym.static_gaze search")
    chosen = record["chosen"]
    best = max(p["successes"] for p in record["postures"])
    assert chosen["successes"] == best
    from visuomotor_gym.bench.evaluate import evaluate

    replay = evaluate(chosen["spec"], "EyeCatch-v0", episodes=2, seed=100000, keep_traces=True)
    assert sum(tr.success for tr in replay.traces) == chosen["successes"]


def test_vergence_is_searched_only_under_the_depth_law():
    from visuomotor_gym.static_gaze import (
        FIXATION_GRID_M,
        parse_fixations,
        registered_kwargs,
        search,
        vision_has_depth_law,
    )

    depth = {"vision_params": {"depth_pedestal_arcmin": 10.0}}
    assert not vision_has_depth_law("EyeCatch-v0")
    with registered_kwargs("EyeCatch-v0", depth):
        assert vision_has_depth_law("EyeCatch-v0")
    with registered_kwargs("EyeCatch-v0", {**depth, "vision": "full_view"}):
        assert not vision_has_depth_law("EyeCatch-v0")  # FullView: no periphery, no depth law
    assert parse_fixations("auto") is None and parse_fixations("none") == ()
    assert parse_fixations("0.5,3") == (0.5, 3.0)
    for bad in ("", "x", "0,1", "-1", "nan"):
        with pytest.raises(SystemExit, match="--fixations"):
            parse_fixations(bad)
    assert 2.0 in FIXATION_GRID_M

    tiny = {"coarse_step": 90.0, "coarse_episodes": 1, "final_episodes": 1, "refine_steps": (), "finalists": 1,
            "neck_step": 0.0}
    record = search("EyeCatch-v0", "eyecatch", env_kwargs=depth, fixations=(1.0, 4.0), **tiny)
    stage = next(s for s in record["stages"] if s["name"] == "fixation")
    assert stage["postures"] == 2 and stage["fixations_m"] == [1.0, 4.0]
    played = {p["fix"] for p in record["postures"] if p["stage"] == "fixation"}
    assert played == {1.0, 4.0}
    assert record["rules"]["fixations_m"] == [1.0, 4.0]
    # auto and no depth law: no fixation stage, every posture at the default vergence
    plain = search("EyeCatch-v0", "eyecatch", **tiny)
    assert all(s["name"] != "fixation" for s in plain["stages"])
    assert {p["fix"] for p in plain["postures"]} == {2.0}


def test_json_object_options_are_checked_naming_the_option():
    from visuomotor_gym.static_gaze import parse_json_object

    assert parse_json_object('{"crowding": true}', "--vision", "VisionParams fields") == {"crowding": True}
    with pytest.raises(SystemExit, match="--env-kwargs: not JSON"):
        parse_json_object("{crowding}", "--env-kwargs", "constructor arguments")
    with pytest.raises(SystemExit, match="--vision: must be a JSON object of VisionParams fields"):
        parse_json_object("[1, 2]", "--vision", "VisionParams fields")


def test_grid_vergence_and_the_fixation_stage_over_several_postures():
    from visuomotor_gym.static_gaze import search

    depth = {"vision_params": {"depth_pedestal_arcmin": 10.0}}
    tiny = {"coarse_step": 90.0, "coarse_episodes": 1, "final_episodes": 1, "refine_steps": (), "finalists": 2,
            "neck_step": 0.0}
    record = search("EyeCatch-v0", "eyecatch", env_kwargs=depth, fixations=(4.0,), grid_fixation=0.8,
                    fixation_top=2, **tiny)
    grid = {p["fix"] for p in record["postures"] if p["stage"] != "fixation"}
    assert grid == {0.8} and record["rules"]["grid_fixation_m"] == 0.8
    stage = next(s for s in record["stages"] if s["name"] == "fixation")
    assert len(stage["around_all"]) == 2 and stage["postures"] == 2  # both finalists tried at 4 m
    verged = {(p["az"], p["el"]) for p in record["postures"] if p["stage"] == "fixation"}
    assert len(verged) == 2
    with pytest.raises(ValueError, match="grid_fixation"):
        search("EyeCatch-v0", "eyecatch", grid_fixation=100.0, **tiny)
    with pytest.raises(ValueError, match="fixation_top"):
        search("EyeCatch-v0", "eyecatch", fixation_top=0, **tiny)
