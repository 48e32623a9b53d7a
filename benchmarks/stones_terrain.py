"""SteppingStones terrain sweep: an agent, its held twin and static twins on a course preset
under the human periphery, with success, failure causes and the stones realism score.

Each condition is a set of ``SteppingStonesEnv`` keyword arguments (``course_distribution`` preset,
``vision_params`` fields over the walk family's); every agent plays the same seeds (episode ``i``
resets with ``seed + i``, as ``vmgym bench``) and is given the env's exact ``VisionParams``
(``agents.match_vision``: its stone memory weights samples, and flags crowded ones, with the eye's own
model). Agent specs are those of ``make_agent`` (``lookahead``, ``gaze_blind:lookahead``,
``static_gaze:az=0,el=-35,neck_yaw=0,neck_pitch=-15:lookahead``...).

    OPENBLAS_CORETYPE=Haswell nice -n 10 .venv/bin/python benchmarks/stones_terrain.py --episodes 40 \\
        --conditions "rough + all four" --agents lookahead,gaze_blind:lookahead \\
        --out docs/reproductions/data/terrain/stepping_stones_sweep.json

Writes a JSON (conditions, rows: agent, per-seed outcomes, rate with its 95 % Wilson interval, failure
causes, realism score and components, wall time). ``--resume`` keeps the rows of the file already there.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENV_ID = "SteppingStones-v0"
# The four mechanisms of visuomotor_gym.vision.periphery with the values of the periphery sweep
# (benchmarks/periphery_sweep.py: E2_pos 0.7 deg unconfirmed, Bouma b = 0.5, 10 arcmin pedestal, the
# human field of Spector 1990).
ALL_FOUR = {"field_shape": "human", "position_e2_deg": 0.7, "crowding": True, "depth_pedestal_arcmin": 10.0}
CONDITIONS = {
    "default": {},
    "default + all four": {"vision_params": ALL_FOUR},
    "default + human field + crowding": {"vision_params": {"field_shape": "human", "crowding": True}},
    "rough": {"course_distribution": "rough"},
    "rough + human field": {"course_distribution": "rough", "vision_params": {"field_shape": "human"}},
    "rough + human field + crowding": {"course_distribution": "rough",
                                       "vision_params": {"field_shape": "human", "crowding": True}},
    "rough + human field + crowding + position E2": {
        "course_distribution": "rough", "vision_params": {"field_shape": "human", "crowding": True, "position_e2_deg": 0.7}},
    "rough + human field + crowding + depth": {
        "course_distribution": "rough", "vision_params": {"field_shape": "human", "crowding": True,
                                                          "depth_pedestal_arcmin": 10.0}},
    "rough + all four": {"course_distribution": "rough", "vision_params": ALL_FOUR},
}
# The conditions name courses and eyes relative to the FIRST definition of SteppingStones-v0 ("default":
# ALLSTEPS' course and the walk family's 20 deg cone); since the moving-eye redefinition "rough + all four"
# is the id's default. Each condition spells out the course and the cone it starts from, so the names keep
# their meaning (and the committed data stays reproducible).
def _first_eye() -> dict:
    from visuomotor_gym.envs.walk import WALK_VISION
    from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY

    return {k: getattr(WALK_VISION, k) for k in ("field_of_view_deg", *HUMAN_PERIPHERY)}


FIRST_EYE = _first_eye()  # the walk family's 20 deg cone, every periphery mechanism off
CONDITIONS = {name: {"course_distribution": kw.get("course_distribution", "allsteps"),
                     "vision_params": {**FIRST_EYE, **kw.get("vision_params", {})}}
              for name, kw in CONDITIONS.items()}
# The observability ladder on the rough course with all four mechanisms: the other rungs' ids (their
# registered kwargs: oracle, full view, 0.1 s delay, noise x2) with the same env keyword arguments; the
# agent is built for the rung's id (its assumed delay) and given the env's VisionParams.
LADDER = {f"rough + all four @ {rung}": (f"SteppingStones{rung}-v0", CONDITIONS["rough + all four"])
          for rung in ("Oracle", "FullView", "Delayed", "PoorVision")}

# The conditions with a static-gaze search (python -m visuomotor_gym.static_gaze search ... --env-kwargs),
# its results in <folder>/stepping_stones_static_<slug>.json.
STATIC_SEARCHES = {"rough + all four": "rough_all_four", "rough + human field + crowding": "rough_field_crowding",
                   "default + all four": "default_all_four", "default + human field + crowding": "default_field_crowding"}


def play(agent: str, kwargs: dict, seeds: list[int], env_id: str = ENV_ID) -> tuple[list, dict]:
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent, match_vision
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.metrics.stones_realism import stones_gaze_realism

    env = gym.make(env_id, **kwargs)
    policy = make_agent(agent, env_id, int(env.action_space.shape[0]), seed=seeds[0])
    match_vision(policy, env.unwrapped.vision_params)
    traces = [run_episode(env, policy, seed=s, env_id=env_id, agent=agent) for s in seeds]
    env.close()
    return traces, stones_gaze_realism(traces)


def table(sweep: Path, folder: Path, agent: str = "lookahead") -> str:
    """Markdown: condition x (``agent``, held twin, best static twin, gain, realism) from the sweep JSON and,
    per condition of :data:`STATIC_SEARCHES`, the static-gaze search JSON in ``folder``
    (``stepping_stones_static_<slug>[_<agent>].json``; the lookahead's without the suffix) whose chosen
    posture was replayed in the sweep (its row's agent is the chosen spec)."""
    rows = json.loads(sweep.read_text())["rows"]
    by = {(r["condition"], r["agent"]): r for r in rows}
    suffix = "" if agent == "lookahead" else f"_{agent}"
    out = [f"| condition | {agent} | held twin | best static twin (posture; design seeds) | gain | "
           f"realism ({agent} / static) |", "|---|---|---|---|---|---|"]
    for name in CONDITIONS:
        base, held = by.get((name, agent)), by.get((name, f"gaze_blind:{agent}"))
        if base is None:
            continue
        static_text, static_rate, static_real, unsearched = "not searched", None, "-", 0.0
        other = [r for (c, a), r in by.items() if c == name and a.startswith("static_gaze:") and a.endswith(f":{agent}")]
        if other:  # a posture played but not searched under this condition (the default vision's)
            r = other[0]
            static_text = f"{100 * r['rate']:.1f} % (`{r['agent'].split(':')[1]}`, not searched here)"
            static_real = f"{r['realism']:.3f}"
            unsearched = r["rate"]
        path = folder / f"stepping_stones_static_{STATIC_SEARCHES.get(name, '-')}{suffix}.json"
        if name in STATIC_SEARCHES and path.exists():
            rec = json.loads(path.read_text())
            c = rec["chosen"]
            row = by.get((name, c["spec"]))
            static_real = "-"
            pinned = rec.get("pinned")
            if row is not None:
                static_rate, static_real = row["rate"], f"{row['realism']:.3f}"
            elif pinned is not None:
                static_rate = pinned["success"]
            posture = f"az {c['az']:g}, el {c['el']:g}, neck {c['neck_yaw']:g}/{c['neck_pitch']:g}"
            static_text = (f"{100 * static_rate:.1f} % ({posture}; {c['successes']}/{c['episodes']})"
                           if static_rate is not None else f"not replayed ({posture})")
        held_rate = held["rate"] if held else 0.0
        best_twin = max(held_rate, static_rate if static_rate is not None else 0.0)
        # without a search here: an upper bound (against the held twin and the posture played, if any)
        gain = f"{100 * (base['rate'] - best_twin):+.1f}" if static_rate is not None else \
            f"(<= {100 * (base['rate'] - max(best_twin, unsearched)):+.1f})"
        held_text = f"{100 * held_rate:.1f} %" if held else "-"
        out.append(f"| {name} | {100 * base['rate']:.1f} % | {held_text} | {static_text} | {gain} | "
                   f"{base['realism']:.3f} / {static_real} |")
    ladder = [(name, by[(name, agent)]) for name in LADDER if (name, agent) in by]
    if ladder:
        out += ["", f"| rung (rough + all four) | env id | {agent} | realism |", "|---|---|---|---|"]
        out += [f"| {name.split(' @ ')[-1]} | {r['env_id']} | {100 * r['rate']:.1f} % | {r['realism']:.3f} |"
                for name, r in ladder]
    return "\n".join(out) + "\n"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--agents", default="lookahead,gaze_blind:lookahead")
    ap.add_argument("--conditions", default="rough + all four", help="comma-separated condition names")
    ap.add_argument("--out", required=True)
    ap.add_argument("--resume", action="store_true")
    ap.add_argument("--table", action="store_true",
                    help="print the markdown table of --out and the static searches in its folder, play nothing")
    args = ap.parse_args(argv)
    if args.table:
        folder = Path(args.out).parent
        print("\n".join(table(Path(args.out), folder, agent) for agent in args.agents.split(",")), end="")
        return
    sys.path.insert(0, str(ROOT))
    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.metrics.stats import wilson_interval

    out = Path(args.out)
    rows = json.loads(out.read_text())["rows"] if args.resume and out.exists() else []
    seeds = list(range(args.seed, args.seed + args.episodes))
    for name in args.conditions.split(","):
        env_id, kwargs = LADDER[name] if name in LADDER else (ENV_ID, CONDITIONS[name])
        # agents: comma-separated, or semicolon-separated when a spec holds commas (static_gaze postures)
        for agent in args.agents.split(";") if ";" in args.agents or "static_gaze" in args.agents \
                else args.agents.split(","):
            t0 = time.time()
            traces, realism = play(agent, kwargs, seeds, env_id)
            ok = [bool(tr.success) for tr in traces]
            why = ["success" if tr.success else "fell" if tr.task.get("fell") else "other" for tr in traces]
            k, n = sum(ok), len(ok)
            lo, hi = wilson_interval(k, n)
            rows = [r for r in rows if not (r["condition"] == name and r["agent"] == agent and r["seed"] == args.seed)]
            rows.append({"condition": name, "env_id": env_id, "kwargs": kwargs, "agent": agent, "seed": args.seed, "episodes": n,
                         "success": k, "rate": k / n, "wilson95": [round(lo, 4), round(hi, 4)],
                         "outcomes": {r: why.count(r) for r in sorted(set(why))},
                         "realism": round(float(realism["score"]), 4),
                         "realism_components": {c: {kk: (round(v, 4) if isinstance(v, float) else v)
                                                    for kk, v in d.items()}
                                                for c, d in realism["components"].items()},
                         "seconds": round(time.time() - t0, 1), "per_seed": [int(o) for o in ok]})
            print(f"{name:32s} {agent:40s} {100 * k / n:5.1f} % [{100 * lo:4.1f}, {100 * hi:4.1f}] "
                  f"realism {realism['score']:.3f} {rows[-1]['outcomes']} ({rows[-1]['seconds']} s)", flush=True)
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps({"env": ENV_ID, "command": " ".join(sys.argv), "conditions": CONDITIONS,
                                       "rows": rows}, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
