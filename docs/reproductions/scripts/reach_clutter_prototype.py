"""Prototype, not part of the package: ShelfReach with the other shelf targets occupied (clutter).

Superseded: the clutter is now part of ShelfReach-v0 (``ShelfReachEnv(shelf_clutter=29)``, the default, which
reproduces this prototype seed for seed). Kept as the record of the prototype's data; it lays its distractors
over the env's own, so rerun it only with ``shelf_clutter=0`` registered or on a checkout before that change.

``N`` distractor objects stand on ``N`` of the other 29 shelf targets (all of them with ``N = 29``), as
still points that the retina sees as targets of the object's kind, so crowding (Bouma 1970; compulsory
averaging, Parkes et al. 2001) pools them with the object in the periphery; the observation still
carries the object's sample only (the agent knows which object it reaches for, as a person told to
fetch "the red cup"). Which targets are occupied is drawn from a generator seeded by the episode's
generator after the scenario (target, jitter, gaze jitter), so a seed is one scene on every rung. Laid
over ``tasks.reach.ReachTask.reset_episode`` in this process only (a monkeypatch), then either the common
evaluator on pinned seeds or the static-posture search (``visuomotor_gym.static_gaze``)::

    python docs/reproductions/scripts/reach_clutter_prototype.py bench 29 200 0.0 \\
        "faraway;gaze_blind:faraway;static_gaze:az=-30,el=0,neck_yaw=-10,neck_pitch=0,fix=0.4:faraway" out.json
    python docs/reproductions/scripts/reach_clutter_prototype.py search 29 --out search.json [static_gaze args]
"""

from __future__ import annotations

import json
import sys

import numpy as np


def install(n_distractors: int) -> None:
    """Lay the clutter over ``ReachTask.reset_episode`` (this process)."""
    from visuomotor_gym.core.retina import PointTarget
    from visuomotor_gym.tasks import reach as R

    if not 0 <= n_distractors <= 29:
        raise SystemExit(f"N (distractors) must be 0..29, got {n_distractors}")
    orig = R.ReachTask.reset_episode

    def reset_episode(self, data, rng):
        orig(self, data, rng)
        if not hasattr(self, "_distractors"):
            self._distractors = [PointTarget(f"distractor{i}") for i in range(n_distractors)]
            self.targets = [self.object, *self._distractors]
        g = np.random.default_rng(int(rng.integers(2**31)))
        others = [i for i in range(len(self.positions)) if i != self.target_index]
        for p, k in zip(self._distractors, g.choice(others, n_distractors, replace=False)):
            p.place(*self.positions[k])

    R.ReachTask.reset_episode = reset_episode


def main(argv: list[str]) -> int:
    mode, n = argv[0], int(argv[1])
    install(n)
    from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY

    if mode == "search":
        from visuomotor_gym import static_gaze

        rest = argv[2:]
        kw = json.dumps({"vision_params": HUMAN_PERIPHERY})
        return static_gaze.main(["search", "--env", "ShelfReach-v0", "--agent", "faraway", "--env-kwargs", kw, *rest])
    episodes, disarray, specs, out = int(argv[2]), float(argv[3]), argv[4].split(";"), argv[5]
    from visuomotor_gym.bench.evaluate import evaluate
    from visuomotor_gym.static_gaze import registered_kwargs

    vision = {**HUMAN_PERIPHERY, "position_disarray": disarray}
    record = {"description": __doc__.splitlines()[0], "command": " ".join(sys.argv), "distractors": n,
              "vision_params": vision, "episodes": episodes, "seed": 0, "cells": []}
    for spec in specs:
        with registered_kwargs("ShelfReach-v0", {"vision_params": vision}):
            r = evaluate(spec, "ShelfReach-v0", episodes, 0, workers=1, keep_traces=True, progress=False)
        s = r.summary
        record["cells"].append({"agent": spec, "success_rate": s["success_rate"],
                                "success_rate_ci95": s["success_rate_ci95"],
                                "gaze_realism": s["gaze_realism"]["score"],
                                "per_seed": [int(bool(t.success)) for t in r.traces]})
        print(f"clutter {n} disarray {disarray} {spec}: {100 * s['success_rate']:.1f} % "
              f"realism {s['gaze_realism']['score']:.3f}", flush=True)
        with open(out, "w") as f:
            f.write(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
