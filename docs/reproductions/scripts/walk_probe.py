"""Quick probes of ObstacleWalk-v0 course variants: agents on the pinned seeds with a course
given as fields laid over ``ROUGH_COURSE`` and a vision as ``VisionParams`` fields, one line per agent
(successes, failure kinds, per-seed outcomes). Not the common evaluator: for design only.

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl nice -n 10 .venv/bin/python docs/reproductions/scripts/walk_probe.py \\
        --course '{"rough_step_m": [0.45, 0.8]}' --seeds 0:40 \\
        --vision '{"field_shape": "human", "position_e2_deg": 0.7, "crowding": true, "depth_pedestal_arcmin": 10.0,
                   "position_disarray": 0.8}' \\
        --agents "iwao;static_gaze:az=-5,el=-30,neck_yaw=-5,neck_pitch=-10,fix=4:iwao"

``--env`` picks a rung (e.g. ObstacleWalkOracle-v0); ``PLANNER='{"lateral_margin_m": 0.06}'`` in the
environment lays fields over iwao's ``PlannerParams``.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rough_walk as rw

ALL_FOUR = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--course", default="{}", help="JSON: CourseDistribution fields over ROUGH_COURSE")
    ap.add_argument("--vision", default=json.dumps(ALL_FOUR), help="JSON: VisionParams fields")
    ap.add_argument("--agents", default="iwao", help="semicolon-separated agent specs")
    ap.add_argument("--seeds", default="0:40", help="first:end")
    ap.add_argument("--env", default="ObstacleWalk-v0")
    ap.add_argument("--tag", default="")
    a = ap.parse_args(argv)
    rw._setup()
    rw.ENV_ID = a.env
    from visuomotor_gym.tasks.obstacle_walk import ROUGH_COURSE

    if os.environ.get("PLANNER"):
        pl = importlib.import_module("visuomotor_gym.baselines.iwao.planner")
        over = json.loads(os.environ["PLANNER"])
        init = pl.FootstepPlanner.__init__

        def patched(self, gait=None, params=None):
            init(self, gait, params or pl.PlannerParams(**over))

        pl.FootstepPlanner.__init__ = patched
    course = dataclasses.asdict(dataclasses.replace(ROUGH_COURSE, **json.loads(a.course)))
    kwargs = {"course_distribution": course, "vision_params": json.loads(a.vision)}
    lo, hi = map(int, a.seeds.split(":"))
    for spec in a.agents.split(";"):
        t0 = time.time()
        ok, why = rw.play(spec, kwargs, list(range(lo, hi)))
        print(f"{a.tag:<20} {spec:<60} {sum(ok)}/{len(ok)} {why} {time.time() - t0:.0f}s {''.join(map(str, ok))}",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
