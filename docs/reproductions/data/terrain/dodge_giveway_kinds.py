"""Replay ``fajen_warren`` on ObstacleDodge-v0 seeds with the give-way rule off and on (the "wide" crowd,
``CrowdDistribution.give_way``) and, for each collision, name the pedestrian struck and its kind: its bearing
from the walker's direction of travel (averaged over the last 0.5 s, as the rule judges it) at the contact
and its largest over the last 2 s before it, whether its course walks the walker's way, and (rule on)
whether it gave way. "overtaking" = behind the walker's frontal field (bearing > 90 deg) at some time in the
last 2 s with a course walking the walker's way.

    python docs/reproductions/data/terrain/dodge_giveway_kinds.py SEED [SEED ...]
"""

import dataclasses
import math
import sys

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.tasks.obstacle_dodge import CROWD_PRESETS

ENV = "ObstacleDodge-v0"


def replay(give_way: bool, seed: int) -> str:
    env = gym.make(ENV, crowd_distribution=dataclasses.replace(CROWD_PRESETS["wide"], give_way=give_way))
    agent = make_agent("fajen_warren", ENV, action_dim=int(env.action_space.shape[0]), seed=seed)
    obs, info = env.reset(seed=seed)
    task, data = env.unwrapped.task, env.unwrapped.data
    hist, done = [], False
    while not done:
        action, _ = agent.predict(obs, deterministic=True)
        obs, _, term, trunc, info = env.step(action)
        done = term or trunc
        hist.append((float(data.time), float(data.qpos[0]), float(data.qpos[1]), task.pos.copy(), list(task.active)))
    env.close()
    if not info["collided"]:
        return "reached the goal" if info["finished"] else "timed out"
    t, wx, wy, pos, active = hist[-1]
    i = min((math.hypot(pos[k, 0] - wx, pos[k, 1] - wy), k) for k in range(len(pos)) if active[k])[1]
    bearings = []
    for j in range(max(25, len(hist) - 100), len(hist)):  # the last 2 s
        _, x, y, p, _ = hist[j]
        _, x0, y0, _, _ = hist[j - 25]  # 0.5 s earlier
        hx, hy = x - x0, y - y0
        rx, ry = p[i, 0] - x, p[i, 1] - y
        c = (rx * hx + ry * hy) / ((math.hypot(rx, ry) * math.hypot(hx, hy)) or 1.0)
        bearings.append(math.degrees(math.acos(max(-1.0, min(1.0, c)))))
    course_vx = float(task.crowd.pedestrians[i, 3])
    veers = bool(task.crowd.pedestrians[i, 7] > 0.0)
    kind = "overtaking" if max(bearings) > 90.0 and course_vx > 0.0 else "other"
    gave = f", gave way {task.gave_way[i]}" if give_way else ""
    return (f"collided at {t:.2f} s with pedestrian {i} ({kind}): bearing {bearings[-1]:.0f} deg at contact, "
            f"max {max(bearings):.0f} deg in the last 2 s, course vx {course_vx:+.2f} m/s, veers {veers}{gave}")


def main() -> None:
    for seed in (int(s) for s in sys.argv[1:]):
        print(f"seed {seed}: off: {replay(False, seed)}")
        print(f"seed {seed}: on:  {replay(True, seed)}", flush=True)


if __name__ == "__main__":
    main()
