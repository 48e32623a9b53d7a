"""Play agent specs on ObstacleDodge-v0 (constructor kwargs laid over the registered id's, common evaluator,
1 worker) and print, per spec, the successes and how many of them stayed within 0.5-2 m of the start's line
(the largest lateral excursion of the pelvis); writes ``{spec: [[success, max_lateral_m], ...]}``.

    python dodge_lateral_eval.py KWARGS_JSON FIRST N OUT.json SPEC...
"""

import json
import sys

import numpy as np

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.static_gaze import registered_kwargs

ENV = "ObstacleDodge-v0"


def main() -> None:
    kwargs, seed, n, out = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    res = {}
    for spec in sys.argv[5:]:
        with registered_kwargs(ENV, kwargs):
            r = evaluate(spec, ENV, n, seed, workers=1)
        rows = []
        for tr in r.traces:
            p = np.asarray(tr.pelvis_pos)
            rows.append((bool(tr.success), float(np.max(np.abs(p[:, 1] - p[0, 1])))))
        res[spec] = rows
        s, m = np.array([a for a, _ in rows]), np.array([b for _, b in rows])
        print(spec, int(s.sum()), [(w, int((s & (m <= w)).sum())) for w in (0.5, 0.75, 1.0, 1.5, 2.0)], flush=True)
    with open(out, "w") as fh:
        json.dump(res, fh)


if __name__ == "__main__":
    main()
