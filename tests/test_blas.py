"""One OpenBLAS kernel family on every x86 CPU (visuomotor_gym._blas): importing the package first pins
it, a user's own choice is kept, and the kernels in use can be read back."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"), reason="x86-64 only")

PROBE = "import os, visuomotor_gym; from visuomotor_gym._blas import openblas_core; " \
        "print(os.environ.get('OPENBLAS_CORETYPE'), openblas_core())"


def _run(env_extra: dict, code: str = PROBE) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


def test_importing_the_package_first_pins_the_kernels():
    coretype, core = _run({})
    assert coretype == "Haswell"
    if core != "None":  # numpy's OpenBLAS reports its kernels
        assert core == "Haswell"


def test_a_users_core_type_is_kept():
    coretype, core = _run({"OPENBLAS_CORETYPE": "Zen"})
    assert coretype == "Zen"
    if core != "None":  # OpenBLAS runs its Haswell kernels for a Zen core type
        assert core in ("Zen", "Haswell")


def test_numpy_imported_first_is_reported_not_overridden():
    code = "import numpy, os, visuomotor_gym; from visuomotor_gym._blas import pin_kernels, openblas_core; " \
           "print(os.environ.get('OPENBLAS_CORETYPE'), openblas_core(), pin_kernels())"
    coretype, core, pinned = _run({}, code)
    assert coretype == "None"  # too late to choose: the CPU's kernels stay, and pin_kernels says whether they match
    assert pinned == str(core in ("Haswell", "Zen"))


def test_importing_the_package_before_torch_pins_mkl_and_a_users_choice_is_kept():
    """MKL's code path (PyTorch's float32 layers of the ppo-npz policies) is pinned like OpenBLAS's: set when the
    package is imported before torch, left alone when the user chose one."""
    code = "import os, visuomotor_gym; print(os.environ.get('MKL_ENABLE_INSTRUCTIONS'))"
    base = {k: v for k, v in os.environ.items() if k != "MKL_ENABLE_INSTRUCTIONS"}
    for extra, want in (({}, "SSE4_2"), ({"MKL_ENABLE_INSTRUCTIONS": "AVX2"}, "AVX2")):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**base, **extra},
                             timeout=120)
        assert out.returncode == 0, out.stderr
        assert out.stdout.split() == [want]
