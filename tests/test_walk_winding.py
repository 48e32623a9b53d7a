"""ObstacleWalk's opt-in winding walkway (``CourseDistribution(layout="winding")``, preset ``"winding"``): the
centre line's geometry against its ranges, path coordinates against hand-computed cases, the hazards laid in
path coordinates and turned to the path's heading, the env's turning walker and ``path_ahead`` block, the
iwao agent's own copy of the centre line, and one real-physics crossing by the planner with true footprints."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.iwao.agent import AgentPath, IwaoAgent

from visuomotor_gym.agents import make_agent
from visuomotor_gym.envs.walk import OBSTACLE_WALK_VISION, WALK_VISION, WALKWAY_DEFINITION, ObstacleWalkEnv
from visuomotor_gym.static_gaze import registered_kwargs
from visuomotor_gym.tasks.obstacle_walk import (
    COURSE_PRESETS,
    K_SLOTS,
    N_POINTS,
    PATH_DS_M,
    WINDING_COURSE,
    CourseDistribution,
    WindingPath,
    sample_course,
    sample_path,
    top_points,
)
from visuomotor_gym.vision.foveation import human_periphery


@pytest.mark.parametrize("seed", range(12))
def test_the_centre_line_turns_within_its_ranges(seed):
    d = WINDING_COURSE
    path = sample_path(np.random.default_rng(seed), d, 16.0)
    h = path.heading
    assert path.length == pytest.approx(16.0, abs=PATH_DS_M)
    n0 = int(d.winding_straight_start_m / PATH_DS_M)
    assert np.all(h[:n0] == 0.0)  # the start is straight
    assert np.abs(h).max() <= math.radians(d.winding_max_heading_deg) + 1e-9
    kappa = np.abs(np.diff(h)) / PATH_DS_M
    # the sharpest arc: the largest turn over the shortest arc
    assert kappa.max() <= math.radians(d.winding_turn_deg[1]) / d.winding_turn_m[0] + 1e-6
    assert np.abs(h).max() >= math.radians(d.winding_turn_deg[0]) - 1e-9  # it does turn
    step = np.hypot(*np.diff(path.xy, axis=0).T)
    assert np.allclose(step, PATH_DS_M)


def test_path_coordinates_by_hand():
    # A quarter circle of radius 2 m to the left after 1 m straight, then straight along +y.
    s = np.arange(0.0, 6.0 + 1e-9, PATH_DS_M)
    r, arc = 2.0, 0.5 * math.pi * 2.0
    h = np.clip((s - 1.0) / r, 0.0, 0.5 * math.pi)
    xy = np.zeros((len(s), 2))
    mid = h[:-1] + 0.5 * np.diff(h)
    xy[1:, 0] = np.cumsum(np.cos(mid) * PATH_DS_M)
    xy[1:, 1] = np.cumsum(np.sin(mid) * PATH_DS_M)
    path = WindingPath(xy, h)
    assert path.to_world(0.5, 0.2) == pytest.approx((0.5, 0.2), abs=1e-9)
    end = 1.0 + arc  # the arc's end: (1 + r, r), heading +y
    x, y = path.to_world(end + 0.5, 0.3)  # 0.5 m on along +y, 0.3 m left of it (= -x)
    assert (x, y) == pytest.approx((1.0 + r - 0.3, r + 0.5), abs=3e-3)
    assert path.project(1.0 + r - 0.3, r + 0.5) == pytest.approx((end + 0.5, 0.3), abs=3e-3)
    assert path.heading_at(end + 1.0) == pytest.approx(0.5 * math.pi)


def test_hazards_are_laid_in_path_coordinates_and_turned_to_the_path():
    course = sample_course(np.random.default_rng(3), WINDING_COURSE, 16)
    assert course.path is not None and course.local.shape == course.obstacles.shape
    assert np.any(np.abs(course.yaw) > 0.2)  # some hazards lie on a turned part of the walkway
    for world, local, yaw in zip(course.obstacles, course.local, course.yaw):
        assert tuple(world[:2]) == pytest.approx(course.path.to_world(local[0], local[1]))
        assert yaw == pytest.approx(course.path.heading_at(local[0]))
        assert np.array_equal(world[2:], local[2:])
        assert abs(local[1]) <= 0.5 + 1e-9


def test_top_points_turned_by_hand():
    # A 0.2 m deep, 0.4 m wide patch at (1, 2) turned 90 deg left: its depth runs along +y.
    pts = top_points(1.0, 2.0, 0.2, 0.4, 0.01, 0.5 * math.pi)
    # near-left (behind, to the left = -x), far-right, near and far edge midpoints
    want = ((0.8, 1.9, 0.01), (1.2, 2.1, 0.01), (1.0, 1.9, 0.01), (1.0, 2.1, 0.01))
    for p, w in zip(pts, want):
        assert p == pytest.approx(w, abs=1e-12)
    assert top_points(1.0, 2.0, 0.2, 0.4, 0.01) == top_points(1.0, 2.0, 0.2, 0.4, 0.01, 0.0)


def test_the_winding_preset_is_the_default_and_checks_its_fields():
    assert COURSE_PRESETS["winding"] is WINDING_COURSE and WINDING_COURSE.rough
    assert ObstacleWalkEnv().course_distribution == WINDING_COURSE  # the default (ObstacleWalk-v0 redefined)
    assert ObstacleWalkEnv().vision_params == OBSTACLE_WALK_VISION == human_periphery(WALK_VISION)
    with pytest.raises(ValueError, match="winding_turn_deg"):
        CourseDistribution(layout="winding", winding_turn_deg=(10.0, 120.0))
    with pytest.raises(ValueError, match="winding_max_heading_deg"):
        CourseDistribution(layout="winding", winding_max_heading_deg=-1.0)


def test_the_env_turns_its_walker_and_shows_the_centre_line_ahead():
    env = gym.make("ObstacleWalk-v0", course_distribution="winding")
    u = env.unwrapped
    assert env.action_space.shape == (9,) and u.action_structure["footstep"] == 4
    obs, _ = env.reset(seed=1)
    ahead = obs[u.layout.slices["path_ahead"]].reshape(-1, 2)
    qx, qy = float(u.data.qpos[0]), float(u.data.qpos[1])
    s0, n0 = u.course.path.project(qx, qy)
    assert abs(n0) < 0.02 and -0.5 < s0 < 0.5  # at the start the pelvis is by the straight start (behind its heel)
    for k, (x, y) in enumerate(ahead.tolist()):
        px, py = u.course.path.to_world(s0 + 0.5 * k, 0.0)
        assert (x, y) == pytest.approx((px - qx, py - qy), abs=2e-3)
    straight = gym.make("ObstacleWalk-v0", **WALKWAY_DEFINITION)
    assert straight.action_space.shape == (8,) and "path_ahead" not in straight.unwrapped.layout.structure
    env.close()
    straight.close()


def test_the_agent_path_follows_the_centre_line():
    course = sample_course(np.random.default_rng(5), WINDING_COURSE, 16)
    ap = AgentPath()
    for s0 in np.arange(0.0, 8.0, 0.03):  # as the block shows it while the pelvis walks the centre line
        x0, y0 = course.path.to_world(s0, 0.0)
        yaw = course.path.heading_at(s0)
        c, s = math.cos(yaw), math.sin(yaw)
        block = []
        for k in range(13):
            wx, wy = course.path.to_world(s0 + 0.5 * k, 0.0)
            block += [c * (wx - x0) + s * (wy - y0), -s * (wx - x0) + c * (wy - y0)]
        ap.update(block, (x0, y0, yaw))
    for s_true in (1.0, 4.0, 7.5, 12.0):
        for n_true in (-0.5, 0.0, 0.4):
            x, y = course.path.to_world(s_true, n_true)
            s_, n_, _ = ap.project(x, y)
            assert (s_, n_) == pytest.approx((s_true, n_true), abs=0.03)
            assert ap.to_world(s_, n_) == pytest.approx((x, y), abs=0.01)  # a polyline: 1 cm at its kinks


def test_iwao_picks_the_winding_mode_from_the_registered_course():
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "walkway"}):
        assert not IwaoAgent.for_env("ObstacleWalk-v0").params.winding
    assert IwaoAgent.for_env("ObstacleWalk-v0").params.winding  # the default
    assert IwaoAgent.for_env("ObstacleWalk-v0").params.gaze_mode == "footholds"


def test_the_planner_with_true_footprints_walks_a_winding_course():
    env_id = "ObstacleWalkOracle-v0"
    with registered_kwargs(env_id, {"course_distribution": "winding"}):
        env = gym.make(env_id)
        agent = make_agent("iwao", env_id, 9, seed=0)
        obs, _ = env.reset(seed=2)
        u = env.unwrapped
        end = u.course.path.to_world(u.course.length, 0.0)
        assert abs(math.degrees(u.course.path.heading_at(u.course.length))) > 30.0  # it turns
        done, first = False, True
        while not done:
            a, _ = agent.predict(obs, episode_start=np.array([first]))
            first = False
            obs, _, term, trunc, info = env.step(a)
            done = term or trunc
        assert info["is_success"] and not info["off_path"]
        assert np.hypot(*(info["pelvis_pos"][:2] - np.array(end))) < 0.8  # at the finish, not on a straight line
        env.close()


def test_walk_realism_reads_the_winding_walkway_in_path_coordinates():
    from types import SimpleNamespace

    from visuomotor_gym.metrics.walk_realism import distance_left, on_walkway

    # The centre line turns 90 deg left on a 2 m arc after 1 m straight (as in test_path_coordinates_by_hand).
    s = np.arange(0.0, 8.0 + 1e-9, PATH_DS_M)
    h = np.clip((s - 1.0) / 2.0, 0.0, 0.5 * math.pi)
    xy = np.zeros((len(s), 2))
    mid = h[:-1] + 0.5 * np.diff(h)
    xy[1:, 0] = np.cumsum(np.cos(mid) * PATH_DS_M)
    xy[1:, 1] = np.cumsum(np.sin(mid) * PATH_DS_M)
    path = WindingPath(xy, h)
    eye = np.array([[*path.to_world(2.0, 0.0), 1.6]])
    ground = np.array(path.to_world(4.5, 0.1))  # on the walkway 2.5 m further along it, 1.5 m beside the x axis
    d = np.array([*(ground - eye[0, :2]), -1.6])
    trace = SimpleNamespace(eye_pos=eye, gaze_dir=d[None] / np.linalg.norm(d), obstacles=np.zeros((0, 6)),
                            obstacles_path=np.zeros((0, 6)), course_length=10.0,
                            pelvis_pos=np.array([[*path.to_world(7.0, 0.0), 0.9]]),
                            task={"path": np.column_stack((path.xy, path.heading))})
    assert abs(ground[1]) > 1.0 and on_walkway(trace).tolist() == [True]
    assert distance_left(trace) == pytest.approx(3.0, abs=0.02)
    off = np.array(path.to_world(4.5, 1.2))  # beside the walkway
    d = np.array([*(off - eye[0, :2]), -1.6])
    trace.gaze_dir = d[None] / np.linalg.norm(d)
    assert on_walkway(trace).tolist() == [False]
    trace.task = {}  # the straight walkway's reading: the arc's point lies 1.5 m beside y = 0
    trace.gaze_dir = np.array([[*(ground - eye[0, :2]), -1.6]]) / np.linalg.norm([*(ground - eye[0, :2]), -1.6])
    assert on_walkway(trace).tolist() == [False]


@pytest.mark.parametrize("steady", [True, False])
def test_the_fixation_request_takes_the_eye_bob_out_of_the_eyes_height(steady):
    """With ``fixation_steady_height`` the held fixation's direction is asked from the eye at its height averaged
    over the last step (the head's bob out), else from its height now; by hand: a ground point 2 m ahead, the eye
    bobbing 1.55 / 1.60 m, the eye frame level along x (its requested elevation is then the action's)."""
    from visuomotor_gym.baselines.iwao.agent import IwaoParams

    agent = IwaoAgent(IwaoParams(gaze_mode="footholds", fixation_steady_height=steady))
    agent.target, agent.target_id, agent.fixation = (2.0, 0.0, 0.0), -1, (2.0, 0.0, 0.0)
    rot = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    heights = [1.55 if k % 2 else 1.60 for k in range(3 * agent.period_steps)]
    obs = np.zeros(agent.layout.size)
    for z in heights:
        agent.fix_steps = 0  # hold the fixation: no new target is chosen
        action = agent._look_footholds(obs, 0.0, ([0.0, 0.0, 0.0], rot, (0.0, 0.0, 0.0, z)))
    window = heights[-agent.period_steps:]
    z_seen = sum(window) / len(window) if steady else heights[-1]
    assert action[1] * agent.gaze_range == pytest.approx(math.atan2(-z_seen, 2.0), abs=1e-9)
    assert steady == (abs(z_seen - heights[-1]) > 0.02)  # the two differ by about half the bob


def test_iwao_steadies_its_fixations_on_the_winding_walkway_only():
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "winding"}):
        assert IwaoAgent.for_env("ObstacleWalk-v0").params.fixation_steady_height
        assert not IwaoAgent.for_env("ObstacleWalk-v0", fixation_steady_height=False).params.fixation_steady_height
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": "rough"}):
        assert not IwaoAgent.for_env("ObstacleWalk-v0").params.fixation_steady_height


def test_an_obstacle_passed_unseen_changes_no_slot_id_on_the_winding_walkway():
    """Counterfactual courses on the default (winding) walkway: in A a patch lies beside the straight start at
    s = 1.2 m, which the walker passes while looking up; in B the same patch lies behind the start. Every other
    obstacle is the same. The observations are identical all along (while looking up every slot is empty, id
    -1; once the walker looks down the first obstacle it sees is labelled 0 in both, although A has passed one
    obstacle more). The oracle rung (true points, course indices) is the positive control: there it shows."""
    patches = {"kind_p": (0.0, 0.0, 1.0), "first_m": (5.5, 5.5)}  # flat patches, beyond the 5 m sight range
    runs = {}
    for vision in ("foveated", "oracle"):
        for name, s_ in (("A", 1.2), ("B", -3.0)):
            env = ObstacleWalkEnv(vision=vision, course_distribution={**WINDING_COURSE.__dict__, **patches})
            env.reset(seed=3)
            task = env.task
            assert task.course.path.heading_at(0.0) == 0.0 and task.course.path.heading_at(1.2) == 0.0
            row = task.course.local[0].copy()
            row[0], row[1] = s_, 0.6  # on the straight start (path = world frame there), beside the feet
            task.course.local[0] = row
            task.course.obstacles[0] = row
            task.course.yaw[0] = 0.0
            x, y, depth, width, height, _ = row.tolist()
            task.pool.place(env.model, env.data, 0, x, y, depth, width, height, yaw=0.0)
            for t, point in zip(task.targets[:N_POINTS], top_points(x, y, depth, width, height)):
                t.place(*point)
            out = []
            slots = [env.layout.slices[f"obstacle_{k}"] for k in range(K_SLOTS)]
            for t in range(140):  # straight at the nominal step: gaze and head up, then 25 deg down
                a = np.zeros(9, np.float32)
                up = t < 100
                elevation = np.degrees(np.arcsin(env.eye.rot[2, 0]))  # the line of sight's (test driver only)
                a[5] = 0.5 if up else float(np.clip((-25.0 - elevation) / 60.0, -0.5, 0.0))
                a[8] = 1.0 if up else 0.0
                obs, _, term, trunc, info = env.step(a)
                out.append(([obs[sl] for sl in slots], obs, info))
                assert not term and not trunc
            runs[vision, name] = out
            env.close()
    a, b = runs["foveated", "A"], runs["foveated", "B"]
    assert a[99][2]["obstacles_passed"] == 1 and b[99][2]["obstacles_passed"] == 1  # A passed it walking
    assert a[0][2]["obstacles_passed"] == 0
    for (_, oa, _), (_, ob, _) in zip(a, b):
        np.testing.assert_array_equal(oa, ob)
    assert {float(sl[0]) for slots, _, _ in a[:100] for sl in slots} == {-1.0}
    seen = [(float(sl[0]), sl[1 + 3 * N_POINTS:]) for slots, _, _ in a[100:] for sl in slots]
    assert any(flags.any() for _, flags in seen)
    assert min(i for i, flags in seen if flags.any()) == 0.0
    assert any(not np.array_equal(oa, ob) for (_, oa, _), (_, ob, _) in zip(runs["oracle", "A"], runs["oracle", "B"]))


def test_a_nan_arc_length_reads_nan_not_an_error():
    """Diverged physics makes the pelvis NaN: the centre line then gives NaN points (the env flags the
    divergence) instead of raising while it builds the observation."""
    path = sample_path(np.random.default_rng(0), WINDING_COURSE, 16.0)
    assert all(math.isnan(v) for v in path.to_world(float("nan"), 0.0))
    assert path.to_world(1.0, 0.0) == pytest.approx((1.0, 0.0))  # finite arc lengths as before
