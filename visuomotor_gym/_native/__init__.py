"""Optional compiled kernels for the per-step hot loops (``_kernels.c``, a plain C extension).

Each kernel mirrors one Python function operation for operation, so the compiled and the pure-Python
paths give the same numbers bit for bit (``tests/test_native.py``, the golden digests). The Python
code is the reference and always stays: it runs when the extension was not built (no compiler at
install time; ``setup.py`` makes the build optional), when it fails to import, or when the
environment variable ``VISUOMOTOR_GYM_PURE_PYTHON`` is set to anything but ``""``/``"0"``.

Objects decide once, at construction, through :func:`enabled`; ``kernels`` is the module (or None).
"""

from __future__ import annotations

import contextlib
import os

kernels = None
if os.environ.get("VISUOMOTOR_GYM_PURE_PYTHON", "") in ("", "0"):
    try:
        from visuomotor_gym._native import _kernels as kernels
    except ImportError:  # not built: the pure-Python path
        kernels = None


def enabled() -> bool:
    """Whether objects built now use the compiled kernels."""
    return kernels is not None


@contextlib.contextmanager
def disabled():
    """Objects built inside this block use the pure-Python path (for comparisons: tests, benchmarks)."""
    global kernels
    saved, kernels = kernels, None
    try:
        yield
    finally:
        kernels = saved


__all__ = ["disabled", "enabled", "kernels"]
