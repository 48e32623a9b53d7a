"""Reward terms: named, weighted, summed exactly."""

import math

import pytest

from visuomotor_gym.tasks.catch_rewards import SHAPED_WEIGHTS, SPARSE_WEIGHTS, catch_reward


def test_sparse_reward_is_one_on_catch_only():
    assert catch_reward(SPARSE_WEIGHTS, True, False, 0.0, None, 0.0) == (1.0, {"catch": 1.0})
    assert catch_reward(SPARSE_WEIGHTS, False, True, 0.3, 0.1, 0.5) == (0.0, {"catch": 0.0})


def test_shaped_terms_have_the_documented_values():
    reward, terms = catch_reward(SHAPED_WEIGHTS, False, True, 0.5, math.radians(5.0), 0.25)
    assert terms["miss"] == pytest.approx(-0.2)
    assert terms["approach"] == pytest.approx(-0.01 * 0.5)
    assert terms["foveation"] == pytest.approx(0.005 * math.exp(-1.0))
    assert terms["effort"] == pytest.approx(-0.001 * 0.25)
    assert reward == sum(terms.values())


def test_unseen_ball_earns_no_foveation_and_zero_weights_are_dropped():
    _, terms = catch_reward({"foveation": 1.0, "effort": 0.0}, False, False, 0.0, None, 1.0)
    assert terms == {"foveation": 0.0}


def test_unknown_term_is_an_error():
    with pytest.raises(KeyError, match="unknown reward term"):
        catch_reward({"bogus": 1.0}, False, False, 0.0, None, 0.0)
