"""Upright counts of PushRecovery specs split by the wall's side (the ninth pass's measurements).

    python docs/reproductions/data/push/push_sides.py [--env ID] [--first SEED] OUT.json KWARGS_JSON SPEC [SPEC ...]

``KWARGS_JSON`` is laid over the registered id's constructor arguments for the env and every agent's
``for_env`` (``static_gaze.registered_kwargs``; ``'{}'`` for the registered env, e.g.
``'{"push_force_n": [330, 380]}'``). Seeds 0-199 (the pinned seeds; ``--first 100000``: the static
search's design seeds 100000-100199), the common evaluator's episode
runner, one process; ``--env`` plays a rung of the family (e.g. ``PushRecoveryOracle-v0``). Writes, per spec, the right-wall (-1) and left-wall (+1) counts and the failed seeds.
"""

import json
import sys
from pathlib import Path

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.bench.evaluate import run_chunk
from visuomotor_gym.static_gaze import registered_kwargs

ENV = "PushRecovery-v0"


def main() -> None:
    argv = sys.argv[1:]
    env_id, first = ENV, 0
    while argv[0] in ("--env", "--first"):
        if argv[0] == "--env":
            env_id = argv[1]
        else:
            first = int(argv[1])
        argv = argv[2:]
    seeds = list(range(first, first + 200))
    out, kwargs, specs = Path(argv[0]), json.loads(argv[1]), argv[2:]
    res = json.loads(out.read_text()) if out.exists() else {}
    with registered_kwargs(env_id, kwargs):
        env = gym.make(env_id)
        side = {}
        for s in seeds:
            env.reset(seed=s)
            side[s] = int(env.unwrapped.task.wall_side)
        for spec in specs:
            traces = []
            for i in range(0, len(seeds), 20):
                traces += run_chunk(spec, env_id, seeds[i:i + 20], env=env)
            ok = {s: bool(t.success) for s, t in zip(seeds, traces)}
            row = {"env": env_id, "first_seed": first, "kwargs": kwargs, "upright": sum(ok.values()), "n": len(seeds)}
            for sd, name in ((-1, "right"), (1, "left")):
                ss = [s for s in seeds if side[s] == sd]
                row[name] = {"upright": sum(ok[s] for s in ss), "n": len(ss), "failed": [s for s in ss if not ok[s]]}
            key = spec if env_id == ENV else f"{env_id} {spec}"
            key = key if first == 0 else f"{key} seeds {first}-{first + 199}"
            key = f"{key} {json.dumps(kwargs, sort_keys=True)}" if kwargs else key
            res[key] = row
            print(f"{key}: {row['upright']}/200 (right {row['right']['upright']}/{row['right']['n']}, "
                  f"left {row['left']['upright']}/{row['left']['n']})", flush=True)
            out.write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
