"""What :class:`~visuomotor_gym.core.env.VisuomotorEnv` needs from a body and a task: the two base
classes every family subclasses (the seated body and the catch task are the worked examples:
:mod:`visuomotor_gym.body.seated`, :mod:`visuomotor_gym.tasks.catch`). Modelled on dm_control's
``composer.Task``: only what every family must do is abstract; every other hook has a documented
no-op default, so a part overrides only what it uses.

The order of one step is fixed by the skeleton: check the action; eye command (gaze, vergence);
head command; ``body.command``; ``task.before_physics``; physics substeps (with
``task.check_substep`` after each when ``task.needs_substep_checks``); kinematics;
``task.check_substep`` once more; the VOR; ``body.frame.update``; ``task.before_observe``; the
retina samples ``task.targets``; the observation (``task.observe_leading``, eye, head,
``body.observe``, ``task.observe_trailing``: each must append exactly the values of its declared
blocks, which the skeleton checks); ``task.evaluate``.

The order of a reset: ``task.reset_state``; ``body.reset_pose``; head reset; ``task.reset_episode``;
``mj_forward``; ``task.initial_gaze`` and ``task.initial_fixation`` (the eye's start);
``body.start``; the observation (as in a step); ``task.reset_info``.
"""

from __future__ import annotations

import abc
from typing import Any

import mujoco
import numpy as np

from visuomotor_gym.core.observation import Block

__all__ = ["Body", "Task"]


class Body(abc.ABC):
    """A body: its action blocks, servo commands, proprioception and frame.

    Attributes a subclass sets (on the class or in ``__init__``):

    * ``frame`` - a :mod:`visuomotor_gym.core.frames` frame; positions in the observation are
      expressed in it (the skeleton calls ``frame.update(data)`` before every observation);
    * ``observation_blocks`` - the body's observation blocks (after the eye's and head's);
    * ``action_structure`` - the body's action blocks (name -> size), first in the action vector;
    * ``n_action`` - their total size;
    * ``trace_step_fields`` - ``info`` keys (float arrays) the evaluator records per step.
    """

    frame: Any
    observation_blocks: tuple[Block, ...] = ()
    action_structure: dict[str, int]
    n_action: int
    trace_step_fields: tuple[str, ...] = ()

    def reset_pose(self, data: mujoco.MjData) -> None:
        """At reset, after ``mj_resetData`` and before ``mj_forward``: write the start posture into
        ``data`` (qpos, act, ...). Default: nothing (the model's reference pose)."""

    def start(self, data: mujoco.MjData) -> None:
        """At reset, after ``mj_forward`` and the eye's start: set controller memories from the
        computed kinematics. May change the body's own state only. Default: nothing."""

    @abc.abstractmethod
    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None:
        """Every step, before physics: turn the body's action block (the first ``n_action`` values
        of ``a``, an array, and ``al``, the same values as a list) into ``data.ctrl`` (and the body's
        own controller state) for the coming ``dt`` seconds."""

    @abc.abstractmethod
    def observe(self, values: list, data: mujoco.MjData) -> None:
        """Every observation: append exactly the values of ``observation_blocks``, in order, to
        ``values``. Must not change ``data``."""

    def info(self, data: mujoco.MjData) -> dict:
        """Every step and reset: the body's ``info`` entries (scoring only). Default: none."""
        return {}


class Task(abc.ABC):
    """A task: scene state, visual targets, task observation blocks, events, rewards and info.

    Attributes a subclass sets (on the class or in ``__init__``):

    * ``targets`` - the :class:`~visuomotor_gym.core.retina.VisualTarget` s, in the order the retina
      samples them (``samples`` in the observe hooks follow it);
    * ``leading_blocks`` / ``trailing_blocks`` - observation blocks before the eye's / after the
      body's (default: none);
    * ``success`` - ``info["is_success"]`` (``reset_state`` sets it);
    * ``trace_step_fields`` / ``trace_flag_fields`` - ``info`` keys the evaluator records per step
      (float arrays / flags; default: none).
    """

    targets: list
    leading_blocks: tuple[Block, ...] = ()
    trailing_blocks: tuple[Block, ...] = ()
    success: bool = False
    trace_step_fields: tuple[str, ...] = ()
    trace_flag_fields: tuple[str, ...] = ()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        """At construction (the task calls it) and at every reset, before any physics: clear the
        per-episode flags and memories (``success`` included). Must not touch ``data``. Default:
        nothing."""

    @abc.abstractmethod
    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """At reset, after the body's start pose and before ``mj_forward``: draw the episode from
        ``rng`` (the env's seeded generator) and write the scene into ``data`` (and the model's
        per-episode fields)."""

    @abc.abstractmethod
    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        """At reset, after ``mj_forward``: the world point gaze starts on and an (azimuth,
        elevation) offset from it in radians."""

    def initial_fixation(self, distance: float) -> float:
        """At reset, right after :meth:`initial_gaze`: the fixation (vergence) distance the eye
        starts with, given ``distance`` (m) from the eye to the gaze point. Default: ``distance``."""
        return distance

    def reset_info(self) -> dict:
        """At reset, last: the task's extra ``info`` entries of ``reset()`` (the episode's draw;
        scoring only). Default: :meth:`trace_episode_fields`."""
        return self.trace_episode_fields()

    # --- physics ------------------------------------------------------------------------------
    def before_physics(self, data: mujoco.MjData) -> None:
        """Every step, after the body's command and before the substeps: move scripted scene
        objects, remember pre-step state. May write ``data``. Default: nothing."""

    def needs_substep_checks(self, data: mujoco.MjData) -> bool:
        """Every step, before the substeps: whether :meth:`check_substep` must run after each
        substep this step (an event may fall within it). Default: ``False`` (one substep call)."""
        return False

    def check_substep(self, data: mujoco.MjData) -> bool:
        """After each substep when :meth:`needs_substep_checks` said so, and once after the last
        substep's kinematics: detect the task's event (a catch, a touch) and return whether it fired
        (passed to :meth:`evaluate` as ``fired``). May update the task's event state. Default:
        ``False``."""
        return False

    # --- observation --------------------------------------------------------------------------
    def before_observe(self, data: mujoco.MjData) -> None:
        """Every observation, after the body frame's update and before the retina samples
        ``targets``: per-step bookkeeping (which objects fill the observation's slots; ``targets``
        may be changed here). Default: nothing."""

    def observe_leading(self, values: list, samples: list) -> None:
        """Every observation, first: append exactly the values of ``leading_blocks`` to
        ``values``, from the retina's ``samples`` ((position, velocity, visible) per target).
        Default: nothing (for no leading blocks)."""

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        """Every observation, last: append exactly the values of ``trailing_blocks``. Default:
        nothing (for no trailing blocks)."""

    # --- outcome ------------------------------------------------------------------------------
    @abc.abstractmethod
    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        """Every step, after the observation: ``(reward, reward terms, terminated, info)``, with
        ``fired`` from the substep checks, ``a`` the checked action and ``eye`` the
        :class:`~visuomotor_gym.core.eye.Eye`. Sets ``success``."""

    @abc.abstractmethod
    def info(self, data: mujoco.MjData, *, diverged: bool = False) -> dict:
        """At reset and after a divergence (nothing happened this step): the task's ``info``
        entries, the same keys :meth:`evaluate` returns (scoring only)."""

    # --- what the evaluator records (bench/trace.py) ------------------------------------------
    def trace_episode_fields(self) -> dict:
        """Right after reset: the episode's values the evaluator records. Default: none."""
        return {}

    def trace_final_fields(self, info: dict) -> dict:
        """After the last step: the outcome fields the evaluator records from its ``info``.
        Default: none."""
        return {}
