"""visuomotor_gym: Gymnasium environments where an embodied agent sees only through a human-like eye.

Importing the package registers every environment id (see :mod:`visuomotor_gym.registration`)::

    import gymnasium as gym
    import visuomotor_gym  # noqa: F401

    env = gym.make("EyeCatch-v0")
"""

# Before numpy loads OpenBLAS: one kernel family on every x86 CPU, so episodes are bit-identical across
# machines (golden digests, leaderboard replays; see visuomotor_gym._blas).
from visuomotor_gym._blas import pin_kernels as _pin_kernels

_pin_kernels()

from visuomotor_gym.registration import CATCH_ENV_IDS, ENV_IDS, ENV_SPECS, FAMILIES, register_envs  # noqa: E402

__version__ = "0.1.0"
__all__ = ["CATCH_ENV_IDS", "ENV_IDS", "ENV_SPECS", "FAMILIES", "__version__", "register_envs"]

register_envs()
