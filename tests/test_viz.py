"""``visuomotor_gym.viz``: the numeric helpers behind the Eyecatch-style figures (against closed forms),
the figures of a real oracle episode, the MP4 recorder and the ``plot`` / ``record`` subcommands."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")
iio = pytest.importorskip("imageio.v3")

from visuomotor_gym.bench.trace import EpisodeTrace, run_episode, save_traces  # noqa: E402
from visuomotor_gym.viz import commands, plots  # noqa: E402

ENV_ID = "EyeCatchOracle-v0"
DT = 0.02


def synthetic_trace(n=51, gaze=None, hand=None, ball=None, ball_vel=None, eye=None, head=None,
                    onset=None, in_saccade=None, caught=True) -> EpisodeTrace:
    """An EpisodeTrace from given arrays (defaults: everything still, looking straight ahead)."""
    t = np.arange(n) * DT
    ahead = np.tile([1.0, 0.0, 0.0], (n, 1))
    return EpisodeTrace(
        env_id="Synthetic-v0", agent="none", seed=0, dt=DT, t=t,
        gaze_dir=ahead if gaze is None else np.asarray(gaze, float),
        eye_pos=np.tile([0.1, 0.0, 1.2], (n, 1)) if eye is None else np.asarray(eye, float),
        head_dir=ahead if head is None else np.asarray(head, float),
        in_saccade=np.zeros(n, bool) if in_saccade is None else np.asarray(in_saccade, bool),
        saccade_onset=np.zeros(n, bool) if onset is None else np.asarray(onset, bool),
        action=np.full((n, 9), np.nan), latency_s=np.full(n, np.nan),
        success=caught, diverged=False, truncated=False,
        task={
            "ball_pos": np.tile([3.0, 0.0, 1.2], (n, 1)) if ball is None else np.asarray(ball, float),
            "ball_vel": np.zeros((n, 3)) if ball_vel is None else np.asarray(ball_vel, float),
            "hand_pos": np.tile([0.3, -0.2, 0.9], (n, 1)) if hand is None else np.asarray(hand, float),
            "ball_visible": np.ones(n, bool), "missed": not caught,
            "release_pos": np.array([3.0, 0.0, 1.2]), "arrival_pos": np.array([0.3, -0.2, 0.9]),
            "flight_time": 1.0,
        },
    )


def circle(n, rate_deg_s, axis="yaw", start_deg=0.0):
    """Unit directions turning at a constant rate: about z (yaw) or in the x-z plane (pitch)."""
    a = np.radians(start_deg + rate_deg_s * DT * np.arange(n))
    if axis == "yaw":
        return np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    return np.stack([np.cos(a), np.zeros(n), np.sin(a)], axis=1)


# ----------------------------------------------------------------------------------------------
# Numeric helpers against closed forms
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("axis", ["yaw", "pitch"])
def test_gaze_turning_at_50_deg_s_gives_eye_speed_50(axis):
    speed = plots.angular_speed_deg_s(circle(40, 50.0, axis, start_deg=-30.0), DT)
    np.testing.assert_allclose(speed, 50.0, rtol=1e-9)
    v = plots.velocity_profiles(synthetic_trace(40, gaze=circle(40, 50.0, axis)))
    np.testing.assert_allclose(v["eye_speed"], 50.0, rtol=1e-9)
    np.testing.assert_allclose(v["t"], (np.arange(39) + 0.5) * DT)


def test_eye_speed_about_a_tilted_axis_and_of_unnormalised_directions():
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    u = np.cross(axis, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    a = np.radians(120.0) * DT * np.arange(30)
    d = np.cos(a)[:, None] * u + np.sin(a)[:, None] * w  # a great circle at 120 deg/s
    np.testing.assert_allclose(plots.angular_speed_deg_s(3.0 * d, DT), 120.0, rtol=1e-9)


def test_hand_tangential_speed_closed_forms():
    n = 30
    line = np.outer(np.arange(n) * DT, [0.6, -0.8, 0.0]) * 1.5  # 1.5 m/s along a unit vector
    np.testing.assert_allclose(plots.tangential_speed(line, DT), 1.5, rtol=1e-9)
    r, omega = 0.25, 4.0  # circle: step chord 2 r sin(omega dt / 2) per dt
    a = omega * DT * np.arange(n)
    ring = np.stack([r * np.cos(a), r * np.sin(a), np.full(n, 1.0)], axis=1)
    v = plots.velocity_profiles(synthetic_trace(n, hand=ring))
    np.testing.assert_allclose(v["hand_speed"], 2 * r * math.sin(omega * DT / 2) / DT, rtol=1e-9)


def test_direction_angles_in_a_yawed_head_frame():
    from visuomotor_gym.oculomotor.plant import direction_from_angles

    az, el = np.radians(25.0), np.radians(-10.0)
    d = direction_from_angles(az, el)
    got = plots.direction_angles(d)
    np.testing.assert_allclose(got, (25.0, -10.0), atol=1e-9)
    head = np.tile(direction_from_angles(np.radians(30.0), np.radians(15.0)), (3, 1))  # pitched head
    frame = plots.reference_frame(synthetic_trace(3, head=head))
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(frame[2], [0, 0, 1])  # elevation stays relative to the horizon
    np.testing.assert_allclose(plots.direction_angles(d, frame), (-5.0, -10.0), atol=1e-9)


def test_gaze_on_the_ball_gives_identical_angles_and_zero_error():
    n = 20
    ball = np.stack([4.0 - 3.0 * DT * np.arange(n), np.full(n, 0.5), 1.2 + 0.05 * np.arange(n)], axis=1)
    eye = np.tile([0.1, 0.0, 1.2], (n, 1)) + np.outer(np.arange(n), [0.0, 0.001, 0.0])  # moving eye
    tr = synthetic_trace(n, ball=ball, eye=eye, gaze=ball - eye)
    a = plots.gaze_ball_angles(tr)
    np.testing.assert_allclose(a["gaze_az"], a["ball_az"], atol=1e-9)
    np.testing.assert_allclose(a["gaze_el"], a["ball_el"], atol=1e-9)
    np.testing.assert_allclose(a["error_deg"], 0.0, atol=1e-6)
    first = plots.direction_angles(ball[0] - eye[0])
    np.testing.assert_allclose((a["ball_az"][0], a["ball_el"][0]), first, atol=1e-9)
    b = plots.gaze_ball_angles(tr, origin="initial")  # from the eye at reset: parallax only
    assert 0 < np.max(np.abs(b["ball_az"] - a["ball_az"])) < 1.0
    with pytest.raises(ValueError, match="origin"):
        plots.gaze_ball_angles(tr, origin="head")


def test_saccade_intervals_onsets_and_apex():
    n = 40
    onset = np.zeros(n, bool)
    flying = np.zeros(n, bool)
    onset[[5, 20]] = True  # saccades start at t[4] and t[19]
    flying[[5, 6]] = True  # the first lasts into step 7, the second ends within step 20
    g, v0 = 9.81, 3.0  # ballistic: apex at v0 / g
    t = np.arange(n) * DT
    vel = np.stack([np.full(n, -4.0), np.zeros(n), v0 - g * t], axis=1)
    pos = np.stack([5.0 - 4.0 * t, np.zeros(n), 1.0 + v0 * t - 0.5 * g * t * t], axis=1)
    tr = synthetic_trace(n, onset=onset, in_saccade=flying, ball=pos, ball_vel=vel)
    np.testing.assert_allclose(plots.saccade_onset_times(tr), [4 * DT, 19 * DT])
    np.testing.assert_allclose(plots.saccade_intervals(tr), [(4 * DT, 7 * DT), (19 * DT, 20 * DT)])
    assert plots.apex_time(tr) == pytest.approx(v0 / g, abs=1e-9)
    # Thrown downward: no apex in flight, the highest row (the first) stands in for it.
    vel_down = vel * [1, 1, 0] + np.outer(-1.0 - g * t, [0, 0, 1])
    pos_down = pos * [1, 1, 0] + np.outer(2.0 - t - 0.5 * g * t * t, [0, 0, 1])
    assert plots.apex_time(synthetic_trace(n, ball=pos_down, ball_vel=vel_down)) == 0.0


# ----------------------------------------------------------------------------------------------
# A real episode
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def oracle_trace():
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent

    env = gym.make(ENV_ID)
    try:
        policy = make_agent("oracle", ENV_ID, env.action_space.shape[0], seed=0)
        return run_episode(env, policy, 0, ENV_ID, "oracle")
    finally:
        env.close()


def test_oracle_gaze_converges_on_the_ball(oracle_trace):
    a = plots.gaze_ball_angles(oracle_trace)
    assert a["error_deg"].shape == oracle_trace.t.shape
    err = a["error_deg"]
    # The initial saccade and the pursuit that follows bring the line of sight onto the ball while
    # it rises. The plant pursues like a human (150 ms latency, gain < 1), so once the first saccade
    # has landed and pursuit has started (t >= 0.25 s) the gaze stays within a few degrees, closer
    # than at the start: pursuit lags a little and catch-up saccades correct it (measured median ~3.6 deg).
    rising = (a["t"] >= 0.25) & (a["t"] <= 0.9 * plots.apex_time(oracle_trace))
    assert rising.sum() >= 5
    assert np.median(err[rising]) < 5.0
    assert np.min(err[rising]) < err[0]
    # The angles agree with the angular error: a small error means near-identical angles.
    close = rising & (err < 2.0)
    assert np.all(np.abs(a["gaze_el"][close] - a["ball_el"][close]) < 2.5)


def test_plot_episode_writes_a_real_png(oracle_trace, tmp_path):
    path = plots.plot_episode(oracle_trace, tmp_path / "sub" / "episode.png")
    assert path.exists() and path.stat().st_size > 50_000
    img = iio.imread(path)
    assert img.ndim == 3 and img.shape[0] > 800 and img.shape[1] > 1200
    rgb = img[..., :3].astype(float)
    assert rgb.std() > 20
    assert np.mean(rgb.min(axis=2) < 200) > 0.03  # a fair share of drawn (non-white) pixels
    assert np.mean(np.ptp(rgb, axis=2) > 60) > 0.005  # and coloured ones (red, green, orange)


def test_each_panel_draws_its_data(oracle_trace):
    az, el = plots.plot_gaze_vs_ball(oracle_trace)
    assert len(az.lines) >= 3 and len(el.lines) >= 3 and az.figure is el.figure
    one = plots.plot_gaze_vs_ball(oracle_trace, ax=plots._new_figure((4, 3)).subplots())
    assert len(one.lines) >= 4
    left, right = plots.plot_tangential_velocities(oracle_trace)
    assert right.lines[0].get_ydata().max() > 0 and left.lines[0].get_ydata().max() > 0
    assert len(plots.plot_gaze_path(oracle_trace).lines) >= 4
    assert plots.plot_paths_3d(oracle_trace).name == "3d"


def test_a_missed_episode_is_plotted_too(tmp_path):
    n = 30
    tr = synthetic_trace(n, gaze=circle(n, 40.0), caught=False, onset=np.eye(n, dtype=bool)[3])
    path = plots.plot_episode(tr, tmp_path / "missed.png")
    assert path.stat().st_size > 20_000
    assert "missed" in plots.outcome(tr)


# ----------------------------------------------------------------------------------------------
# Every family: a real short episode of its reference agent, plotted
# ----------------------------------------------------------------------------------------------
# (env id, agent, control steps: a few seconds, enough for saccades, footholds and a target in view,
# titles each figure must have)
FAMILY_EPISODES = {
    "catch": ("EyeCatch-v0", "eyecatch", 125, ("Gaze vs ball", "Visual field", "Tangential velocity",
                                               "Ball and hand paths")),
    "reach": ("ShelfReach-v0", "faraway", 150, ("Top view", "Seen from the eye", "line of sight and the object",
                                                "Hand to object")),
    "walk": ("ObstacleWalk-v0", "iwao", 200, ("Top view", "Side view", "Gaze over time", "Look-ahead")),
    "stones": ("SteppingStones-v0", "lookahead", 200, ("Top view", "Gaze over time", "Which stone")),
    "dodge": ("ObstacleDodge-v0", "fajen_warren", 250, ("Top view", "Gaze over time", "each pedestrian",
                                                        "distance to each pedestrian")),
    "push": ("PushRecovery-v0", "eom_brace", 200, ("The wall seen from the body", "Gaze over time",
                                                  "Hand and centre of pressure")),
}


def short_episode(env_id, agent, steps, seed=0):
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent

    env = gym.make(env_id, max_episode_steps=steps)
    try:
        policy = make_agent(agent, env_id, env.action_space.shape[0], seed=seed)
        return run_episode(env, policy, seed, env_id, agent)
    finally:
        env.close()


@pytest.mark.parametrize("family", sorted(FAMILY_EPISODES))
def test_every_family_is_plotted_from_a_real_episode(family, tmp_path):
    from matplotlib.collections import PathCollection

    env_id, agent, steps, titles = FAMILY_EPISODES[family]
    trace = short_episode(env_id, agent, steps)
    assert plots.trace_family(trace) == family
    # The record's trace field tells the family of the same trace under an unregistered id, and no
    # other family's trace field is in it.
    from visuomotor_gym.families import families

    marker = {f.name: f.viz.trace_field for f in families()}
    assert [name for name, field in marker.items() if field in trace.task] == [family]
    renamed = EpisodeTrace(**{**trace.__dict__, "env_id": "Unregistered-v0"})
    assert plots.trace_family(renamed) == family
    assert trace.steps <= steps and np.count_nonzero(trace.saccade_onset) >= 1
    fig = plots.episode_figure(trace)
    got = [ax.get_title() for ax in fig.axes]
    for title in titles:
        assert any(title in t for t in got), (title, got)
    assert env_id in fig.get_suptitle() and agent in fig.get_suptitle()
    if family != "catch":
        # The gaze points are drawn, coloured by time (a colour bar in seconds), some on the scene.
        assert any(ax.get_ylabel() == "time (s)" for ax in fig.axes)
        scatters = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)
                    and c.get_label().startswith("gaze")]
        assert scatters and max(len(c.get_offsets()) for c in scatters) >= 5
    path = plots.save_figure(fig, tmp_path / f"{family}.png")  # what plot_episode writes
    img = iio.imread(path)
    assert img.ndim == 3 and img.shape[0] >= 900 and img.shape[1] >= 1400 and path.stat().st_size > 80_000
    rgb = img[..., :3].astype(float)
    assert np.mean(rgb.min(axis=2) < 200) > 0.03 and np.mean(np.ptp(rgb, axis=2) > 60) > 0.005


def test_the_push_figure_hatches_exactly_the_loose_cubes():
    from matplotlib.patches import Rectangle

    trace = short_episode("PushRecovery-v0", "eom_brace", 30, seed=1)
    loose = np.asarray(trace.task["block_loose"], dtype=bool)
    assert loose.any() and (~loose).any()  # seed 1: cubes 0, 2, 4 and 5 loose (one of the nearest two always is)
    wall = plots.episode_figure(trace).axes[0]
    cubes = [p for p in wall.patches if isinstance(p, Rectangle)]
    assert len(cubes) == len(loose)
    assert [bool(p.get_hatch()) for p in cubes] == loose.tolist()
    labels = [t.get_text() for t in wall.get_legend().get_texts()]
    assert "loose cube (gives way)" in labels and "cube face" in labels


def test_gaze_points_meet_the_floor_and_the_boxes():
    from visuomotor_gym.viz import family_plots as fp

    n = 4
    eye = np.tile([0.0, 0.0, 1.5], (n, 1))
    down45 = np.array([1.0, 0.0, -1.0])
    gaze = np.array([down45, down45, [1.0, 0.0, 0.0], [0.0, 1.0, -0.01]])
    tr = synthetic_trace(n, gaze=gaze, eye=eye)
    p = fp.gaze_points(tr)
    np.testing.assert_allclose(p[0], [1.5, 0.0, 0.0], atol=1e-12)  # 45 deg down from 1.5 m: 1.5 m ahead
    assert np.isnan(p[2]).all()  # level: never meets the floor
    assert np.isnan(p[3]).all()  # meets it 150 m away, beyond the range drawn
    box = (np.array([1.0, -0.5, 0.0]), np.array([1.2, 0.5, 0.3]))  # a 30 cm box between the eye and that point
    p = fp.gaze_points(tr, boxes=[box])
    np.testing.assert_allclose(p[0], [1.2, 0.0, 0.3], atol=1e-12)  # its top face, 1.2 m ahead
    assert np.isinf(fp.ray_box_distance(eye[:1], -gaze[:1], *box)).all()  # behind the eye: no hit


def test_footholds_are_the_still_planted_runs_of_a_sole():
    from visuomotor_gym.viz import family_plots as fp

    n = 30
    feet = np.zeros((n, 2, 3))
    feet[:, 0, :2] = [0.2, 0.1]  # left planted throughout
    feet[:10, 1, :2] = [0.0, -0.1]  # right planted, swings (lifted, moving), planted again
    feet[10:20, 1] = np.stack([np.linspace(0.0, 0.6, 10), np.full(10, -0.1), np.full(10, 0.1)], axis=1)
    feet[20:, 1, :2] = [0.6, -0.1]
    tr = synthetic_trace(n)
    tr.task["feet_pos"] = feet
    left, right = fp.footholds(tr)
    np.testing.assert_allclose(left[:, :2], [[0.2, 0.1]])
    np.testing.assert_allclose(right[:, :2], [[0.0, -0.1], [0.6, -0.1]])
    np.testing.assert_allclose(right[:, 2:], [[0.0, 9 * DT], [20 * DT, 29 * DT]])


def test_a_trace_of_no_known_family_is_refused():
    tr = synthetic_trace(5)
    tr.task = {}
    with pytest.raises(ValueError, match="cannot tell the family"):
        plots.episode_figure(tr)


# ----------------------------------------------------------------------------------------------
# Video and commands
# ----------------------------------------------------------------------------------------------
def _parser():
    parser = argparse.ArgumentParser(prog="vmgym")
    commands.register(parser.add_subparsers(dest="command", required=True))
    return parser


def _run(argv):
    args = _parser().parse_args(argv)
    return args.func(args)


@pytest.mark.render
def test_record_writes_a_readable_mp4(tmp_path, capsys):
    from visuomotor_gym.viz.video import record_episode

    out = tmp_path / "ep.mp4"
    trace = record_episode("oracle", ENV_ID, 0, out, width=96, height=72, fps=25)
    frames = iio.imread(out)
    assert frames.shape == (trace.steps + 1, 72, 2 * 96, 3)
    assert trace.extras["video"]["frames"] == trace.steps + 1 and trace.caught
    assert frames.std() > 10
    assert not list(tmp_path.glob(".*partial*"))  # the temporary file was renamed
    with pytest.raises(FileExistsError, match="overwrite"):
        record_episode("oracle", ENV_ID, 0, out, width=96, height=72)
    before = out.stat().st_mtime_ns
    # The command line refuses too, before playing anything, and says how to force it.
    assert _run(["record", "--agent", "oracle", "--env", ENV_ID, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "already exists" in err and "--force" in err and err.count("\n") == 1
    assert out.stat().st_mtime_ns == before
    # --force replaces it (odd sizes padded to even for H.264); --stride 5 keeps every 5th step and the last.
    assert _run(["record", "--agent", "oracle", "--env", ENV_ID, "--out", str(out), "--width", "33",
                 "--height", "25", "--camera", "eye", "--stride", "5", "--force"]) == 0
    assert str(out) in capsys.readouterr().out
    frames = iio.imread(out)
    assert frames.shape[1:] == (26, 34, 3)
    assert len(frames) == 1 + math.ceil(trace.steps / 5)


def _walker_share(env, views, info):
    """Share of the pixels of ``views`` (160 x 120 each) showing the walker, and the body names seen."""
    import mujoco

    from visuomotor_gym.viz.video import FrameRenderer

    m = env.unwrapped.model
    # Without the line of sight: the translucent gaze line blends with what lies behind it, and a blended
    # pixel decodes to no segment at all (MuJoCo's renderer then raises IndexError: ~1 run in 6).
    renderer = FrameRenderer(env, views, 160, 120, line_of_sight=False)
    try:
        renderer.renderer.enable_segmentation_rendering()
        seg = renderer.render(info)
    finally:
        renderer.close()
    ids, types = seg[..., 0], seg[..., 1]
    geom = (types == int(mujoco.mjtObj.mjOBJ_GEOM)) & (ids >= 0)
    bodies = m.geom_bodyid[ids[geom]]
    pelvis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    share = np.count_nonzero(m.body_rootid[bodies] == m.body_rootid[pelvis]) / ids.size
    return share, {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(b)) for b in np.unique(bodies)}


@pytest.mark.render
@pytest.mark.parametrize("env_id", ["ObstacleWalk-v0", "SteppingStones-v0", "ObstacleDodge-v0"])
def test_the_walker_families_scene_view_shows_the_walker_and_its_targets(env_id):
    """The follow view keeps the walker readable (>= 0.4 % of the image, ~25 x 25 pixels at 480 x 360),
    and the targets in view: obstacles, stones, a pedestrian. The dodge scene's own top camera, the old
    scene view, shows the walker on ~0.03 % of the image (a few pixels) and fails the same check."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.viz.video import resolve_views

    env = gym.make(env_id)
    try:
        env.reset(seed=0)
        # 2 s of the nominal gait (the zero action: nominal footsteps, which miss the small stones of the
        # rough course at step 104), 3 s elsewhere: the first pedestrian is on stage
        for _ in range(100 if env_id.startswith("SteppingStones") else 150):
            _, _, terminated, truncated, info = env.step(np.zeros(env.action_space.shape, np.float32))
            assert not (terminated or truncated)
        # The recorder renders the env's own model (the task moved and resized the obstacles and stones
        # at reset) and leaves its visual settings as they were.
        from visuomotor_gym.viz.video import FrameRenderer

        u = env.unwrapped
        before = (u.model.vis.quality.offsamples, u.model.vis.global_.offwidth, u.model.vis.global_.fovy)
        renderer = FrameRenderer(env, resolve_views(env, "both"), 2000, 100)
        renderer.render(info)
        assert renderer.renderer.model is u.model
        renderer.close()
        assert (u.model.vis.quality.offsamples, u.model.vis.global_.offwidth, u.model.vis.global_.fovy) == before
        share, seen = _walker_share(env, resolve_views(env, "scene"), info)
        assert share >= 0.004, share
        target = {"ObstacleWalk-v0": "obstacle", "SteppingStones-v0": "stone", "ObstacleDodge-v0": "pedestrian"}
        assert any(target[env_id] in (name or "") for name in seen), seen
        if env_id == "ObstacleDodge-v0":
            assert _walker_share(env, ("dodge_top",), info)[0] < 0.001
    finally:
        env.close()


def test_record_rejects_bad_arguments_without_playing(tmp_path):
    from visuomotor_gym.viz.video import record_episode

    with pytest.raises(ValueError, match="must end in"):
        record_episode("oracle", ENV_ID, 0, tmp_path / "x.gif")
    with pytest.raises(ValueError, match="pixels"):
        record_episode("oracle", ENV_ID, 0, tmp_path / "x.mp4", width=4)
    with pytest.raises(ValueError, match="stride"):
        record_episode("oracle", ENV_ID, 0, tmp_path / "x.mp4", stride=0)
    with pytest.raises(ValueError, match="quality"):
        record_episode("oracle", ENV_ID, 0, tmp_path / "x.mp4", quality="ultra")
    assert _run(["record", "--agent", "oracle", "--env", ENV_ID, "--out", str(tmp_path / "x.gif")]) == 2
    assert not list(tmp_path.iterdir())


def _one_line_exit_2(argv, capsys, *needles):
    """The command exits 2 at once with one line on stderr that holds every needle."""
    import time

    start = time.perf_counter()
    assert _run(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, (needle, err)
    assert time.perf_counter() - start < 5.0  # refused before any episode is played or rendered
    return err


@pytest.mark.parametrize("command", ["plot", "record"])
def test_outputs_env_and_agent_are_checked_before_any_work(command, tmp_path, capsys):
    out_arg = (lambda p: str(p / "ep.mp4")) if command == "record" else str
    base = [command, "--agent", "oracle", "--env", ENV_ID]
    # An output under /proc, and one in a folder that cannot be written.
    _one_line_exit_2(base + ["--out", out_arg(Path("/proc/vmgym-no-such"))], capsys, "cannot write")
    blocker = tmp_path / "a-file"  # a folder that cannot be made: its parent is a file (root or not)
    blocker.write_text("")
    _one_line_exit_2(base + ["--out", out_arg(blocker / "sub")], capsys, "cannot write")
    if os.geteuid() != 0:  # a read-only folder (root may write anywhere)
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        try:
            _one_line_exit_2(base + ["--out", out_arg(locked)], capsys, "cannot write")
        finally:
            locked.chmod(0o700)
    # A bad env id and a bad agent: one line naming the choices.
    _one_line_exit_2([command, "--agent", "oracle", "--env", "NoSuchEnv-v0", "--out", out_arg(tmp_path)], capsys,
                     "unknown env id 'NoSuchEnv-v0'", "EyeCatch-v0")
    _one_line_exit_2([command, "--agent", "no-such-agent", "--env", ENV_ID, "--out", out_arg(tmp_path)], capsys,
                     "unknown agent 'no-such-agent'", "eyecatch")
    # An existing output file is refused without --force and left alone.
    target = (tmp_path / "ep.mp4") if command == "record" else tmp_path / commands.plot_filename(ENV_ID, "oracle", 0)
    target.write_bytes(b"keep me")
    _one_line_exit_2(base + ["--out", out_arg(tmp_path)], capsys, "already exists", "--force")
    assert target.read_bytes() == b"keep me"
    assert not list(tmp_path.glob(".vmgym-write-probe*"))


def test_plot_command_from_a_run_and_from_saved_traces(oracle_trace, tmp_path, capsys):
    assert _run(["plot", "--agent", "oracle", "--env", ENV_ID, "--seed", "0", "--out", str(tmp_path)]) == 0
    expected = tmp_path / f"{ENV_ID}_oracle_seed0.png"
    assert capsys.readouterr().out.strip() == str(expected) and expected.stat().st_size > 50_000
    assert _run(["plot", "--agent", "oracle", "--env", ENV_ID, "--seed", "0", "--out", str(tmp_path)]) == 2
    assert "--force" in capsys.readouterr().err
    assert _run(["plot", "--agent", "oracle", "--env", ENV_ID, "--seed", "0", "--out", str(tmp_path),
                 "--force"]) == 0
    capsys.readouterr()

    other = synthetic_trace(20, gaze=circle(20, 30.0))
    npz = tmp_path / "traces.npz"
    save_traces(npz, [oracle_trace, other])
    out = tmp_path / "from_npz"
    assert _run(["plot", "--traces", str(npz), "--episode", "1", "--out", str(out)]) == 0
    assert (out / "Synthetic-v0_none_seed0.png").exists()
    assert _run(["plot", "--traces", str(npz), "--episode", "2", "--out", str(out)]) == 2
    assert "out of range" in capsys.readouterr().err
    assert _run(["plot", "--out", str(out)]) == 2
    assert _run(["plot", "--agent", "no-such-agent", "--env", ENV_ID, "--out", str(out)]) == 2
    assert "unknown agent" in capsys.readouterr().err
    name = commands.plot_filename("EyeCatch-v0", "eyecatch:alpha=1,b=x", 3)
    assert name == "EyeCatch-v0_eyecatch_alpha_1_b_x_seed3.png"


def test_plot_help_says_what_it_draws_for_every_family(capsys):
    with pytest.raises(SystemExit):
        _parser().parse_args(["plot", "--help"])
    text = capsys.readouterr().out
    from visuomotor_gym.families import families

    for record in families():
        assert f"  {record.name}: {record.viz.contents[:40]}" in text
    assert tuple(f.name for f in families()) == plots.FAMILIES  # the old name, derived from the records
    assert "footholds" in text and "pedestrian" in text and "shelf" in text


def test_commands_are_wired_into_vmgym(tmp_path, capsys):
    from visuomotor_gym import cli

    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    if "plot" not in sub.choices:
        pytest.skip("visuomotor_gym.viz.commands.register is not called from visuomotor_gym/cli.py yet")
    assert cli.main(["plot", "--agent", "oracle", "--env", ENV_ID, "--out", str(tmp_path)]) == 0
    assert (tmp_path / f"{ENV_ID}_oracle_seed0.png").exists()


def test_outcome_speaks_each_familys_words():
    """A catch episode is 'caught'/'missed'; another family's is 'succeeded'/'failed'."""
    caught = synthetic_trace(caught=True)
    caught.env_id = "EyeCatch-v0"
    assert plots.outcome(caught).startswith("caught at")
    walk = synthetic_trace(caught=True)
    walk.env_id = "ObstacleWalk-v0"
    walk.task.pop("missed")  # the walk family has no 'missed' field
    assert plots.outcome(walk).startswith("succeeded at")
    walk.success = False
    assert plots.outcome(walk) == "failed"


def test_record_refuses_a_camera_the_env_does_not_have(tmp_path):
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-m", "visuomotor_gym.cli", "record", "--agent", "zero", "--env", "ObstacleWalk-v0",
         "--camera", "over_shoulder", "--out", str(tmp_path / "w.mp4")],
        capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 2 and "camera='over_shoulder' is not one of" in proc.stderr
    assert "'follow'" in proc.stderr and "'scene'" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "w.mp4").exists()


# ----------------------------------------------------------------------------------------------
# The records' viz fields (visuomotor_gym.family.Viz): the one place plot, video and page facts live
# ----------------------------------------------------------------------------------------------
def test_every_record_says_how_its_episodes_are_shown():
    import inspect

    from visuomotor_gym.families import families
    from visuomotor_gym.family import FollowView, resolve
    from visuomotor_gym.viz import family_plots, video

    records = families()
    assert set(FAMILY_EPISODES) == {f.name for f in records}  # every family's figure is drawn from an episode
    assert all(f.viz is not None for f in records), [f.name for f in records if f.viz is None]
    fields = [f.viz.trace_field for f in records]
    assert len(set(fields)) == len(fields), fields  # a trace field tells one family only
    for record in records:
        figure = resolve(record.viz.figure)
        assert callable(figure) and next(iter(inspect.signature(figure).parameters)) == "trace", record.name
        assert family_plots.FIGURES[record.name] is figure
        assert video.scene_view(f"{record.prefix}-v0") == record.viz.scene_view == video.SCENE_VIEWS[record.name]
        assert video.default_stride(f"{record.prefix}Oracle-v0") == record.viz.video_stride
        assert commands.plot_contents()[record.name] == record.viz.contents
    # The walker families follow the pelvis; the seated ones film from their scene's camera.
    assert {f.name for f in records if isinstance(f.viz.scene_view, FollowView)} == {
        f.name for f in records if f.body == "walker"}
    assert video.scene_view("Unregistered-v0") is None and video.default_stride("Unregistered-v0") == 1


def _viz(**changes):
    from dataclasses import replace

    from visuomotor_gym.families import family

    return replace(family("walk").viz, **changes)


@pytest.mark.parametrize("changes, error, match", [
    ({"figure": "walk_figure"}, ValueError, r"Viz.figure must be a 'visuomotor_gym.module:attribute' string"),
    ({"contents": ""}, ValueError, r"Viz.contents must be a non-empty string"),
    ({"trace_field": None}, ValueError, r"Viz.trace_field must be a non-empty string"),
    ({"scene_view": ("side",)}, TypeError, r"Viz.scene_view must be an MJCF camera name or a FollowView"),
    ({"video_stride": 0}, ValueError, r"Viz.video_stride must be a positive int, got 0"),
    ({"dpi": 5}, ValueError, r"Viz.dpi must be an int in \[20, 600\], got 5"),
    ({"outcome_words": ("caught",)}, ValueError, r"Viz.outcome_words must be 2 non-empty strings"),
    ({"failure_field": ""}, ValueError, r"Viz.failure_field must be None or a trace field name"),
])
def test_a_bad_viz_field_is_named(changes, error, match):
    with pytest.raises(error, match=match):
        _viz(**changes)


@pytest.mark.parametrize("changes, match", [
    ({"distance": 0.0}, r"FollowView.distance and heading_tau_s must be > 0"),
    ({"azimuth": math.nan}, r"FollowView.azimuth must be a finite number"),
    ({"fovy": 180.0}, r"FollowView.fovy must be in \(0, 180\) degrees"),
    ({"offset": (1.0, 0.0)}, r"FollowView.offset must be a tuple of 3 finite numbers"),
])
def test_a_bad_follow_view_is_named(changes, match):
    from dataclasses import replace

    from visuomotor_gym.families import family

    with pytest.raises(ValueError, match=match):
        replace(family("dodge").viz.scene_view, **changes)


@pytest.mark.parametrize("changes, error, match", [
    ({"viz": "plots"}, TypeError, r"Family 'reach': viz must be a Viz or None"),
    ({"rate_aliases": ("success_rate",)}, ValueError, r"rate_aliases must be a tuple of result keys other than"),
    ({"doc_links": (("Faraway", "/abs/faraway.md"),)}, ValueError, r"doc_links must be a tuple of \(title, page"),
    ({"doc_pictures": (("images/x.md", "a page, not a picture"),)}, ValueError, r"doc_pictures must be a tuple"),
])
def test_a_bad_family_display_field_is_named(changes, error, match):
    from dataclasses import replace

    from visuomotor_gym.families import family

    with pytest.raises(error, match=match):
        replace(family("reach"), **changes)


def test_a_family_without_viz_is_refused_by_plot_and_filmed_from_its_own_scene(monkeypatch):
    """viz=None (a new family before its figure): the figure is refused with the reason; the video
    falls back to the env's own scene camera, every control step."""
    from dataclasses import replace

    import visuomotor_gym.families as registry
    from visuomotor_gym.viz import video

    bare = tuple(replace(f, viz=None) if f.name == "reach" else f for f in registry.families())
    monkeypatch.setattr(registry, "families", lambda: bare)
    registry._by_id.cache_clear()
    try:
        trace = synthetic_trace(5)
        trace.env_id, trace.task = "ShelfReach-v0", {"object_pos": np.zeros((5, 3))}
        with pytest.raises(ValueError, match="the reach family declares no figure"):
            plots.episode_figure(trace)
        assert video.scene_view("ShelfReach-v0") is None and video.default_stride("ShelfReach-v0") == 1
        assert "reach" not in commands.plot_contents() and "reach" not in plots.FAMILIES
    finally:
        monkeypatch.undo()
        registry._by_id.cache_clear()


def test_results_hold_a_familys_own_rate_name_equal_to_the_success_rate():
    """``rate_aliases``: on a catch id ``catch_rate`` is the success rate (a results file whose two
    differ is refused); on a family without the alias the check does not apply."""
    from visuomotor_gym.bench.results import _success_problems

    obj = {"success_rate": 0.5, "success": 3, "catch_rate": 0.25}
    (problem,) = _success_problems(obj, 6, "EyeCatch-v0")
    assert problem[0] == "$.success_rate" and "differs from catch_rate = 0.25" in problem[1]
    assert "catch env id (EyeCatch-v0)" in problem[1]
    assert _success_problems(obj, 6, "ShelfReach-v0") == []
    assert _success_problems(obj, 6, "Unregistered-v0") == []
    assert _success_problems({**obj, "catch_rate": 0.5}, 6, "EyeCatch-v0") == []
