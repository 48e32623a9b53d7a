"""One conformance suite over every family x every rung: what any env of this package must do.

The ids come from ``visuomotor_gym.registration.ENV_SPECS`` and the family of each from
``registration.family_of``, so a new family or rung is checked the moment it is registered. Everything
here goes through public behaviour (``gym.make``, the observation/action structures, ``info``, the
class docstring and constructor signature), never a family's internals; family-specific behaviour
(sampling, success, realism) stays in each family's own test file.

Invariants, each at its strongest: Gymnasium's checker in flat and dict modes (and SB3's); the
observation and Arguments tables of the docstring against the layout and the constructor signature;
two instances with the same seed and actions give identical episodes; a mid-episode pickle (and
deepcopy) goes on identically; bad actions and bad constructor arguments raise errors naming what is
wrong; ``reward == sum(info["reward_terms"])``; the env's eye is the eye the agent is told about
(``registration.env_vision_params``); no returned array is aliased across steps or with the physics; no
observation element stays constant over random-action episodes (except the documented constants
listed below); a reset with another seed gives another start.
"""

from __future__ import annotations

import ast
import copy
import inspect
import math
import pickle
import re
import warnings
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.registration import ENV_SPECS, env_vision, env_vision_params, family_of

ENV_IDS = [spec.id for spec in ENV_SPECS]
MAX_STEPS = {spec.id: spec.max_episode_steps for spec in ENV_SPECS}
# One id per family (its first registered rung): the class-level checks (docstring, signature) run once.
FAMILY_IDS: dict[str, str] = {}
for _id in ENV_IDS:
    FAMILY_IDS.setdefault(family_of(_id), _id)

# Warnings Gymnasium's checker may legitimately raise for these envs; anything else fails the test.
ALLOWED_CHECKER_WARNINGS = (
    r"A Box observation space minimum value is -infinity",  # MuJoCo-style observations are unbounded
    r"A Box observation space maximum value is infinity",
)

# Observation elements that stay constant over random-action episodes by design, with the reason. A
# label is ``block[index]``; ``rungs`` (``vision`` values) limits an entry, None = every rung.
DOCUMENTED_CONSTANTS: tuple[tuple[str, str, tuple[str, ...] | None, str], ...] = (
    # (family or "*", label regex, rungs, reason)
    ("*", r"(ball|object)_age\[0\]", None, "the age of the visual sample is the rung's visual latency"),
    ("*", r"(ball|object)_visible\[0\]", ("oracle", "full_view"),
     "without foveation or saccadic blindness every step gives a visual sample"),
    ("walk", r"obstacle_\d+\[(13|14|15|16)\]", ("oracle", "full_view"),
     "seen flags: every top-face point of a present obstacle is seen without a field-of-view limit"),
    ("stones", r"stone_\d+\[4\]", ("oracle", "full_view"), "seen flag: every stone is seen without a field limit"),
    ("stones", r"stone_\d+\[0\]|stones_left\[0\]", None,
     ("course index / stones left change only once a stone is stepped on; random footsteps fall first "
      "(tests/test_stepping_stones.py steps on stones)")),
    ("push", r"block_age\[0\]", None, "the age of the visual samples is the rung's visual latency"),
    ("push", r"block_visible\[\d\]", ("oracle", "full_view"), "every cube is seen without a field-of-view limit"),
    ("push", r"block_firm\[\d\]", ("foveated",),
     ("a cube is identified only within ~2 deg of its face (central vision, tests/test_push_recovery.py); a random "
      "gaze seldom lands there")),
    ("catch", r"balls_caught\[[01]\]|holding\[0\]", None,
     "touch blocks change only on a catch, which random actions do not make (tests/test_two_balls.py)"),
)


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------
def actions_for(env, seed: int, length: int) -> np.ndarray:
    """A seeded sequence of actions uniform in [-1, 1]."""
    shape = (length, *env.action_space.shape)
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=shape).astype(np.float32)


def rollout(env, seed: int, actions) -> list[tuple]:
    """Reset with ``seed`` and step ``actions`` until the end; deep copies of every transition."""
    obs, info = env.reset(seed=seed)
    out = [(copy.deepcopy(obs), None, False, False, copy.deepcopy(info))]
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        out.append((copy.deepcopy(obs), reward, terminated, truncated, copy.deepcopy(info)))
        if terminated or truncated:
            break
    return out


def same(a, b) -> bool:
    """Exact equality of observations/infos: arrays by dtype, shape and values (NaN equal to NaN, as
    the padding rows of a scene table are NaN), dicts by keys and values, in any nesting."""
    if isinstance(a, dict) or isinstance(b, dict):
        return isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return type(a) is type(b) and a == b


def assert_same_transitions(a: list[tuple], b: list[tuple]) -> None:
    assert len(a) == len(b), f"episode lengths differ: {len(a)} vs {len(b)}"
    for k, (ta, tb) in enumerate(zip(a, b)):
        assert same(ta[0], tb[0]), f"observations differ at step {k}"
        assert ta[1] == tb[1], f"rewards differ at step {k}: {ta[1]} vs {tb[1]}"
        assert ta[2:4] == tb[2:4], f"terminated/truncated differ at step {k}"
        differing = sorted(key for key in set(ta[4]) | set(tb[4])
                           if key not in ta[4] or key not in tb[4]
                           or not same(ta[4][key], tb[4][key]))
        assert not differing, f"info differs at step {k} in {differing}"


def observation_labels(env) -> list[str]:
    """``block[index]`` for every element of the flat observation, in order."""
    return [f"{name}[{j}]" for name, size in env.unwrapped.observation_structure.items() for j in range(size)]


def constructor_parameters(cls) -> dict[str, inspect.Parameter]:
    """The keyword arguments ``cls(...)`` accepts, following ``**kwargs`` forwarded up the class chain
    (as Gymnasium's MuJoCo envs forward to ``MujocoEnv``) and stopping at an ``__init__`` without one."""
    out: dict[str, inspect.Parameter] = {}
    for klass in cls.__mro__:
        if klass is gym.Env or not issubclass(klass, gym.Env):
            break
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        forwards = False
        for name, p in inspect.signature(init).parameters.items():
            if name == "self" or p.kind is inspect.Parameter.VAR_POSITIONAL:
                continue
            if p.kind is inspect.Parameter.VAR_KEYWORD:
                forwards = True
                continue
            out.setdefault(name, p)
        if not forwards:
            break
    return out


def docstring_section(doc: str, title: str) -> str:
    assert f"## {title}" in doc, f"the docstring has no '## {title}' section"
    return doc.split(f"## {title}", 1)[1].split("## ", 1)[0]


def arguments_table(doc: str) -> dict[str, str]:
    """Argument name -> documented default, from the ``## Arguments`` table (``a``, ``b`` rows too)."""
    rows: dict[str, str] = {}
    for line in docstring_section(doc, "Arguments").splitlines():
        line = line.strip()
        if not line.startswith("| ``"):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        names = re.findall(r"``(\w+)``", cells[0])
        defaults = [d.strip() for d in cells[1].split(",")] if len(names) > 1 else [cells[1]]
        assert len(defaults) == len(names), f"names and defaults do not pair up in {line!r}"
        for name, default in zip(names, defaults):
            assert name not in rows, f"argument {name} documented twice"
            rows[name] = default
    return rows


def index_range(cell: str) -> list[int]:
    if cell.strip() == "-":
        return []
    lo, _, hi = cell.strip().partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


# ----------------------------------------------------------------------------------------------
# API checkers, spaces, dict == flat
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("obs_mode", ["flat", "dict"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_checker(env_id, obs_mode):
    env = gym.make(env_id, obs_mode=obs_mode)
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped, skip_render_check=True)
    messages = [str(r.message) for r in records]
    unexpected = [m for m in messages if not any(re.search(p, m) for p in ALLOWED_CHECKER_WARNINGS)]
    assert not unexpected, unexpected


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_sb3_checker(env_id):
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(env_id)
    with warnings.catch_warnings(record=True) as records:
        warnings.simplefilter("always")
        sb3_check_env(env.unwrapped, warn=True, skip_render_check=True)
    assert not [str(r.message) for r in records]


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_structures_add_up_and_the_dict_observation_is_the_flat_one_split(env_id):
    flat, as_dict = gym.make(env_id), gym.make(env_id, obs_mode="dict")
    structure = flat.unwrapped.observation_structure
    assert sum(structure.values()) == flat.observation_space.shape[0]
    assert flat.observation_space.dtype == np.float32
    assert sum(flat.unwrapped.action_structure.values()) == flat.action_space.shape[0]
    assert set(as_dict.observation_space.spaces) == set(structure)  # gymnasium's Dict sorts its keys
    for name, size in structure.items():
        assert as_dict.observation_space[name].shape == (size,) and as_dict.observation_space[name].dtype == np.float32
    actions = actions_for(flat, 17, 60)
    ep_flat, ep_dict = rollout(flat, 4, actions), rollout(as_dict, 4, actions)
    assert len(ep_flat) == len(ep_dict)
    for k, (tf, td) in enumerate(zip(ep_flat, ep_dict)):
        joined = np.concatenate([td[0][name] for name in structure])
        np.testing.assert_array_equal(joined, tf[0], err_msg=f"dict != flat at step {k}")
        assert tf[1:4] == td[1:4] and same(tf[4], td[4]), f"step {k}"


# ----------------------------------------------------------------------------------------------
# documentation vs code (once per family: the docstring and signature belong to the class)
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("family", sorted(FAMILY_IDS))
def test_docstring_observation_and_action_tables_match_the_layout(family):
    env = gym.make(FAMILY_IDS[family])
    cls = type(env.unwrapped)
    base = cls()  # the class defaults, which the docstring documents
    doc = cls.__doc__
    assert "OBSERVATION_TABLE" not in doc and "ACTION_TABLE" not in doc and "(N,)" not in doc
    size = base.observation_space.shape[0]
    assert f"Box(-inf, inf, ({size},), float32)" in doc
    start = 0
    for name, n in base.observation_structure.items():
        index = f"{start}" if n == 1 else f"{start}-{start + n - 1}"
        assert f"| {index} | {name} | {n} |" in doc, f"observation row {index} {name} missing or wrong"
        start += n
    n_act = base.action_space.shape[0]
    assert f"Box(-1, 1, ({n_act},), float32)" in doc
    section = docstring_section(doc, "Action Space")
    rows = [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in section.splitlines() if re.match(r"\s*\| (\d+(-\d+)?|-) \|", line)]
    covered = [i for row in rows for i in index_range(row[0])]
    assert sorted(covered) == list(range(n_act)), f"action table indices {covered}"
    header = next(line for line in section.splitlines() if line.strip().startswith("| index"))
    if "| block |" in header:  # the block column names the action_structure block of every index
        blocks = [name for name, k in base.action_structure.items() for _ in range(k)]
        for row in rows:
            for i in index_range(row[0]):
                assert row[1] == blocks[i], f"action index {i}: documented {row[1]}, structure {blocks[i]}"


@pytest.mark.parametrize("family", sorted(FAMILY_IDS))
def test_docstring_arguments_table_matches_the_constructor(family):
    cls = type(gym.make(FAMILY_IDS[family]).unwrapped)
    rows = arguments_table(cls.__doc__)
    params = constructor_parameters(cls)
    # Sets, not order: shared rows may be generated in another order than the signature's.
    assert set(rows) == set(params), (
        f"undocumented: {sorted(set(params) - set(rows))}; documented but not accepted: {sorted(set(rows) - set(params))}"
    )
    for name, documented in rows.items():
        value = ast.literal_eval(documented.replace("``", ""))
        actual = params[name].default
        assert value == actual, f"{name}: documented default {documented}, actual {actual!r}"


# ----------------------------------------------------------------------------------------------
# determinism, randomised start, pickling
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_two_instances_with_the_same_seed_and_actions_are_identical(env_id):
    seed = 1000 + ENV_IDS.index(env_id)
    env_a, env_b = gym.make(env_id), gym.make(env_id)
    actions = actions_for(env_a, seed, 150)
    ep_a = rollout(env_a, seed, actions)
    assert_same_transitions(ep_a, rollout(env_b, seed, actions))
    # Episodes do not leak into each other: after another episode, the same seed replays exactly.
    rollout(env_a, seed + 7, actions_for(env_a, seed + 7, 40))
    assert_same_transitions(rollout(env_a, seed, actions), ep_a)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_another_seed_gives_another_start(env_id):
    """The scenario is drawn at reset: two seeds differ in the true state (info) and, within a few
    steps of a fixed action, in what the agent observes."""
    env = gym.make(env_id)
    zero = np.zeros(env.action_space.shape, np.float32)
    ep = [rollout(env, seed, [zero] * 25) for seed in (0, 1)]
    assert not same(ep[0][0][4], ep[1][0][4]), "reset info is the same for two seeds"
    assert not all(same(a[0], b[0]) for a, b in zip(*ep)), (
        "the observations of two seeds are the same for 25 steps"
    )


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_mid_episode_pickle_and_deepcopy_continue_identically(env_id):
    env = gym.make(env_id).unwrapped
    actions = actions_for(env, 7, 80)
    env.reset(seed=21)
    for action in actions[:10]:
        _, _, terminated, truncated, _ = env.step(action)
        assert not (terminated or truncated), "the episode ended before the round trip"
    twins = {"pickle": pickle.loads(pickle.dumps(env)), "deepcopy": copy.deepcopy(env)}
    for twin in twins.values():
        assert twin is not env and twin.data is not env.data and twin.model is not env.model
    for k, action in enumerate(actions[10:]):
        ref = env.step(action)
        for how, twin in twins.items():
            got = twin.step(action)
            assert same(ref[0], got[0]), f"{how}: observation differs {k} steps on"
            assert ref[1:4] == got[1:4], f"{how}: reward/flags differ {k} steps on"
            assert same(ref[4], got[4]), f"{how}: info differs {k} steps on"
        if ref[2] or ref[3]:
            break
    for twin in twins.values():  # a fresh episode on a clone matches one on the original
        assert_same_transitions(rollout(twin, 3, actions[:20]), rollout(env, 3, actions[:20]))


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_actions_raise_and_leave_the_env_usable(env_id):
    env = gym.make(env_id).unwrapped  # the env itself must validate, not a wrapper
    n = env.action_space.shape[0]
    with pytest.raises(RuntimeError, match="before reset"):
        env.step(np.zeros(n, np.float32))
    env.reset(seed=0)
    before = copy.deepcopy(env.data.qpos)
    for value in (np.nan, np.inf, -np.inf):
        bad = np.zeros(n, np.float32)
        bad[n // 2] = value
        with pytest.raises(ValueError, match=r"NaN or inf"):
            env.step(bad)
    for bad in (np.zeros(n + 1, np.float32), np.zeros(n - 1, np.float32), np.zeros((1, n), np.float32)):
        with pytest.raises(ValueError, match=r"shape") as excinfo:
            env.step(bad)
        assert f"({n},)" in str(excinfo.value), "the message should say which shape is expected"
    for bad in (np.array(["a"] * n), [None] * n):
        with pytest.raises(ValueError, match=r"(?i)numeric"):
            env.step(bad)
    np.testing.assert_array_equal(env.data.qpos, before)  # a refused action does not advance the physics
    with pytest.raises(ValueError, match="options"):
        env.reset(seed=0, options={"anything": 1})
    obs, *_ = env.step(np.zeros(n, np.float32))  # still usable
    assert np.all(np.isfinite(obs))


BAD_ARGUMENTS = [
    ({"no_such_argument": 1}, TypeError, "no_such_argument"),
    ({"vision": "xray"}, ValueError, "vision"),
    ({"obs_mode": "image"}, ValueError, "obs_mode"),
    ({"vision_noise_scale": -1.0}, ValueError, "vision_noise_scale"),
    ({"vision_noise_scale": float("nan")}, ValueError, "vision_noise_scale"),
    ({"control_dt": 0.0}, ValueError, "control_dt"),
    ({"visual_delay_s": -0.1}, ValueError, "visual_delay_s"),
    ({"gaze_action_range_deg": 0.0}, ValueError, "gaze_action_range_deg"),
    ({"render_mode": "ascii"}, ValueError, "render_mode"),
    ({"render_camera": "no_such_camera"}, ValueError, "render_camera"),
    ({"record_plant": "yes"}, TypeError, "record_plant"),
    ({"reward_weights": {"no_such_term": 1.0}}, ValueError, "no_such_term"),
    ({"reward_weights": [1.0]}, TypeError, "reward_weights"),
    ({"vision_params": {"no_such_field": 1.0}}, TypeError, "no_such_field"),
    ({"oculomotor_params": {"no_such_field": 1.0}}, TypeError, "no_such_field"),
]


@pytest.mark.filterwarnings("ignore:.*render_mode='ascii'")  # Gymnasium's own warning before the env refuses it
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_constructor_arguments_raise_naming_the_argument(env_id):
    for kwargs, exc, name in BAD_ARGUMENTS:
        with pytest.raises(exc) as excinfo:
            gym.make(env_id, **kwargs)
        assert name in str(excinfo.value), f"{kwargs}: the {exc.__name__} does not name {name!r}: {excinfo.value}"


# ----------------------------------------------------------------------------------------------
# rewards, vision
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("weights", ["registered", "all-nonzero"])
def test_reward_is_the_sum_of_the_named_terms(env_id, weights):
    env = gym.make(env_id)
    if weights == "all-nonzero":  # every term weighted, each differently, so none can hide
        names = list(env.unwrapped.reward_weights)
        env = gym.make(env_id, reward_weights={t: (-1) ** k * (0.5 + 0.25 * k) for k, t in enumerate(names)})
    weighted = {t for t, w in env.unwrapped.reward_weights.items() if w != 0}
    for seed in (0, 1):
        _, info = env.reset(seed=40 + seed)
        assert info["reward_terms"] == {}, "reset reports reward terms"
        for action in actions_for(env, 50 + seed, 300):
            _, reward, terminated, truncated, info = env.step(action)
            terms = info["reward_terms"]
            assert set(terms) == weighted, f"terms {sorted(terms)} vs weighted {sorted(weighted)}"
            assert isinstance(reward, float) and math.isfinite(reward)
            assert reward == pytest.approx(math.fsum(terms.values()), rel=0, abs=1e-12), (
                f"reward {reward!r} is not the sum of its terms {terms}")
            if terminated or truncated:
                break


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_env_vision_is_the_agents_vision(env_id):
    """What registration tells an agent about its eye (``env_vision_params``, ``env_vision``) is the
    eye the env builds; the oracle rung is the true state (no noise, nothing foveated)."""
    u = gym.make(env_id).unwrapped
    want = u.vision_params
    if u.vision == "oracle":
        want = replace(want, noise_scale=0.0, foveated=False)
    assert env_vision_params(env_id) == want
    told = env_vision(env_id)
    assert told["foveated"] == (u.vision == "foveated") == env_vision_params(env_id).foveated
    assert told["vision_noise_scale"] == (0.0 if u.vision == "oracle" else u.vision_params.noise_scale)
    assert told["gaze_action_range_deg"] == pytest.approx(math.degrees(u.gaze_action_range), rel=1e-12)


# ----------------------------------------------------------------------------------------------
# observation memory and content
# ----------------------------------------------------------------------------------------------
def _vandalise(obj) -> None:
    """Overwrite, in place, every array (and dict) handed out by the env."""
    if isinstance(obj, np.ndarray):
        if obj.flags.writeable:
            obj[...] = 1e6 if obj.dtype.kind == "f" else 1
    elif isinstance(obj, dict):
        for value in obj.values():
            _vandalise(value)
    elif isinstance(obj, list):
        for value in obj:
            _vandalise(value)


@pytest.mark.parametrize("obs_mode", ["flat", "dict"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_no_shared_observation_memory(env_id, obs_mode):
    """Returned observations and info are the caller's: consecutive observations do not share memory,
    nor with the physics state, and overwriting them (and the action passed in) changes nothing."""
    env_a = gym.make(env_id, obs_mode=obs_mode).unwrapped
    env_b = gym.make(env_id, obs_mode=obs_mode).unwrapped
    actions = actions_for(env_a, 3, 40)
    obs_a, info_a = env_a.reset(seed=8)
    obs_b, info_b = env_b.reset(seed=8)
    leaves = (lambda o: list(o.values())) if obs_mode == "dict" else (lambda o: [o])
    prev = obs_a
    for k, action in enumerate(actions):
        assert same(obs_a, obs_b), f"observation corrupted at step {k}"
        assert same(info_a, info_b), f"info corrupted at step {k}"
        _vandalise(obs_a)
        _vandalise(info_a)
        info_a["reward_terms"].clear()
        action_a = action.astype(np.float64).copy()
        obs_a, _, term_a, trunc_a, info_a = env_a.step(action_a)
        action_a[...] = 0.9  # the env must not keep a reference to the caller's action either
        obs_b, _, term_b, trunc_b, info_b = env_b.step(action)
        for new, old in zip(leaves(obs_a), leaves(prev)):
            assert not np.shares_memory(new, old), f"consecutive observations share memory at step {k}"
        for new in leaves(obs_a):
            for state in (env_a.data.qpos, env_a.data.qvel, env_a.data.mocap_pos):
                assert not np.shares_memory(new, state), f"the observation is a view of the physics at step {k}"
        prev = obs_a
        if term_a or trunc_a or term_b or trunc_b:
            assert (term_a, trunc_a) == (term_b, trunc_b)
            break
    assert same(obs_a, obs_b)
    assert same(info_a, info_b)


def _documented_constant(env_id: str, vision: str, label: str) -> bool:
    family = family_of(env_id)
    return any(fam in ("*", family) and re.fullmatch(pattern, label) and (rungs is None or vision in rungs)
               for fam, pattern, rungs, _ in DOCUMENTED_CONSTANTS)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_no_observation_element_is_constant_over_random_episodes(env_id):
    """Six seeded random-action episodes (to their end, at most the registered step limit): every
    observation element takes two values or more, except the documented constants
    (``DOCUMENTED_CONSTANTS``); a visual-sample age equals the rung's visual latency. Six, not fewer:
    a random gaze sees the fourth pedestrian of a dodge crowd in about one episode of eight (seeds 0-7:
    once), a measured rate, so three episodes would flag its slot as constant."""
    env = gym.make(env_id)
    observations = []
    for seed in range(6):
        observations += [t[0] for t in rollout(env, seed, actions_for(env, seed, MAX_STEPS[env_id]))]
    table = np.array(observations)
    assert np.all(np.isfinite(table)), "non-finite observation"
    labels = observation_labels(env)
    vision = env.unwrapped.vision
    constant = [labels[i] for i in np.flatnonzero(table.max(0) == table.min(0))]
    undocumented = [label for label in constant if not _documented_constant(env_id, vision, label)]
    assert not undocumented, f"constant over {len(table)} observations: {undocumented}"
    for i, label in enumerate(labels):
        if re.fullmatch(r"(ball|object)_age\[0\]", label):
            assert np.all(table[:, i] == np.float32(env_vision(env_id)["visual_delay_s"])), label


def test_constructor_parameters_follow_forwarded_keyword_arguments():
    """The Arguments check reads arguments a subclass forwards with ``**kwargs`` to its base (the
    ``AntEnv`` -> ``MujocoEnv`` pattern), stops at an ``__init__`` without ``**``, and ignores gym.Env's."""

    class Base(gym.Env):
        def __init__(self, render_mode=None, *, vision="foveated", **unknown):
            pass

    class Family(Base):
        def __init__(self, *, course=None, **shared):
            super().__init__(**shared)

    class Closed(Base):
        def __init__(self, *, course=None):
            pass

    assert {n: p.default for n, p in constructor_parameters(Family).items()} == {
        "course": None, "render_mode": None, "vision": "foveated"}
    assert list(constructor_parameters(Closed)) == ["course"]
