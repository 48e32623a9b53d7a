"""Bad actions, constructor arguments and reset options fail loudly, with a message naming the problem."""

from __future__ import annotations

import inspect
import re

import gymnasium as gym
import numpy as np
import pytest

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.envs.catch import EyeCatchEnv

N_ACT = 9


@pytest.fixture
def env():
    env = gym.make("EyeCatch-v0").unwrapped  # unwrapped: the env itself must validate, not a wrapper
    env.reset(seed=0)
    return env


def _valid() -> np.ndarray:
    return np.zeros(N_ACT, np.float32)


# ----------------------------------------------------------------------------------------------
# actions
# ----------------------------------------------------------------------------------------------
def _with(index: int, value: float) -> np.ndarray:
    a = _valid()
    a[index] = value
    return a


@pytest.mark.parametrize(
    "action",
    [
        _with(0, np.nan),
        _with(4, np.inf),
        _with(8, -np.inf),
        np.full(N_ACT, np.nan),
        [0.0] * 8 + [float("nan")],
    ],
    ids=["nan", "inf", "-inf", "all-nan", "list-with-nan"],
)
def test_non_finite_action_raises(env, action):
    with pytest.raises(ValueError, match=r"(?i)nan|inf|finite"):
        env.step(action)


@pytest.mark.parametrize(
    "action",
    [
        np.zeros(8, np.float32),
        np.zeros(10, np.float32),
        np.zeros((1, N_ACT), np.float32),
        np.zeros((N_ACT, 1), np.float32),
        np.zeros((3, 3), np.float32),
        np.float32(0.0),
        [],
        [0.0] * 8,
        None,
    ],
    ids=["8", "10", "1x9", "9x1", "3x3", "scalar", "empty", "list-8", "None"],
)
def test_wrong_shape_action_raises(env, action):
    with pytest.raises(ValueError, match=r"shape") as excinfo:
        env.step(action)
    assert "(9,)" in str(excinfo.value), "the message should say which shape is expected"


@pytest.mark.parametrize(
    "action",
    [["a"] * N_ACT, "abc", {"hand": 1}, [object()] * N_ACT, [0.0, [1.0, 2.0]] + [0.0] * 7, b"abcdefghi"],
    ids=["strings", "str", "dict", "objects", "ragged", "bytes"],
)
def test_non_numeric_action_raises(env, action):
    with pytest.raises(ValueError, match=r"(?i)action.*numeric|numeric.*action"):
        env.step(action)


@pytest.mark.parametrize(
    "action",
    [np.array(["0.1"] * N_ACT), np.zeros(N_ACT, dtype="datetime64[s]")],
    ids=["numeric-strings", "datetime64"],
)
def test_non_numeric_dtype_action_raises(env, action):
    with pytest.raises(ValueError, match=r"(?i)numeric"):
        env.step(action)


def test_bad_action_does_not_advance_the_env(env):
    before = env.data.time
    with pytest.raises(ValueError):
        env.step(_with(0, np.nan))
    assert env.data.time == before
    obs, *_ = env.step(_valid())  # still usable
    assert np.all(np.isfinite(obs))


@pytest.mark.parametrize("scale", [1.5, 5.0, 1e30, np.finfo(np.float64).max])
def test_out_of_range_finite_actions_are_clipped(scale):
    rng = np.random.default_rng(1)
    base = rng.uniform(-1, 1, N_ACT)
    base[np.abs(base) < 0.3] = 0.7  # every component well away from zero
    big = np.sign(base) * scale  # far outside [-1, 1]
    env_big = gym.make("EyeCatch-v0").unwrapped
    env_clip = gym.make("EyeCatch-v0").unwrapped
    env_big.reset(seed=2)
    env_clip.reset(seed=2)
    for _ in range(10):
        obs_big, _r_big, term_big, _, _info_big = env_big.step(big)  # float64, out of range: no error
        obs_clip, _r_clip, term_clip, _, _info_clip = env_clip.step(np.sign(base).astype(np.float32))
        np.testing.assert_array_equal(obs_big, obs_clip)
        assert term_big == term_clip
        if term_big:
            break
    # effort is computed on the clipped action too
    env_big = gym.make("EyeCatch-v0", reward="shaped").unwrapped
    env_big.reset(seed=2)
    _, _, _, _, info = env_big.step(big)
    assert info["reward_terms"]["effort"] == pytest.approx(-0.001 * 1.0, rel=1e-9)


def test_equivalent_action_containers_give_the_same_step():
    action = np.random.default_rng(5).uniform(-1, 1, N_ACT)
    results = []
    for container in (action.astype(np.float32), action.astype(np.float32).astype(np.float64),
                      action.astype(np.float32).tolist(), tuple(action.astype(np.float32).tolist())):
        e = gym.make("EyeCatch-v0").unwrapped
        e.reset(seed=4)
        results.append(e.step(container)[0])
    for obs in results[1:]:
        np.testing.assert_array_equal(obs, results[0])


# ----------------------------------------------------------------------------------------------
# constructor arguments
# ----------------------------------------------------------------------------------------------
def _allowed() -> list[str]:
    params = inspect.signature(EyeCatchEnv.__init__).parameters
    return [n for n, p in params.items() if n != "self" and p.kind is not inspect.Parameter.VAR_KEYWORD]


@pytest.mark.parametrize("via", ["gym.make", "direct"])
@pytest.mark.parametrize(
    "kwargs", [{"foo": 1}, {"visual_delay": 0.1}, {"foo": 1, "bar": 2, "vision": "oracle"}]
)
def test_unknown_kwargs_raise_type_error_listing_allowed_names(via, kwargs):
    with pytest.raises(TypeError) as excinfo:
        if via == "gym.make":
            gym.make("EyeCatch-v0", **kwargs)
        else:
            EyeCatchEnv(**kwargs)
    message = str(excinfo.value)
    for name in kwargs:
        if name not in _allowed():
            assert name in message, f"the unknown name {name!r} is not named"
    for name in _allowed():
        assert re.search(rf"\b{name}\b", message), f"allowed argument {name!r} not listed in: {message}"


BAD_VALUES = [
    ({"vision": "x"}, "vision"),
    ({"vision": None}, "vision"),
    ({"control": "x"}, "control"),
    ({"obs_mode": "x"}, "obs_mode"),
    ({"reward": "x"}, "reward"),
    ({"render_mode": "x"}, "render_mode"),
    ({"render_camera": "x"}, "render_camera"),
    ({"control_dt": 0.003}, "control_dt"),
    ({"control_dt": 0.0}, "control_dt"),
    ({"control_dt": -0.02}, "control_dt"),
    ({"visual_delay_s": 0.03}, "visual_delay_s"),
    ({"visual_delay_s": -0.02}, "visual_delay_s"),
    ({"reward_weights": {"nope": 1}}, "nope"),
    ({"vision_params": {"nope": 1}}, "nope"),
    ({"vision_params": 3}, "vision_params"),
    ({"oculomotor_params": {"nope": 1}}, "nope"),
    ({"hand_params": {"nope": 1}}, "nope"),
    ({"throw_distribution": {"nope": 1}}, "nope"),
    ({"throw_distribution": {"flight_time_s": (1.4, 0.8)}}, "flight_time_s"),
    ({"vision_noise_scale": -1.0}, "vision_noise_scale"),
    ({"vision_noise_scale": float("nan")}, "vision_noise_scale"),
    ({"catch_radius": 0.0}, "catch_radius"),
    ({"grasp_closed_fraction": 1.5}, "grasp_closed_fraction"),
]


# gym.make's own warning about render_mode="x", before the env raises
@pytest.mark.filterwarnings("ignore:.*not in the possible render_modes")
@pytest.mark.parametrize("via", ["gym.make", "direct"])
@pytest.mark.parametrize(
    "kwargs,named", BAD_VALUES, ids=[f"{k}={v!r}" for (kw, _) in BAD_VALUES for k, v in kw.items()]
)
def test_bad_constructor_values_raise_clear_error(via, kwargs, named):
    with pytest.raises((ValueError, TypeError)) as excinfo:
        if via == "gym.make":
            gym.make("EyeCatch-v0", **kwargs)
        else:
            EyeCatchEnv(**kwargs)
    assert named in str(excinfo.value), f"{excinfo.value!r} does not name {named!r}"


@pytest.mark.parametrize("kwargs,choices", [
    ({"vision": "x"}, ["foveated", "full_view", "oracle"]),
    ({"control": "x"}, ["hand", "joint"]),
    ({"obs_mode": "x"}, ["flat", "dict"]),
    ({"reward": "x"}, ["sparse", "shaped"]),
    ({"render_mode": "x"}, ["rgb_array", "human"]),
])
def test_bad_choice_lists_the_valid_choices(kwargs, choices):
    with pytest.raises(ValueError) as excinfo:
        EyeCatchEnv(**kwargs)
    for choice in choices:
        assert choice in str(excinfo.value)


@pytest.mark.parametrize("kwargs", [
    {"control_dt": 0.004}, {"control_dt": 0.01}, {"visual_delay_s": 0.04}, {"vision_noise_scale": 0.0},
    {"reward_weights": {"catch": 2.0}}, {"vision_params": {}}, {"render_mode": None},
])
def test_valid_edge_values_are_accepted(kwargs):
    env = gym.make("EyeCatch-v0", **kwargs)
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step(_valid())
    assert np.all(np.isfinite(obs))


# ----------------------------------------------------------------------------------------------
# reset
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("options", [{"x": 1}, {"seed": 3}, {"throw": None}])
def test_reset_with_unknown_options_raises(env, options):
    with pytest.raises(ValueError, match=re.escape(str(sorted(options)))):
        env.reset(options=options)


def test_reset_with_empty_or_no_options_is_fine(env):
    obs_a, _ = env.reset(seed=1, options=None)
    obs_b, _ = env.reset(seed=1, options={})
    np.testing.assert_array_equal(obs_a, obs_b)


# ----------------------------------------------------------------------------------------------
# constructor arguments that used to be accepted but wrong: each refused at construction,
# with the argument's name in the message
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs, error, pattern",
    [
        ({"reward_weights": {"catch": float("nan")}}, ValueError, r"reward_weights\['catch'\] must be a finite"),
        ({"reward": "shaped", "reward_weights": {"approach": float("inf")}}, ValueError, r"reward_weights\['approach'\]"),
        ({"reward_weights": [("catch", 1.0)]}, TypeError, r"reward_weights must be a dict"),
        ({"vision_noise_scale": 1e40}, ValueError, r"vision_noise_scale must be in \[0, 1000\]"),
        ({"vision_noise_scale": "10"}, TypeError, r"vision_noise_scale must be a real number"),
        ({"gaze_action_range_deg": float("inf")}, ValueError, r"gaze_action_range_deg must be a finite number"),
        ({"control_dt": float("inf")}, ValueError, r"control_dt must be a finite number"),
        ({"control_dt": 0.003}, ValueError, r"control_dt=0.003 must be a positive whole multiple"),
        ({"visual_delay_s": float("inf")}, ValueError, r"visual_delay_s must be a finite number"),
        ({"visual_delay_s": 0.05}, ValueError, r"visual_delay_s=0.05 must be a non-negative whole multiple"),
        ({"bounce_wall": "no"}, TypeError, r"bounce_wall must be True or False, got 'no'"),
        ({"bounce_wall": 1}, TypeError, r"bounce_wall must be True or False"),
        ({"record_plant": "yes"}, TypeError, r"record_plant must be True or False"),
        ({"throw_distribution": {"second_max_flight_s": 0.0}, "n_balls": 2}, ValueError, r"second_max_flight_s"),
        ({"throw_distribution": {"second_stagger_s": (-0.1, 0.2)}}, ValueError, r"throw_distribution.second_stagger_s must hold finite numbers in \(0, 5\]"),
        ({"width": -1}, ValueError, r"width must be an integer in \[1, 8192\]"),
        ({"height": 2.5}, TypeError, r"height must be an integer"),
        ({"catch_radius": 0.0}, ValueError, r"catch_radius must be in \(0, 0.5\]"),
        ({"release_after_catch_s": float("nan")}, ValueError, r"release_after_catch_s must be a finite"),
    ],
)
def test_bad_constructor_argument_is_refused_with_its_name(kwargs, error, pattern):
    with pytest.raises(error, match=pattern):
        EyeCatchEnv(**kwargs)


def test_step_before_reset_is_a_clear_error():
    env = EyeCatchEnv()
    with pytest.raises(RuntimeError, match=r"step\(\) called before reset\(\)"):
        env.step(np.zeros(N_ACT, np.float32))


def test_step_after_the_episode_ended_warns_once_and_goes_on():
    """Gymnasium's own checker warns rather than raises here; so do we (documented in the env)."""
    env = gym.make("EyeCatchOracle-v0").unwrapped
    env.reset(seed=0)
    open_hand = np.zeros(N_ACT, np.float32)
    open_hand[3] = -1.0
    for _ in range(200):
        *_, terminated, _, _ = env.step(open_hand)
        if terminated:
            break
    assert terminated
    with pytest.warns(UserWarning, match="after the episode ended"):
        env.step(open_hand)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env.step(open_hand)  # only once per episode
    env.reset(seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env.step(open_hand)  # a fresh episode: no warning
