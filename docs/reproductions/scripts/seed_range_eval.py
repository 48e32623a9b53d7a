"""Successes of agent specs on a range of seeds, with the common evaluator (one worker); e.g. static twins on the
static search's design seeds 100000-100199, disjoint from the pinned seeds.

    python docs/reproductions/scripts/seed_range_eval.py ENV FIRST N OUT.json SPEC [SPEC ...]

OUT.json (updated after each spec, kept specs stay) holds per spec the count and the per-seed outcomes.
"""

import json
import sys
import time
from pathlib import Path

from visuomotor_gym.bench.evaluate import evaluate


def main() -> None:
    env, first, n, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    res = json.loads(out.read_text()) if out.exists() else {}
    for spec in sys.argv[5:]:
        t = time.time()
        r = evaluate(spec, env, n, first, workers=1)
        succ = [bool(tr.success) for tr in r.traces]
        res[spec] = {"env": env, "first_seed": first, "n": n, "success": sum(succ), "per_seed": succ,
                     "s": round(time.time() - t)}
        print(f"{env} {spec}: {sum(succ)}/{n} {time.time() - t:.0f}s", flush=True)
        out.write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
