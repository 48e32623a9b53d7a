"""For each pedestrian of fajen_warren's episodes on ObstacleDodge-v0 (a crowd preset laid over the id), whether the
realism metric counts it fixated (the line of sight within 4 deg of its seen point for 0.1 s while ahead of the eye,
as ``metrics.dodge_realism.pedestrian_fixations``) and whether the agent ever chose it as its gaze target: tells
deliberate fixations from a pedestrian crossing the line of sight by chance. Prints the counts.

    python docs/reproductions/data/terrain/dodge_fixation_kinds.py CROWD FIRST_SEED EPISODES
"""

import math
import sys

import gymnasium as gym
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.metrics.dodge_realism import FIXATION_DEG, FIXATION_MIN_S, MIN_PRESENT_S
from visuomotor_gym.tasks.obstacle_dodge import SEEN_HEIGHT_M

ENV = "ObstacleDodge-v0"


def episode(env, seed: int, totals: dict) -> None:
    agent = make_agent("fajen_warren", ENV, action_dim=int(env.action_space.shape[0]), seed=seed)
    obs, _ = env.reset(seed=seed)
    u = env.unwrapped
    task, rows = u.task, u.crowd.pedestrians
    cos_fix = math.cos(math.radians(FIXATION_DEG))
    need = max(round(FIXATION_MIN_S / u.dt), 1)
    run, fixated, targeted = [0] * len(rows), [False] * len(rows), [False] * len(rows)
    done, t = False, 0.0
    while not done:
        action, _ = agent.predict(obs, deterministic=True)
        obs, _, term, trunc, _ = env.step(action)
        done = term or trunc
        t = float(u.data.time)
        eye, rot = np.asarray(u.eye.pos, dtype=float), np.asarray(u.eye.rot, dtype=float)
        for i in range(len(rows)):
            if not task.active[i]:
                run[i] = 0
                continue
            d = np.array([task.pos[i, 0], task.pos[i, 1], SEEN_HEIGHT_M]) - eye
            on = d @ rot[:, 0] / np.linalg.norm(d) >= cos_fix and (rot.T @ d)[0] > 0.0
            run[i] = run[i] + 1 if on else 0
            fixated[i] = fixated[i] or run[i] >= need
        if agent.target is not None and agent.target[0] == "ped":
            for i in range(len(rows)):
                targeted[i] = targeted[i] or (task.active[i] and task.slot_of[i] == agent.target[1])
    for i, row in enumerate(rows):
        if t - row[0] < MIN_PRESENT_S:
            continue
        totals["counted"] += 1
        totals["fixated"] += fixated[i]
        totals["targeted"] += targeted[i]
        totals["fixated_not_targeted"] += fixated[i] and not targeted[i]
        totals["targeted_not_fixated"] += targeted[i] and not fixated[i]


def main() -> None:
    crowd, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    env = gym.make(ENV, crowd_distribution=crowd)
    totals = dict.fromkeys(("counted", "fixated", "targeted", "fixated_not_targeted", "targeted_not_fixated"), 0)
    for seed in range(first, first + n):
        episode(env, seed, totals)
    print(crowd, totals)


if __name__ == "__main__":
    main()
