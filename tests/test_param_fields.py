"""Every field of every parameter dataclass the envs accept is checked at construction.

Each field is walked with NaN, +-inf, a negative (or, where the field's rule allows negatives, a value
below its lower bound), a value above its upper bound, a wrong type and, for ranges, an inverted pair:
each must be refused with ValueError/TypeError naming ``<Class>.<field>`` (direct construction) and
``<argument>.<field>`` (through ``gym.make``), before any physics, so MuJoCo never writes
``MUJOCO_LOG.TXT`` into the working folder. A value a rule documents as legitimate (``inf`` for
``position_slip_knee_deg_s``: the paper's static acuity) is accepted. The defaults still construct.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # registers the ids
from visuomotor_gym.body.walker import GAIT_RULES, GaitParams
from visuomotor_gym.control.hand import HAND_RULES, HandControlParams
from visuomotor_gym.core.args import Choice, Flag, Int, Many, Num, Optional, Pair, Weights, field_rule
from visuomotor_gym.oculomotor.plant import OCULOMOTOR_RULES, OculomotorParams
from visuomotor_gym.scenarios.throws import THROW_RULES, ThrowDistribution
from visuomotor_gym.tasks.obstacle_dodge import CROWD_RULES, CrowdDistribution
from visuomotor_gym.tasks.obstacle_walk import COURSE_RULES
from visuomotor_gym.tasks.obstacle_walk import CourseDistribution as WalkCourse
from visuomotor_gym.tasks.reach import SHELF_RULES, ShelfLayout
from visuomotor_gym.tasks.stepping_stones import STONES_RULES
from visuomotor_gym.tasks.stepping_stones import CourseDistribution as StonesCourse
from visuomotor_gym.vision.foveation import VISION_RULES, VisionParams

NAN, INF = float("nan"), float("inf")

# (class, its rules, an env id that takes it, the constructor argument); ShelfLayout is the reach scene's
# layout (a module constant, not a constructor argument).
TABLE = [
    (GaitParams, GAIT_RULES, "ObstacleWalk-v0", "gait_params"),
    (GaitParams, GAIT_RULES, "SteppingStones-v0", "gait_params"),
    (GaitParams, GAIT_RULES, "ObstacleDodge-v0", "gait_params"),
    (WalkCourse, COURSE_RULES, "ObstacleWalk-v0", "course_distribution"),
    (StonesCourse, STONES_RULES, "SteppingStones-v0", "course_distribution"),
    (CrowdDistribution, CROWD_RULES, "ObstacleDodge-v0", "crowd_distribution"),
    (ThrowDistribution, THROW_RULES, "EyeCatch-v0", "throw_distribution"),
    (HandControlParams, HAND_RULES, "EyeCatch-v0", "hand_params"),
    (HandControlParams, HAND_RULES, "ShelfReach-v0", "hand_params"),
    (VisionParams, VISION_RULES, "EyeCatch-v0", "vision_params"),
    (VisionParams, VISION_RULES, "ObstacleWalk-v0", "vision_params"),
    (OculomotorParams, OCULOMOTOR_RULES, "EyeCatch-v0", "oculomotor_params"),
    (OculomotorParams, OCULOMOTOR_RULES, "SteppingStones-v0", "oculomotor_params"),
    (ShelfLayout, SHELF_RULES, None, None),
]
CLASSES = {cls: rules for cls, rules, _, _ in TABLE}


def _bad_numbers(rule: Num) -> list:
    bad = [NAN, -INF, "1.0", None, True]
    if not rule.inf_ok:
        bad.append(INF)
    # a negative, or below the lower bound where the rule documents negatives as legitimate
    bad.append(-1.0 if rule.low is not None and rule.low >= 0 else (rule.low - 1.0 if rule.low is not None else None))
    if rule.low is not None and rule.low_open:
        bad.append(rule.low)
    if rule.high is not None:
        bad.append(rule.high * 1.5 + 1.0)
    return [b for b in bad if b is not None or b is bad[3]]


def bad_values(rule, default) -> list:
    """Values the rule must refuse, from the rule's kind and the field's default."""
    if isinstance(rule, Optional):  # None is legitimate (the mechanism off)
        return [b for b in bad_values(rule.rule, default) if b is not None]
    if isinstance(rule, Choice):
        return ["no such choice", 1, None]
    if isinstance(rule, Num):
        return _bad_numbers(rule)
    if isinstance(rule, Int):
        return [NAN, 1.5, "3", True, -1, (rule.high or 10) + 1]
    if isinstance(rule, Pair):
        lo, hi = default
        b = rule.bounds
        below = -1.0 if b.low is not None and b.low >= 0 else b.low - 1.0
        out = [(NAN, hi), (lo, INF), (-INF, hi), (below, hi), (lo, b.high * 1.5 + 1.0), (lo,), (lo, hi, hi), "ab",
               None, (lo, "x")]
        if hi > lo:
            out.append((hi, lo))  # inverted
        else:
            out.append((lo, lo - 1.0))
        if b.low_open:
            out.append((b.low, hi))
        return out
    if isinstance(rule, Many):
        first = default[0]
        return [(NAN, *default[1:]), (INF, *default[1:]), (rule.bounds.high + 1.0, *default[1:]),
                (rule.bounds.low - 1.0, *default[1:]), default[:-1], "abc", (first, *default[1:], first)]
    if isinstance(rule, Weights):
        return [(NAN, *default[1:]), (-0.1, *default[1:]), (1.5, *default[1:]), (0.0,) * rule.n, default[:-1],
                (INF, *default[1:])]
    if isinstance(rule, Flag):
        return ["no", 1, 0.0, None]
    # a rule of its own (OculomotorParams.pursuit_gain_points)
    return [((10.0, NAN),), ((NAN, 0.9),), ((10.0, 0.9), (5.0, 0.8)), ((10.0, -0.5),), ((-10.0, 0.9),), (),
            ((10.0, INF),), "ab"]


def rule(cls, f):
    return field_rule(f, CLASSES[cls], getattr(cls(), f.name))


CASES = [(cls, f.name, bad) for cls in CLASSES for f in dataclasses.fields(cls)
         for bad in bad_values(rule(cls, f), getattr(cls(), f.name))]


def _id(case):
    cls, name, bad = case
    return f"{cls.__module__.rsplit('.', 1)[-1]}.{cls.__name__}.{name}={bad!r}"


def test_every_field_has_a_declared_rule():
    """In the class's rules dict or in the field's metadata (``bounds`` / ``choices``); a boolean needs none
    (True or False is all it can be)."""
    for cls, rules in CLASSES.items():
        names = {f.name for f in dataclasses.fields(cls)}
        missing = sorted(f.name for f in dataclasses.fields(cls) if f.name not in rules
                         and not {"bounds", "choices"} & set(f.metadata) and not isinstance(f.default, bool))
        assert not missing, (f"{cls.__name__} fields without a declared rule: {missing}; declare their bounds next to "
                             f"the class (its *_RULES dict) or in the field's metadata")
        assert not set(rules) - names, f"{cls.__name__}: rules for fields it does not have: {set(rules) - names}"


def _dataclass_arguments(env_cls) -> set:
    hints = typing.get_type_hints(env_cls.__init__)
    found = set()
    for name, hint in hints.items():
        for t in typing.get_args(hint) or (hint,):
            if dataclasses.is_dataclass(t):
                found.add((t, name))
    return found


def test_the_table_covers_every_dataclass_argument_of_every_env():
    env_classes = {gym.spec(i).entry_point for i in visuomotor_gym.ENV_IDS}
    covered = {(cls, arg) for cls, _, _, arg in TABLE}
    for entry in env_classes:
        module, _, attr = entry.partition(":")
        env_cls = getattr(__import__(module, fromlist=[attr]), attr)
        for cls, arg in _dataclass_arguments(env_cls):
            assert (cls, arg) in covered, f"{env_cls.__name__}({arg}=...) takes {cls.__name__}: add it to TABLE"


def test_the_defaults_construct_and_satisfy_their_rules():
    for cls in CLASSES:
        obj = cls()
        for f in dataclasses.fields(cls):
            rule(cls, f)(getattr(obj, f.name), f.name)  # no exception


@pytest.mark.parametrize("case", CASES, ids=[_id(c) for c in CASES])
def test_bad_field_is_refused_naming_the_class_and_field(case):
    cls, name, bad = case
    with pytest.raises((ValueError, TypeError)) as excinfo:
        cls(**{name: bad})
    assert f"{cls.__name__}.{name}" in str(excinfo.value), str(excinfo.value)
    assert "\n" not in str(excinfo.value)


ENV_CASES = [(env_id, arg, f.name, bad) for cls, _, env_id, arg in TABLE if env_id is not None
             for f in dataclasses.fields(cls) for bad in bad_values(rule(cls, f), getattr(cls(), f.name))]


def test_bad_fields_through_gym_make_name_the_argument_and_write_no_mujoco_log(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert len(ENV_CASES) > 400
    for env_id, arg, name, bad in ENV_CASES:
        with pytest.raises((ValueError, TypeError)) as excinfo:
            gym.make(env_id, **{arg: {name: bad}})
        assert f"{arg}.{name}" in str(excinfo.value), (env_id, arg, name, bad, str(excinfo.value))
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT, nothing else


def test_documented_special_values_are_accepted():
    assert VisionParams(position_slip_knee_deg_s=INF).position_slip_knee_deg_s == INF  # static acuity
    assert GaitParams(lateral_range_m=(-0.5, 0.5), pelvis_lead_m=-0.3).lateral_range_m == (-0.5, 0.5)
    # lists (e.g. from JSON) are stored as tuples of floats
    assert GaitParams(step_range_m=[0.3, 0.9]).step_range_m == (0.3, 0.9)
    assert CrowdDistribution(speed_m_s=np.array([1.0, 1.2])).speed_m_s == (1.0, 1.2)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"double_support_s": 0.5}, r"GaitParams.double_support_s must be < step_s"),
    ({"heel_off_s": 0.25}, r"GaitParams.heel_off_s must lie between mid-stance, .* = 0.3 s, and toe-off"),
    ({"min_step_width_m": 0.2}, r"GaitParams.min_step_width_m must be <= step_width_m"),
    ({"nominal_step_m": 1.0}, r"GaitParams.nominal_step_m must lie inside step_range_m"),
    ({"swing_move": (0.4, 0.6)}, r"GaitParams.swing_move must be a \(low, high\) pair with high - low >= 0.5"),
])
def test_orders_between_fields(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        GaitParams(**kwargs)


def test_a_course_the_gait_cannot_step_is_refused_before_any_physics(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=r"course_distribution.spacing_m must start above the widest step"):
        gym.make("SteppingStones-v0", course_distribution={"spacing_m": (0.3, 0.8)})
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_without_the_check_a_nan_gait_writes_mujoco_log(tmp_path, monkeypatch):
    """The control of the test above: the same NaN smuggled past the check (``object.__setattr__`` on the
    frozen instance) reaches MuJoCo, which writes its log into the working folder."""
    monkeypatch.chdir(tmp_path)
    params = GaitParams()
    object.__setattr__(params, "nominal_step_m", NAN)
    env = gym.make("ObstacleWalk-v0", gait_params=params)
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.zeros(env.action_space.shape, np.float32))
    env.close()
    assert (tmp_path / "MUJOCO_LOG.TXT").exists()


# Extreme but allowed values: the bounds are modelling choices, so each one is played for a few steps.
EPS = 0.002  # inside an open end: one physics step (the gait's times are whole numbers of them)


def _edges(rule):
    if isinstance(rule, Num):
        lo = None if rule.low is None else rule.low + (EPS if rule.low_open else 0.0)
        hi = None if rule.high is None else rule.high - (EPS if rule.high_open else 0.0)
        return [v for v in (lo, hi) if v is not None]
    if isinstance(rule, Pair):
        b = rule.bounds
        return [(b.low + (EPS if b.low_open else 0.0), b.high - (EPS if b.high_open else 0.0))]
    return []


GAIT_EDGES = [(name, v) for name, rule in GAIT_RULES.items() for v in _edges(rule)]


@pytest.mark.slow
def test_gait_at_the_edges_of_its_rules_walks_without_diverging(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(0)
    played = 0
    for name, value in GAIT_EDGES:
        try:
            env = gym.make("ObstacleWalk-v0", gait_params={name: value})
        except ValueError as exc:  # an order with another field's default (e.g. nominal_step_m in step_range_m)
            assert "must be <" in str(exc) or "must lie" in str(exc), str(exc)
            continue
        obs, _ = env.reset(seed=0)
        for t in range(120):  # zero actions (nominal footsteps) first, then random ones
            action = rng.uniform(-1, 1, env.action_space.shape) if t >= 60 else np.zeros(env.action_space.shape)
            obs, reward, terminated, truncated, info = env.step(action)
            assert np.all(np.isfinite(obs)) and math.isfinite(reward) and not info["physics_diverged"], (name, value)
            if terminated or truncated:
                break
        env.close()
        played += 1
    assert played >= 25
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
