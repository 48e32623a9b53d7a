"""Diagnostic for docs/baselines/rl.md, "The same idea on SteppingStones-v0": which block of the cloned action
fails? The teacher (``lookahead``) and the student (the cloned policy) see the same observation stream; the
played action takes the footstep block (0-3) from one and the look block (4-8) from the other.

    python docs/baselines/stones_clone_blocks.py baselines/ppo/policies/ppo-free-clone__SteppingStones-v0.npz
"""

import sys

import gymnasium as gym
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent

ENV = "SteppingStones-v0"
SEEDS = 40


def crossed(policy_file: str, feet: str, look: str) -> int:
    """Courses crossed on seeds 0..SEEDS-1 with the footsteps of ``feet`` and the look of ``look``."""
    env = gym.make(ENV)
    ok = 0
    for seed in range(SEEDS):
        teacher = make_agent("lookahead", ENV, 9)
        student = make_agent(f"ppo:{policy_file}", ENV, 9)
        x, _ = env.reset(seed=seed)
        done, first, info = False, True, {}
        while not done:
            actions = {"teacher": teacher.predict(x)[0],
                       "student": student.predict(x, episode_start=np.array([first]))[0]}
            first = False
            a = np.concatenate([actions[feet][:4], actions[look][4:]]).astype(np.float32)
            x, _, terminated, truncated, info = env.step(a)
            done = terminated or truncated
        ok += bool(info["is_success"])
    env.close()
    return ok


def main() -> None:
    for feet, look in (("teacher", "student"), ("student", "teacher")):
        print(f"feet={feet} look={look}: {crossed(sys.argv[1], feet, look)}/{SEEDS} crossed (seeds 0-{SEEDS - 1})")


if __name__ == "__main__":
    main()
