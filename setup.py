"""Build of the optional C extension ``visuomotor_gym._native._kernels`` and the package list (the rest is
in pyproject.toml).

The packages are found: every package under ``visuomotor_gym/``, and those of the top-level folders
``baselines/`` and ``envs_assets/``, installed inside the package (pyproject.toml's package-dir).

``optional=True``: a machine without a C compiler (or any build error) installs the package without
it, and the pure-Python path runs (same numbers, slower). The flags keep the compiled arithmetic
identical to Python's: no fused multiply-add contraction, no fast-math, no builtin maths (libm's
sin/cos/atan2/pow are called as Python's math module calls them).
"""

from setuptools import Extension, find_namespace_packages, find_packages, setup

PACKAGES = (
    find_packages(include=["visuomotor_gym", "visuomotor_gym.*"])
    + ["visuomotor_gym." + p for p in find_packages(include=["baselines", "baselines.*"])]
    # the asset folders hold no Python (envs_assets/common has no __init__.py): found as namespace packages
    + ["visuomotor_gym." + p for p in find_namespace_packages(include=["envs_assets", "envs_assets.*"],
                                                              exclude=["*__pycache__*"])]
)

setup(
    packages=PACKAGES,
    ext_modules=[
        Extension(
            "visuomotor_gym._native._kernels",
            sources=["visuomotor_gym/_native/_kernels.c"],
            extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math", "-fno-builtin"],
            optional=True,
        )
    ]
)
