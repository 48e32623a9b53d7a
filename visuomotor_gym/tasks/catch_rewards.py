"""Reward of the catch family: a sum of named terms, each reported in ``info["reward_terms"]``."""

from __future__ import annotations

import math

SPARSE_WEIGHTS = {"catch": 1.0}
SHAPED_WEIGHTS = {
    "catch": 1.0,  # +1 on the step the ball is caught
    "miss": -0.2,  # on the step the ball is judged missed
    "approach": -0.01,  # per step, x distance (m) from the catch site to the ball
    "foveation": 0.005,  # per step, exp(-(eccentricity / 5 deg)^2) of the true ball when visible
    "effort": -0.001,  # per step, mean squared action
}
REWARD_TERMS = tuple(SHAPED_WEIGHTS)
FOVEATION_WIDTH_RAD = math.radians(5.0)


def catch_reward(
    weights: dict[str, float],
    caught: bool,
    missed: bool,
    hand_ball_distance: float,
    ball_eccentricity: float | None,
    action_sq_mean: float,
) -> tuple[float, dict[str, float]]:
    """Return ``(reward, terms)``; ``reward`` is exactly ``sum(terms.values())``.

    Only terms with a non-zero weight appear. ``ball_eccentricity`` is None when the ball was not
    seen this step.
    """
    terms: dict[str, float] = {}
    for name, w in weights.items():
        if w == 0.0:
            continue
        if name == "catch":
            value = 1.0 if caught else 0.0
        elif name == "miss":
            value = 1.0 if missed else 0.0
        elif name == "approach":
            value = hand_ball_distance
        elif name == "foveation":
            value = 0.0 if ball_eccentricity is None else math.exp(-((ball_eccentricity / FOVEATION_WIDTH_RAD) ** 2))
        elif name == "effort":
            value = action_sq_mean
        else:  # validated in the env constructor; kept as a guard for direct callers
            raise KeyError(f"unknown reward term {name!r}; known terms: {REWARD_TERMS}")
        terms[name] = w * value
    return float(sum(terms.values())), terms
