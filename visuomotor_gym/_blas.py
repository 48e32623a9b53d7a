"""Bit-identical episodes across x86 CPUs: one OpenBLAS kernel family for every machine.

numpy's matrix products (``@`` on float arrays: the hand controller's three products, the agents'
filters) go through OpenBLAS, which picks its kernels at run time from the CPU. Kernels differ in
their summation order, so the same episode differs in the last bits from one CPU to another, and a
last-bit difference grows into a different episode (measured on an AMD EPYC with AVX-512, where
OpenBLAS chooses its ``SkylakeX`` kernels: 139 of the 276 golden digests changed, and
``gaze_blind:iwao`` on ObstacleWalk-v0 seed 154 took 716 steps instead of the leaderboard's 691;
with ``OPENBLAS_CORETYPE=Haswell`` or ``Zen`` every digest and that replay match).

:func:`pin_kernels` sets ``OPENBLAS_CORETYPE=Haswell`` (AVX2 + FMA, which every x86-64 CPU that runs
the other kernels also runs) when it runs before numpy is imported and the user has not chosen a
core type; importing ``visuomotor_gym`` calls it. If numpy was imported first, the kernels are the
CPU's: :func:`openblas_core` tells which one is in use, and the golden-digest test and the
leaderboard check say so when it is not the pinned family. Set ``OPENBLAS_CORETYPE`` yourself
(before anything imports numpy) to override; the Makefile and CI export it.

The same holds for PyTorch's MKL, which runs the ``ppo-npz`` policies' layers (``baselines/ppo/agent.py``): MKL
picks its code path from the CPU's vendor and features, so a policy's float32 actions differ in the last bits
between an Intel CPU with AVX-512 and an AMD one (measured on an Intel Xeon with AVX-512: the leaderboard's
``gaze-blind-recurrentppo-free-100k`` on EyeCatch-v0 seed 77 missed by 0.13071443 m instead of the recorded
0.13071187 m, made on an AMD EPYC; with ``MKL_ENABLE_INSTRUCTIONS=SSE4_2`` the Intel machine gives the recorded
values exactly, as it does with ``AVX``, which MKL maps to SSE4.2 with a deprecation warning). :func:`pin_kernels`
therefore also sets ``MKL_ENABLE_INSTRUCTIONS=SSE4_2`` (:data:`PINNED_MKL`) when torch is not imported yet and the
user has not chosen; MKL reads it when torch loads it. Training in such a process runs on that path too: a PPO
minibatch update (512 x 256) took 3.4x as long as on MKL's own choice on the Intel machine; set
``MKL_ENABLE_INSTRUCTIONS`` yourself (e.g. ``AVX512``) to train faster where identical replays do not matter.
"""

from __future__ import annotations

import ctypes
import os
import platform
import sys

#: The OpenBLAS core type every reference number (golden digests, leaderboard entries) was made with.
PINNED_CORETYPE = "Haswell"
#: Core names that give the same results as the pinned one (checked: every golden digest matches).
EQUIVALENT_CORES = ("Haswell", "Zen")
#: MKL's instruction set for every reference number made with a torch policy (the leaderboard's ppo entries).
PINNED_MKL = "SSE4_2"


def pin_kernels() -> bool:
    """Choose :data:`PINNED_CORETYPE` for OpenBLAS if numpy is not imported yet, the machine is x86-64
    and ``OPENBLAS_CORETYPE`` is unset (and :data:`PINNED_MKL` for MKL if torch is not imported yet and
    ``MKL_ENABLE_INSTRUCTIONS`` is unset). Returns whether the pinned family will be used (True also when
    the user set an equivalent core type)."""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return False
    if "numpy" not in sys.modules:
        os.environ.setdefault("OPENBLAS_CORETYPE", PINNED_CORETYPE)
    if "torch" not in sys.modules:
        os.environ.setdefault("MKL_ENABLE_INSTRUCTIONS", PINNED_MKL)
    core = openblas_core() if "numpy" in sys.modules else os.environ.get("OPENBLAS_CORETYPE")
    return core is not None and core.lower() in (c.lower() for c in EQUIVALENT_CORES)


def openblas_core() -> str | None:
    """The kernel family numpy's OpenBLAS runs (``"Haswell"``, ``"SkylakeX"``, ``"Zen"``...), or None when
    it cannot be read (another BLAS, an unknown library layout). Imports numpy."""
    import numpy as np

    folder = os.path.join(os.path.dirname(os.path.dirname(np.__file__)), "numpy.libs")
    try:
        names = [n for n in os.listdir(folder) if "openblas" in n]
    except OSError:
        return None
    for name in names:
        try:
            lib = ctypes.CDLL(os.path.join(folder, name))
        except OSError:
            continue
        for symbol in ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename"):
            fn = getattr(lib, symbol, None)
            if fn is not None:
                fn.restype = ctypes.c_char_p
                value = fn()
                return value.decode() if value else None
    return None


def kernel_note() -> str:
    """One line for a failure message: the OpenBLAS kernels in use against the pinned ones."""
    core = openblas_core()
    if core is None or core.lower() in (c.lower() for c in EQUIVALENT_CORES):
        return ""
    return (f" (numpy's OpenBLAS runs its {core!r} kernels; the reference numbers were made with "
            f"OPENBLAS_CORETYPE={PINNED_CORETYPE}: set it before numpy is imported, e.g. "
            f"`export OPENBLAS_CORETYPE={PINNED_CORETYPE}`)")
