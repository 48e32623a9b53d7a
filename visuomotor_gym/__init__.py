"""visuomotor_gym: Gymnasium environments where an embodied agent sees only through a human-like eye.

Importing the package registers every environment id (see :mod:`visuomotor_gym.registration`)::

    import gymnasium as gym
    import visuomotor_gym  # noqa: F401

    env = gym.make("EyeCatch-v0")
"""

from visuomotor_gym.registration import CATCH_ENV_IDS, ENV_IDS, ENV_SPECS, FAMILIES, register_envs

__version__ = "0.1.0"
__all__ = ["CATCH_ENV_IDS", "ENV_IDS", "ENV_SPECS", "FAMILIES", "register_envs", "__version__"]

register_envs()
