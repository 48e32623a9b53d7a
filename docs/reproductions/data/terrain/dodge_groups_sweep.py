"""Pedestrians in groups on ObstacleDodge-v0 (opt-in ``CrowdDistribution.group_size``): fajen_warren, its
held twin (``gaze_blind:fajen_warren``) and its best static twin (``static_gaze:fajen_warren`` at a posture
searched under the same condition on the design seeds 100000+), with realism of the baseline.

A condition is a ``crowd_distribution`` and a set of ``VisionParams`` fields, laid over the registered
id's kwargs **in this process** (``gym.registry[env_id].kwargs``, as
docs/reproductions/scripts/periphery_sweep.py does), so the env and every agent's ``for_env`` agree.

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl nice -n 10 python docs/reproductions/data/terrain/dodge_groups_sweep.py \\
        --condition groups --episodes 40 --out docs/reproductions/data/terrain/dodge_groups.json

``--search`` first runs the static posture search (coarse step 30 deg, ``--coarse-episodes``) under the
condition and plays the chosen posture; ``--posture AZ,EL`` plays a given one instead. Every cell is
written to ``--out`` (merged by condition) as it finishes. ``--combine OUT PART.json ...`` merges the
per-condition records into one and prints the table.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[4]
ENV_ID = "ObstacleDodge-v0"
AGENT = "fajen_warren"
GROUPS = {"group_size": (2, 3)}  # pairs and triads (Moussaid et al. 2010, Fig. 1); spacing: the default
HUMAN = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True}  # periphery_sweep.py's (b)+(c)+(d)
HUMAN_ALL = {**HUMAN, "depth_pedestal_arcmin": 10.0}  # vision.foveation.HUMAN_PERIPHERY: all four
CONDITIONS = {
    "default": ({}, {}),
    "groups": (GROUPS, {}),
    "groups + field+E2+crowding": (GROUPS, HUMAN),
    "groups + human periphery": (GROUPS, HUMAN_ALL),
    # all four + the retinotopic positional disarray (vision.periphery.DisarrayField, Hess & Field 1993)
    "groups + human periphery + disarray 0.8": (GROUPS, {**HUMAN_ALL, "position_disarray": 0.8}),
    "groups + human periphery + disarray 0.5": (GROUPS, {**HUMAN_ALL, "position_disarray": 0.5}),
    "groups + human periphery + disarray 1.0": (GROUPS, {**HUMAN_ALL, "position_disarray": 1.0}),
}


def set_condition(name: str | None) -> None:
    import gymnasium as gym

    kwargs = gym.registry[ENV_ID].kwargs
    kwargs.pop("crowd_distribution", None)
    kwargs.pop("vision_params", None)
    if name is None:
        return
    crowd, vision = CONDITIONS[name]
    if crowd:
        kwargs["crowd_distribution"] = dict(crowd)
    if vision:
        kwargs["vision_params"] = dict(vision)


def play(spec: str, seeds: list[int]) -> tuple[list[int], dict, list]:
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent, match_vision
    from visuomotor_gym.bench.trace import run_episode

    env = gym.make(ENV_ID)
    policy = make_agent(spec, ENV_ID, int(env.action_space.shape[0]), seed=seeds[0])
    match_vision(policy, env.unwrapped.vision_params)
    ok, why, traces = [], {}, []
    for s in seeds:
        trace = run_episode(env, policy, seed=s, env_id=ENV_ID, agent=spec)
        traces.append(trace)
        ok.append(int(bool(trace.success)))
        if not trace.success:
            flags = [k for k, v in trace.task.items() if v is True and k != "success"]
            why[flags[0] if flags else "other"] = why.get(flags[0] if flags else "other", 0) + 1
    env.close()
    return ok, why, traces


def combine(parts: list[Path], out: Path) -> str:
    """Merge the per-condition records ``parts`` into ``out``; return the Markdown table (condition x
    baseline, held, static, gain = baseline - max(held, static), realism of the baseline)."""
    cells = [c for p in parts for c in json.loads(p.read_text())["cells"]]
    record = {"env_id": ENV_ID, "agent": AGENT, "command": " ".join(sys.argv), "conditions": {
        k: {"crowd_distribution": v[0], "vision_params": v[1]} for k, v in CONDITIONS.items()}, "cells": cells}
    out.write_text(json.dumps(record, indent=1) + "\n")
    by = {(c["condition"], c["role"]): c for c in cells}
    lines = ["| condition | fajen_warren | held twin | best static twin (posture) | gaze gain | realism |",
             "|---|---|---|---|---|---|"]
    for cond in CONDITIONS:
        b, h, s_ = (by.get((cond, r)) for r in ("baseline", "held", "static"))
        if b is None:
            continue
        pct = [f"{100 * c['rate']:.1f} % ({c['successes']}/{c['episodes']})" if c else "–" for c in (b, h, s_)]
        if s_:
            pct[2] += f" ({s_['spec'].split(':')[1]})"
        gain = f"**{100 * (b['rate'] - max(h['rate'], s_['rate'])):+.1f}**" if h and s_ else "–"
        lines.append(f"| {cond} | {pct[0]} | {pct[1]} | {pct[2]} | {gain} | {b.get('gaze_realism', float('nan')):.3f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    if argv is None and len(sys.argv) > 1 and sys.argv[1] == "--combine":
        print(combine([Path(p) for p in sys.argv[3:]], Path(sys.argv[2])), end="")
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--condition", required=True, choices=list(CONDITIONS))
    ap.add_argument("--roles", default="baseline,held,static")
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--search", action="store_true", help="search the static posture under the condition")
    ap.add_argument("--posture", default=None, help="az=..,el=..,neck_yaw=..,neck_pitch=.. (deg) of the static twin instead of a search")
    ap.add_argument("--coarse-step", type=float, default=30.0)
    ap.add_argument("--coarse-episodes", type=int, default=8)
    ap.add_argument("--final-episodes", type=int, default=16)
    ap.add_argument("--out", required=True)
    ap.add_argument("--crowd", default=None, help="JSON of CrowdDistribution fields laid over the condition's")
    ap.add_argument("--agent", default=AGENT, help="the baseline's agent spec (e.g. fajen_warren:notice_s=0.2)")
    ap.add_argument("--label", default=None, help="name of the condition in the record (default: --condition)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from gaze_gain_sweep import _use_checkout_baselines

    _use_checkout_baselines()
    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.metrics.dodge_realism import dodge_summary

    out = Path(args.out)
    record = json.loads(out.read_text()) if out.exists() else {"env_id": ENV_ID, "agent": AGENT, "cells": []}
    crowd, vision = CONDITIONS[args.condition]
    if args.crowd:
        crowd = {**crowd, **json.loads(args.crowd)}
        CONDITIONS[args.condition] = (crowd, vision)
    label = args.label or args.condition
    seeds = list(range(args.seed, args.seed + args.episodes))

    def save(cell: dict) -> None:
        record["cells"] = [c for c in record["cells"]
                           if (c["condition"], c["role"]) != (cell["condition"], cell["role"])] + [cell]
        out.write_text(json.dumps(record, indent=1) + "\n")

    set_condition(args.condition)
    for role in args.roles.split(","):
        t0 = time.time()
        if role == "static":
            if args.search:
                from visuomotor_gym.static_gaze import search

                rec = search(ENV_ID, AGENT, coarse_step=args.coarse_step, coarse_episodes=args.coarse_episodes,
                             final_episodes=args.final_episodes, refine_steps=(),
                             command=" ".join(sys.argv), log=lambda line: print(line, flush=True))
                spec, search_record = rec["chosen"]["spec"], rec
            else:
                spec, search_record = f"static_gaze:{args.posture}:{AGENT}", None
        else:
            spec, search_record = {"baseline": args.agent, "held": f"gaze_blind:{args.agent}"}[role], None
        ok, why, traces = play(spec, seeds)
        cell = {"condition": label, "crowd_distribution": crowd, "vision_params": vision, "role": role,
                "spec": spec, "seeds": [seeds[0], seeds[-1]], "successes": sum(ok), "episodes": len(ok),
                "rate": sum(ok) / len(ok), "per_seed": ok, "failures": why, "seconds": round(time.time() - t0, 1)}
        if role == "baseline" or role == "static":
            s = dodge_summary(traces)
            g = s["gaze_realism"]
            cell["gaze_realism"] = g["score"]
            cell["gaze_realism_components"] = {k: {kk: v.get(kk) for kk in ("measured", "score", "value")
                                                   if isinstance(v, dict) and kk in v}
                                               for k, v in g.get("components", {}).items()}
        if search_record is not None:
            cell["search"] = search_record
        save(cell)
        print(f"{label} {role} {spec}: {sum(ok)}/{len(ok)} {why} realism={cell.get('gaze_realism')} "
              f"({cell['seconds']} s)", flush=True)
    set_condition(None)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
