"""The human periphery, mechanism by mechanism, on every family (docs/reproductions/data/periphery/).

For each family's best baseline, its held twin (``gaze_blind:<agent>``) and its best static twin
(``static_gaze:<agent>``, the posture searched under the *default* vision, from
``visuomotor_gym/data/static_postures.json``), the success rate on the pinned seeds ``0..N-1`` under
each vision condition: (a) today's default; (b) + human field shape; (c) + position E2 law;
(d) + crowding; (e) + depth pedestal; (f) all four on. The gaze gain of each condition is
``success - max(held, static)`` (the definition of ``vmgym bench --gaze-gain``).

A condition is a set of ``VisionParams`` fields laid over the family's own (the walker families keep
Iwao's 20 deg cone unless the human field replaces it). It is applied by overriding the registered
id's ``vision_params`` kwarg **in this process** (``gym.registry[env_id].kwargs``), so the env and every
agent's ``for_env`` (which reads the registered kwargs, ``registration.env_vision_params``) agree on
the eye; the script also calls ``agents.match_vision`` on the agent, as ``vmgym bench`` does for
non-default ``vision_params``. The static posture search under a condition
(``--search ENV:AGENT``) goes through the same override and calls
``visuomotor_gym.static_gaze.search`` on the design seeds 100000+.

One command makes the table from scratch (2 shared cores, ``nice -n 10``; ~1 h, dodge most of it)::

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl nice -n 10 python docs/reproductions/scripts/periphery_sweep.py \\
        --episodes 40 --out docs/reproductions/data/periphery/families_sweep.json

``--families walk,stones`` limits it, ``--resume`` keeps the cells already in ``--out`` (written after
every cell), ``--table`` only prints the Markdown table of an existing JSON.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]

# family -> (env id, best baseline). The best baselines of the gaze-gain table (docs/gaze_gain.md).
FAMILIES = {
    "catch": ("EyeCatch-v0", "eyecatch"),
    "reach": ("ShelfReach-v0", "faraway"),
    "walk": ("ObstacleWalk-v0", "iwao"),
    "stones": ("SteppingStones-v0", "lookahead"),
    "dodge": ("ObstacleDodge-v0", "fajen_warren"),
}

# The constants of the conditions, and their sources (see visuomotor_gym/vision/periphery.py):
HUMAN_FIELD = {"field_shape": "human"}  # 60 up / 75 down / 100 to each side (Spector 1990, ch. 116)
# E2 of position (localisation, vernier, bisection) judgements: 0.7 deg, the middle of the 0.6-0.8 deg
# usually quoted after Levi, Klein & Aitsebaomo (1985); not confirmed in the paper here, so swept
# (0.35 / 1.4 deg, with --extra).
POSITION_E2 = {"position_e2_deg": 0.7}
CROWDING = {"crowding": True}  # Bouma's b = 0.5 (Bouma 1970), compulsory averaging (Parkes et al. 2001)
# Disparity pedestal at which the depth std doubles: 10 arcmin, modelling choice (stereo thresholds rise
# steeply with the pedestal, Blakemore 1970; McKee et al.); swept (60 arcmin and off, with --extra).
DEPTH = {"depth_pedestal_arcmin": 10.0}
CONDITIONS = {
    "a default": {},
    "b + human field": dict(HUMAN_FIELD),
    "c + position E2 0.7 deg": dict(POSITION_E2),
    "d + crowding b 0.5": dict(CROWDING),
    "e + depth pedestal 10 arcmin": dict(DEPTH),
    "f all on": {**HUMAN_FIELD, **POSITION_E2, **CROWDING, **DEPTH},
}
# The modelling choices' sweep (--extra): the all-on condition with the other value of each.
EXTRA = {
    "f' all on: E2 0.35 deg": {**HUMAN_FIELD, "position_e2_deg": 0.35, **CROWDING, **DEPTH},
    "f' all on: E2 1.4 deg": {**HUMAN_FIELD, "position_e2_deg": 1.4, **CROWDING, **DEPTH},
    "f' all on: depth 60 arcmin": {**HUMAN_FIELD, **POSITION_E2, **CROWDING, "depth_pedestal_arcmin": 60.0},
    "f' all on: no depth law": {**HUMAN_FIELD, **POSITION_E2, **CROWDING},
}
ROLES = ("baseline", "held", "static")
# SteppingStones-v0 was redefined after this sweep (the rough course and the human periphery are its default):
# its rows start from the first definition, pinned here (ALLSTEPS' course, the walk family's 20 deg cone and
# the static posture searched then), so the committed data stays reproducible.
FIRST_DEFINITION = {
    "SteppingStones-v0": {
        "kwargs": {"course_distribution": "allsteps"},
        "static": "static_gaze:az=0,el=-35,neck_yaw=0,neck_pitch=-15,fix=2:{}",
    },
}


def _wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, centre - half), min(1.0, centre + half))


def _setup() -> None:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from gaze_gain_sweep import _use_checkout_baselines

    _use_checkout_baselines()
    import visuomotor_gym  # noqa: F401  (registers the ids)


def set_vision(env_id: str, fields: dict) -> None:
    """Override the registered id's ``vision_params`` kwarg in this process (``{}``: the id's own vision;
    None: restore the registered kwargs). An id of :data:`FIRST_DEFINITION` starts from its first definition."""
    import gymnasium as gym

    kwargs = gym.registry[env_id].kwargs
    first = FIRST_DEFINITION.get(env_id)
    if first is not None and fields is not None:
        kwargs.update(first["kwargs"])
        fields = {**_cone_eye(), **fields}
    elif first is not None:
        for k in first["kwargs"]:
            kwargs.pop(k, None)
    if fields:
        kwargs["vision_params"] = dict(fields)
    else:
        kwargs.pop("vision_params", None)


def _cone_eye() -> dict:
    """The walk family's 20 deg cone with every periphery mechanism off (the first stones definition's eye)."""
    from visuomotor_gym.envs.walk import WALK_VISION
    from visuomotor_gym.vision.foveation import HUMAN_PERIPHERY

    return {k: getattr(WALK_VISION, k) for k in ("field_of_view_deg", *HUMAN_PERIPHERY)}


def agent_spec(role: str, agent: str, env_id: str = "") -> str:
    if role == "static" and env_id in FIRST_DEFINITION:
        return FIRST_DEFINITION[env_id]["static"].format(agent)
    return {"baseline": agent, "held": f"gaze_blind:{agent}", "static": f"static_gaze:{agent}"}[role]


def play(spec: str, env_id: str, fields: dict, seeds: list[int]) -> tuple[list[int], dict]:
    """Play ``spec`` on ``seeds`` under the vision ``fields``: per-seed success and failure counts."""
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent, match_vision
    from visuomotor_gym.bench.trace import run_episode

    set_vision(env_id, fields)
    try:
        env = gym.make(env_id)
        policy = make_agent(spec, env_id, int(env.action_space.shape[0]), seed=seeds[0])
        match_vision(policy, env.unwrapped.vision_params)
        ok, why = [], {}
        for s in seeds:
            trace = run_episode(env, policy, seed=s, env_id=env_id, agent=spec)
            ok.append(int(bool(trace.success)))
            if not trace.success:
                flags = [k for k, v in trace.task.items() if v is True and k != "success"]
                key = flags[0] if flags else "other"
                why[key] = why.get(key, 0) + 1
        env.close()
    finally:
        set_vision(env_id, None)
    return ok, why


def table(record: dict) -> str:
    """The Markdown table: one row per (family, condition)."""
    cells = {(c["family"], c["condition"], c["role"]): c for c in record["cells"]}
    lines = ["| family · baseline | condition | baseline | held twin | static twin | gaze gain |",
             "|---|---|---|---|---|---|"]
    names = list(CONDITIONS) + list(EXTRA)
    for fam, (env_id, agent) in FAMILIES.items():
        for cond in names:
            row = [cells.get((fam, cond, r)) for r in ROLES]
            if row[0] is None:
                continue
            pct = [f"{100 * c['rate']:.1f} %" if c else "–" for c in row]
            gain = "–"
            if all(row):
                gain = f"{100 * (row[0]['rate'] - max(row[1]['rate'], row[2]['rate'])):+.1f}"
            lines.append(f"| {env_id} · {agent} | {cond} | {pct[0]} | {pct[1]} | {pct[2]} | **{gain}** |")
    return "\n".join(lines) + "\n"


def search_posture(target: str, condition: str, out: Path, coarse_step: float, coarse_episodes: int,
                   final_episodes: int, refine_steps: tuple = (10.0,)) -> None:
    """The static posture search under ``condition`` for ``ENV:AGENT`` (design seeds)."""
    from visuomotor_gym.static_gaze import search

    env_id, agent = target.split(":", 1)
    fields = {**CONDITIONS, **EXTRA}[condition]
    set_vision(env_id, fields)
    try:
        record = search(env_id, agent, coarse_step=coarse_step, coarse_episodes=coarse_episodes,
                        final_episodes=final_episodes, refine_steps=refine_steps, command=" ".join(sys.argv),
                        log=lambda line: print(line, flush=True))
    finally:
        set_vision(env_id, {})
    record["vision_params"] = fields
    record["condition"] = condition
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {out}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--families", default=",".join(FAMILIES), help=f"comma-separated, of {list(FAMILIES)}")
    ap.add_argument("--conditions", default=None, help="comma-separated condition names (default: a-f)")
    ap.add_argument("--extra", action="store_true", help="also the modelling choices' sweep (all on, other values)")
    ap.add_argument("--roles", default=",".join(ROLES))
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=str(ROOT / "docs/reproductions/data/periphery/families_sweep.json"))
    ap.add_argument("--resume", action="store_true", help="keep the cells already in --out")
    ap.add_argument("--table", action="store_true", help="print the table of --out and exit")
    ap.add_argument("--search", default=None, metavar="ENV:AGENT",
                    help="search the static posture under --search-condition instead of sweeping")
    ap.add_argument("--search-condition", default="f all on")
    ap.add_argument("--coarse-step", type=float, default=30.0)
    ap.add_argument("--coarse-episodes", type=int, default=12)
    ap.add_argument("--final-episodes", type=int, default=20)
    ap.add_argument("--refine-steps", default="10", help="comma-separated refinement steps (deg)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.table:
        print(table(json.loads(out.read_text())), end="")
        return 0
    _setup()
    if args.search:
        search_posture(args.search, args.search_condition, out, args.coarse_step, args.coarse_episodes,
                       args.final_episodes, tuple(float(x) for x in args.refine_steps.split(",")))
        return 0
    families = args.families.split(",")
    for f in families:
        if f not in FAMILIES:
            raise SystemExit(f"--families: unknown family {f!r}; allowed: {', '.join(FAMILIES)}")
    conditions = dict(CONDITIONS, **(EXTRA if args.extra else {}))
    if args.conditions:
        names = args.conditions.split(",")
        bad = [n for n in names if n not in {**CONDITIONS, **EXTRA}]
        if bad:
            raise SystemExit(f"--conditions: unknown {bad}; allowed: {list(CONDITIONS) + list(EXTRA)}")
        conditions = {n: {**CONDITIONS, **EXTRA}[n] for n in names}
    roles = args.roles.split(",")
    record = {"description": __doc__.splitlines()[0], "episodes": args.episodes, "seed": args.seed,
              "command": " ".join(sys.argv), "conditions": {**CONDITIONS, **EXTRA}, "cells": []}
    if args.resume and out.exists():
        before = json.loads(out.read_text())
        record["cells"] = before["cells"]
        record.update({k: v for k, v in before.items() if k not in record})  # notes, superseded cells
    done = {(c["family"], c["condition"], c["role"]) for c in record["cells"]}
    seeds = list(range(args.seed, args.seed + args.episodes))
    for fam in families:
        env_id, agent = FAMILIES[fam]
        for cond, fields in conditions.items():
            for role in roles:
                if (fam, cond, role) in done:
                    continue
                spec = agent_spec(role, agent, env_id)
                t0 = time.time()
                ok, why = play(spec, env_id, fields, seeds)
                k, n = sum(ok), len(ok)
                cell = {"family": fam, "env_id": env_id, "condition": cond, "vision_params": fields, "role": role,
                        "agent": spec, "episodes": n, "success": k, "rate": k / n, "wilson95": list(_wilson(k, n)),
                        "failures": why, "seconds": round(time.time() - t0, 1), "per_seed": ok}
                record["cells"].append(cell)
                print(f"{env_id:18s} {cond:30s} {spec:26s} {100 * k / n:5.1f} %  {why}  ({cell['seconds']} s)",
                      flush=True)
                out.parent.mkdir(parents=True, exist_ok=True)
                out.write_text(json.dumps(record, indent=1) + "\n")
    print(table(record), end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
