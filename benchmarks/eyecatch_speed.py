"""How fast the Eyecatch heuristic thinks, and how long a 200-episode evaluation takes.

Both figures are reported as ratios to references measured in the same run (machines are noisy):

* policy latency p95 per 20 ms control step, as a fraction of the control period (real time
  needs < 1; the issue's target is p95 < 2 ms, i.e. < 0.1 of the period);
* the wall time of ``evaluate("eyecatch", "EyeCatch-v0", 200, ...)`` against the same evaluation
  with the ``zero`` agent (the environment's own cost), and against the 2-minute budget.

    python benchmarks/eyecatch_speed.py [--episodes 200] [--workers 2] [--json out.json]
"""

from __future__ import annotations

import argparse
import shlex
import sys

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.bench.provenance import provenance, report_benchmark


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="EyeCatch-v0")
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the result to this JSON file")
    args = parser.parse_args(argv)

    reference = evaluate("zero", args.env, args.episodes, args.seed, workers=args.workers, keep_traces=False)
    agent = evaluate("eyecatch", args.env, args.episodes, args.seed, workers=args.workers, keep_traces=False)
    period_ms = 1000.0 * agent.control_period_s
    lat = agent.summary["latency_ms"]
    result = {
        "benchmark": "eyecatch_speed",
        "env_id": args.env,
        "episodes": args.episodes,
        "workers": args.workers,
        "catch_rate": agent.summary["catch_rate"],
        "latency_ms": lat,
        "latency_p95_over_control_period": round(lat["p95"] / period_ms, 4),
        "latency_target_p95_ms": 2.0,
        "meets_latency_target": lat["p95"] < 2.0,
        "eval_wall_s": round(agent.wall_time_s, 2),
        "zero_agent_eval_wall_s": round(reference.wall_time_s, 2),
        "eval_wall_over_zero_agent": round(agent.wall_time_s / reference.wall_time_s, 3),
        "eval_wall_over_2_min_budget": round(agent.wall_time_s / 120.0, 4),
        "meets_wall_target": agent.wall_time_s < 120.0,
        "env_steps": agent.env_steps,
        "provenance": provenance(shlex.join(["python", *sys.argv])),
    }
    return report_benchmark(result, args.json)


if __name__ == "__main__":
    main()
