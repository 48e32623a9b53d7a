"""Shared test configuration for visuomotor_gym.

Rendering is headless: ``MUJOCO_GL`` must be chosen before ``mujoco`` is imported anywhere, so it is
set here, at conftest import time (pytest imports conftest files before any test module). Child
processes (``multiprocessing`` spawn, ``subprocess``) inherit it through ``os.environ``.

This module deliberately does **not** import ``visuomotor_gym`` (nor ``gymnasium``/``mujoco``) at
module level: :func:`spawn_rollout` runs in a freshly *spawned* interpreter, which imports this module
to find the function, and it has to check that ``gym.make("visuomotor_gym:EyeCatch-v0")`` itself
imports and registers the package.
"""

from __future__ import annotations

import os
import sys

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
# One OpenBLAS kernel family on every x86 CPU (visuomotor_gym._blas): the golden digests and the
# leaderboard's recorded episodes were made with it. Effective only if numpy is not imported yet; the
# Makefile exports it too.
os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")


def spawn_rollout(env_id: str, seed: int, actions: list[list[float]]) -> dict:
    """Worker for the ``multiprocessing`` "spawn" test: make ``env_id``, reset(seed), step ``actions``.

    Returns the observations (as nested lists, to be independent of pickling numpy arrays), and
    whether ``visuomotor_gym`` had already been imported before ``gym.make`` was called.
    """
    imported_before = "visuomotor_gym" in sys.modules
    import gymnasium as gym
    import numpy as np

    env = gym.make(env_id)
    obs, _info = env.reset(seed=seed)
    observations = [np.asarray(obs).tolist()]
    for action in actions:
        obs, _reward, terminated, truncated, _info = env.step(np.asarray(action, dtype=np.float32))
        observations.append(np.asarray(obs).tolist())
        if terminated or truncated:
            break
    env.close()
    return {
        "imported_before": imported_before,
        "module_file": sys.modules["visuomotor_gym"].__file__,
        "mujoco_gl": os.environ.get("MUJOCO_GL"),
        "observations": observations,
    }


@pytest.fixture
def spawn_worker():
    """The module-level :func:`spawn_rollout` (picklable by reference for the "spawn" context)."""
    return spawn_rollout
