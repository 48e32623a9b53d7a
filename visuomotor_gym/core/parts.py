"""What :class:`~visuomotor_gym.core.env.VisuomotorEnv` needs from a body and a task: the two
protocols every family implements (the seated body and the catch task are the worked examples:
:mod:`visuomotor_gym.body.seated`, :mod:`visuomotor_gym.tasks.catch`).

The order of one step is fixed by the skeleton: check the action; eye command (gaze, vergence);
head command; ``body.command``; ``task.before_physics``; physics substeps (with
``task.check_substep`` after each when ``task.needs_substep_checks``); kinematics;
``task.check_substep`` once more; the VOR; the retina samples ``task.targets``; the observation
(``task.observe_leading``, eye, head, ``body.observe``, ``task.observe_trailing``);
``task.evaluate``.
"""

from __future__ import annotations

from typing import Any, Protocol

import mujoco
import numpy as np

from visuomotor_gym.core.observation import Block


class Body(Protocol):
    frame: Any  # a core.frames frame: positions in the observation are expressed in it
    observation_blocks: tuple[Block, ...]
    trace_step_fields: tuple[str, ...]  # info keys (float arrays) the evaluator records per step
    action_structure: dict[str, int]  # the body's action blocks, first in the action vector
    n_action: int

    def reset_pose(self, data: mujoco.MjData) -> None: ...  # before mj_forward
    def start(self, data: mujoco.MjData) -> None: ...  # after mj_forward
    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None: ...
    def observe(self, values: list, data: mujoco.MjData) -> None: ...
    def info(self, data: mujoco.MjData) -> dict: ...


class Task(Protocol):
    targets: list  # core.retina.VisualTarget, in the order the retina samples them
    leading_blocks: tuple[Block, ...]  # observation blocks before the eye's
    trailing_blocks: tuple[Block, ...]  # observation blocks after the body's
    success: bool  # info["is_success"]
    trace_step_fields: tuple[str, ...]
    trace_flag_fields: tuple[str, ...]

    def reset_state(self) -> None: ...
    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None: ...
    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]: ...  # world point, (az, el) offset
    def initial_fixation(self, distance: float) -> float: ...
    def reset_info(self) -> dict: ...
    def before_physics(self, data: mujoco.MjData) -> None: ...
    def needs_substep_checks(self, data: mujoco.MjData) -> bool: ...
    def check_substep(self, data: mujoco.MjData) -> bool: ...
    def before_observe(self, data: mujoco.MjData) -> None: ...  # per-step bookkeeping before the blocks
    def observe_leading(self, values: list, samples: list) -> None: ...
    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None: ...
    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]: ...
    def info(self, data: mujoco.MjData, *, diverged: bool = False) -> dict: ...
    def trace_episode_fields(self) -> dict: ...
    def trace_final_fields(self, info: dict) -> dict: ...
