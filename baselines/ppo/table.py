"""The RL baseline table (docs/baselines/rl.md): one command per cell, then one to collect the cells.

    python -m visuomotor_gym.baselines.ppo.table --env SteppingStones-v0 --algo ppo --timesteps 100000 \\
        --seed 0 --out runs/table --policy-dir baselines/ppo/policies
    python -m visuomotor_gym.baselines.ppo.table --collect runs/table --doc docs/baselines/rl.md \\
        --images docs/baselines/images

A **cell** is one env id x one algorithm (``ppo``: SB3 PPO with an MLP; ``recurrentppo``: sb3-contrib
RecurrentPPO with an LSTM; ``sac``: SB3 SAC with an MLP, ``hyperparams.yml`` ``sac:``) x one training seed at
one budget of transitions. It

1. trains with ``baselines/ppo/train.py`` on **free gaze**: the env's own action vector (``--belief no
   --hand-action absolute --gaze-action free``: no belief features, no look gate, no intercept hand), with
   the id's hyperparameters and its named training-only shaping term (``hyperparams.yml``);
2. converts the final policy (not a best checkpoint) into the pickle-free ``ppo-npz`` file
   ``<algo>-free-<budget>__<env>.npz`` (proven equal to the trained model's actions);
3. evaluates that file with the common evaluator (:func:`visuomotor_gym.bench.evaluate.evaluate`) on the
   200 pinned seeds 0-199, the registered env and its own reward;
4. writes ``<out>/cells/<env>__<algo>__s<seed>__<budget>.json``: success with its 95 % Wilson interval,
   gaze realism, the family's foveation share, saccades per episode, transitions, training and
   evaluation wall time, the learning curve (EvalCallback), versions, the exact command, the
   resolved hyperparameters and the bench results object.

``--collect`` reads every cell JSON under the given folders and writes the Markdown table (cells not run
say so, with their command) between the ``<!-- rl-table -->`` markers of the doc, and the learning curves
(success against transitions and against wall time) into ``--images``.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
import math
import os
import platform
import shlex
import sys
import time
from pathlib import Path

# The table's rows: every family's foveated -v0 and its Oracle rung, in the order cells are
# filled (families whose envs are settled first).
FAMILY_ROWS = (
    ("stones", "SteppingStones-v0", "SteppingStonesOracle-v0"),
    ("reach", "ShelfReach-v0", "ShelfReachOracle-v0"),
    ("dodge", "ObstacleDodge-v0", "ObstacleDodgeOracle-v0"),
    ("catch", "EyeCatch-v0", "EyeCatchOracle-v0"),
    ("walk", "ObstacleWalk-v0", "ObstacleWalkOracle-v0"),
)
ALGOS = {"ppo": "PPO", "recurrentppo": "RecurrentPPO", "sac": "SAC"}
# Each family's share of steps with the eye on what the task is about (a component of its gaze-realism
# table, metrics.realism / the family's reference): the ball, the stones, the pedestrians, the shelf object,
# the obstacles.
FOVEATION_COMPONENT = {
    "catch": "ball_foveation",
    "stones": "stone_fixation_share",
    "dodge": "pedestrian_fixated_share",
    "reach": "object_fixation_share",
    "walk": "obstacle_fixation_share",
}
# Families whose default eye may still change in this round: their cells are marked "under the
# current definition" of the env. Empty since the catch and walk cells were retrained on the one eye and
# the winding walkway (a family whose default changes again goes back in here until its cells are rerun).
UNSETTLED: tuple[str, ...] = ()
EPISODES = 200  # the pinned seeds 0-199 of the common evaluator
EVAL_POINTS = 5  # learning-curve points per run (EvalCallback every budget / 5 transitions): modelling choice
MAX_CURVE_EPISODES = 20  # EvalCallback episodes per point, at most (modelling choice: walker episodes are long)
MARK_BEGIN, MARK_END = "<!-- rl-table:begin -->", "<!-- rl-table:end -->"


class TableArgumentError(ValueError):
    """A refused argument (one line)."""


def family_of(env_id: str) -> str:
    for family, foveated, oracle in FAMILY_ROWS:
        if env_id in (foveated, oracle):
            return family
    known = [i for _, f, o in FAMILY_ROWS for i in (f, o)]
    raise TableArgumentError(f"--env must be one of the table's ids {known}, got {env_id!r}")


def budget_tag(timesteps: int) -> str:
    """``100000`` -> ``"100k"``, ``2000000`` -> ``"2M"``, else the number."""
    if timesteps % 1_000_000 == 0:
        return f"{timesteps // 1_000_000}M"
    if timesteps % 1000 == 0:
        return f"{timesteps // 1000}k"
    return str(timesteps)


def cell_name(env_id: str, algo: str, seed: int, timesteps: int) -> str:
    return f"{env_id}__{algo}__s{seed}__{budget_tag(timesteps)}"


def policy_name(env_id: str, algo: str, timesteps: int) -> str:
    return f"{algo}-free-{budget_tag(timesteps)}__{env_id}.npz"


def cell_command(env_id: str, algo: str, timesteps: int, seed: int, out: str = "runs/table",
                 policy_dir: str = "baselines/ppo/policies", overrides=(), episodes: int = 200) -> str:
    argv = ["python", "-m", "visuomotor_gym.baselines.ppo.table", "--env", env_id, "--algo", algo,
            "--timesteps", str(timesteps), "--seed", str(seed), "--out", out]
    if episodes != EPISODES:
        argv += ["--episodes", str(episodes)]
    if policy_dir:
        argv += ["--policy-dir", policy_dir]
    if overrides:
        argv += ["--set", *overrides]
    return shlex.join(argv)


def versions() -> dict:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("visuomotor_gym", "stable_baselines3", "sb3_contrib", "torch", "gymnasium", "mujoco", "numpy"):
        try:
            out[name] = version(name.replace("_", "-"))
        except PackageNotFoundError:
            out[name] = None
    return out


def saccades_per_episode(traces) -> float:
    """Mean saccade onsets per episode (rows after reset)."""
    import numpy as np

    return float(np.mean([np.asarray(t.saccade_onset[1:], dtype=bool).sum() for t in traces]))


def learning_curve(run_dir: Path) -> list[dict]:
    """The EvalCallback's points: transitions, wall seconds before the evaluation (training time, earlier
    evaluations included), success rate and mean return on its held-out episodes (seeds 10 000 + seed,
    never the evaluator's 0-199)."""
    import numpy as np

    path = run_dir / "eval" / "evaluations.npz"
    if not path.is_file():
        return []
    z = np.load(path, allow_pickle=False)
    wall_path = run_dir / "eval" / "wall_time.json"
    wall = {w["timesteps"]: w["wall_s"] for w in json.loads(wall_path.read_text())} if wall_path.is_file() else {}
    train_rows = []  # (transitions, shaped training return) from SB3's progress.csv (Monitor: raw rewards)
    progress = run_dir / "progress.csv"
    if progress.is_file():
        import csv

        with progress.open() as fh:
            for rec in csv.DictReader(fh):
                with contextlib.suppress(KeyError, ValueError, TypeError):
                    train_rows.append((int(float(rec["time/total_timesteps"])), float(rec["rollout/ep_rew_mean"])))
    rows = []
    for i, steps in enumerate(z["timesteps"]):
        row = {"timesteps": int(steps), "wall_s": wall.get(int(steps)),
               "mean_return": float(np.mean(z["results"][i])), "mean_length": float(np.mean(z["ep_lengths"][i]))}
        if "successes" in z.files and len(z["successes"]) > i:
            row["success_rate"] = float(np.mean(z["successes"][i]))
        before = [r for t, r in train_rows if t <= int(steps)]
        if before:  # the training episodes' shaped return (stochastic policy), last logged at this point
            row["train_shaped_return"] = before[-1]
        rows.append(row)
    return rows


def parse_args(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--env", help="a table id (every family's -v0 and its Oracle rung)")
    p.add_argument("--algo", choices=sorted(ALGOS), default="ppo")
    p.add_argument("--timesteps", type=int, default=100_000, help="the budget of transitions (the same for all cells)")
    p.add_argument("--seed", type=int, default=0, help="training seed (evaluation is always seeds 0-199)")
    p.add_argument("--out", default="runs/table", help="cells go to <out>/cells, training runs to <out>/train")
    p.add_argument("--policy-dir", default="", help="also copy the pickle-free policy here (default: <out>/policies only)")
    p.add_argument("--workers", type=int, default=1, help="evaluator processes")
    p.add_argument("--episodes", type=int, default=EPISODES,
                   help=f"pinned seeds 0..N-1 (the table's cells use {EPISODES}; fewer only for smoke tests, and "
                        f"--collect leaves such cells out)")
    p.add_argument("--set", nargs="*", default=[], help="hyperparameter overrides (train.py --set), recorded in the cell")
    p.add_argument("--collect", nargs="*", metavar="DIR", help="collect the cells under these folders instead")
    p.add_argument("--twin", nargs="*", metavar="CELL",
                   help="add the held (gaze-blind) twin of these cell JSONs' policies, on the same seeds, to them")
    p.add_argument("--doc", default="docs/baselines/rl.md", help="--collect: the page whose table is replaced")
    p.add_argument("--images", default="docs/baselines/images", help="--collect: where the curves go")
    p.add_argument("--budget", type=int, default=100_000, help="--collect: the budget of the table's cells")
    p.add_argument("--data", default="", help="--collect: also copy the table's cell JSONs into this folder")
    args = p.parse_args(argv)
    if args.twin is not None:
        if not args.twin:
            raise TableArgumentError("--twin needs at least one cell JSON")
        return args
    if args.collect is None:
        if not args.env:
            raise TableArgumentError("--env is required (or --collect DIR ...)")
        family_of(args.env)
        if not 1 <= args.timesteps <= 10**9:
            raise TableArgumentError(f"--timesteps must be in [1, 1e9], got {args.timesteps}")
        if not 0 <= args.seed < 2**31:
            raise TableArgumentError(f"--seed must be in [0, 2**31), got {args.seed}")
        if not 1 <= args.episodes <= 10_000:
            raise TableArgumentError(f"--episodes must be in [1, 10000], got {args.episodes}")
        if not 1 <= args.workers <= 64:
            raise TableArgumentError(f"--workers must be in [1, 64], got {args.workers}")
    elif not args.collect:
        raise TableArgumentError("--collect needs at least one folder of cells")
    return args


def run_cell(args: argparse.Namespace, argv: list[str]) -> Path:
    """Train, convert, evaluate, write the cell's JSON; returns its path."""
    import numpy as np
    from visuomotor_gym.baselines.ppo import train
    from visuomotor_gym.baselines.ppo.agent import pack_npz

    from visuomotor_gym.bench.evaluate import evaluate
    from visuomotor_gym.bench.results import build_results

    out = Path(args.out)
    name = cell_name(args.env, args.algo, args.seed, args.timesteps)
    cell_path = out / "cells" / f"{name}.json"
    if cell_path.exists():
        raise TableArgumentError(f"{cell_path} exists: cells are never overwritten (remove it to run again)")
    family = family_of(args.env)
    algo_flag = {"recurrentppo": ["--recurrent"], "sac": ["--sac"]}.get(args.algo, [])
    config = train.load_config(train.parse_args(["--env", args.env, *algo_flag, "--set", *args.set] if args.set else
                                                ["--env", args.env, *algo_flag]))
    eval_freq = max(1, args.timesteps // EVAL_POINTS)
    eval_episodes = min(int(config["eval_episodes"]), MAX_CURVE_EPISODES)
    train_argv = ["--env", args.env, "--timesteps", str(args.timesteps), "--seed", str(args.seed),
                  "--out", str(out / "train"), "--run-name", name, "--no-progress-bar",
                  "--belief", "no", "--hand-action", "absolute", "--gaze-action", "free",
                  "--set", f"eval_freq={eval_freq}", f"eval_episodes={eval_episodes}",
                  f"checkpoint_freq={max(args.timesteps, 1)}", *args.set]
    train_argv += algo_flag
    t0 = time.time()
    run_dir = train.main(train_argv)
    train_wall = time.time() - t0
    meta = json.loads((run_dir / "ppo_meta.json").read_text())
    resolved = __import__("yaml").safe_load((run_dir / "config.yml").read_text())

    data = pack_npz(run_dir)
    policy_dir = out / "policies"
    policy_dir.mkdir(parents=True, exist_ok=True)
    policy = policy_dir / policy_name(args.env, args.algo, args.timesteps)
    policy.write_bytes(data)
    committed = None
    if args.policy_dir:
        Path(args.policy_dir).mkdir(parents=True, exist_ok=True)
        committed = Path(args.policy_dir) / policy.name
        committed.write_bytes(data)

    spec_path = committed if committed is not None else policy
    agent = f"ppo:{spec_path}"
    command = cell_command(args.env, args.algo, args.timesteps, args.seed, args.out, args.policy_dir, args.set, args.episodes)
    t1 = time.time()
    result = evaluate(agent, args.env, args.episodes, 0, workers=args.workers)
    eval_wall = time.time() - t1
    results = build_results(result, command)
    s = result.summary
    components = s["gaze_realism"]["components"]
    fov_name = FOVEATION_COMPONENT[family]
    fov = components.get(fov_name, {}).get("value")
    curve = learning_curve(run_dir)
    cell = {
        "cell": name,
        "env_id": args.env,
        "family": family,
        "rung": "oracle" if "Oracle" in args.env else "foveated",
        "algo": ALGOS[args.algo],
        "policy_class": "MlpLstmPolicy" if args.algo == "recurrentppo" else "MlpPolicy",
        "gaze": "free (the env's own actions: no belief features, no look gate, absolute hand)",
        "seed": args.seed,
        "budget_transitions": args.timesteps,
        "transitions": int(meta["timesteps"]),
        "train_wall_s": round(train_wall, 1),
        "eval_wall_s": round(eval_wall, 1),
        "episodes": args.episodes,
        "seeds": [0, args.episodes - 1],
        "success": int(s["success"]),
        "success_rate": float(s["success_rate"]),
        "success_rate_ci95": [float(x) for x in s["success_rate_ci95"]],
        "gaze_realism": float(s["gaze_realism"]["score"]),
        "foveation": {"component": fov_name, "value": None if fov is None or not math.isfinite(fov) else float(fov)},
        "saccades_per_episode": saccades_per_episode(result.traces),
        "mean_episode_steps": float(np.mean([t.steps for t in result.traces])),
        "gaze_components": {k: v.get("value") for k, v in components.items()},
        "shaping": {"env_kwargs": resolved.get("env_kwargs", {}),
                    "intercept_shaping": resolved.get("intercept_shaping", 0.0)},
        "hyperparameters": resolved,
        "learning_curve": curve,
        "policy": {"file": str(spec_path), "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest(),
                   "format": "ppo-npz"},
        "under_current_definition": family in UNSETTLED,
        "command": command,
        "run_dir": str(run_dir),
        "train_command": shlex.join(["python", *shlex.split((run_dir / "command.txt").read_text())[1:]]),
        "argv": argv,
        "versions": versions(),
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count(),
                    "loadavg_at_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
                    "omp_num_threads": os.environ.get("OMP_NUM_THREADS")},
        "results": results,
    }
    cell_path.parent.mkdir(parents=True, exist_ok=True)
    cell_path.write_text(json.dumps(cell, indent=1, default=float) + "\n")
    print(f"{name}: success {cell['success_rate']:.3f} [{cell['success_rate_ci95'][0]:.3f}, "
          f"{cell['success_rate_ci95'][1]:.3f}], {cell['transitions']} transitions in {train_wall / 60:.1f} min "
          f"(+{eval_wall / 60:.1f} min evaluation); {cell_path}")
    return cell_path


def add_twin(path: Path, workers: int = 1) -> dict:
    """The held twin of a cell's policy (``gaze_blind:ppo:<file>``: the same policy with its gaze and head
    held where reset put them) on the cell's seeds, and the held-twin difference (success minus the twin's),
    written into the cell as ``held_twin``. (The best static twin needs a posture searched for the policy,
    ``static_gaze search``; none is searched for the table's policies.)"""
    from visuomotor_gym.bench.evaluate import evaluate, twin_spec

    cell = json.loads(path.read_text())
    agent = twin_spec(f"ppo:{cell['policy']['file']}")
    t0 = time.time()
    twin = evaluate(agent, cell["env_id"], int(cell["episodes"]), 0, workers=workers)
    s = twin.summary
    cell["held_twin"] = {"agent": agent, "success_rate": float(s["success_rate"]),
                         "success_rate_ci95": [float(x) for x in s["success_rate_ci95"]],
                         "held_difference": cell["success_rate"] - float(s["success_rate"]),
                         "eval_wall_s": round(time.time() - t0, 1)}
    path.write_text(json.dumps(cell, indent=1) + "\n")
    print(f"{cell['cell']}: held twin {s['success_rate']:.3f}, difference {cell['held_twin']['held_difference']:+.3f}")
    return cell


# ----------------------------------------------------------------------------------------- collect


def load_cells(folders) -> list[dict]:
    cells = []
    for folder in folders:
        root = Path(folder)
        paths = sorted(root.glob("cells/*.json")) + sorted(root.glob("*.json"))
        for path in paths:
            cell = json.loads(path.read_text())
            if isinstance(cell, dict) and "cell" in cell and "success_rate" in cell:
                cell["_path"] = str(path)
                cells.append(cell)
    return cells


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.1f} %"


def _twin_text(cell: dict) -> str:
    twin = cell.get("held_twin")
    if not twin:
        return "–"
    return f"{_pct(twin['success_rate'])} ({100 * twin['held_difference']:+.1f} pts)"


def sac_env_ids() -> set[str]:
    """The ids the hyperparameter file's ``sac`` section has (SAC cells run only for them)."""
    from importlib import resources

    import yaml

    table = yaml.safe_load(resources.files("visuomotor_gym.baselines.ppo").joinpath("hyperparams.yml").read_text())
    return {k for k in (table.get("sac") or {}) if k != "default"}


def table_markdown(cells: list[dict], budget: int) -> str:
    """The table: one row per (family, rung, algorithm), the cells at ``budget`` (seeds pooled as rows)."""
    by_key: dict[tuple, list[dict]] = {}
    for c in cells:
        if c["budget_transitions"] == budget and c["episodes"] == EPISODES:
            by_key.setdefault((c["env_id"], c["algo"]), []).append(c)
    from visuomotor_gym.families import family_for

    lines = [
        "| family | env id | algorithm | success [95 % Wilson] | failed episodes (median) | gaze realism "
        "| foveation share | saccades / episode | held twin (difference) | transitions | train wall | policy |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    not_run = []
    sac_ids = sac_env_ids()
    for family, foveated, oracle in FAMILY_ROWS:
        for env_id in (foveated, oracle):
            for algo_key, algo in ALGOS.items():
                group = sorted(by_key.get((env_id, algo), []), key=lambda c: c["seed"])
                label = f"{env_id}" + (" (under the current definition)" if family in UNSETTLED else "")
                if not group:
                    if algo_key == "sac" and env_id not in sac_ids:  # no command would run
                        lines.append(f"| {family} | {label} | {algo} | not run (no `sac:` hyperparameters "
                                     f"for this id) | | | | | | | | |")
                        continue
                    lines.append(f"| {family} | {label} | {algo} | not run | | | | | | | | |")
                    not_run.append(cell_command(env_id, algo_key, budget, 0))
                    continue
                miss_label = family_for(env_id).outcome_labels[2].replace(", failed walks", "").replace(
                    ", failed reaches", "").replace(", failed crossings", "")
                for c in group:
                    lo, hi = c["success_rate_ci95"]
                    fov = c["foveation"]
                    miss = (c.get("results") or {}).get("miss_distance_m", {}).get("median")
                    miss_text = "–" if miss is None else f"{miss_label} {miss:.3g}"
                    lines.append(
                        f"| {family} | {label} | {algo} (seed {c['seed']}) | **{_pct(c['success_rate'])}** "
                        f"[{100 * lo:.1f}, {100 * hi:.1f}] | {miss_text} | {c['gaze_realism']:.3f} | "
                        f"{_pct(fov['value'])} ({fov['component']}) | {c['saccades_per_episode']:.1f} | "
                        f"{_twin_text(c)} | "
                        f"{c['transitions']:,} | {c['train_wall_s'] / 60:.1f} min | "
                        f"`{Path(c['policy']['file']).name}` |")
    text = "\n".join(lines) + "\n"
    if not_run:
        text += "\nThe empty cells, one command each:\n\n```bash\n" + "\n".join(not_run) + "\n```\n"
    return text


def plot_curves(cells: list[dict], budget: int, out_dir: Path) -> list[Path]:
    """Success of the EvalCallback's held-out episodes against transitions and against wall time, their
    mean length (steps) against transitions, and the training episodes' shaped return, one row of panels
    per family."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = [c for c in cells if c["budget_transitions"] == budget and c["episodes"] == EPISODES
             and c.get("learning_curve")]
    if not cells:
        return []
    families = [f for f, _, _ in FAMILY_ROWS if any(c["family"] == f for c in cells)]
    fig, axes = plt.subplots(len(families), 4, figsize=(16, 2.6 * len(families)), squeeze=False)
    for row, family in enumerate(families):
        for c in cells:
            if c["family"] != family:
                continue
            curve = c["learning_curve"]
            xs = [p["timesteps"] for p in curve]
            ws = [(p["wall_s"] or float("nan")) / 60 for p in curve]
            ys = [100 * p.get("success_rate", float("nan")) for p in curve]
            style = "-" if c["rung"] == "foveated" else "--"
            marker = {"PPO": "o", "RecurrentPPO": "s"}.get(c["algo"], "^")
            label = f"{c['env_id']} {c['algo']} s{c['seed']}"
            ls = [p.get("mean_length", float("nan")) for p in curve]
            axes[row, 0].plot(xs, ys, style, marker=marker, label=label)
            axes[row, 1].plot(ws, ys, style, marker=marker, label=label)
            axes[row, 2].plot(xs, ls, style, marker=marker, label=label)
            axes[row, 3].plot(xs, [p.get("train_shaped_return", float("nan")) for p in curve], style, marker=marker,
                              label=label)
        axes[row, 0].set_ylabel(f"{family}: success %")
        axes[row, 0].set_ylim(-3, 103)
        axes[row, 1].set_ylim(-3, 103)
        axes[row, 2].set_ylabel("episode steps")
        axes[row, 3].set_ylabel("training return (shaped)")
        axes[row, 3].legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("transitions")
    axes[-1, 1].set_xlabel("wall time (min, this machine, shared CPU)")
    axes[-1, 2].set_xlabel("transitions")
    axes[-1, 3].set_xlabel("transitions")
    fig.suptitle(f"Free-gaze PPO / RecurrentPPO / SAC, EvalCallback held-out episodes (budget {budget_tag(budget)})",
                 fontsize=10)
    fig.tight_layout()
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"rl_curves_{budget_tag(budget)}.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return [path]


def collect(args: argparse.Namespace) -> str:
    cells = load_cells(args.collect)
    table = table_markdown(cells, args.budget)
    doc = Path(args.doc)
    if doc.is_file():
        text = doc.read_text()
        if MARK_BEGIN not in text or MARK_END not in text:
            raise TableArgumentError(f"{doc} has no {MARK_BEGIN} ... {MARK_END} markers for the table")
        head, rest = text.split(MARK_BEGIN, 1)
        _, tail = rest.split(MARK_END, 1)
        doc.write_text(f"{head}{MARK_BEGIN}\n{table}{MARK_END}{tail}")
    print(table)
    if args.data:
        data = Path(args.data)
        data.mkdir(parents=True, exist_ok=True)
        for c in cells:
            if c["budget_transitions"] == args.budget and c["episodes"] == EPISODES:
                body = {k: v for k, v in c.items() if not k.startswith("_")}
                (data / f"{c['cell']}.json").write_text(json.dumps(body, indent=1) + "\n")
    for path in plot_curves(cells, args.budget, Path(args.images)):
        print(f"wrote {path}")
    return table


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = parse_args(argv)
        if args.twin is not None:
            for path in args.twin:
                add_twin(Path(path), args.workers)
        elif args.collect is not None:
            collect(args)
        else:
            run_cell(args, argv)
    except TableArgumentError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
