"""The common evaluator under an opt-in vision (``human_periphery()`` by default), on pinned seeds.

``vmgym bench`` plays a registered id as registered; this runs its evaluator
(:func:`visuomotor_gym.bench.evaluate.evaluate`, the same per-episode code, realism included) with the id's
``vision_params`` laid over in this process (:func:`visuomotor_gym.static_gaze.registered_kwargs`), so the
env, every agent's ``for_env`` and the twins' wrappers see the same eye. One line and one JSON cell per agent
spec (success, Wilson 95 % interval, realism, per-seed outcomes)::

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/scripts/periphery_bench.py \\
        --env ShelfReach-v0 --episodes 200 --seed 0 \\
        --agents "faraway;gaze_blind:faraway;faraway:gaze_blind=true;static_gaze:az=-5,el=5,neck_yaw=-5,neck_pitch=5,fix=2:faraway" \\
        --out docs/reproductions/data/periphery/reach_human_periphery_200.json

``--vision '{"depth_pedestal_arcmin": null}'`` overrides fields of ``human_periphery()``; ``--resume`` keeps
the cells already in ``--out``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", required=True)
    ap.add_argument("--agents", required=True, help="agent specs separated by ';'")
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--vision", default="{}", help="JSON object of VisionParams fields over human_periphery()")
    ap.add_argument("--out", required=True)
    ap.add_argument("--resume", action="store_true")
    args = ap.parse_args(argv)

    from visuomotor_gym.bench.evaluate import evaluate
    from visuomotor_gym.static_gaze import parse_json_object, registered_kwargs
    from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY

    overrides = parse_json_object(args.vision, "--vision", "VisionParams fields")
    vision = {**HUMAN_PERIPHERY, **overrides}
    out = Path(args.out)
    record = {"description": __doc__.splitlines()[0], "command": " ".join(sys.argv), "env_id": args.env,
              "vision_params": vision, "episodes": args.episodes, "seed": args.seed, "cells": []}
    if args.resume and out.exists():
        record["cells"] = json.loads(out.read_text())["cells"]
    done = {c["agent"] for c in record["cells"]}
    for spec in args.agents.split(";"):
        if spec in done:
            continue
        t0 = time.time()
        with registered_kwargs(args.env, {"vision_params": dict(vision)}):
            result = evaluate(spec, args.env, args.episodes, args.seed, workers=1, keep_traces=True, progress=False)
        s = result.summary
        cell = {"agent": spec, "success_rate": s["success_rate"], "success_rate_ci95": s["success_rate_ci95"],
                "success": s["success"], "gaze_realism": s["gaze_realism"]["score"],
                "per_seed": [int(bool(t.success)) for t in result.traces],
                "seconds": round(time.time() - t0, 1)}
        record["cells"].append(cell)
        lo, hi = cell["success_rate_ci95"]
        print(f"{args.env} {spec}: {100 * cell['success_rate']:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}] "
              f"realism {cell['gaze_realism']}", flush=True)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
