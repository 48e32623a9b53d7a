"""For each pedestrian of fajen_warren's episodes on ObstacleDodge-v0 (a crowd preset laid over the id), whether the
realism metric counts it fixated (``metrics.dodge_realism.first_fixations``, on the episode's trace) and whether the
agent ever chose it as its gaze target: tells deliberate fixations from a pedestrian crossing the line of sight by
chance. Pedestrians counted as the metric counts them (present ``MIN_PRESENT_S`` before the end). Prints the counts.

    python docs/reproductions/data/terrain/dodge_fixation_kinds.py CROWD FIRST_SEED EPISODES
"""

import sys

import gymnasium as gym
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.bench.trace import run_episode
from visuomotor_gym.metrics.dodge_realism import MIN_PRESENT_S, first_fixations

ENV = "ObstacleDodge-v0"


class TargetLog:
    """The agent, with the gaze targets (its pedestrian slots) it chose along the episode."""

    def __init__(self, agent) -> None:
        self.agent, self.slots = agent, set()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        out = self.agent.predict(observation, state=state, episode_start=episode_start, deterministic=deterministic)
        if self.agent.target is not None and self.agent.target[0] == "ped":
            self.slots.add(self.agent.target[1])
        return out


def main() -> None:
    crowd, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    env = gym.make(ENV, crowd_distribution=crowd)
    totals = dict.fromkeys(("counted", "fixated", "targeted", "fixated_not_targeted", "targeted_not_fixated"), 0)
    for seed in range(first, first + n):
        log = TargetLog(make_agent("fajen_warren", ENV, action_dim=int(env.action_space.shape[0]), seed=seed))
        trace = run_episode(env, log, seed, ENV, "fajen_warren")
        # with groups a slot is given at first sight and stays the pedestrian's; without, slot k is pedestrian k
        task = env.unwrapped.task
        slot_of = task.slot_of if task.dist.groups else list(range(len(task.slot_of)))
        onsets = np.asarray(trace.pedestrians, dtype=float).reshape(-1, 9)[:, 0]
        for i, start in enumerate(first_fixations(trace)):
            if trace.t[-1] - onsets[i] < MIN_PRESENT_S:
                continue
            fixated, targeted = start is not None, slot_of[i] in log.slots
            totals["counted"] += 1
            totals["fixated"] += fixated
            totals["targeted"] += targeted
            totals["fixated_not_targeted"] += fixated and not targeted
            totals["targeted_not_fixated"] += targeted and not fixated
    print(crowd, totals)


if __name__ == "__main__":
    main()
