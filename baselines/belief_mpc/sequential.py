"""The Eyecatch heuristic on two balls, one after the other (the comparison of Eom et al. 2019, Fig. 4b).

Eom et al. describe what Yeo et al.'s heuristic does with two balls: it tracks and catches the first,
and "looks at the other ball only after catching the first one". :class:`SequentialEyecatch` does
exactly that with the unmodified :class:`~visuomotor_gym.baselines.eyecatch.EyecatchAgent`: it shows
the heuristic the single-ball observation of the current ball (the first ball's blocks, then, once
the touch sense reports the first catch, the second ball's blocks in their place) and starts it
afresh (new filter, new phases) when it switches. On single-ball envs it is the heuristic itself.

It is not a registered agent (the registry keeps one name per method); the reproduction page and the
tests build it directly and play it with the evaluator's episode runner.
"""

from __future__ import annotations

import numpy as np
from visuomotor_gym.baselines.eyecatch import EyecatchAgent

from visuomotor_gym.envs.observation import ObservationLayout, catch_observation

_ONE = ObservationLayout()
_TWO = ObservationLayout(catch_observation(2))


class SequentialEyecatch:
    """Eyecatch on the first ball, then on the second (SB3 ``predict`` interface)."""

    def __init__(self, agent: EyecatchAgent | None = None):
        self.agent = agent or EyecatchAgent()
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> SequentialEyecatch:
        return cls(EyecatchAgent.for_env(env_id, **overrides))

    def reset(self) -> None:
        self.agent.reset()
        self.current = 0  # the ball the heuristic is shown
        self.switch_time = float("nan")

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]):
            self.reset()
        if obs.shape == (_ONE.size,):
            return self.agent.predict(obs, state, None, deterministic)
        if obs.shape != (_TWO.size,):
            raise ValueError(f"SequentialEyecatch expects a catch observation of size {_ONE.size} or {_TWO.size}")
        S = _TWO.slices
        if self.current == 0 and obs[S["balls_caught"]][0] > 0.5:
            self.current = 1
            self.switch_time = float(obs[S["time"]][0])
            self.agent.reset()  # a new ball: a new filter and new phases
        view = obs[: _ONE.size].copy()
        if self.current == 1:
            for src, dst in (("ball2_pos", "ball_pos"), ("ball2_vel", "ball_vel"), ("ball2_visible", "ball_visible")):
                view[_ONE.slices[dst]] = obs[S[src]]
        return self.agent.predict(view, state, None, deterministic)
