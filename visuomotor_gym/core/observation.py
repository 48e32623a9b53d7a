"""Observation blocks and their layout: one ordered table per env, used for the flat vector, the
``obs_mode="dict"`` space, ``observation_structure`` and the docstring's index table.

Each part of an env (the task's percepts, the eye, the head, the body, the task's own state)
declares its blocks; the env concatenates them in a fixed order.
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


class ObservationLayout:
    """Slices of each named block in the flat observation vector."""

    def __init__(self, blocks):
        self.blocks = tuple(blocks)
        names = [b.name for b in self.blocks]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise ValueError(f"observation blocks must have unique names; repeated: {duplicated}")
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

    def markdown_table(self, only=None) -> str:
        """The index table used in env docstrings (``only``: the block names to list, default all)."""
        rows = ["| index | name | size | unit | description |", "|---|---|---|---|---|"]
        for block in self.blocks:
            if only is not None and block.name not in only:
                continue
            s = self.slices[block.name]
            index = f"{s.start}" if block.size == 1 else f"{s.start}-{s.stop - 1}"
            rows.append(f"| {index} | {block.name} | {block.size} | {block.unit} | {block.description} |")
        return "\n".join(rows)
