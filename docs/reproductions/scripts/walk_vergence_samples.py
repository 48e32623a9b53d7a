"""Per-sample consistency of iwao's obstacle memory on the winding walkway: for every sample fused into a
corner (``Corner.add``), its true error along the true line of sight (depth) and across it, against the std
the memory fused it with, binned by true distance. Design only (not the common evaluator).

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl .venv/bin/python docs/reproductions/scripts/walk_vergence_samples.py \\
        "static_gaze:az=-10,el=-40,neck_yaw=-10,neck_pitch=-40,fix=3:iwao" 0:20

Environment ``IWAO`` (JSON): fields laid over IwaoParams (probes only).
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rough_walk as rw

VISION = {**rw.CONE, **rw.ONE_EYE_METRIC}  # the one eye before the angular draw (its numbers were recorded so)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    rw._setup()
    import gymnasium as gym
    import numpy as np
    import visuomotor_gym.baselines.iwao.perception as pc

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.static_gaze import registered_kwargs
    from visuomotor_gym.tasks.obstacle_walk import WINDING_COURSE, top_points

    ag = importlib.import_module("visuomotor_gym.baselines.iwao.agent")
    if os.environ.get("IWAO"):
        over_i = json.loads(os.environ["IWAO"])
        init_i = ag.IwaoAgent.__init__

        def patched_i(self, params=None, *a, **k):
            init_i(self, dataclasses.replace(params or ag.IwaoParams(), **over_i), *a, **k)

        ag.IwaoAgent.__init__ = patched_i
    spec, seeds = argv[0], range(*map(int, argv[1].split(":")))
    ctx, rec = {}, []
    mem_add, corner_add = pc.ObstacleMemory.add, pc.Corner.add

    def m_add(self, index, which, p_eye, eye_pos, rot_rows, odo, *a, **k):
        ox, oy, yaw, pz = odo
        c, s = math.cos(yaw), math.sin(yaw)
        ctx["cur"] = (index, which, (ox + c * eye_pos[0] - s * eye_pos[1], oy + s * eye_pos[0] + c * eye_pos[1],
                                     pz + eye_pos[2]))
        return mem_add(self, index, which, p_eye, eye_pos, rot_rows, odo, *a, **k)

    def c_add(self, z, u, s_depth, s_lat):
        index, which, eye = ctx["cur"]
        task = ctx["task"]
        inv = ctx.setdefault("inv", {})
        if not inv:
            inv.update({v: k for k, v in task.labels.items()})
        i = inv.get(index)
        if i is None:
            inv.clear()
            inv.update({v: k for k, v in task.labels.items()})
            i = inv[index]
        row = task.course.obstacles[i, :5].tolist()
        t = np.array(top_points(*row, float(task.course.yaw[i]))[which])
        los = t - np.array(eye)
        d = float(np.linalg.norm(los))
        ut = los / d
        err = np.array(z) - t
        along = float(err @ ut)
        across = float(np.linalg.norm(err - along * ut))
        rec.append((ctx["seed"], d, along, across, s_depth, s_lat, self.n))
        return corner_add(self, z, u, s_depth, s_lat)

    pc.ObstacleMemory.add, pc.Corner.add = m_add, c_add
    with registered_kwargs("ObstacleWalk-v0", {"course_distribution": dataclasses.asdict(WINDING_COURSE),
                                               "vision_params": VISION}):
        env = gym.make("ObstacleWalk-v0")
        policy = make_agent(spec, "ObstacleWalk-v0", int(env.action_space.shape[0]), seed=seeds[0])
        for s in seeds:
            obs, _ = env.reset(seed=s)
            ctx["task"], ctx["seed"] = env.unwrapped.task, s
            ctx.pop("inv", None)
            if hasattr(policy, "reset"):
                policy.reset()
            done = False
            while not done:
                action, _ = policy.predict(obs)
                obs, _, terminated, truncated, _ = env.step(action)
                done = terminated or truncated
    r = np.array(rec, dtype=float)
    print(spec, argv[1], "samples", len(r))
    for lo, hi in ((0.5, 1.5), (1.5, 2.0), (2.0, 2.5), (2.5, 3.0), (3.0, 4.0), (4.0, 8.0)):
        e = r[(r[:, 1] >= lo) & (r[:, 1] < hi)]
        if not len(e):
            continue
        w = 1.0 / e[:, 4] ** 2
        zd, zl = e[:, 2] / e[:, 4], e[:, 3] / e[:, 5]
        print(f"  d {lo}-{hi} m: n {len(e):6d} | depth err sd {np.std(e[:, 2]):.3f} mean {np.mean(e[:, 2]):+.3f}"
              f" info-weighted mean {np.sum(w * e[:, 2]) / np.sum(w):+.3f} | believed s_depth med {np.median(e[:, 4]):.3f}"
              f" | err/s_depth rms {np.sqrt(np.mean(zd ** 2)):.2f} |z|>3 {np.mean(np.abs(zd) > 3):.3f}"
              f" | across err/s_lat rms {np.sqrt(np.mean(zl ** 2) / 2):.2f}")
    if len(argv) > 2:
        np.save(argv[2], r)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
