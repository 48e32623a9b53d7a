"""The observation layout of the catch family: one ordered table, used for the flat vector, the
``obs_mode="dict"`` space, ``observation_structure`` and the docstring (a test compares them).

Frames: *eye* = the eye frame at the time of the visual sample (x along the visual axis, z up in
the reference position); *seat* = the fixed frame at the pelvis joint, axes parallel to the world
(x toward the thrower, y left, z up).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces


@dataclass(frozen=True)
class Block:
    name: str
    size: int
    unit: str
    description: str


CATCH_OBSERVATION = (
    Block("ball_pos", 3, "m", "perceived ball position, eye frame (zeros when not visible)"),
    Block("ball_vel", 3, "m/s", "perceived ball velocity, world velocity in eye-frame axes (zeros when not visible)"),
    Block("ball_visible", 1, "0/1", "1 if this step produced a visual sample of the ball"),
    Block("ball_age", 1, "s", "age of the visual sample (the visual latency; 0 without delay)"),
    Block("eye_pos", 3, "m", "eye (globe centre) position, seat frame"),
    Block("eye_rot", 9, "-", "eye frame axes in the seat frame, row-major 3x3 (column 0 = gaze direction)"),
    Block("eye_in_head", 2, "rad", "eye azimuth and elevation relative to the head"),
    Block("fixation", 1, "m", "fixation (vergence) distance"),
    Block("saccade", 2, "0/1, s", "in a saccade now; time since the last saccade onset (capped at 1 s)"),
    Block("head_qpos", 2, "rad", "neck yaw and pitch"),
    Block("head_qvel", 2, "rad/s", "neck yaw and pitch velocities"),
    Block("body_qpos", 10, "rad", "torso (yaw, pitch, roll) and arm (7) joint angles"),
    Block("body_qvel", 10, "rad/s", "torso and arm joint velocities"),
    Block("hand_pos", 3, "m", "catch-site (centre of the palm's catch volume) position, seat frame"),
    Block("hand_vel", 3, "m/s", "catch-site velocity, seat frame"),
    Block("grasp", 1, "0..1", "finger closure (1 = fully closed)"),
    Block("time", 1, "s", "time since the throw"),
)

# Appended after CATCH_OBSERVATION in EyeCatchTwoBalls-v0 (``n_balls=2``) only: the single-ball layout
# is unchanged and stays a prefix, so its slices hold in both.
SECOND_BALL_OBSERVATION = (
    Block("ball2_pos", 3, "m", "perceived position of the second ball, eye frame (zeros when not visible)"),
    Block("ball2_vel", 3, "m/s", "perceived velocity of the second ball, eye-frame axes (zeros when not visible)"),
    Block("ball2_visible", 1, "0/1", "1 if this step produced a visual sample of the second ball"),
    Block("balls_caught", 2, "0/1", "touch: 1 once the first / second ball has been caught (stays 1 after release)"),
    Block("holding", 1, "0/1", "touch: 1 while a caught ball is held in the hand"),
)


def catch_observation(n_balls: int = 1) -> tuple[Block, ...]:
    """The blocks of the catch family's observation for ``n_balls`` balls (1 or 2)."""
    if n_balls == 1:
        return CATCH_OBSERVATION
    if n_balls == 2:
        return CATCH_OBSERVATION + SECOND_BALL_OBSERVATION
    raise ValueError(f"n_balls must be 1 or 2, got {n_balls!r}")


class ObservationLayout:
    """Slices of each named block in the flat observation vector."""

    def __init__(self, blocks=CATCH_OBSERVATION):
        self.blocks = tuple(blocks)
        self.slices = {}
        start = 0
        for block in self.blocks:
            self.slices[block.name] = slice(start, start + block.size)
            start += block.size
        self.size = start

    @property
    def structure(self) -> dict[str, int]:
        """Name -> size, like Gymnasium MuJoCo envs' ``observation_structure``."""
        return {b.name: b.size for b in self.blocks}

    def flat_space(self) -> spaces.Box:
        return spaces.Box(-np.inf, np.inf, shape=(self.size,), dtype=np.float32)

    def dict_space(self) -> spaces.Dict:
        return spaces.Dict(
            {b.name: spaces.Box(-np.inf, np.inf, shape=(b.size,), dtype=np.float32) for b in self.blocks}
        )

    def to_dict(self, flat: np.ndarray) -> dict[str, np.ndarray]:
        """Split a flat observation into its named blocks (copies)."""
        return {name: flat[s].copy() for name, s in self.slices.items()}

    def markdown_table(self) -> str:
        """The index table used in the env docstring."""
        rows = ["| index | name | size | unit | description |", "|---|---|---|---|---|"]
        for block in self.blocks:
            s = self.slices[block.name]
            index = f"{s.start}" if block.size == 1 else f"{s.start}-{s.stop - 1}"
            rows.append(f"| {index} | {block.name} | {block.size} | {block.unit} | {block.description} |")
        return "\n".join(rows)
