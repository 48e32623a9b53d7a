"""Why fajen_warren collides on ObstacleDodge-v0 with groups + all four + disarray 0.8: for each seed given,
the colliding pedestrian, whether it veered, when the agent last chose it as its gaze target, and its filter's
position std and centre distance 0.5 s before the contact (``SPEC`` env var: another agent spec).

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/periphery/disarray/dodge_failures.py 0 29 31
"""

from __future__ import annotations

import math
import os
import sys

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent, match_vision
from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY

ENV_ID = "ObstacleDodge-v0"


def fmt(v) -> str:
    return "None" if v is None else f"{v:.2f}"


def diagnose(seed: int, spec: str) -> str:
    env = gym.make(ENV_ID)
    policy = make_agent(spec, ENV_ID, int(env.action_space.shape[0]), seed=seed)
    match_vision(policy, env.unwrapped.vision_params)
    agent = policy
    while hasattr(agent, "base"):
        agent = agent.base
    obs, _ = env.reset(seed=seed)
    u = env.unwrapped
    task = u.task
    last_fix: dict = {}
    log = []  # (t, pedestrian, slot, centre distance, veered, last chosen as gaze target, position std)
    done, i = False, 0
    while not done:
        action = policy.predict(obs)[0]
        t = i * u.dt
        if agent.target is not None and agent.target[0] == "ped":
            last_fix[agent.target[1]] = t
        obs, _, terminated, truncated, _ = env.step(action)
        done, i = terminated or truncated, i + 1
        x, y = float(u.data.qpos[0]), float(u.data.qpos[1])
        gaps = [(math.hypot(task.pos[j][0] - x, task.pos[j][1] - y), j) for j in range(len(task.pos)) if task.active[j]]
        if gaps:
            g, j = min(gaps)
            k = task.slot_of[j]
            f = agent.filters[k] if 0 <= k < len(agent.filters) and agent.filters[k].known else None
            std = None if f is None else math.sqrt(max(0.5 * (f.P[0, 0] + f.P[1, 1]), 0.0))
            log.append((t, j, k, g, task.veered[j], last_fix.get(k), std))
    env.close()
    if not task.collided:
        return f"seed {seed} ok"
    hit = next((r for r in log if r[3] < task.contact_distance), log[-1])
    before = [r for r in log if r[1] == hit[1] and r[0] <= hit[0] - 0.5]
    b = before[-1] if before else hit
    return (f"seed {seed} contact t {hit[0]:.2f} ped {hit[1]} veered {hit[4]} last gaze target {fmt(b[5])} "
            f"std@-0.5s {fmt(b[6])} centre distance@-0.5s {b[3]:.2f}")


def main() -> int:
    kw = gym.registry[ENV_ID].kwargs
    kw["crowd_distribution"] = "groups"
    kw["vision_params"] = {**HUMAN_PERIPHERY, "position_disarray": 0.8}
    spec = os.environ.get("SPEC", "fajen_warren")
    for seed in (int(a) for a in sys.argv[1:]):
        print(diagnose(seed, spec), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
