"""Where does ``belief_mpc`` look on SteppingStones-v0, and what decides it? Gaze statistics per agent.

For each agent spec, plays ``--episodes`` pinned-seed courses through the evaluator's episode runner
(``visuomotor_gym.bench.trace.run_episode``) and reports

* success with its Wilson 95 % interval;
* the fixated stone (``metrics.stones_realism.fixated_stones``: the line of sight meets its top) in
  steps ahead of the stance foot (``next_stone - 1``, as the realism table), as a distribution and
  its median, and the share of steps with gaze on a stone at all;
* the fixation lead before landing (``metrics.stones_realism.fixation_lead``, median per episode,
  then over episodes), the number of fixations per stone landed on and their median duration;
* the same human numbers as ``visuomotor_gym.metrics.stones_realism.STONES_REFERENCE``.

    python benchmarks/belief_mpc_stones_gaze.py --episodes 30 \
        --agents belief_mpc lookahead belief_mpc:w_uct=0 belief_mpc:w_tsk=0 belief_mpc:q_m2_per_s=0
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

from visuomotor_gym.bench.provenance import provenance, report_benchmark  # noqa: E402


def _runs(mask: np.ndarray):
    """(start, end) index pairs of the True runs of ``mask``."""
    out, i, n = [], 0, len(mask)
    while i < n:
        if mask[i]:
            j = i
            while j < n and mask[j]:
                j += 1
            out.append((i, j))
            i = j
        else:
            i += 1
    return out


def gaze_stats(traces) -> dict:
    from visuomotor_gym.metrics.stones_realism import MIN_FIXATION_S, fixated_stones, fixation_lead

    ahead_all, on_share, leads, per_stone, durations = [], [], [], [], []
    for tr in traces:
        fix = fixated_stones(tr)
        n = np.asarray(tr.next_stone, dtype=float)
        ok = (fix >= 0) & (n >= 1)
        ahead_all.append((fix[ok] - (n[ok] - 1)).astype(int))
        on_share.append(float(np.mean(fix >= 0)))
        lead = fixation_lead(tr)
        if np.isfinite(lead):
            leads.append(lead)
        min_len = max(1, round(MIN_FIXATION_S / tr.dt))
        runs = []
        for s in np.unique(fix[fix >= 0]):
            runs += [(a, b) for a, b in _runs(fix == s) if b - a >= min_len]
        landed = int(n.max()) if len(n) else 0
        if landed:
            per_stone.append(len(runs) / landed)
        durations += [(b - a) * tr.dt for a, b in runs]
    ahead = np.concatenate(ahead_all) if ahead_all else np.zeros(0, int)
    dist = {int(k): round(float(np.mean(ahead == k)), 3) for k in range(5)} if ahead.size else {}
    return {
        "steps_ahead_median": float(np.median(ahead)) if ahead.size else float("nan"),
        "steps_ahead_mean": round(float(np.mean(ahead)), 3) if ahead.size else float("nan"),
        "steps_ahead_share": dist,
        "gaze_on_a_stone_share": round(float(np.mean(on_share)), 3),
        "fixation_lead_s_median_of_episode_medians": round(float(np.median(leads)), 3) if leads else float("nan"),
        "fixation_lead_s_mean_of_episode_medians": round(float(np.mean(leads)), 3) if leads else float("nan"),
        "fixations_per_stone": round(float(np.mean(per_stone)), 2) if per_stone else float("nan"),
        "fixation_duration_s_median": round(float(np.median(durations)), 3) if durations else float("nan"),
    }


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="SteppingStones-v0")
    parser.add_argument("--agents", nargs="+", default=["belief_mpc", "lookahead"])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the result to this JSON file")
    args = parser.parse_args(argv)

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.evaluate import make_env
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.metrics.stats import wilson_interval
    from visuomotor_gym.metrics.stones_realism import STONES_REFERENCE

    env = make_env(args.env)
    rows = {}
    for spec in args.agents:
        policy = make_agent(spec, args.env, int(env.action_space.shape[0]), seed=args.seed)
        traces = [run_episode(env, policy, seed=args.seed + i, env_id=args.env, agent=spec) for i in range(args.episodes)]
        k = sum(bool(t.success) for t in traces)
        lo, hi = wilson_interval(k, len(traces))
        lat = np.concatenate([np.asarray(t.latency_s[1:]) for t in traces]) * 1e3
        rows[spec] = {"success": f"{k}/{len(traces)}", "success_rate": k / len(traces),
                      "success_ci95": [round(lo, 4), round(hi, 4)],
                      "latency_ms_p50_p95": [round(float(np.percentile(lat, 50)), 3), round(float(np.percentile(lat, 95)), 3)],
                      **gaze_stats(traces)}
        print(spec, rows[spec], file=sys.stderr)
    result = {
        "benchmark": "belief_mpc_stones_gaze",
        "env_id": args.env,
        "episodes": args.episodes,
        "seeds": [args.seed, args.seed + args.episodes - 1],
        "agents": rows,
        "human": {k: {"value": v["value"], "range": [v["low"], v["high"]], "source": v["source"]}
                  for k, v in STONES_REFERENCE.items()},
        "provenance": provenance(shlex.join(["python", *sys.argv])),
    }
    return report_benchmark(result, args.json)


if __name__ == "__main__":
    main()
