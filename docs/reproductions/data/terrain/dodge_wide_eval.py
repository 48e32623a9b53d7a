"""Play agent specs on ObstacleDodge-v0 with constructor kwargs laid over the registered id's
(``static_gaze.registered_kwargs``, so the env and every agent's ``for_env`` agree), one spec after the
other, 1 worker, with the common evaluator (``bench.evaluate.evaluate``); writes per-seed outcomes and the gaze
realism (``metrics.dodge_realism.dodge_gaze_realism``, with its components' values).

    python docs/reproductions/data/terrain/dodge_wide_eval.py KWARGS_JSON FIRST_SEED EPISODES OUT.json SPEC...
"""

import json
import sys
import time
from pathlib import Path

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.metrics.dodge_realism import dodge_gaze_realism
from visuomotor_gym.static_gaze import registered_kwargs

ENV = "ObstacleDodge-v0"


def main() -> None:
    kwargs, seed, n, out = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    res = {}
    for spec in sys.argv[5:]:
        t = time.time()
        with registered_kwargs(ENV, kwargs):
            r = evaluate(spec, ENV, n, seed, workers=1)
        succ = [bool(tr.success) for tr in r.traces]
        realism = dodge_gaze_realism(r.traces)
        values = {k: round(v["value"], 3) for k, v in realism["components"].items()}
        res[spec] = {"success": sum(succ), "n": n, "realism": round(realism["score"], 3), "components": values,
                     "per_seed": succ, "s": round(time.time() - t)}
        print(f"{spec}: {sum(succ)}/{n} ({100 * sum(succ) / n:.1f} %) realism {realism['score']:.3f} {values} "
              f"{time.time() - t:.0f}s", flush=True)
        out.write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
