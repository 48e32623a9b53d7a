"""Replay an agent on ObstacleDodge-v0 seeds and, for each collision, print the struck pedestrian's last 1.6 s:
its position relative to the walker and bearing, whether the eye sampled it, the agent's estimate error (position,
velocity), the estimate's age and position std, and the agent's gaze target (``fajen_warren`` internals).

    python docs/reproductions/data/terrain/dodge_failures.py [--agent SPEC] SEED [SEED ...]
"""

import argparse
import math

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent

ENV = "ObstacleDodge-v0"


def replay(env, agent_spec: str, seed: int) -> None:
    agent = make_agent(agent_spec, ENV, action_dim=int(env.action_space.shape[0]), seed=seed)
    obs, info = env.reset(seed=seed)
    task = env.unwrapped.task
    sx, sy = task.body.start_xy
    hist, done = [], False
    while not done:
        action, _ = agent.predict(obs, deterministic=True)
        obs, _, term, trunc, info = env.step(action)
        done = term or trunc
        d = env.unwrapped.data
        t = float(d.time)
        row = {"t": t, "xy": (float(d.qpos[0]) - sx, float(d.qpos[1]) - sy), "target": agent.target, "peds": {}}
        for i in range(len(task.pos)):
            if not task.active[i]:
                continue
            k = task.slot_of[i]
            est = None
            if 0 <= k < len(agent.filters) and agent.filters[k].known:
                f = agent.filters[k]
                est = (*f.x.tolist(), t - f.t_seen, math.sqrt(max(0.5 * (f.P[0, 0] + f.P[1, 1]), 0.0)))
            row["peds"][i] = (task.pos[i, 0] - sx, task.pos[i, 1] - sy, float(task.vel[i, 0]), float(task.vel[i, 1]),
                              k, est, bool(task.seen[i]))
        hist.append(row)
    if not info["collided"]:
        print(f"seed {seed}: reached the goal" if info["finished"] else f"seed {seed}: timed out")
        return
    last = hist[-1]
    _, i = min((math.hypot(p[0] - last["xy"][0], p[1] - last["xy"][1]), i) for i, p in last["peds"].items())
    print(f"seed {seed}: collided at {last['t']:.2f} s with pedestrian {i} (slot {last['peds'][i][4]})")
    for row in hist[-80::8]:
        if i not in row["peds"]:
            continue
        px, py, vx, vy, _, est, seen = row["peds"][i]
        wx, wy = row["xy"]
        bearing = math.degrees(math.atan2(py - wy, px - wx))
        e = "not known" if est is None else (
            f"error {math.hypot(est[0] - px, est[1] - py):.2f} m, velocity error {math.hypot(est[2] - vx, est[3] - vy):.2f}"
            f" m/s, age {est[4]:.2f} s, std {est[5]:.2f} m")
        print(f"  t {row['t']:.2f}  relative ({px - wx:+.2f}, {py - wy:+.2f}) m, bearing {bearing:+.0f} deg, "
              f"sampled {int(seen)}, {e}, gaze target {row['target']}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--agent", default="fajen_warren")
    ap.add_argument("seeds", type=int, nargs="+")
    a = ap.parse_args()
    env = gym.make(ENV)
    for s in a.seeds:
        replay(env, a.agent, s)


if __name__ == "__main__":
    main()
