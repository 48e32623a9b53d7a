"""Periphery sweep: what each opt-in mechanism of human peripheral vision
(``visuomotor_gym.vision.periphery``) does to an agent and its gaze-blind twin.

Each configuration is a set of ``VisionParams`` fields laid over the env's own (for ObstacleWalk-v0:
the 20 deg field of the walk family); every agent plays the same pinned courses (episode ``i`` resets
with seed ``seed + i``, as ``vmgym bench``) and the success rate is recorded with its 95 % Wilson
interval. The model-based agents are given the exact ``VisionParams`` of the eye they see with (their
noise model then includes the position law; their depth model does not know the vergence law, and no
agent knows about crowding).

    nice -n 10 python benchmarks/periphery_sweep.py --episodes 40 \\
        --out docs/reproductions/data/periphery/obstacle_walk_sweep.json
    nice -n 10 python benchmarks/periphery_sweep.py --env SteppingStones-v0 --episodes 40 \\
        --agents lookahead,gaze_blind:lookahead --out docs/reproductions/data/periphery/stepping_stones_sweep.json

Writes a JSON (configurations, agents, per-seed outcomes, rates, run time) and a CSV beside it.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from gaze_gain_sweep import _use_checkout_baselines, wilson  # noqa: E402 (after the sys.path line)

# name -> VisionParams fields over the env's defaults. Values: E2_pos 0.7 deg (middle of the 0.6-0.8 deg
# often quoted for position tasks, unconfirmed), Bouma b = 0.5, a 10-arcmin disparity pedestal doubling
# the depth std (modelling choice), the human field 60 up / 75 down / 100 to each side (Spector 1990).
CONFIGS = {
    "defaults (today)": {},
    "human field": {"field_shape": "human"},
    "position E2 0.7 deg": {"position_e2_deg": 0.7},
    "crowding b 0.5": {"crowding": True},
    "depth pedestal 10 arcmin": {"depth_pedestal_arcmin": 10.0},
    "depth pedestal 60 arcmin": {"depth_pedestal_arcmin": 60.0},
    "human field + position E2": {"field_shape": "human", "position_e2_deg": 0.7},
    "human field + crowding": {"field_shape": "human", "crowding": True},
    "human field + position E2 + crowding": {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True},
    "all four": {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0},
}
AGENTS = ("iwao", "gaze_blind:iwao")
FAILURE_FLAGS = ("tripped", "off_path", "misstepped", "fell")


def give_vision(policy, vision) -> None:
    """The agent (inside its gaze-blind wrapper) and its obstacle memory model the eye they see with."""
    from visuomotor_gym.agents import GazeBlind, match_vision

    match_vision(policy, vision)
    inner = policy
    while isinstance(inner, GazeBlind):
        inner = inner.base
    memory = getattr(inner, "memory", None)
    if memory is not None and hasattr(memory, "vision"):
        memory.vision = vision


def play(agent_spec: str, env_id: str, fields: dict, seeds: list[int]) -> tuple[list[bool], list[str]]:
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    env = gym.make(env_id, vision_params=dict(fields))
    policy = make_agent(agent_spec, env_id, int(env.action_space.shape[0]), seed=seeds[0])
    give_vision(policy, env.unwrapped.vision_params)
    ok, why = [], []
    for s in seeds:
        trace = run_episode(env, policy, seed=s, env_id=env_id, agent=agent_spec)
        ok.append(bool(trace.success))
        # the family's failure flags (walk: tripped, misstepped, off_path; stones: fell), else "other"
        flags = [k for k in FAILURE_FLAGS if bool(trace.task.get(k, False))]
        why.append("success" if trace.success else flags[0] if flags else "other")
    env.close()
    return ok, why


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default="ObstacleWalk-v0")
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--agents", default=",".join(AGENTS))
    ap.add_argument("--only", default=None, help="comma-separated configuration names")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    _use_checkout_baselines()
    import visuomotor_gym  # noqa: F401  (registers the ids)

    configs = CONFIGS if not args.only else {k: CONFIGS[k] for k in args.only.split(",")}
    seeds = list(range(args.seed, args.seed + args.episodes))
    rows = []
    for name, fields in configs.items():
        for agent in args.agents.split(","):
            t0 = time.time()
            ok, why = play(agent, args.env, fields, seeds)
            k, n = sum(ok), len(ok)
            lo, hi = wilson(k, n)
            rows.append({"config": name, "vision_params": fields, "agent": agent, "episodes": n, "success": k,
                         "rate": k / n, "wilson95": [lo, hi], "outcomes": {r: why.count(r) for r in sorted(set(why))},
                         "seconds": round(time.time() - t0, 1), "per_seed": [int(o) for o in ok]})
            print(f"{name:26s} {agent:18s} {100 * k / n:5.1f} %  [{100 * lo:4.1f}, {100 * hi:4.1f}]  "
                  f"{rows[-1]['outcomes']}  ({rows[-1]['seconds']} s)", flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"env": args.env, "seed": args.seed, "episodes": args.episodes,
                               "command": " ".join(sys.argv), "rows": rows}, indent=1))
    with open(out.with_suffix(".csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "agent", "episodes", "success", "rate", "wilson_lo", "wilson_hi"])
        for r in rows:
            w.writerow([r["config"], r["agent"], r["episodes"], r["success"], f"{r['rate']:.4f}",
                        f"{r['wilson95'][0]:.4f}", f"{r['wilson95'][1]:.4f}"])
    print(f"wrote {out} and {out.with_suffix('.csv')}")


if __name__ == "__main__":
    main()
