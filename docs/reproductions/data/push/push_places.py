"""Upright counts of PushRecovery specs split by where the wall is (the tenth pass's measurements).

    python docs/reproductions/data/push/push_places.py [--env ID] [--first SEED] [--n N] [--front P] OUT.json KWARGS_JSON SPEC [SPEC ...]

As ``push_sides.py`` (the ninth pass's), with the wall's three places: ``right``, ``left`` and ``front`` (the
side's wall turned to the front, ``tasks.push_recovery.WALL_FRONT_P``). ``KWARGS_JSON`` is laid over the
registered id's constructor arguments for the env and every agent's ``for_env`` (``'{}'`` for the registered env).
Seeds FIRST..FIRST+N-1 (default 0-199, the pinned seeds; ``--first 100000``: the static search's design seeds),
the common evaluator's episode runner, one process; ``--env`` plays a rung of the family; ``--front P`` sets
``WALL_FRONT_P`` in this process (opt-in: 0 in the definition, so without it no wall stands in front). Writes, per
spec, the counts per place and the failed seeds.
"""

import json
import sys
from pathlib import Path

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.bench.evaluate import run_chunk
from visuomotor_gym.static_gaze import registered_kwargs
from visuomotor_gym.tasks import push_recovery as pr

ENV = "PushRecovery-v0"


def place(task) -> str:
    """Where the episode's wall is: right, left or front."""
    if getattr(task, "wall_front", False):
        return "front"
    return "left" if task.wall_side > 0 else "right"


def main() -> None:
    argv = sys.argv[1:]
    env_id, first, n = ENV, 0, 200
    front = None
    while argv[0] in ("--env", "--first", "--n", "--front"):
        if argv[0] == "--front":
            front = pr.WALL_FRONT_P = float(argv[1])
        elif argv[0] == "--env":
            env_id = argv[1]
        elif argv[0] == "--first":
            first = int(argv[1])
        else:
            n = int(argv[1])
        argv = argv[2:]
    seeds = list(range(first, first + n))
    out, kwargs, specs = Path(argv[0]), json.loads(argv[1]), argv[2:]
    res = json.loads(out.read_text()) if out.exists() else {}
    with registered_kwargs(env_id, kwargs):
        env = gym.make(env_id)
        where = {}
        for s in seeds:
            env.reset(seed=s)
            where[s] = place(env.unwrapped.task)
        for spec in specs:
            traces = []
            for i in range(0, len(seeds), 20):
                traces += run_chunk(spec, env_id, seeds[i:i + 20], env=env)
            ok = {s: bool(t.success) for s, t in zip(seeds, traces)}
            row = {"env": env_id, "first_seed": first, "kwargs": kwargs, "upright": sum(ok.values()), "n": len(seeds)}
            for name in ("right", "left", "front"):
                ss = [s for s in seeds if where[s] == name]
                row[name] = {"upright": sum(ok[s] for s in ss), "n": len(ss), "failed": [s for s in ss if not ok[s]]}
            key = spec if env_id == ENV else f"{env_id} {spec}"
            key = key if (first, n) == (0, 200) else f"{key} seeds {first}-{first + n - 1}"
            key = f"{key} {json.dumps(kwargs, sort_keys=True)}" if kwargs else key
            key = f"{key} front {front:g}" if front is not None else key
            row["wall_front_p"] = pr.WALL_FRONT_P
            res[key] = row
            print(f"{key}: {row['upright']}/{n} (" + ", ".join(
                f"{p} {row[p]['upright']}/{row[p]['n']}" for p in ("right", "left", "front")) + ")", flush=True)
            out.write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
