"""Record one episode as an MP4: the scene camera (with the line of sight drawn in green) beside the
eye camera, one video frame per control step.

Timing: the env runs at 50 control steps per second and every step (plus the state after reset)
gives one frame, so ``fps=50`` plays in real time; the default ``fps=25`` plays at **half speed**
(a 1 s throw lasts 2 s on screen, slow enough to see the saccades), as ``vmgym demo`` does.

The episode is played by :func:`visuomotor_gym.bench.trace.run_episode` itself (the policy sees
observations only); a thin wrapper renders a frame after ``reset`` and after every ``step`` and
streams it to the encoder, so the returned trace is exactly the evaluator's.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from visuomotor_gym.bench.trace import EpisodeTrace, run_episode

VIDEO_SUFFIXES = (".mp4", ".mkv", ".mov")


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


def _recording_wrapper(env, sink, labeller):
    import gymnasium as gym

    class FrameRecorder(gym.Wrapper):
        """Renders after ``reset`` and after each ``step`` and hands the frame to ``sink``."""

        def reset(self, **kwargs):
            obs, info = self.env.reset(**kwargs)
            self._emit(info, None)
            return obs, info

        def step(self, action):
            obs, reward, terminated, truncated, info = self.env.step(action)
            final = None
            if info.get("is_success"):
                final = "CAUGHT"
            elif terminated or truncated:
                final = "MISSED" if info.get("missed") else ("TRUNCATED" if truncated else "ENDED")
            self._emit(info, final)
            return obs, reward, terminated, truncated, info

        def _emit(self, info, final):
            frame = np.asarray(self.env.render())
            if labeller is not None:
                frame = labeller(frame, info, final)
            sink(_even(frame))

    return FrameRecorder(env)


def make_render_env(env_id: str, width: int, height: int, camera: str = "both"):
    """``gym.make(env_id, render_mode="rgb_array", render_camera=camera, width, height)``; envs that
    take no ``render_camera`` argument are made without it."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401  (registers the ids)

    try:
        return gym.make(env_id, render_mode="rgb_array", render_camera=camera, width=width, height=height)
    except TypeError as exc:
        if "render_camera" not in str(exc):
            raise
        return gym.make(env_id, render_mode="rgb_array", width=width, height=height)


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
) -> EpisodeTrace:
    """Play one episode of ``agent_spec`` on ``env_id`` with ``seed`` and write it to ``path`` (MP4, H.264).

    Each camera image is ``width`` x ``height``; with ``camera="both"`` (scene beside eye) a frame is
    ``2 * width`` wide (odd sizes are padded by one pixel). One frame per control step plus the
    state after reset (``trace.steps + 1`` frames); ``fps=50`` is real time, the default 25 half
    speed. ``overlay`` writes a small label (env, agent, seed, time, saccade, outcome) on every
    frame. The video is written to a temporary file beside ``path`` and renamed when the episode
    ends, so a failed run leaves no partial video. Refuses to replace an existing ``path``
    (``FileExistsError``) unless ``overwrite``. Returns the episode's trace, with
    ``trace.extras["video"] = {"path", "frames", "fps", "frame_size"}``.
    """
    path = Path(path)
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise ValueError(f"video path must end in one of {VIDEO_SUFFIXES}, got {str(path)!r}")
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} already exists; refusing to overwrite it "
                              "(pass overwrite=True, or --force on the command line)")
    if not (int(width) >= 16 and int(height) >= 16 and int(fps) >= 1):
        raise ValueError(f"width and height must be >= 16 pixels and fps >= 1, got {width}x{height} at {fps}")
    _default_headless_gl()
    import imageio.v2 as imageio

    from visuomotor_gym.agents import make_agent

    width, height, fps = int(width), int(height), int(fps)
    tmp = path.with_name(f".{path.stem}.partial{path.suffix}")
    env = make_render_env(env_id, width, height, camera)
    try:
        both = getattr(env.unwrapped, "render_camera", None) == "both"
        panels = ("scene camera", "eye camera") if both else ()
        header = f"{env_id} | {agent_spec} | seed {seed}"
        labeller = _Labeller(height, header, panels, width) if overlay else None
        policy = make_agent(agent_spec, env_id, env.action_space.shape[0], seed=seed)
        path.parent.mkdir(parents=True, exist_ok=True)
        writer = imageio.get_writer(tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=7,
                                    pixelformat="yuv420p", macro_block_size=1)
        frames: list[tuple[int, int]] = []  # (width, height) of every frame written

        def sink(frame):
            writer.append_data(frame)
            frames.append((frame.shape[1], frame.shape[0]))

        try:
            trace = run_episode(_recording_wrapper(env, sink, labeller), policy, seed, env_id, agent_spec)
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
        env.close()
    trace.extras["video"] = {"path": str(path), "frames": len(frames), "fps": fps, "frame_size": frames[0]}
    return trace
