"""Record one episode as an MP4: the scene view (with the line of sight drawn in green, ending in a
green dot where it meets the floor) beside the eye camera.

**Timing**: the env runs at 50 control steps per second; a frame is rendered after ``reset`` and after
every ``stride``-th step (the last step always), so ``fps = 50 / stride`` plays in real time. With
the default ``fps=25`` the catch and reach families (``stride`` 1 by default, episodes of 1-3 s) play
at **half speed** (a 1 s throw lasts 2 s on screen, slow enough to see the saccades), as ``vmgym
demo`` does; the walker families (``stride`` 2 by default, episodes of 10-20 s) in real time
(the family record's ``viz.video_stride``, :func:`default_stride`).

**Scene views** (the family record's ``viz.scene_view``, :func:`scene_view`): the catch and reach
families use their scene's fixed camera (``scene_camera`` in the MJCF); the walker families (walk,
stones, dodge) a :class:`~visuomotor_gym.family.FollowView` declared in their record, not in the MJCF
(so the compiled models and their golden digests do not change): a free :class:`mujoco.MjvCamera`
whose look-at point follows the pelvis each frame, at a distance and angle chosen per family so that
what the task is about stays in view: the next obstacles (walk), the next stones (stones), the
pedestrians 4-6 m to either side (dodge).

**Speed** (software OpenGL, Mesa llvmpipe, on a headless machine): shadows and 4x multisampling cost
~4-8x the rest of a frame, so they are off unless ``quality="high"``; one :class:`mujoco.Renderer`
(one GL context) renders both views of every frame; x264 encodes with its ``veryfast`` preset. One
ObstacleWalk-v0 episode (iwao, seed 0, 765 steps) on a 2-core machine under load (~9.5): before,
765 frames in 460 s wall, 146 CPU-s (190 ms CPU a frame); now 765 frames (``stride=1``) in 56-60 s
wall, 28-30 CPU-s (37-39 ms CPU a frame), and with the walker default ``stride=2`` 383 frames in
25 s wall, 15 CPU-s.

The episode is played by :func:`visuomotor_gym.bench.trace.run_episode` itself (the policy sees
observations only); a thin wrapper renders a frame after ``reset`` and after every ``stride``-th
``step`` and streams it to the encoder, so the returned trace is exactly the evaluator's.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from visuomotor_gym.bench.trace import EpisodeTrace, run_episode
from visuomotor_gym.family import FollowView  # declared in the family records; importable from here too

VIDEO_SUFFIXES = (".mp4", ".mkv", ".mov")
QUALITIES = ("fast", "high")
CONTROL_HZ = 50  # the envs' control rate (dt = 20 ms): fps = CONTROL_HZ / stride is real time


def scene_view(env_id: str | None):
    """The scene view of ``env_id``'s family (its record's ``viz.scene_view``: an MJCF camera name or
    a :class:`FollowView`); None for an unregistered id or a family without ``viz``."""
    record = _record(env_id)
    return None if record is None or record.viz is None else record.viz.scene_view


def default_stride(env_id: str) -> int:
    """Frames per control step when ``stride`` is not given: the family record's ``viz.video_stride``
    (1 for an unregistered id or a family without ``viz``)."""
    record = _record(env_id)
    return 1 if record is None or record.viz is None else record.viz.video_stride


def _record(env_id):
    from visuomotor_gym.families import family_for

    if env_id is None:
        return None
    try:
        return family_for(env_id)
    except ValueError:
        return None


def __getattr__(name: str):
    """``DEFAULT_STRIDE`` and ``SCENE_VIEWS`` (family name -> stride, scene view), built from the family
    records for older callers; the records' ``viz`` is the one place these are declared."""
    from visuomotor_gym.families import families

    if name == "DEFAULT_STRIDE":
        return {f.name: f.viz.video_stride for f in families() if f.viz is not None}
    if name == "SCENE_VIEWS":
        return {f.name: f.viz.scene_view for f in families() if f.viz is not None}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _default_headless_gl() -> None:
    """Choose EGL on a display-less Linux machine, if MuJoCo is not imported and nothing was chosen."""
    if "mujoco" in sys.modules or "MUJOCO_GL" in os.environ or not sys.platform.startswith("linux"):
        return
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ["MUJOCO_GL"] = "egl"


def _even(frame: np.ndarray) -> np.ndarray:
    """Pad to even height and width by repeating the last row/column (H.264 with yuv420p needs it)."""
    h, w = frame.shape[:2]
    if h % 2 or w % 2:
        frame = np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
    return frame


class _Labeller:
    """Draws a small text label on each frame with Pillow (a dependency of imageio); no-op without it."""

    def __init__(self, height: int, header: str, panels: tuple[str, ...], panel_width: int):
        try:
            from PIL import Image, ImageDraw, ImageFont
        except ImportError:  # pragma: no cover - Pillow comes with imageio and matplotlib
            self.ok = False
            return
        self.ok = True
        self._image, self._draw = Image, ImageDraw
        size = max(9, int(round(height / 26)))
        try:
            self.font = ImageFont.load_default(size=size)
        except TypeError:  # Pillow < 10.1: fixed bitmap font
            self.font = ImageFont.load_default()
        self.size = size
        self.header = header
        self.panels = panels
        self.panel_width = panel_width
        self._was_saccading = False

    def __call__(self, frame: np.ndarray, info: dict, final: str | None) -> np.ndarray:
        if not self.ok:
            return frame
        img = self._image.fromarray(frame)
        draw = self._draw.Draw(img, "RGBA")
        state = []
        if info.get("in_saccade") or info.get("saccade_onset") or self._was_saccading:
            state.append("SACCADE")  # a saccade was in flight during some part of the step shown
        self._was_saccading = bool(info.get("in_saccade"))
        if not info.get("ball_visible", True):
            state.append("ball not seen")
        if final:
            state.append(final)
        lines = [self.header, f"t = {float(info.get('time', 0.0)):.2f} s   " + "   ".join(state)]
        pad = max(2, self.size // 4)
        y = pad
        for line in lines:
            box = draw.textbbox((pad, y), line, font=self.font)
            draw.rectangle((box[0] - pad, box[1] - pad, box[2] + pad, box[3] + pad), fill=(0, 0, 0, 150))
            draw.text((pad, y), line, fill=(255, 255, 255, 255), font=self.font)
            y = box[3] + 2 * pad
        if len(self.panels) > 1:
            for i, name in enumerate(self.panels):
                x = i * self.panel_width + pad
                yb = frame.shape[0] - self.size - 3 * pad
                box = draw.textbbox((x, yb), name, font=self.font)
                draw.rectangle((box[0] - pad, box[1] - pad, box[2] + pad, box[3] + pad), fill=(0, 0, 0, 150))
                draw.text((x, yb), name, fill=(255, 255, 255, 255), font=self.font)
        return np.asarray(img)


def _mark_decor(geom, index: int) -> None:
    """A drawn geom is decoration of no model object (``mjv_initGeom`` leaves the slot's old object id,
    which segmentation rendering would read as a model geom); its segmentation id is its index, as
    ``mjv_updateScene`` numbers the scene's geoms."""
    import mujoco

    geom.objtype = int(mujoco.mjtObj.mjOBJ_UNKNOWN)
    geom.objid = -1
    geom.category = int(mujoco.mjtCatBit.mjCAT_DECOR)
    geom.segid = index


def _draw_line_of_sight(scene, eye_pos, gaze_dir, radius: float, max_range_m: float = 30.0) -> None:
    """A green capsule from the eye along the line of sight to where it meets the floor (a green dot
    there), or ``max_range_m / 4`` long when it does not meet the floor within ``max_range_m``."""
    import mujoco

    eye = np.asarray(eye_pos, dtype=float)
    g = np.asarray(gaze_dir, dtype=float)
    g = g / max(float(np.linalg.norm(g)), 1e-12)
    s = -eye[2] / g[2] if g[2] < -1e-9 else np.inf
    hit = s <= max_range_m
    end = eye + (s if hit else max_range_m / 4.0) * g
    color = np.array([0.1, 0.9, 0.2, 0.7], dtype=np.float32)
    if scene.ngeom < scene.maxgeom:
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), np.zeros(3), np.eye(3).ravel(), color)
        mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_CAPSULE, radius, eye, end)
        _mark_decor(geom, scene.ngeom)
        scene.ngeom += 1
    if hit and scene.ngeom < scene.maxgeom:
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_SPHERE, np.full(3, 3.0 * radius), end, np.eye(3).ravel(),
                            np.array([0.1, 0.9, 0.2, 1.0], dtype=np.float32))
        _mark_decor(geom, scene.ngeom)
        scene.ngeom += 1


class FrameRenderer:
    """Renders the views of one frame with a single :class:`mujoco.Renderer` (one GL context, made once).

    ``views``: each an MJCF camera name or a :class:`FollowView`; ``line_of_sight``: draw the gaze into
    every view but the eye camera (the env's own line, eye to fixation point, for catch and reach; a
    line to the floor with a dot for the walker families, thick enough to see from a follow view).
    ``quality="fast"`` (default) renders without shadows, reflections and multisampling (``"high"``:
    the MJCF's settings, ~8x slower in software OpenGL).
    """

    def __init__(self, env, views, width: int, height: int, quality: str = "fast", line_of_sight: bool = True):
        import mujoco

        self._mujoco = mujoco
        u = env.unwrapped
        self.env = u
        # The env's own model (a task resizes and moves its geoms at reset: a copy would go stale). The
        # visual settings read when the GL context is made are changed for that moment only.
        model = u.model
        self.fast = quality == "fast"
        saved = (int(model.vis.global_.offwidth), int(model.vis.global_.offheight), int(model.vis.quality.offsamples))
        try:
            model.vis.global_.offwidth = max(saved[0], width)
            model.vis.global_.offheight = max(saved[1], height)
            if self.fast:
                model.vis.quality.offsamples = 0
            self.renderer = mujoco.Renderer(model, height, width)
        finally:
            model.vis.global_.offwidth, model.vis.global_.offheight, model.vis.quality.offsamples = saved
        self.views = tuple(views)
        self.line_of_sight = line_of_sight
        self.eye_camera = getattr(u, "eye_camera", "")
        self._cameras = {}
        self._headings: dict = {}
        self._pelvis = None
        for view in self.views:
            if isinstance(view, FollowView):
                cam = mujoco.MjvCamera()
                cam.type = mujoco.mjtCamera.mjCAMERA_FREE
                cam.distance, cam.azimuth, cam.elevation = view.distance, view.azimuth, view.elevation
                self._cameras[view] = cam
                if self._pelvis is None:
                    from visuomotor_gym.body import walker_names as wn

                    self._pelvis = mujoco.mj_name2id(u.model, mujoco.mjtObj.mjOBJ_BODY, wn.WALKER_PELVIS)
                    if self._pelvis < 0:
                        raise ValueError(f"a follow view needs a walker body named {wn.WALKER_PELVIS!r}")
            elif mujoco.mj_name2id(u.model, mujoco.mjtObj.mjOBJ_CAMERA, view) < 0:
                raise ValueError(f"the model of {u.spec.id if u.spec else type(u).__name__} has no camera {view!r}")

    def render(self, info: dict) -> np.ndarray:
        mujoco = self._mujoco
        r, d = self.renderer, self.env.data
        images = []
        for view in self.views:
            if isinstance(view, FollowView):
                cam = self._cameras[view]
                offset = np.asarray(view.offset, dtype=float)
                if view.follow_heading:
                    heading = self._heading(view, d)
                    c, s = np.cos(heading), np.sin(heading)
                    offset = np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], offset[2]])
                    cam.azimuth = view.azimuth + np.degrees(heading)
                cam.lookat[:] = d.xpos[self._pelvis] + offset
                vis = self.env.model.vis.global_
                fovy, vis.fovy = float(vis.fovy), view.fovy  # a free camera's field of view, for this view only
                try:
                    r.update_scene(d, camera=cam)
                finally:
                    vis.fovy = fovy
            else:
                r.update_scene(d, camera=view)
            if self.fast:
                r.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
                r.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
            if self.line_of_sight and view != self.eye_camera:
                if isinstance(view, FollowView):
                    _draw_line_of_sight(r.scene, info["eye_pos"], info["gaze_dir"], radius=0.0025 * view.distance)
                else:
                    self.env.eye.draw(r.scene)
            images.append(r.render())
        return np.concatenate(images, axis=1) if len(images) > 1 else images[0].copy()

    def _heading(self, view: FollowView, data) -> float:
        """The pelvis's heading (rad, about z), low-pass filtered per view over the frames rendered."""
        x_axis = data.xmat[self._pelvis].reshape(3, 3)[:, 0]
        now = float(np.arctan2(x_axis[1], x_axis[0]))
        last = self._headings.get(view)
        if last is None:
            self._headings[view] = (now, float(data.time))
            return now
        value, t = last
        alpha = 1.0 - np.exp(-max(float(data.time) - t, 0.0) / view.heading_tau_s)
        value += alpha * float(np.angle(np.exp(1j * (now - value))))  # the short way round
        self._headings[view] = (value, float(data.time))
        return value

    def close(self) -> None:
        self.renderer.close()


def _recording_wrapper(env, render, sink, labeller, stride: int):
    import gymnasium as gym

    class FrameRecorder(gym.Wrapper):
        """Renders after ``reset`` and after every ``stride``-th ``step`` (and the last) for ``sink``."""

        def reset(self, **kwargs):
            obs, info = self.env.reset(**kwargs)
            self._steps = 0
            self._emit(info, None)
            return obs, info

        def step(self, action):
            obs, reward, terminated, truncated, info = self.env.step(action)
            self._steps += 1
            final = None
            if info.get("is_success"):
                final = "SUCCESS" if "missed" not in info else "CAUGHT"
            elif terminated or truncated:
                final = _failure_word(info, truncated)
            if final is not None or self._steps % stride == 0:
                self._emit(info, final)
            return obs, reward, terminated, truncated, info

        def _emit(self, info, final):
            frame = render(info)
            if labeller is not None:
                frame = labeller(frame, info, final)
            sink(_even(frame))

    return FrameRecorder(env)


def _failure_word(info: dict, truncated: bool) -> str:
    for key, word in (("missed", "MISSED"), ("tripped", "TRIPPED"), ("misstepped", "MISSTEPPED"),
                      ("off_path", "OFF PATH"), ("fell", "FELL"), ("collided", "COLLIDED"),
                      ("panel_hit", "PANEL HIT")):
        if info.get(key):
            return word
    return "TRUNCATED" if truncated else "ENDED"


def resolve_views(env, camera: str) -> tuple:
    """The views of ``camera`` for this env: ``both`` (scene view beside the eye camera), ``scene``,
    ``eye``, or one of the env's own ``render_camera`` sets (its MJCF cameras: catch/reach
    ``over_shoulder``, walker ``side``/``follow``, ...). ValueError naming the choices otherwise."""
    u = env.unwrapped
    scene = scene_view(u.spec.id if u.spec is not None else None)
    own = dict(getattr(u, "render_cameras", {}))
    if scene is None:  # an unregistered env: its own scene set
        scene = own.get("scene", own.get("both", ("",)))[0]
    eye = u.eye_camera
    views = {"both": (scene, eye), "scene": (scene,), "eye": (eye,)}
    for name, cams in own.items():
        views.setdefault(name, tuple(cams))
    if camera not in views:
        raise ValueError(f"camera={camera!r} is not one of {sorted(views)} for {u.spec.id if u.spec else type(u).__name__}")
    return views[camera]


def record_episode(
    agent_spec: str,
    env_id: str,
    seed: int,
    path,
    width: int = 480,
    height: int = 360,
    fps: int = 25,
    camera: str = "both",
    overlay: bool = True,
    overwrite: bool = False,
    stride: int | None = None,
    quality: str = "fast",
) -> EpisodeTrace:
    """Play one episode of ``agent_spec`` on ``env_id`` with ``seed`` and write it to ``path`` (MP4, H.264).

    Each view is ``width`` x ``height``; with ``camera="both"`` (scene view beside eye camera) a frame
    is ``2 * width`` wide (odd sizes are padded by one pixel). A frame after reset and after every
    ``stride``-th step and the last (``ceil(steps / stride) + 1`` frames); ``fps = 50 / stride`` is
    real time. ``stride=None`` takes the family's :func:`default_stride` (1 for catch and reach: half
    speed at the default 25 fps; 2 for the walker families: real time). ``quality``: ``"fast"`` (no shadows or
    multisampling) or ``"high"``. ``overlay`` writes a small label (env, agent, seed, time, saccade,
    outcome) on every frame. The video is written to a temporary file beside ``path`` and renamed
    when the episode ends, so a failed run leaves no partial video. Refuses to replace an existing
    ``path`` (``FileExistsError``) unless ``overwrite``. Returns the episode's trace, with
    ``trace.extras["video"] = {"path", "frames", "fps", "frame_size", "stride", "seconds"}``.
    """
    import time

    path = Path(path)
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise ValueError(f"video path must end in one of {VIDEO_SUFFIXES}, got {str(path)!r}")
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} already exists; refusing to overwrite it "
                              "(pass overwrite=True, or --force on the command line)")
    if not (int(width) >= 16 and int(height) >= 16 and int(fps) >= 1):
        raise ValueError(f"width and height must be >= 16 pixels and fps >= 1, got {width}x{height} at {fps}")
    if stride is not None and not int(stride) >= 1:
        raise ValueError(f"stride must be >= 1 control step, got {stride!r}")
    if quality not in QUALITIES:
        raise ValueError(f"quality must be one of {QUALITIES}, got {quality!r}")
    _default_headless_gl()
    import gymnasium as gym
    import imageio.v2 as imageio

    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.agents import make_agent

    start = time.perf_counter()
    if stride is None:
        stride = default_stride(env_id)
    width, height, fps, stride = int(width), int(height), int(fps), int(stride)
    tmp = path.with_name(f".{path.stem}.partial{path.suffix}")
    env = gym.make(env_id)
    renderer = None
    try:
        views = resolve_views(env, camera)
        policy = make_agent(agent_spec, env_id, env.action_space.shape[0], seed=seed)
        renderer = FrameRenderer(env, views, width, height, quality=quality)
        panels = ("scene view", "eye camera") if camera == "both" else ()
        header = f"{env_id} | {agent_spec} | seed {seed}"
        labeller = _Labeller(height, header, panels, width) if overlay else None
        path.parent.mkdir(parents=True, exist_ok=True)
        # x264's "veryfast" preset: half the encoding time of the default ("medium") at the same size.
        writer = imageio.get_writer(tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=7,
                                    pixelformat="yuv420p", macro_block_size=1, output_params=["-preset", "veryfast"])
        frames: list[tuple[int, int]] = []  # (width, height) of every frame written

        def sink(frame):
            writer.append_data(frame)
            frames.append((frame.shape[1], frame.shape[0]))

        try:
            trace = run_episode(_recording_wrapper(env, renderer.render, sink, labeller, stride), policy, seed,
                                env_id, agent_spec)
        finally:
            writer.close()
        if path.exists() and not overwrite:  # appeared while we were recording
            tmp.unlink(missing_ok=True)
            raise FileExistsError(f"{path} appeared during the recording; refusing to overwrite it")
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    finally:
        if renderer is not None:
            renderer.close()
        env.close()
    trace.extras["video"] = {"path": str(path), "frames": len(frames), "fps": fps, "frame_size": frames[0],
                             "stride": stride, "seconds": time.perf_counter() - start}
    return trace
