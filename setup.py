"""Build of the optional C extension ``visuomotor_gym._native._kernels`` (the rest is in pyproject.toml).

``optional=True``: a machine without a C compiler (or any build error) installs the package without
it, and the pure-Python path runs (same numbers, slower). The flags keep the compiled arithmetic
identical to Python's: no fused multiply-add contraction, no fast-math, no builtin maths (libm's
sin/cos/atan2/pow are called as Python's math module calls them).
"""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "visuomotor_gym._native._kernels",
            sources=["visuomotor_gym/_native/_kernels.c"],
            extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math", "-fno-builtin"],
            optional=True,
        )
    ]
)
