"""The observation layout of the catch family: the blocks its parts declare, in the env's order
(the task's ball percepts, the eye, the head, the seated body, time, and with two balls the second
ball's blocks). Used for the flat vector, the ``obs_mode="dict"`` space, ``observation_structure``
and the docstring (a test compares them).

Frames: *eye* = the eye frame at the time of the visual sample (x along the visual axis, z up in
the reference position); *seat* = the fixed frame at the pelvis joint, axes parallel to the world
(x toward the thrower, y left, z up).
"""

from __future__ import annotations

from visuomotor_gym.body.seated import SEATED_BLOCKS
from visuomotor_gym.core.eye import EYE_BLOCKS
from visuomotor_gym.core.head import HEAD_BLOCKS
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.observation import ObservationLayout as _Layout
from visuomotor_gym.tasks.catch import BALL_PERCEPT_BLOCKS, SECOND_BALL_BLOCKS, TIME_BLOCK

__all__ = ["CATCH_OBSERVATION", "SECOND_BALL_OBSERVATION", "Block", "ObservationLayout", "catch_observation"]

CATCH_OBSERVATION = BALL_PERCEPT_BLOCKS + EYE_BLOCKS + HEAD_BLOCKS + SEATED_BLOCKS + (TIME_BLOCK,)
SECOND_BALL_OBSERVATION = SECOND_BALL_BLOCKS


def catch_observation(n_balls: int = 1) -> tuple[Block, ...]:
    """The blocks of the catch family's observation for ``n_balls`` balls (1 or 2)."""
    if n_balls == 1:
        return CATCH_OBSERVATION
    if n_balls == 2:
        return CATCH_OBSERVATION + SECOND_BALL_OBSERVATION
    raise ValueError(f"n_balls must be 1 or 2, got {n_balls!r}")


class ObservationLayout(_Layout):
    """The catch family's layout (one ball unless other blocks are given)."""

    def __init__(self, blocks=CATCH_OBSERVATION):
        super().__init__(blocks)
