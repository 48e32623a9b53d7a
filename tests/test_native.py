"""The optional compiled kernels (visuomotor_gym/_native) give the pure-Python path's numbers bit for bit.

Each case runs the same episode twice, once with the kernels and once without
(``_native.disabled()``: what ``VISUOMOTOR_GYM_PURE_PYTHON=1`` or a missing build gives), and compares the episode digests
(observations, rewards, flags, info; tests/golden/digests.py). The golden digests themselves are
checked on whichever path is active, so running the suite with and without the variable covers both.
"""

from __future__ import annotations

import contextlib
import math
import os
import pickle
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from golden.digests import _agent_policy, _random_policy, episode_digest

from visuomotor_gym import _native
from visuomotor_gym.core.retina import PointTarget, Retina, periphery_constants
from visuomotor_gym.vision import periphery
from visuomotor_gym.vision.foveation import VisionParams, human_periphery

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


# --- the human periphery (vision/periphery.py, Retina._see_all_periphery) ----------------------------
def _direction(rng, spread_deg: float, around=(1.0, 0.0, 0.0)) -> list[float]:
    """A unit vector within about ``spread_deg`` of ``around`` (a random small rotation of it)."""
    v = np.asarray(around, dtype=float) + np.tan(np.radians(spread_deg)) * rng.uniform(-1.0, 1.0, 3)
    return (v / np.linalg.norm(v)).tolist()


def _scene(rng, n: int):
    """Directions, eccentricities, kinds and objects of ``n`` seen targets, in clusters (so that many
    are crowded): objects of 1-4 points, point objects of their own, two kinds; a tenth of the
    eccentricities inside the crowding fovea."""
    dirs, kinds, objects = [], [], []
    while len(dirs) < n:
        centre = _direction(rng, 40.0)
        points = int(rng.integers(1, 5))
        kind = "ab"[int(rng.integers(2))]
        name = f"o{len(dirs)}" if rng.random() < 0.7 else f"o{int(rng.integers(3))}"  # some names repeat
        for _ in range(min(points, n - len(dirs))):
            dirs.append(_direction(rng, 3.0, centre))
            kinds.append(kind)
            objects.append(name)
    eccs = [math.acos(max(-1.0, min(1.0, u[0]))) if rng.random() > 0.1 else 0.1 * rng.random() * DEG for u in dirs]
    return dirs, eccs, kinds, objects


DEG = math.pi / 180.0
CROWDING_PARAMS = [human_periphery(), human_periphery(crowding_bouma=1.5), human_periphery(crowding_fovea_deg=5.0),
                   VisionParams(crowding=True), human_periphery(crowding=False)]


@needs_kernels
@pytest.mark.parametrize("p", range(len(CROWDING_PARAMS)))
def test_crowding_groups_and_pooling_are_identical_on_random_scenes(p):
    params = CROWDING_PARAMS[p]
    constants = periphery_constants(params)
    crowded = 0
    for seed in range(150):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(0, 40)) if seed % 10 else int(seed % 3)  # empty, one and two targets too
        dirs, eccs, kinds, objects = _scene(rng, n)
        groups = periphery.crowding_groups(dirs, eccs, kinds, objects, params)
        assert _native.kernels.crowding_groups(dirs, eccs, kinds, objects, constants) == groups
        vecs = rng.normal(0.0, 3.0, (n, 3)).tolist()
        for g in groups:
            crowded += len(g) > 1
            assert repr(_native.kernels.pooled(vecs, g)) == repr(periphery.pooled(vecs, g))
    assert crowded > 100 if params.crowding else crowded == 0  # the scenes do crowd


@needs_kernels
def test_a_flanker_exactly_at_the_critical_spacing_and_a_target_on_the_crowding_fovea():
    """Bouma's test is strict (``< b theta``) and the crowding fovea inclusive (``theta <= fovea``): at the
    exact boundaries both paths leave the target alone, one ulp inside they both crowd it."""
    rng = np.random.default_rng(3)
    exact = 0
    for _ in range(200):
        target, flanker = _direction(rng, 30.0), _direction(rng, 30.0)
        theta = math.acos(target[0])
        sep = periphery.angular_separation(target, flanker)
        bouma = sep / theta
        for b in (bouma, math.nextafter(bouma, 0.0), math.nextafter(bouma, 3.0)):
            if 0.0 < b <= 2.0 and b * theta == sep:  # the flanker exactly at the critical spacing
                exact += 1
                above = math.nextafter(b, 3.0)
                while above * theta == sep:
                    above = math.nextafter(above, 3.0)
                for bb, expect in ((b, [[0]]), (above, [[0], [1]])):  # at the spacing, then just beyond it
                    if bb > 2.0:
                        continue
                    params = human_periphery(crowding_bouma=bb, crowding_fovea_deg=0.0)
                    args = ([target, flanker], [theta, math.acos(flanker[0])], ["k", "k"], ["t", "f"])
                    groups = periphery.crowding_groups(*args, params)
                    assert groups[0] == expect
                    assert _native.kernels.crowding_groups(*args, periphery_constants(params)) == groups
                break
    assert exact > 50
    params = human_periphery(crowding_bouma=2.0)
    fovea = params.crowding_fovea_deg * DEG
    u, v = [math.cos(fovea), math.sin(fovea), 0.0], [1.0, 0.0, 0.0]
    for theta, expect in ((fovea, [[0]]), (math.nextafter(fovea, 1.0), [[0], [1]])):
        args = ([u, v], [theta, 0.0], ["k", "k"], ["t", "f"])
        assert periphery.crowding_groups(*args, params)[0] == expect
        assert _native.kernels.crowding_groups(*args, periphery_constants(params)) == \
            periphery.crowding_groups(*args, params)


class _Eye:
    """What the retina reads of an eye (pose lists, vergence), with the real Eye.retinal_speed."""

    from visuomotor_gym.core.eye import Eye as _E

    retinal_speed = _E.retinal_speed

    def __init__(self, rng, fixation):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        q *= np.sign(np.linalg.det(q))
        self.rot_flat = q.ravel().tolist()
        self.pos_list = rng.normal(0.0, 0.3, 3).tolist()
        self.prev_pos = (np.array(self.pos_list) + rng.normal(0.0, 0.01, 3)).tolist()
        self.prev_gaze = _direction(rng, 3.0, q[:, 0])
        self.fixation = fixation


PERIPHERY_PARAMS = [
    human_periphery(), human_periphery(position_disarray=0.0), human_periphery(field_shape="cone"),
    human_periphery(position_e2_deg=None, depth_pedestal_arcmin=None), human_periphery(crowding=False),
    VisionParams(crowding=True), VisionParams(depth_pedestal_arcmin=4.0, noise_scale=10.0),
    human_periphery(position_slip_knee_deg_s=math.inf, crowding_bouma=1.2), human_periphery(noise_scale=3.7),
]


@needs_kernels
@pytest.mark.parametrize("p", range(len(PERIPHERY_PARAMS)))
def test_the_retina_sees_the_same_through_the_periphery_on_both_paths(p):
    """Retina._see_all_periphery compiled and in Python on random scenes of clustered point targets
    (objects of several points, kinds, hidden ones, some behind the eye or outside the field): the same samples bit for bit (repr: signed zeros too) and the same draws."""
    params = PERIPHERY_PARAMS[p]
    assert params.periphery_on
    with _native.disabled():
        python = Retina("foveated", params, 0, 0.02)
        alone = Retina("foveated", replace(params, crowding=False), 0, 0.02)  # to see crowding act
    compiled = Retina("foveated", params, 0, 0.02)
    assert compiled._native and not python._native
    seen = crowded = 0
    for seed in range(60):
        rng = np.random.default_rng(seed)
        eye = _Eye(rng, None if seed % 7 == 0 else float(rng.uniform(0.3, 6.0)))
        n = int(rng.integers(0, 30)) if seed % 10 else int(seed % 3)
        dirs, _, kinds, objects = _scene(rng, n)
        targets = []
        for k, (u, kind, obj) in enumerate(zip(dirs, kinds, objects)):
            t = PointTarget(f"t{k}", None if rng.random() < 0.2 else obj)
            world = np.array(eye.rot_flat).reshape(3, 3) @ np.array(u)  # eye frame -> world
            if rng.random() < 0.1:
                world = -world  # behind the eye
            t.place(*(np.array(eye.pos_list) + float(rng.uniform(0.2, 8.0)) * world))
            t.kind = kind
            t.hidden = rng.random() < 0.1
            targets.append(t)
        if n and seed % 5 == 1:  # a target at the eye's centre: the retinal slip divides by zero on both
            saved = targets[0].position.copy()
            targets[0].place(*eye.pos_list)
            targets[0].hidden = False
            for retina in (python, compiled):
                with pytest.raises(ZeroDivisionError):
                    retina.sample(None, targets, eye, False, np.random.default_rng(0))
            targets[0].place(*saved)
        for retina in (python, compiled, alone):
            retina.draw_field(np.random.default_rng(seed + 1000))
        assert (python._disarray is not None) == (params.position_disarray > 0.0)
        for t in range(3):  # the same eye a few steps (the field is the episode's)
            rng_a, rng_b = np.random.default_rng([seed, t]), np.random.default_rng([seed, t])
            a = python.sample(None, targets, eye, False, rng_a)
            b = compiled.sample(None, targets, eye, False, rng_b)
            assert repr(b) == repr(a)
            assert rng_a.standard_normal() == rng_b.standard_normal()
            seen += sum(s[2] for s in a)
            crowded += repr(alone.sample(None, targets, eye, False, np.random.default_rng([seed, t]))) != repr(a)
    assert seen > 200
    assert crowded > 20 if params.crowding else crowded == 0


PERIPHERY_ENVS = ["SteppingStones-v0", "ShelfReach-v0", "ObstacleDodge-v0"]


@needs_kernels
@pytest.mark.parametrize("env_id", PERIPHERY_ENVS)
def test_the_periphery_families_step_identically_on_both_paths(env_id):
    """A few hundred random steps of each family that sees through the human periphery, built with the
    kernels and without: the same observations and rewards, byte for byte."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    def run(native: bool):
        with contextlib.nullcontext() if native else _native.disabled():
            env = gym.make(env_id)
        retina = env.unwrapped.retina
        assert retina._native == native and retina.params.periphery_on and retina.params.crowding
        rng = np.random.default_rng(7)
        obs, _ = env.reset(seed=11)
        out = [obs.tobytes()]
        for _ in range(300):
            obs, reward, terminated, truncated, _ = env.step(rng.uniform(-1.0, 1.0, env.action_space.shape)
                                                             .astype(np.float32))
            out += [obs.tobytes(), reward]
            if terminated or truncated:
                out.append(env.reset()[0].tobytes())
        env.close()
        return out

    assert run(True) == run(False)


@needs_kernels
def test_a_pickled_periphery_env_keeps_stepping_identically():
    """The retina's packed periphery constants and the episode's disarray field travel with the pickle."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    env = gym.make("ShelfReach-v0").unwrapped
    env.reset(seed=2)
    action = np.full(env.action_space.shape, 0.2, dtype=np.float32)
    for _ in range(5):
        env.step(action)
    twin = pickle.loads(pickle.dumps(env))
    assert twin.retina._native and twin.retina.params.periphery_on and twin.retina._disarray is not None
    for _ in range(40):
        a, b = env.step(action), twin.step(action)
        assert a[0].tobytes() == b[0].tobytes() and a[1] == b[1]


@needs_kernels
def test_the_periphery_kernels_reject_bad_constants_by_name():
    with pytest.raises(TypeError, match="periphery_constants"):
        _native.kernels.crowding_groups([], [], [], [], b"short")
    with pytest.raises(ValueError, match="same length"):
        _native.kernels.crowding_groups([[1.0, 0.0, 0.0]], [], [], [], periphery_constants(human_periphery()))
