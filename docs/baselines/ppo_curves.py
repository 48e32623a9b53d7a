"""Learning curves of PPO training runs (from each run's progress.csv) as one PNG: catch rate
against environment transitions (left) and against training wall time (right).

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
    """(steps, minutes, training catch rate) per update and (steps, minutes, eval catch rate) per
    EvalCallback run; an eval row has no time of its own, so it takes the last update's."""
    rows = list(csv.DictReader((run / "progress.csv").open()))
    train, evals = ([], [], []), ([], [], [])
    minutes = 0.0
    for r in rows:
        if r.get("time/time_elapsed"):
            minutes = float(r["time/time_elapsed"]) / 60.0
        for key, out in (("rollout/success_rate", train), ("eval/success_rate", evals)):
            if r.get(key):
                out[0].append(float(r["time/total_timesteps"]))
                out[1].append(minutes)
                out[2].append(float(r[key]))
    return train, evals


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--base", type=float, default=None,
                        help="catch rate of the residual's base (belief_intercept) on EyeCatch-v0, drawn as a line")
    parser.add_argument("--line", action="append", default=[], metavar="RATE=LABEL",
                        help="a horizontal reference line (catch rate in [0, 1] and its label); repeatable")
    args = parser.parse_args(argv)
    fig = Figure(figsize=(13, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax_steps, ax_min = fig.subplots(1, 2, sharey=True)
    for run in args.runs:
        meta = json.loads((run / "ppo_meta.json").read_text()) if (run / "ppo_meta.json").exists() else {}
        label = f"{run.parent.name} / {run.name}"
        if meta:
            label += f" ({meta['timesteps'] / 1e6:.2f} M steps, {meta['train_wall_s'] / 60:.0f} min)"
        train, evals = read(run)
        line, = ax_steps.plot(train[0], train[2], alpha=0.4, lw=1, label=label + ": training episodes")
        ax_steps.plot(evals[0], evals[2], "o-", color=line.get_color(), ms=3, label=label + ": EvalCallback (40 eps)")
        ax_min.plot(train[1], train[2], alpha=0.4, lw=1, color=line.get_color())
        ax_min.plot(evals[1], evals[2], "o-", color=line.get_color(), ms=3)
    ax_steps.set_xlabel("environment transitions")
    ax_min.set_xlabel("training wall time (min, this 2-core machine, shared with other jobs)")
    ax_steps.set_ylabel("catch rate")
    ax_steps.set_ylim(0, 1)
    for ax in (ax_steps, ax_min):
        ax.grid(alpha=0.3)
    ax_min.axhline(0.85, color="k", lw=0.8, ls="--")
    ax_min.text(0.5, 0.86, "goal: 85 %", fontsize=8)
    if args.base is not None:
        ax_min.axhline(args.base, color="0.3", lw=1.0, ls=":")
        ax_steps.axhline(args.base, color="0.3", lw=1.0, ls=":",
                         label=f"belief_intercept on EyeCatch-v0, nothing learned: {args.base:.0%} (200 throws)")
    for k, item in enumerate(args.line):
        rate, _, text = item.partition("=")
        style = {"color": f"C{k + 5}", "lw": 1.0, "ls": "-."}
        ax_min.axhline(float(rate), **style)
        ax_steps.axhline(float(rate), label=text, **style)
    fig.legend(*ax_steps.get_legend_handles_labels(), loc="outside lower center", ncols=2, fontsize=7)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
