"""ShelfReach-v0 (full shelves, the id's definition) under human_periphery(position_disarray=0.8), 200 pinned seeds.

faraway, its held twin and the searched static posture (static_postures.json), through the common evaluator with
the disarray laid over the registered id in this process::

    python docs/reproductions/scripts/reach_full_shelves_disarray.py out.json
"""

from __future__ import annotations

import json
import sys
from dataclasses import asdict

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.static_gaze import registered_kwargs
from visuomotor_gym.vision.foveation import human_periphery

SPECS = ("faraway", "gaze_blind:faraway", "static_gaze:az=-30,el=15,neck_yaw=-30,neck_pitch=15,fix=0.8:faraway")


def main(out: str) -> None:
    vision = asdict(human_periphery(position_disarray=0.8))
    rec = {"description": __doc__.splitlines()[0], "vision_params": vision, "episodes": 200, "seed": 0, "cells": []}
    for spec in SPECS:
        with registered_kwargs("ShelfReach-v0", {"vision_params": vision}):
            r = evaluate(spec, "ShelfReach-v0", 200, 0, workers=1, keep_traces=True, progress=False)
        s = r.summary
        rec["cells"].append({"agent": spec, "success_rate": s["success_rate"],
                             "success_rate_ci95": s["success_rate_ci95"], "gaze_realism": s["gaze_realism"]["score"],
                             "per_seed": [int(bool(t.success)) for t in r.traces]})
        print(spec, s["success_rate"], s["gaze_realism"]["score"], flush=True)
        with open(out, "w") as f:
            json.dump(rec, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1])
