"""fajen_warren on every rung of the dodge ladder (the registered ids, so the default crowd), seeds FIRST..FIRST+N-1,
common evaluator, 1 worker; writes per-seed outcomes.

    python docs/reproductions/data/terrain/dodge_wide_ladder.py FIRST N OUT.json
"""

import json
import sys
import time

from visuomotor_gym.bench.evaluate import evaluate

RUNGS = ("ObstacleDodgeOracle-v0", "ObstacleDodgeFullView-v0", "ObstacleDodge-v0", "ObstacleDodgeDelayed-v0",
         "ObstacleDodgePoorVision-v0")


def main() -> None:
    first, n, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    res = {}
    for env_id in RUNGS:
        t = time.time()
        succ = [bool(tr.success) for tr in evaluate("fajen_warren", env_id, n, first, workers=1).traces]
        res[env_id] = {"success": sum(succ), "n": n, "per_seed": succ}
        print(env_id, f"{sum(succ)}/{n}", f"{time.time() - t:.0f}s", flush=True)
        with open(out, "w") as f:
            json.dump(res, f, indent=1)


if __name__ == "__main__":
    main()
