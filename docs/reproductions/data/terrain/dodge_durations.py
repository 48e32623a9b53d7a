"""Time to the goal of ObstacleDodge-v0 episodes, per spec, on the 200 pinned seeds (the common evaluator's runner).

    python docs/reproductions/data/terrain/dodge_durations.py OUT.json SPEC [SPEC ...]

Writes, per spec, every seed's (reached the goal, episode time in s), and prints the median, 95th percentile and
maximum time of the successful walks. It was written to size a deadline against the dodge's dawdling loophole
(docs/baselines/rl.md, "Their best static twins").
"""

import json
import sys

import gymnasium as gym
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.bench.evaluate import run_chunk

ENV = "ObstacleDodge-v0"


def main() -> None:
    out, specs = sys.argv[1], sys.argv[2:]
    env = gym.make(ENV)
    res = {}
    for spec in specs:
        traces = []
        for i in range(0, 200, 20):
            traces += run_chunk(spec, ENV, list(range(i, i + 20)), env=env)
        rows = [(bool(t.success), float(t.t[-1])) for t in traces]
        res[spec] = rows
        ok = [d for s, d in rows if s]
        print(f"{spec}: {len(ok)}/200 reached the goal; time of those: median {np.median(ok):.1f} s, "
              f"95th percentile {np.percentile(ok, 95):.1f} s, max {max(ok):.1f} s", flush=True)
    with open(out, "w") as f:
        json.dump(res, f)


if __name__ == "__main__":
    main()
