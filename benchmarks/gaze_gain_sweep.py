"""Gaze gain sweep: which definition of EyeCatch-v0 makes *where the eye looks* decide the catch?

For each candidate mechanism (a set of ``EyeCatchEnv`` keyword arguments on top of a ladder rung) the
script plays agents on the same pinned throws (episode ``i`` resets with seed ``seed + i``, as
``vmgym bench``) and records the catch rate with its 95 % Wilson interval. The *gaze gain* of an agent
is its rate minus the rate of its gaze-blind twin (``gaze_blind:<agent>``; ``fixed_gaze`` is
``gaze_blind:eyecatch``) on the same seeds.

Model-based agents are given the exact ``VisionParams`` of the env they play
(:func:`visuomotor_gym.agents.match_vision`): a brain adapted to its own eye.

    python benchmarks/gaze_gain_sweep.py --phase explore --episodes 60 --out outputs/gaze_sweep_explore.json
    python benchmarks/gaze_gain_sweep.py --phase final --episodes 200 --out docs/reproductions/data/gaze_default.json

Writes a JSON (configs, agents, per-seed outcomes, rates) and a CSV beside it. Runs in one process
(2 shared cores); the Eyecatch agent takes ~0.04 s per throw, belief_mpc ~0.35 s.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _use_checkout_baselines() -> None:
    """Import ``visuomotor_gym.baselines`` from this checkout's ``baselines/``.

    An editable install maps that subpackage to the *installed* checkout's folder, which may not be
    this one (a git worktree run with ``PYTHONPATH``); without this the agents would silently come from
    elsewhere.
    """
    import visuomotor_gym

    if "visuomotor_gym.baselines" in sys.modules or Path(visuomotor_gym.__file__).parents[1] != ROOT:
        return
    init = ROOT / "baselines" / "__init__.py"
    spec = importlib.util.spec_from_file_location("visuomotor_gym.baselines", init,
                                                  submodule_search_locations=[str(init.parent)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (centre - half, centre + half)


# --------------------------------------------------------------------------------------------------
# Candidate mechanisms. Each: name -> (ladder rung whose registered kwargs are the base, extra kwargs).
# ``vision_params`` entries are VisionParams fields; ``throw_distribution`` entries ThrowDistribution's.
# --------------------------------------------------------------------------------------------------
OLD = {"position_slip_knee_deg_s": math.inf}  # static 20/20 acuity at any retinal speed (the paper's model)


def slip(knee, **more):
    return {"vision_params": {"position_slip_knee_deg_s": knee, **more}}


EXPLORE = {
    # the first default: static acuity, E2 = 2 deg, +-60 deg field
    "static (old default)": ("EyeCatch-v0", {"vision_params": dict(OLD)}),
    # moving-target localisation: lateral std x max(1, slip / knee)
    "slip knee 1 deg/s": ("EyeCatch-v0", slip(1.0)),
    "slip knee 2.5 deg/s": ("EyeCatch-v0", slip(2.5)),
    "slip knee 5 deg/s": ("EyeCatch-v0", slip(5.0)),
    "slip knee 10 deg/s": ("EyeCatch-v0", slip(10.0)),
    # steeper eccentricity falloff (position acuity), static
    "E2 0.8 deg, static": ("EyeCatch-v0", {"vision_params": {**OLD, "fovea_e2_deg": 0.8}}),
    # narrower field
    "field 30 deg, static": ("EyeCatch-v0", {"vision_params": {**OLD, "field_of_view_deg": 30.0}}),
    # wider / faster throws
    "throws +-2 m lateral, static": ("EyeCatch-v0", {"vision_params": dict(OLD),
                                                     "throw_distribution": {"release_y_m": (-2.0, 2.0)}}),
    "throws 0.6-1.0 s, static": ("EyeCatch-v0", {"vision_params": dict(OLD),
                                                 "throw_distribution": {"flight_time_s": (0.6, 1.0)}}),
}


def ladder(extra_vision: dict, poor_knee_note: str = "") -> dict:
    """The ladder rungs with the same vision constants (FullView ignores foveation-dependent ones)."""
    vp = {"vision_params": dict(extra_vision)}
    return {
        "Oracle": ("EyeCatchOracle-v0", vp),
        "FullView": ("EyeCatchFullView-v0", vp),
        "foveated": ("EyeCatch-v0", vp),
        "Delayed": ("EyeCatchDelayed-v0", vp),
        "PoorVision": ("EyeCatchPoorVision-v0", vp),
    }


def env_kwargs(rung: str, extra: dict) -> dict:
    import gymnasium as gym

    kwargs = dict(gym.spec(rung).kwargs or {})
    if "vision_params" in extra and "vision_params" in kwargs:  # the rung's own fields, then the extra's
        extra = {**extra, "vision_params": {**kwargs["vision_params"], **extra["vision_params"]}}
    kwargs.update(extra)
    return kwargs


def play(agent_spec: str, rung: str, extra: dict, seeds: list[int]) -> list[bool]:
    import gymnasium as gym

    from visuomotor_gym.agents import make_agent, match_vision
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.registration import vision_params_for

    kwargs = env_kwargs(rung, extra)
    env = gym.make(rung, **kwargs)
    policy = make_agent(agent_spec, rung, int(env.action_space.shape[0]), seed=seeds[0])
    match_vision(policy, vision_params_for(kwargs))
    out = []
    for s in seeds:
        out.append(bool(run_episode(env, policy, seed=s, env_id=rung, agent=agent_spec).caught))
    env.close()
    return out


def run(configs: dict, agents: list[str], seeds: list[int], log=print) -> list[dict]:
    rows = []
    for name, (rung, extra) in configs.items():
        for agent in agents:
            if agent == "oracle" and rung != "EyeCatchOracle-v0":
                continue
            t0 = time.time()
            caught = play(agent, rung, extra, seeds)
            k, n = sum(caught), len(caught)
            lo, hi = wilson(k, n)
            row = {"config": name, "rung": rung, "kwargs": _jsonable(extra), "agent": agent, "episodes": n,
                   "caught": k, "rate": k / n, "wilson95": [lo, hi], "seconds": round(time.time() - t0, 1),
                   "per_seed": [int(c) for c in caught]}
            rows.append(row)
            log(f"{name:34s} {rung:24s} {agent:22s} {100 * k / n:5.1f} %  [{100 * lo:4.1f}, {100 * hi:4.1f}]"
                f"  ({row['seconds']} s)")
    return rows


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (tuple, list)):
        return [_jsonable(v) for v in x]
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return x


def phase_configs(phase: str) -> tuple[dict, list[str]]:
    import gymnasium as gym  # noqa: F401

    if phase == "explore":
        return EXPLORE, ["eyecatch", "fixed_gaze"]
    if phase == "knee":  # the headline-deciding constant, with every agent that matters
        cfg = {f"slip knee {k} deg/s": ("EyeCatch-v0", slip(k)) for k in (1.0, 2.5, 5.0, 10.0)}
        cfg["static (old default)"] = ("EyeCatch-v0", {"vision_params": dict(OLD)})
        return cfg, ["eyecatch", "fixed_gaze", "belief_mpc", "gaze_blind:belief_mpc"]
    if phase == "final":  # the new default (registered constants) and the paper conditions
        cfg = {f"new default: {k}": v for k, v in ladder({}).items()}
        cfg["paper normal (EyeCatchPaper-v0)"] = ("EyeCatchPaper-v0", {})
        cfg["paper x10 (EyeCatchPaperPoorVision-v0)"] = ("EyeCatchPaperPoorVision-v0", {})
        return cfg, ["oracle", "eyecatch", "fixed_gaze", "belief_mpc", "gaze_blind:belief_mpc",
                     "belief_intercept"]
    raise ValueError(phase)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--phase", default="explore", choices=["explore", "knee", "final"])
    ap.add_argument("--episodes", type=int, default=60)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--agents", default=None, help="comma-separated agent specs (default: the phase's)")
    ap.add_argument("--only", default=None, help="comma-separated config names to run")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    _use_checkout_baselines()
    import visuomotor_gym  # noqa: F401

    configs, agents = phase_configs(args.phase)
    if args.agents:
        agents = args.agents.split(",")
    if args.only:
        keep = set(args.only.split(","))
        configs = {k: v for k, v in configs.items() if k in keep}
    seeds = list(range(args.seed, args.seed + args.episodes))
    rows = run(configs, agents, seeds)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"phase": args.phase, "seed": args.seed, "episodes": args.episodes,
                               "rows": rows}, indent=1))
    with open(out.with_suffix(".csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "rung", "agent", "episodes", "caught", "rate", "wilson_lo", "wilson_hi"])
        for r in rows:
            w.writerow([r["config"], r["rung"], r["agent"], r["episodes"], r["caught"], f"{r['rate']:.4f}",
                        f"{r['wilson95'][0]:.4f}", f"{r['wilson95'][1]:.4f}"])
    print(f"wrote {out} and {out.with_suffix('.csv')}")


if __name__ == "__main__":
    main()
