"""Learning curves of PPO training runs (from each run's progress.csv) as one PNG.

    python docs/baselines/ppo_curves.py RUN_DIR [RUN_DIR ...] --out docs/baselines/images/ppo_curves.png
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def read(run: Path):
    rows = list(csv.DictReader((run / "progress.csv").open()))
    steps, train, evals_s, evals = [], [], [], []
    for r in rows:
        if r.get("rollout/success_rate"):
            steps.append(float(r["time/total_timesteps"]))
            train.append(float(r["rollout/success_rate"]))
        if r.get("eval/success_rate"):
            evals_s.append(float(r["time/total_timesteps"]))
            evals.append(float(r["eval/success_rate"]))
    return steps, train, evals_s, evals


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    fig = Figure(figsize=(8, 4), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for run in args.runs:
        meta = json.loads((run / "ppo_meta.json").read_text()) if (run / "ppo_meta.json").exists() else {}
        label = f"{run.parent.name} / {run.name}"
        if meta:
            label += f" ({meta['timesteps'] / 1e6:.2f} M steps, {meta['train_wall_s'] / 60:.0f} min)"
        steps, train, es, ev = read(run)
        line, = ax.plot(steps, train, alpha=0.5, label=label + ": training episodes")
        ax.plot(es, ev, "o-", color=line.get_color(), ms=3, label=label + ": EvalCallback (40 eps)")
    ax.set_xlabel("environment transitions")
    ax.set_ylabel("catch rate")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
