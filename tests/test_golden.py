"""Whole-episode golden digests (tests/golden/digests.py): a refactor must leave every one unchanged.

A failure names the cases whose observations, rewards, flags or info changed. If a behaviour change
is intended, regenerate with ``python -m tests.golden.digests --write`` and say so in the commit.
"""

from __future__ import annotations

import json

from golden.digests import GOLDEN_FILE, compute


def test_every_golden_episode_is_unchanged():
    golden = json.loads(GOLDEN_FILE.read_text())
    current = compute()
    assert set(current) == set(golden), "the set of golden cases changed: regenerate deliberately"
    changed = sorted(k for k in golden if current[k] != golden[k])
    from visuomotor_gym._blas import kernel_note

    assert not changed, f"{len(changed)} of {len(golden)} golden episodes changed{kernel_note()}: {changed}"


def test_the_golden_cases_cover_catches_and_the_two_ball_release():
    """The digests are only a proof if the episodes they hash exercise the catch, weld and release."""
    import gymnasium as gym
    import numpy as np

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent

    def run(agent_name, env_id, seed):
        env = gym.make(env_id)
        agent = make_agent(agent_name, env_id, env.action_space.shape[0])
        obs, info = env.reset(seed=seed)
        state, infos = None, [info]
        while True:
            action, state = agent.predict(obs, state, None, True)
            obs, _, terminated, truncated, info = env.step(np.asarray(action, dtype=np.float32))
            infos.append(info)
            if terminated or truncated:
                return infos

    assert any(run("oracle", "EyeCatchOracle-v0", s)[-1]["is_success"] for s in (0, 1, 2))
    two = [run("eyecatch", "EyeCatchTwoBalls-v0", s) for s in (0, 1, 2)]
    assert any(max(i.get("balls_caught", 0) for i in infos) >= 1 for infos in two)
