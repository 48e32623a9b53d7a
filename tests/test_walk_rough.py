"""ObstacleWalk-v0's opt-in rough course (``course_distribution="rough"``): the preset is
reproducible and follows its geometry (a hand-computed overlap case), the default course is untouched,
its slots carry no hidden truth (an obstacle passed unseen changes no slot id), the iwao baseline picks
its foothold gaze on it, and the static posture search takes the env's arguments."""

from __future__ import annotations

import json
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.envs.walk import WALK_LAYOUT, ObstacleWalkEnv
from visuomotor_gym.static_gaze import main as static_gaze_main
from visuomotor_gym.static_gaze import registered_kwargs
from visuomotor_gym.tasks.obstacle_walk import (
    BOX,
    DENSE_ROUGH_COURSE,
    K_SLOTS,
    MAT,
    N_POINTS,
    ROUGH_CLEAR_M,
    ROUGH_COURSE,
    CourseDistribution,
    _overlap,
    sample_course,
    top_points,
)

SLOTS = [WALK_LAYOUT.slices[f"obstacle_{k}"] for k in range(K_SLOTS)]


def test_the_preset_is_opt_in_and_the_default_course_unchanged():
    assert CourseDistribution().layout == "walkway" and not CourseDistribution().rough
    assert ROUGH_COURSE.rough
    # The default sampler draws what it drew before the preset existed (seed 0, recorded from main 8bbb66e).
    course = sample_course(np.random.default_rng(0), CourseDistribution(), 16)
    assert len(course.obstacles) == 5
    assert course.length == 18.18480843660727 and float(course.obstacles.sum()) == 56.43376144066628
    env = ObstacleWalkEnv(course_distribution="rough")
    assert env.course_distribution == ROUGH_COURSE
    assert ObstacleWalkEnv(course_distribution={"layout": "rough"}).course_distribution.rough
    with pytest.raises(ValueError, match="course_distribution"):
        ObstacleWalkEnv(course_distribution="bumpy")
    with pytest.raises(ValueError, match=r"course_distribution\.layout"):
        ObstacleWalkEnv(course_distribution={"layout": "bumpy"})


def test_the_rough_course_is_reproducible_on_every_rung():
    a = sample_course(np.random.default_rng(11), ROUGH_COURSE, 16)
    b = sample_course(np.random.default_rng(11), ROUGH_COURSE, 16)
    np.testing.assert_array_equal(a.obstacles, b.obstacles)
    infos = []
    for env_id in ("ObstacleWalk-v0", "ObstacleWalkOracle-v0", "ObstacleWalkPoorVision-v0"):
        env = gym.make(env_id, course_distribution="rough")
        infos.append(env.reset(seed=11)[1])
        env.close()
    for info in infos[1:]:
        np.testing.assert_array_equal(info["obstacles"], infos[0]["obstacles"])
    n = infos[0]["n_obstacles"]
    np.testing.assert_array_equal(infos[0]["obstacles"][:n], a.obstacles)


def test_overlap_against_a_hand_computed_case():
    """Two 0.2 m squares on the centre line: the earlier one spans x 0.25-0.45. A new one from x = -0.001
    to 0.199 keeps 5.1 cm from it (clear of ROUGH_CLEAR_M = 5 cm); from x = 0.001 only 4.9 cm (overlap).
    Beside it (lateral centres 0.251 m apart, 0.2 m wide each: 5.1 cm between them) it is clear; 0.249 m
    apart (4.9 cm) it is not; far beside it but along the same x it is clear."""
    assert ROUGH_CLEAR_M == 0.05
    row = (0.35, 0.0, 0.2, 0.2)
    assert not _overlap(-0.001, 0.2, 0.0, 0.2, row)
    assert _overlap(0.001, 0.2, 0.0, 0.2, row)
    assert not _overlap(0.3, 0.2, 0.251, 0.2, row)
    assert _overlap(0.3, 0.2, 0.249, 0.2, row)
    assert _overlap(0.3, 0.2, -0.249, 0.2, row)
    assert not _overlap(0.3, 0.2, -0.6, 0.2, row)


def test_the_dense_preset_is_the_rough_course_with_hazards_every_045_to_08_m():
    assert replace(ROUGH_COURSE, rough_step_m=(0.45, 0.8)) == DENSE_ROUGH_COURSE
    assert ObstacleWalkEnv(course_distribution="rough_dense").course_distribution == DENSE_ROUGH_COURSE
    from visuomotor_gym.agents import make_agent

    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "rough_dense"}):
        assert make_agent("iwao", "ObstacleWalk-v0", 8, seed=0).params.gaze_mode == "footholds"
    # denser: more hazards per course than the rough preset's, seeds 0-59
    n = {d: sum(len(sample_course(np.random.default_rng(s), d, 16).obstacles) for s in range(60))
         for d in (ROUGH_COURSE, DENSE_ROUGH_COURSE)}
    assert n[DENSE_ROUGH_COURSE] > 1.05 * n[ROUGH_COURSE]


@pytest.mark.parametrize("d", [ROUGH_COURSE, DENSE_ROUGH_COURSE], ids=["rough", "rough_dense"])
def test_rough_courses_follow_their_geometry(d):
    half = 0.5 * d.walkway_width_m
    counts = []
    for seed in range(60):
        course = sample_course(np.random.default_rng(seed), d, 16)
        ob = course.obstacles
        counts.append(len(ob))
        near, far = ob[:, 0] - 0.5 * ob[:, 2], ob[:, 0] + 0.5 * ob[:, 2]
        assert d.first_m[0] <= near[0] and far[-1] <= course.length - d.finish_clear_m + 1e-12
        assert np.all(np.diff(near) >= d.rough_step_m[0] - 1e-12)  # one hazard per step at most
        assert set(ob[:, 5].astype(int)) <= {BOX, MAT}
        assert np.all(np.abs(ob[:, 1]) <= d.rough_lateral_m[1] + 1e-12)
        assert np.all(np.abs(ob[:, 1]) + 0.5 * ob[:, 3] <= half)  # inside the walkway
        mats, rocks = ob[ob[:, 5] == MAT], ob[ob[:, 5] == BOX]
        assert np.all((mats[:, 2:4] >= d.rough_patch_m[0]) & (mats[:, 2:4] <= d.rough_patch_m[1]))
        assert np.all((rocks[:, 4] >= d.height_m[0]) & (rocks[:, 4] <= d.height_m[1]))
        for i in range(len(ob)):
            for j in range(i):
                assert not _overlap(near[i], ob[i, 2], ob[i, 1], ob[i, 3], tuple(ob[j]))
    assert min(counts) >= 10  # small hazards all along the course


def _walk(env, look_up_steps: int, look_down_steps: int):
    """Walk straight at the nominal step; gaze and head up (nothing on the ground in the 20 deg field)
    for ``look_up_steps``, then the head straight and the gaze down to 25 deg below the horizontal (the
    ground ~3.5 m ahead); return the observations and infos."""
    out = []
    for t in range(look_up_steps + look_down_steps):
        a = np.zeros(8, np.float32)
        up = t < look_up_steps
        elevation = np.degrees(np.arcsin(env.eye.rot[2, 0]))  # the line of sight's (test driver only)
        a[4] = 0.5 if up else float(np.clip((-25.0 - elevation) / 60.0, -0.5, 0.0))
        a[7] = 1.0 if up else 0.0  # neck pitch: up to its range's end; then straight
        obs, _, term, trunc, info = env.step(a)
        out.append((obs, info))
        assert not term and not trunc
    return out


def test_an_obstacle_passed_unseen_changes_no_slot_id():
    """Counterfactual courses: A has a patch beside the path at x ~ 1.2 m that the walker passes while
    looking up; in B the same patch lies behind the start (passed before the first step). Every other
    obstacle is the same. The observations are identical all along -- while looking up every slot is
    empty (id -1), and once the walker looks down the first obstacle it sees is labelled 0 in both,
    although A has passed one obstacle more. On the default course (course indices in the slots) the
    same counterfactual shows in the ids: the positive control."""
    # Flat patches only (nothing to trip on), the first 5.5 m ahead: beyond the 5 m sight range at the start.
    patches = {"kind_p": (0.0, 0.0, 1.0), "first_m": (5.5, 5.5)}
    runs = {}
    for layout in ("rough", "walkway"):
        for name, x in (("A", 1.2), ("B", -3.0)):
            dist = {**ROUGH_COURSE.__dict__, **patches} if layout == "rough" else patches
            env = ObstacleWalkEnv(course_distribution=dist)
            env.reset(seed=3)
            task = env.task
            row = task.course.obstacles[0].copy()
            row[0], row[1] = x, 0.6  # beside the feet (which stay within 0.2 m of the centre line)
            task.course.obstacles[0] = row
            _, y, depth, width, height, _ = row.tolist()
            task.pool.place(env.model, env.data, 0, x, y, depth, width, height)
            for t, point in zip(task.targets[:N_POINTS], top_points(x, y, depth, width, height)):
                t.place(*point)
            runs[layout, name] = _walk(env, 100, 40)
            env.close()
    a, b = runs["rough", "A"], runs["rough", "B"]
    assert a[99][1]["obstacles_passed"] == 1 and b[99][1]["obstacles_passed"] == 1  # A passed it walking
    assert a[0][1]["obstacles_passed"] == 0
    for (oa, _), (ob, _) in zip(a, b):
        np.testing.assert_array_equal(oa, ob)
    ids_up = [oa[s][0] for oa, _ in a[:100] for s in SLOTS]
    assert set(ids_up) == {-1.0}
    seen = [(oa[s][0], oa[s][1 + 3 * N_POINTS:]) for oa, _ in a[100:] for s in SLOTS]
    assert any(flags.any() for _, flags in seen)
    assert min(i for i, flags in seen if flags.any()) == 0.0
    differ = any(not np.array_equal(oa, ob) for (oa, _), (ob, _) in zip(runs["walkway", "A"], runs["walkway", "B"]))
    assert differ


def test_iwao_looks_at_footholds_on_the_rough_course():
    from visuomotor_gym.agents import make_agent

    agent = make_agent("iwao", "ObstacleWalk-v0", 8, seed=0)
    assert agent.params.gaze_mode == "iwao"
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "rough"}):
        agent = make_agent("iwao", "ObstacleWalk-v0", 8, seed=0)
        env = gym.make("ObstacleWalk-v0")
        obs, _ = env.reset(seed=0)
        targets = set()
        for _ in range(150):
            a, _ = agent.predict(obs)
            obs, _, term, trunc, _ = env.step(a)
            targets.add(agent.target_id)
            if term or trunc:
                break
        env.close()
    assert agent.params.gaze_mode == "footholds"
    assert len(targets - {-1}) >= 2  # it fixated several hazards, by label
    assert gym.spec("ObstacleWalk-v0").kwargs.get("course_distribution") is None  # restored


def test_registered_kwargs_restores_and_refuses():
    before = dict(gym.spec("ObstacleWalk-v0").kwargs)
    with pytest.raises(ValueError, match="course_distribution"), \
            registered_kwargs("ObstacleWalk-v0", {"course_distribution": "bumpy"}):
        pass
    assert dict(gym.spec("ObstacleWalk-v0").kwargs) == before
    with pytest.raises(TypeError, match="env kwargs"), registered_kwargs("ObstacleWalk-v0", ["rough"]):
        pass


def test_static_search_takes_env_kwargs(tmp_path):
    out = tmp_path / "search.json"
    kwargs = {"course_distribution": "rough", "vision_params": {"field_shape": "human"}}
    assert static_gaze_main(["search", "--env", "ObstacleWalk-v0", "--agent", "iwao", "--out", str(out), "--quiet",
                             "--postures", "0,-40,0,-40", "--coarse-episodes", "1", "--final-episodes", "1",
                             "--env-kwargs", json.dumps(kwargs)]) == 0
    record = json.loads(out.read_text())
    assert record["env_kwargs"] == kwargs
    assert gym.spec("ObstacleWalk-v0").kwargs.get("course_distribution") is None
    with pytest.raises(SystemExit, match="env-kwargs"):
        static_gaze_main(["search", "--env", "ObstacleWalk-v0", "--agent", "iwao", "--out", str(out),
                          "--postures", "0,-40", "--env-kwargs", "[1, 2]"])


# --- the iwao memory under the human periphery (rough course) ---------------------------------------------
HUMAN_ROUGH = {"course_distribution": "rough",
               "vision_params": {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True,
                                 "depth_pedestal_arcmin": 10.0}}


def test_height_prior_places_a_bearing_on_the_floor_plane():
    """Hand-computed: the eye at (0, 0, 1.6) sees a point along the unit direction toward (2, 0, 0.06),
    precisely across the line of sight (1 mm) and not at all along it (depth std 1 km). With the height
    prior N(0.06, 0.1) the fused point is where that line meets the plane z = 0.06: (2, 0, 0.06); without
    the prior the information matrix is singular along the line (the estimate is no number to trust)."""
    from visuomotor_gym.baselines.iwao.perception import Corner

    eye, target = np.array([0.0, 0.0, 1.6]), np.array([2.0, 0.0, 0.06])
    u = (target - eye) / np.linalg.norm(target - eye)
    far = eye + 5.0 * u  # a perceived point far along the same line (a large depth error)
    corner = Corner((0.06, 0.1))
    corner.add(tuple(far), tuple(u), 1000.0, 0.001)
    pos, sd = corner.estimate()
    np.testing.assert_allclose(pos, target, atol=1e-4)
    assert sd[2] < 0.1 and sd[0] > sd[1]  # height from the prior; along the path from it through the angle
    bare = Corner()
    bare.add(tuple(far), tuple(u), 1000.0, 0.001)
    assert np.linalg.cond(bare._matrix()) > 1e10


def test_the_memory_gate_drops_a_sample_off_its_line_of_sight():
    """Four samples of a point on the floor ahead, taken 0.25 m apart as the walker approaches, agree; a
    fifth whose line of sight passes 0.2 m beside the point (a crowded percept pooled with a flanker,
    far beyond its noise and the estimate's spread) is not fused with ``gate=2``, and is (moving the
    estimate) without a gate."""
    from visuomotor_gym.baselines.iwao.perception import ObstacleMemory

    from visuomotor_gym.vision.foveation import human_periphery

    eye_pos = [0.0, 0.0, 0.6]  # eye in the pelvis frame; pelvis height 1.0 in odo: eye at 1.6 m
    point = np.array([3.0, 0.1, 0.05])
    ex = (point - [0.0, 0.0, 1.6]) / np.linalg.norm(point - [0.0, 0.0, 1.6])  # the line of sight, on the point
    ey = np.cross([0.0, 0.0, 1.0], ex)
    ey /= np.linalg.norm(ey)
    rot = np.column_stack([ex, ey, np.cross(ex, ey)])  # columns: the eye's axes in the pelvis frame

    def sample(mem, x, lateral=0.0):
        p = rot.T @ (point + np.array([-x, lateral, -1.6]))  # the point in the eye frame
        mem.add(0, 0, tuple(p), eye_pos, rot.tolist(), (x, 0.0, 0.0, 1.0), vergence=float(np.linalg.norm(p)))

    out = {}
    for gate in (2.0, None):
        mem = ObstacleMemory(human_periphery(position_disarray=0.0), height_prior=(0.06, 0.1), gate=gate)
        for k in range(4):
            sample(mem, 0.25 * k)
        before = mem.corners[0][0].estimate()[0].copy()
        sample(mem, 1.0, lateral=0.2)
        out[gate] = (mem.corners[0][0].n, float(np.abs(mem.corners[0][0].estimate()[0] - before).max()))
    assert out[2.0] == (4, 0.0)
    assert out[None][0] == 5 and out[None][1] > 0.01


@pytest.mark.parametrize("seed", [0, 1])
def test_iwao_crosses_the_rough_course_under_the_human_periphery_and_its_held_twin_does_not(seed):
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    with registered_kwargs("ObstacleWalk-v0", HUMAN_ROUGH):
        env = gym.make("ObstacleWalk-v0")
        results = {}
        for spec in ("iwao", "gaze_blind:iwao"):
            policy = make_agent(spec, "ObstacleWalk-v0", 8, seed=seed)
            results[spec] = bool(run_episode(env, policy, seed=seed, env_id="ObstacleWalk-v0", agent=spec).success)
        env.close()
    assert results == {"iwao": True, "gaze_blind:iwao": False}


@pytest.mark.parametrize("ecc_deg", [5.0, 25.0])
def test_the_memory_weights_a_peripheral_sample_as_shared_under_disarray(ecc_deg):
    """Hand-computed: with positional disarray (share s) a sample's lateral information is divided by
    1 + (K - 1) w, K = DISARRAY_LOOKS looks sharing one retinal place and w = s (1 - 1/f^2) the fixed
    share of its lateral variance, f = 1 + theta / 0.7 deg the position law's growth (Hess & Field 1993;
    VisionParams.position_disarray). The eye at 1.6 m looks level along x; the point lies ``ecc_deg`` below
    the line of sight, 0.15 m above the floor: its lateral y axis is across the line of sight, so the
    information matrix's yy entry is the sample's 1 / s_lat^2."""
    import math

    from visuomotor_gym.baselines.iwao.perception import DISARRAY_LOOKS, ObstacleMemory

    from visuomotor_gym.vision.foveation import human_periphery

    t = math.radians(ecc_deg)
    d = 1.45 / math.sin(t)  # on the plane 0.15 m above the floor (the memory's first guess of a top)
    p_eye = (d * math.cos(t), 0.0, -d * math.sin(t))  # eccentricity t from the eye's x axis
    eye, rot, odo = [0.0, 0.0, 0.6], np.eye(3).tolist(), (0.0, 0.0, 0.0, 1.0)
    info = {}
    for share in (0.0, 0.8):
        mem = ObstacleMemory(human_periphery(position_disarray=share), height_prior=(0.06, 0.1))
        mem.add(0, 0, p_eye, eye, rot, odo, vergence=d)
        info[share] = mem.corners[0][0].info[3]
    f = 1.0 + math.degrees(t) / 0.7
    w = 0.8 * (1.0 - 1.0 / f**2)
    assert info[0.0] / info[0.8] == pytest.approx(1.0 + (DISARRAY_LOOKS - 1) * w, rel=1e-9)
