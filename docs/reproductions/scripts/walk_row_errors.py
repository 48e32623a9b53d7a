"""Plan-time errors of the hazards ahead on ObstacleWalk's rows-with-gaps course (design probe, not the common
evaluator): at each footstep read, for every hazard whose estimated near edge lies 0-1.5 m beyond the last
foothold, the absolute error of its estimated *inner* lateral edge (the gap's side), its *outer* one (the
walkway's edge) and the larger of its near/far edge errors along the path; median and p90 in cm.

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl nice -n 10 .venv/bin/python docs/reproductions/scripts/walk_row_errors.py \\
        '{"layout": "rows"}' iwao 0:40

The course is given as fields over ``ROUGH_COURSE``; the eye is human_periphery(position_disarray=0.8).
"""
from __future__ import annotations

import dataclasses
import importlib
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rough_walk as rw

rw._setup()
rw.ENV_ID = "ObstacleWalk-v0"
ow = importlib.import_module("visuomotor_gym.tasks.obstacle_walk")
pl = importlib.import_module("visuomotor_gym.baselines.iwao.planner")
V = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0,
     "position_disarray": 0.8}
TRUTH: dict = {}  # the current episode's course (true state: scoring only)
ERRORS: dict[str, list[float]] = {"inner": [], "outer": [], "along": []}


def _reset_episode(orig):
    def wrapped(self, data, rng):
        orig(self, data, rng)
        TRUTH["course"] = self.course.obstacles.copy()
    return wrapped


def _plan(orig):
    def wrapped(self, footholds, obstacles):
        u_b = footholds[-1][0]
        for o in obstacles:
            if not (u_b < o.x0 < u_b + 1.5):
                continue
            t = TRUTH["course"][o.index]
            tx0, tx1 = t[0] - 0.5 * t[2], t[0] + 0.5 * t[2]
            ty0, ty1 = t[1] - 0.5 * t[3], t[1] + 0.5 * t[3]
            inner_is_y0 = abs(ty0) < abs(ty1)  # the gap's side lies nearer the centre line
            ERRORS["inner"].append(abs(o.y0 - ty0) if inner_is_y0 else abs(o.y1 - ty1))
            ERRORS["outer"].append(abs(o.y1 - ty1) if inner_is_y0 else abs(o.y0 - ty0))
            ERRORS["along"].append(max(abs(o.x0 - tx0), abs(o.x1 - tx1)))
        return orig(self, footholds, obstacles)
    return wrapped


def main(argv: list[str]) -> int:
    course_json, spec, seeds = argv
    ow.ObstacleWalkTask.reset_episode = _reset_episode(ow.ObstacleWalkTask.reset_episode)
    pl.FootstepPlanner.plan = _plan(pl.FootstepPlanner.plan)
    course = dataclasses.asdict(dataclasses.replace(ow.ROUGH_COURSE, **json.loads(course_json)))
    lo, hi = map(int, seeds.split(":"))
    ok, _ = rw.play(spec, {"course_distribution": course, "vision_params": V}, list(range(lo, hi)))
    for k, v in ERRORS.items():
        cm = np.array(v) * 100.0
        print(f"{spec[:12]:12} {k:6} n={len(cm)} median={np.median(cm):.1f} p90={np.percentile(cm, 90):.1f} cm")
    print(f"{spec}: {sum(ok)}/{len(ok)} crossed")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
