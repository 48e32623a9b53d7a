"""The optional compiled kernels (visuomotor_gym/_native) give the pure-Python path's numbers bit for bit.

Each case runs the same episode twice, once with the kernels and once without
(``_native.disabled()``: what ``VISUOMOTOR_GYM_PURE_PYTHON=1`` or a missing build gives), and compares the episode digests
(observations, rewards, flags, info; tests/golden/digests.py). The golden digests themselves are
checked on whichever path is active, so running the suite with and without the variable covers both.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest
from golden.digests import _agent_policy, _random_policy, episode_digest

from visuomotor_gym import _native

needs_kernels = pytest.mark.skipif(not _native.enabled(), reason="compiled kernels not built (pure-Python path)")


def _digest(env_id: str, seed: int, agent: str | None, native: bool, **kwargs) -> str:
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    with contextlib.nullcontext() if native else _native.disabled():
        env = gym.make(env_id, **kwargs)  # objects choose their path when built
    policy = _agent_policy(agent, env_id, env) if agent else _random_policy(env, seed)
    digest = episode_digest(env, seed, policy)
    env.close()
    return digest


CASES = [
    ("EyeCatch-v0", 0, None, {}),
    ("EyeCatch-v0", 1, "eyecatch", {}),
    ("EyeCatchPoorVision-v0", 2, None, {}),
    ("EyeCatchFullView-v0", 0, None, {}),
    ("EyeCatchOracle-v0", 0, "oracle", {}),
    ("EyeCatchPaper-v0", 1, None, {}),
    ("EyeCatchTwoBalls-v0", 0, "eyecatch", {}),
    ("EyeCatch-v0", 3, None, {"visual_delay_s": 0.06}),
    ("EyeCatch-v0", 4, None, {"oculomotor_params": {"saccade_endpoint_noise": 0.1}}),
    ("ObstacleWalk-v0", 0, "iwao", {}),
    ("ObstacleWalkFullView-v0", 1, None, {}),
    ("ShelfReach-v0", 0, "faraway", {}),
    ("ObstacleDodge-v0", 0, "fajen_warren", {}),
    ("SteppingStones-v0", 0, "lookahead", {}),
]


@needs_kernels
@pytest.mark.parametrize("env_id,seed,agent,kwargs", CASES, ids=[f"{c[0]}-{c[1]}-{c[2]}" for c in CASES])
def test_compiled_and_python_paths_give_identical_episodes(env_id, seed, agent, kwargs):
    compiled = _digest(env_id, seed, agent, True, **kwargs)
    python = _digest(env_id, seed, agent, False, **kwargs)
    assert compiled == python


@needs_kernels
def test_the_plant_alone_is_identical_on_both_paths():
    """Saccades (with endpoint noise), deferred saccades, pursuit of a moving request, array and tuple targets."""
    from visuomotor_gym.oculomotor.plant import OculomotorParams, OculomotorPlant

    def run(native: bool):
        with contextlib.nullcontext() if native else _native.disabled():
            plant = OculomotorPlant(OculomotorParams(saccade_endpoint_noise=0.05))
        assert plant._native == native
        rng = np.random.default_rng(5)
        out = []
        for k in range(300):
            a = 0.6 * np.sin(0.05 * k) + (0.4 if k % 37 < 3 else 0.0)
            target = (np.cos(a), np.sin(a), 0.1 * np.cos(0.02 * k))
            step = plant.step(np.array(target) if k % 2 else tuple(map(float, target)), 0.02, 10, rng)
            out.append((step, plant.gaze.tobytes(), plant.pursuit_omega, plant.angular_velocity.tobytes(),
                        plant.time, plant.saccade is None))
        return out

    assert run(True) == run(False)


@needs_kernels
def test_a_pickled_env_keeps_stepping_identically():
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    env = gym.make("EyeCatch-v0").unwrapped
    env.reset(seed=0)
    twin = pickle.loads(pickle.dumps(env))
    assert twin.eye._native and twin.plant._native and twin.retina._native
    action = np.full(env.action_space.shape, 0.3, dtype=np.float32)
    for _ in range(20):
        a, b = env.step(action), twin.step(action)
        assert a[0].tobytes() == b[0].tobytes() and a[1] == b[1]


def test_the_environment_variable_forces_pure_python():
    code = "import visuomotor_gym._native as n; print(n.enabled())"
    env = {**os.environ, "VISUOMOTOR_GYM_PURE_PYTHON": "1"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_one_normal_draw_of_6k_is_k_draws_of_6():
    """retina_see_all draws the noise of the k seen targets in one rng.standard_normal(6 k); the Python
    draws standard_normal(6) per target. numpy's Generator gives the same stream either way."""
    for seed in range(50):
        a, b = np.random.default_rng(seed), np.random.default_rng(seed)
        k = 1 + seed % 17
        one = b.standard_normal(6 * k)
        assert np.concatenate([a.standard_normal(6) for _ in range(k)]).tobytes() == one.tobytes()
        assert a.standard_normal() == b.standard_normal()  # and the streams stay in step
