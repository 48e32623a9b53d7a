"""What an ObstacleWalk agent built on iwao's memory knows when it plans: at every footstep read, for each
hazard whose near edge lies 0-1.5 m beyond the last latched foothold, the largest error of the four
edges of its estimate (m) and the estimate's std, binned by distance ahead and lateral offset. Design
only (not the common evaluator).

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl .venv/bin/python docs/reproductions/scripts/walk_plan_errors.py \\
        '{}' "static_gaze:az=0,el=-30,neck_yaw=0,neck_pitch=-50,fix=4:iwao" 0:12

Arguments: CourseDistribution fields over ROUGH_COURSE (JSON), an agent spec, seeds first:end, and
optionally ``x`` (near and far edges only: along the path) or ``y`` (left and right edges). The eye is
the human periphery with the disarray 0.8 (ObstacleWalk-v0's prepared definition).
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rough_walk as rw

VISION = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0,
          "position_disarray": 0.8}


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    rw._setup()
    import gymnasium as gym
    import numpy as np
    import visuomotor_gym.baselines.iwao.planner as pl

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.static_gaze import registered_kwargs
    from visuomotor_gym.tasks.obstacle_walk import ROUGH_COURSE

    course = dataclasses.asdict(dataclasses.replace(ROUGH_COURSE, **json.loads(argv[0])))
    spec, seeds = argv[1], range(*map(int, argv[2].split(":")))
    axis = argv[3] if len(argv) > 3 else "all"
    if axis not in ("all", "x", "y"):
        raise SystemExit(f"axis must be 'x', 'y' or omitted, got {axis!r}")
    ctx, rec = {}, []
    plan = pl.FootstepPlanner.plan

    def recorded(self, footholds, obstacles):
        task, u_b = ctx["task"], footholds[-1][0]
        est = {o.index: o for o in obstacles}
        for i, (x, y, d, w) in enumerate(task.course.obstacles[:, :4].tolist()):
            if not 0.0 <= x - d / 2 - u_b <= 1.5:
                continue
            o = est.get(task.labels.get(i, -1))
            if o is None:
                rec.append((x - d / 2 - u_b, abs(y), np.nan, np.nan))
                continue
            ex = max(abs(o.x0 - (x - d / 2)), abs(o.x1 - (x + d / 2)))
            ey = max(abs(o.y0 - (y - w / 2)), abs(o.y1 - (y + w / 2)))
            err = {"x": ex, "y": ey}.get(axis, max(ex, ey))
            rec.append((x - d / 2 - u_b, abs(y), err, max(o.sx, o.sy)))
        return plan(self, footholds, obstacles)

    pl.FootstepPlanner.plan = recorded
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": course, "vision_params": VISION}):
        env = gym.make("ObstacleWalk-v0")
        policy = make_agent(spec, "ObstacleWalk-v0", int(env.action_space.shape[0]), seed=seeds[0])
        for s in seeds:
            obs, _ = env.reset(seed=s)
            ctx["task"] = env.unwrapped.task
            if hasattr(policy, "reset"):
                policy.reset()
            done = False
            while not done:
                action, _ = policy.predict(obs)
                obs, _, terminated, truncated, _ = env.step(action)
                done = terminated or truncated
    r = np.array(rec)
    for lo, hi in ((0.0, 0.5), (0.5, 1.0), (1.0, 1.5)):
        for ylo, yhi in ((0.0, 0.2), (0.2, 0.6)):
            sub = r[(r[:, 0] >= lo) & (r[:, 0] < hi) & (r[:, 1] >= ylo) & (r[:, 1] < yhi)]
            e = sub[~np.isnan(sub[:, 2])]
            if not len(e):
                continue
            print(f"{spec[:12]:12} ahead {lo}-{hi} |y| {ylo}-{yhi}: n {len(sub):4d} unknown {1 - len(e) / len(sub):.2f} "
                  f"err med {np.median(e[:, 2]):.3f} p90 {np.percentile(e[:, 2], 90):.3f} sd med {np.median(e[:, 3]):.3f} "
                  f"err>2sd {np.mean(e[:, 2] > 2 * e[:, 3]):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
