"""Why a still eye verged far reads the winding walkway better: at every footstep plan of an agent built on
iwao's memory, for each hazard whose near edge lies 0-1.5 m (along the centre line) beyond the last latched
foothold, the error of its box along the path (near/far edges), across it (left/right) and in height, and the
memory's own std for each (consistency: error / std). Design only (not the common evaluator).

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl .venv/bin/python docs/reproductions/scripts/walk_vergence_errors.py \\
        "static_gaze:az=-10,el=-40,neck_yaw=-10,neck_pitch=-40,fix=3:iwao" 0:20 [out.json]

Environment ``IWAO`` (JSON): fields laid over IwaoParams (probes only). Course: the winding walkway
(``WINDING_COURSE``); eye: the human periphery with the disarray 0.8.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rough_walk as rw

VISION = {**rw.CONE, **rw.ONE_EYE_METRIC}  # the one eye before the angular draw (its numbers were recorded so)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    rw._setup()
    import gymnasium as gym
    import numpy as np
    import visuomotor_gym.baselines.iwao.planner as pl

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.static_gaze import registered_kwargs
    from visuomotor_gym.tasks.obstacle_walk import WINDING_COURSE

    rw.patch_iwao_from_env()  # fields laid over IwaoParams from $IWAO (probes only)
    ag = importlib.import_module("visuomotor_gym.baselines.iwao.agent")
    init_c = ag.IwaoAgent.__init__

    def keep(self, *a, **k):
        init_c(self, *a, **k)
        ctx["agent"] = self

    ag.IwaoAgent.__init__ = keep
    course = dataclasses.asdict(WINDING_COURSE)
    spec, seeds = argv[0], range(*map(int, argv[1].split(":")))
    ctx, rec = {}, []
    plan = pl.FootstepPlanner.plan

    def recorded(self, footholds, obstacles):
        task, u_b = ctx["task"], footholds[-1][0]
        # the truth in the agent's own path coordinates (its centre line as shown; s from its first point):
        # the obstacle's centre (odometry frame = the task's frame from the start) projected on it
        proj = ctx["agent"].path.project
        est = {o.index: o for o in obstacles}
        for i, (wx, wy, d, w, h) in enumerate(task.course.obstacles[:, :5].tolist()):
            x, y, _ = proj(wx, wy)
            ahead = x - d / 2 - u_b
            if not 0.0 <= ahead <= 1.5:
                continue
            o = est.get(task.labels.get(i, -1))
            if o is None:
                rec.append((ctx["seed"], ahead, abs(y), h) + (np.nan,) * 7)
                continue
            ex = max(abs(o.x0 - (x - d / 2)), abs(o.x1 - (x + d / 2)))
            ey = max(abs(o.y0 - (y - w / 2)), abs(o.y1 - (y + w / 2)))
            ez = o.height - h
            rec.append((ctx["seed"], ahead, abs(y), h, ex, ey, ez, o.sx, o.sy, o.sz, o.x0 - (x - d / 2)))
        return plan(self, footholds, obstacles)

    pl.FootstepPlanner.plan = recorded
    t0 = time.time()
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": course, "vision_params": VISION}):
        env = gym.make("ObstacleWalk-v0")
        policy = make_agent(spec, "ObstacleWalk-v0", int(env.action_space.shape[0]), seed=seeds[0])
        wins = []
        for s in seeds:
            obs, _ = env.reset(seed=s)
            ctx["task"], ctx["seed"] = env.unwrapped.task, s
            if hasattr(policy, "reset"):
                policy.reset()
            done, info = False, {}
            while not done:
                action, _ = policy.predict(obs)
                obs, _, terminated, truncated, info = env.step(action)
                done = terminated or truncated
            wins.append(int(bool(info.get("is_success", False))))
    r = np.array(rec, dtype=float)
    print(f"{spec}  seeds {argv[1]}  success {sum(wins)}/{len(wins)} {''.join(map(str, wins))}  {time.time() - t0:.0f}s")
    for lo, hi in ((0.0, 0.5), (0.5, 1.0), (1.0, 1.5), (0.0, 1.5)):
        sub = r[(r[:, 1] >= lo) & (r[:, 1] < hi)]
        e = sub[~np.isnan(sub[:, 4])]
        if not len(e):
            continue
        line = f"  ahead {lo}-{hi}: n {len(sub):4d} unknown {1 - len(e) / len(sub):.2f}"
        for name, k in (("along", 4), ("across", 5), ("height", 6)):
            err, sd = np.abs(e[:, k]), e[:, k + 3]
            line += (f" | {name} err med {np.median(err):.3f} p90 {np.percentile(err, 90):.3f} sd med {np.median(sd):.3f}"
                     f" err>2sd {np.mean(err > 2 * sd):.2f}")
        line += f" | near-edge bias {np.mean(e[:, 10]):+.3f} height bias {np.mean(e[:, 6]):+.3f}"
        print(line)
    if len(argv) > 2:
        Path(argv[2]).write_text(json.dumps({"spec": spec, "seeds": argv[1], "wins": wins, "rec": r.tolist()}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
