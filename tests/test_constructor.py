"""The one constructor (VisuomotorEnv.__init__ with the shared arguments, families forwarding
``**shared``), the generated Arguments tables, the Task/Body base classes and the observation
value-count check, for every family."""

from __future__ import annotations

import ast
import inspect
import re

import numpy as np
import pytest

from visuomotor_gym.core.env import SHARED_ARGUMENT_MEANINGS, VisuomotorEnv
from visuomotor_gym.core.parts import Body, Task
from visuomotor_gym.envs.catch import EyeCatchEnv
from visuomotor_gym.envs.dodge import ObstacleDodgeEnv
from visuomotor_gym.envs.reach import ShelfReachEnv
from visuomotor_gym.envs.stones import SteppingStonesEnv
from visuomotor_gym.envs.walk import ObstacleWalkEnv

ENVS = [EyeCatchEnv, ShelfReachEnv, ObstacleWalkEnv, SteppingStonesEnv, ObstacleDodgeEnv]
SHARED = [n for n in inspect.signature(VisuomotorEnv.__init__).parameters if n not in ("self", "unknown")]


def _kwargs(cls) -> dict[str, inspect.Parameter]:
    params = inspect.signature(cls.__init__).parameters
    return {n: p for n, p in params.items() if n != "self"}


def _table_rows(cls) -> dict[str, str]:
    section = cls.__doc__.split("## Arguments", 1)[1].split("\n    ## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        line = line.strip()
        if not line.startswith("| ``"):
            continue
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        names = re.findall(r"``(\w+)``", cells[0])
        defaults = [d.strip() for d in cells[1].split(",")] if len(names) > 1 else [cells[1]]
        assert len(defaults) == len(names), line
        for name, default in zip(names, defaults):
            assert name not in rows, f"{cls.__name__}: argument {name} documented twice"
            rows[name] = default
    return rows


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_signature_lists_own_then_shared_arguments_with_the_shared_defaults(cls):
    kwargs = _kwargs(cls)
    assert not [p for p in kwargs.values() if p.kind is inspect.Parameter.VAR_KEYWORD], "no **shared left visible"
    assert next(iter(kwargs)) == "render_mode"
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for n, p in kwargs.items() if n != "render_mode")
    base = inspect.signature(VisuomotorEnv.__init__).parameters
    for name in SHARED:
        assert name in kwargs, f"{cls.__name__} lost shared argument {name}"
        assert kwargs[name].default == base[name].default
    assert list(kwargs)[-len(SHARED) + 1:] == SHARED[1:], "shared arguments come after the family's own"
    assert sorted(cls._argument_names()) == sorted(kwargs)


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_arguments_table_is_the_signature(cls):
    rows = _table_rows(cls)
    kwargs = _kwargs(cls)
    assert "ARGUMENTS_TABLE" not in cls.__doc__
    assert list(rows) == list(kwargs), f"{cls.__name__}: Arguments table names/order differ from the signature"
    for name, documented in rows.items():
        assert ast.literal_eval(documented.replace("``", "")) == kwargs[name].default, name
    assert cls.arguments_table().splitlines()[2] in cls.__doc__


def test_arguments_table_refuses_an_argument_without_a_meaning():
    class Undocumented(VisuomotorEnv):
        def __init__(self, render_mode=None, *, mystery: int = 1, **shared):
            super().__init__(render_mode, **shared)

    with pytest.raises(TypeError, match="'mystery' has no meaning"):
        Undocumented.arguments_table()
    assert "mystery" not in SHARED_ARGUMENT_MEANINGS


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_unknown_shared_and_own_arguments_are_refused_by_name(cls):
    with pytest.raises(TypeError, match=r"unknown argument\(s\) \['visual_delay'\]") as excinfo:
        cls(visual_delay=0.1)
    for name in ("vision", "record_plant", "render_mode"):
        assert repr(name) in str(excinfo.value)
    own = [n for n in _kwargs(cls) if n not in SHARED]
    assert own and all(repr(n) in str(excinfo.value) for n in own)
    with pytest.raises(ValueError, match="vision"):
        cls(vision="blurry")
    with pytest.raises(ValueError, match="control_dt"):
        cls(control_dt=0.003)


def test_each_observe_call_must_append_exactly_its_blocks():
    env = EyeCatchEnv()
    task_observe = env.task.observe_leading

    def short(values, samples):
        task_observe(values, samples)
        values.pop()

    env.task.observe_leading = short
    with pytest.raises(RuntimeError, match=r"CatchTask\.observe_leading appended 7 .* hold 8 .*block 'ball_age' is not filled"):
        env.reset(seed=0)

    env = EyeCatchEnv()
    body_observe = env.body.observe

    def long(values, data):
        body_observe(values, data)
        values.append(0.0)

    env.body.observe = long
    with pytest.raises(RuntimeError, match=r"SeatedBody\.observe appended .*1 value\(s\) past block"):
        env.reset(seed=0)


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_parts_subclass_the_base_classes_and_the_check_passes(cls):
    env = cls()
    assert isinstance(env.task, Task) and isinstance(env.body, Body)
    obs, _ = env.reset(seed=3)
    obs, *_ = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    assert obs.shape == (env.layout.size,)
    assert env._observe_ends[-1] == env.layout.size


def test_task_and_body_bases_keep_only_the_essentials_abstract():
    assert Task.__abstractmethods__ == {"reset_episode", "initial_gaze", "evaluate", "info"}
    assert Body.__abstractmethods__ == {"command", "observe"}

    class Half(Task):
        def reset_episode(self, data, rng):
            pass

    with pytest.raises(TypeError, match="abstract"):
        Half()

    class Minimal(Half):
        targets: list = []  # noqa: RUF012

        def initial_gaze(self):
            return np.zeros(3), (0.0, 0.0)

        def evaluate(self, data, fired, a, eye):
            return 0.0, {}, False, {}

        def info(self, data, *, diverged=False):
            return {}

        def trace_episode_fields(self):
            return {"k": 1}

    t = Minimal()
    assert t.initial_fixation(2.5) == 2.5
    assert t.reset_info() == {"k": 1}  # reset's info defaults to the recorded episode fields
    assert t.needs_substep_checks(None) is False and t.check_substep(None) is False
    assert t.trace_final_fields({"x": 1}) == {} and t.success is False
    values: list = []
    t.observe_leading(values, [])
    t.observe_trailing(values, [], None)
    assert values == [] and t.leading_blocks == () and t.trailing_blocks == ()
    for hook in ("reset_state", "before_physics", "before_observe", "initial_fixation", "reset_info"):
        assert getattr(Task, hook).__doc__, hook


def test_a_family_without_build_says_so():
    class NoBuild(VisuomotorEnv):
        scene = "catch.xml"
        render_cameras = {"both": ("scene",)}  # noqa: RUF012

    with pytest.raises(NotImplementedError, match="NoBuild must define _build"):
        NoBuild()
