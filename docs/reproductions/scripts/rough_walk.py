"""The rough course of ObstacleWalk-v0 (prototype): a baseline, its held and static twins
under the human periphery, on the pinned seeds ``0..N-1``.

A condition is the rough course (``course_distribution="rough"``) plus a set of ``VisionParams`` fields
laid over the walk family's. Both are applied by overriding the registered id's kwargs **in this process**
(``gym.registry[env_id].kwargs``), so the env, every agent's ``for_env`` (it reads them) and the static posture search
(``python -m visuomotor_gym.static_gaze search --env-kwargs ...`` does the same) agree on them.

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl nice -n 10 .venv/bin/python docs/reproductions/scripts/rough_walk.py \\
        --episodes 40 --out docs/reproductions/data/terrain/obstacle_walk_rough.json

``--bench CONDITION --static-twin SPEC`` runs ``vmgym bench --gaze-gain`` (the common evaluator: the
baseline, its held twin and that static twin on the same seeds, the realism score) under the condition,
writing its results JSON to ``--out`` (the results record the id's name only: the condition is in this
script's summary, ``--table``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
ENV_ID = "ObstacleWalk-v0"
HUMAN_FIELD = {"field_shape": "human"}  # Spector 1990 (visuomotor_gym.vision.periphery)
POSITION_E2 = {"position_e2_deg": 0.7}  # Levi, Klein & Aitsebaomo 1985, as quoted (unconfirmed)
CROWDING = {"crowding": True}  # Bouma 1970, b = 0.5; Parkes et al. 2001
DEPTH = {"depth_pedestal_arcmin": 10.0}  # Blakemore 1970; the constant a modelling choice
DISARRAY = {"position_disarray": 0.8}  # Hess & Field 1993; the share a modelling choice (the lead's 0.8)
CONDITIONS = {
    "walkway, default vision": ({}, {}),
    "rough, default vision": ("rough", {}),
    "rough, human field": ("rough", dict(HUMAN_FIELD)),
    "rough, field + E2 + crowding": ("rough", {**HUMAN_FIELD, **POSITION_E2, **CROWDING}),
    "rough, all four": ("rough", {**HUMAN_FIELD, **POSITION_E2, **CROWDING, **DEPTH}),
    # human_periphery(position_disarray=0.8): the four mechanisms and the retinotopic disarray
    "rough, all four + disarray 0.8": ("rough", {**HUMAN_FIELD, **POSITION_E2, **CROWDING, **DEPTH, **DISARRAY}),
    # the denser rough course (preset "rough_dense": hazards every 0.45-0.8 m) under the same eye
    "rough dense, all four + disarray 0.8": ("rough_dense", {**HUMAN_FIELD, **POSITION_E2, **CROWDING, **DEPTH,
                                                             **DISARRAY}),
    # a variant: the rough course with flat patches only (no rocks), ROUGH_COURSE with kind_p = (0, 0, 1)
    "rough patches only, field + E2 + crowding": ("rough patches", {**HUMAN_FIELD, **POSITION_E2, **CROWDING}),
}


def _setup() -> None:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from gaze_gain_sweep import _use_checkout_baselines

    _use_checkout_baselines()
    import visuomotor_gym  # noqa: F401  (registers the ids)


def env_kwargs(course, vision: dict) -> dict:
    out = {}
    if course == "rough patches":
        import dataclasses

        from visuomotor_gym.tasks.obstacle_walk import ROUGH_COURSE

        course = dataclasses.asdict(dataclasses.replace(ROUGH_COURSE, kind_p=(0.0, 0.0, 1.0)))
    if course:
        out["course_distribution"] = course
    if vision:
        out["vision_params"] = dict(vision)
    return out


def play(spec: str, kwargs: dict, seeds: list[int]) -> tuple[list[int], dict]:
    """Play ``spec`` on ``seeds`` with the registered id's kwargs overridden by ``kwargs``."""
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.static_gaze import registered_kwargs

    with registered_kwargs(ENV_ID, kwargs):
        env = gym.make(ENV_ID)
        policy = make_agent(spec, ENV_ID, int(env.action_space.shape[0]), seed=seeds[0])
        ok, why = [], {}
        for s in seeds:
            trace = run_episode(env, policy, seed=s, env_id=ENV_ID, agent=spec)
            ok.append(int(bool(trace.success)))
            if not trace.success:
                flags = [k for k, v in trace.task.items() if v is True and k != "success"]
                key = flags[0] if flags else "other"
                why[key] = why.get(key, 0) + 1
        env.close()
    return ok, why


def walk_measures(spec: str, kwargs: dict, seeds: list[int]) -> dict:
    """Fixations per step (saccade onsets per 0.5 s step), the share of the resting rows whose gaze is
    within ``ON_OBSTACLE_M`` of a hazard, and the look-ahead from the eye (median over episodes, in m,
    steps and seconds at the nominal gait): the walking measures set beside Matthis, Yates & Hayhoe 2018."""
    import gymnasium as gym
    import numpy as np

    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.body.walker import GaitParams
    from visuomotor_gym.metrics import walk_realism as wr
    from visuomotor_gym.static_gaze import registered_kwargs

    g = GaitParams()
    rows = []
    with registered_kwargs(ENV_ID, kwargs):
        env = gym.make(ENV_ID)
        policy = make_agent(spec, ENV_ID, int(env.action_space.shape[0]), seed=seeds[0])
        for s in seeds:
            tr = run_episode(env, policy, seed=s, env_id=ENV_ID, agent=spec)
            rest = ~np.asarray(tr.in_saccade, bool)
            eye, gaze = np.asarray(tr.eye_pos), np.asarray(tr.gaze_dir)
            on = np.zeros(len(eye), bool)
            for ob in np.asarray(tr.obstacles, dtype=float).reshape(-1, 6):
                on |= wr._on(wr._gaze_hits(eye, gaze, ob[4]), ob, wr.ON_OBSTACLE_M)
            steps = len(eye) * float(tr.dt) / g.step_s
            rows.append((float(np.sum(np.asarray(tr.saccade_onset, bool))) / steps, float(on[rest].mean()),
                         wr.travel_fixation_distance(tr)))
        env.close()
    r = np.array(rows, dtype=float)
    ahead = float(np.nanmedian(r[:, 2]))
    return {"fixations_per_step": float(np.nanmean(r[:, 0])), "hazard_fixation_share": float(np.nanmean(r[:, 1])),
            "look_ahead_m": ahead, "look_ahead_steps": ahead / g.nominal_step_m,
            "look_ahead_s": ahead / (g.nominal_step_m / g.step_s)}


def main(argv=None) -> int:
    global ENV_ID
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--env", default="ObstacleWalk-v0", help="the rung (an ObstacleWalk id)")
    ap.add_argument("--conditions", default=None, help="semicolon-separated condition names")
    ap.add_argument("--agents", default="iwao,gaze_blind:iwao", help="comma-separated agent specs")
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    ap.add_argument("--bench", default=None, metavar="CONDITION", help="run vmgym bench --gaze-gain under it")
    ap.add_argument("--agent", default="iwao", help="with --bench: the agent")
    ap.add_argument("--static-twin", default=None, help="with --bench: the static twin's spec (its posture)")
    ap.add_argument("--measures", default=None, metavar="CONDITION",
                    help="print the walking measures (fixations per step, hazard share, look-ahead) of --agent")
    args = ap.parse_args(argv)
    ENV_ID = args.env
    _setup()
    if args.measures:
        course, vision = CONDITIONS[args.measures]
        seeds = list(range(args.seed, args.seed + args.episodes))
        print(json.dumps(walk_measures(args.agent, env_kwargs(course, vision), seeds)))
        return 0
    if args.bench:
        from visuomotor_gym.cli import main as vmgym
        from visuomotor_gym.static_gaze import registered_kwargs

        course, vision = CONDITIONS[args.bench]
        argv = ["bench", "--agent", args.agent, "--env", ENV_ID, "--episodes", str(args.episodes), "--seed",
                str(args.seed), "--out", args.out, "--gaze-gain", "--no-progress", "--force"]
        if args.static_twin:
            argv += ["--static-twin", args.static_twin]
        with registered_kwargs(ENV_ID, env_kwargs(course, vision)):
            return vmgym(argv)
    out = Path(args.out)
    record = json.loads(out.read_text()) if out.exists() else {"cells": []}
    record.update(description=__doc__.splitlines()[0])
    record.setdefault("commands", [])
    if " ".join(sys.argv) not in record["commands"]:
        record["commands"].append(" ".join(sys.argv))
    names = args.conditions.split(";") if args.conditions else list(CONDITIONS)
    seeds = list(range(args.seed, args.seed + args.episodes))
    for cond in names:
        course, vision = CONDITIONS[cond]
        for spec in args.agents.split(","):
            t0 = time.perf_counter()
            ok, why = play(spec, env_kwargs(course, vision), seeds)
            cell = {"env_id": ENV_ID, "condition": cond, "course": course or "walkway", "vision_params": vision, "agent": spec,
                    "episodes": len(seeds), "seed": args.seed, "success": sum(ok), "rate": sum(ok) / len(ok),
                    "failures": why, "per_seed": ok, "seconds": round(time.perf_counter() - t0, 1)}
            record["cells"] = [c for c in record["cells"]
                               if (c.get("env_id", ENV_ID), c["condition"], c["agent"]) != (ENV_ID, cond, spec)] + [cell]
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps(record, indent=1) + "\n")
            print(f"{ENV_ID:<26} {cond:<32} {spec:<40} {100 * cell['rate']:5.1f} %  {why}  {cell['seconds']} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
