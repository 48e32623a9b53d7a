"""PPO on ObstacleWalk-v0 (docs/baselines/ppo.md): the table of outcomes and gaze statistics from bench
traces, and the learning curve against wall time.

    vmgym bench --agent AGENT --env ObstacleWalk-v0 --episodes 200 --seed 0 --out A.json --traces A.npz
    python docs/baselines/ppo_walk.py table A.npz [B.npz ...] --out rows.json
    python docs/baselines/ppo_walk.py constant --action 0,0,1,0,0,0,0,0 --episodes 200
    python docs/baselines/ppo_walk.py curves RUN_DIR --out docs/baselines/images/ppo_walk_curves.png

Per agent (from the traces the common evaluator writes): success with its 95 % Wilson interval, the
share of episodes that end in a trip, that step on an obstacle (misstep) or stop short, the share of
the course walked, where the eye looks (gaze elevation: the median, and the share of steps with the
line of sight more than 5 deg below the horizon, or below 20 deg, where an obstacle 2-4 m ahead
lies), the share of steps with an obstacle seen at all, saccades per episode, and the mean footstep
actions mapped onto metres (``visuomotor_gym/envs/walk.py``'s action table).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from pathlib import Path

import numpy as np

BESIDE_M = 0.3  # modelling choice: a foot lands at most ~0.3 m beside the pelvis (step width 0.12 m + offset)


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, mid - half), min(1.0, mid + half))


def _lin(a: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return lo + (np.clip(a, -1, 1) + 1) / 2 * (hi - lo)


def table_row(path: Path) -> dict:
    z = np.load(path, allow_pickle=False)
    n = int(z["n_episodes"])
    ok = trip = mis = short = 0
    walked, elev, head, seen, sacc, steps, act = [], [], [], [], [], [], []
    y_end, beside, reached = [], 0, 0
    agent = str(z["ep0/agent"])
    for i in range(n):
        e = f"ep{i}/"
        success, tripped = bool(z[e + "success"]), bool(z[e + "task/tripped"])
        misstepped, finished = bool(z[e + "task/misstepped"]), bool(z[e + "task/finished"])
        ok += success
        trip += tripped
        mis += misstepped and not tripped
        short += not (tripped or finished)
        pel = z[e + "task/pelvis_pos"]
        walked.append(min(1.0, (pel[-1, 0] - pel[0, 0]) / float(z[e + "task/course_length"])))
        # Off the path: the pelvis's lateral offset from the start at the end, and for every obstacle the
        # pelvis reached (obstacles are in the path frame: x from the start, y from the centre line), whether
        # it passed it *beside* (pelvis more than BESIDE_M beyond the obstacle's lateral edge) rather than over.
        y_end.append(abs(pel[-1, 1] - pel[0, 1]))
        x_rel, y_rel = pel[:, 0] - pel[0, 0], pel[:, 1] - pel[0, 1]
        for ox, oy, _, ow, _, _ in z[e + "task/obstacles"]:
            at = np.flatnonzero(x_rel >= ox)
            if len(at):
                reached += 1
                beside += abs(y_rel[at[0]] - oy) - 0.5 * ow > BESIDE_M
        g = z[e + "gaze_dir"]
        elev.append(np.degrees(np.arcsin(np.clip(g[:, 2] / np.linalg.norm(g, axis=1), -1, 1))))
        h = z[e + "head_dir"]
        head.append(np.degrees(np.arcsin(np.clip(h[:, 2] / np.linalg.norm(h, axis=1), -1, 1))))
        seen.append(z[e + "task/obstacle_seen"])
        sacc.append(int(z[e + "saccade_onset"].sum()))
        steps.append(len(g))
        act.append(z[e + "action"][1:])  # row 0 is the reset (no action: NaN)
    elev_all, head_all, act_all = np.concatenate(elev), np.concatenate(head), np.concatenate(act)
    lo, hi = wilson(ok, n)
    return {
        "agent": agent, "episodes": n, "success": ok / n, "success_ci95": [lo, hi],
        "tripped": trip / n, "misstep_no_trip": mis / n, "stopped_short": short / n,
        "course_walked_median": float(np.median(walked)), "steps_median": float(np.median(steps)),
        "pelvis_lateral_end_median_m": float(np.median(y_end)),
        "obstacles_reached": reached, "obstacles_passed_beside_share": beside / max(1, reached),
        "gaze_elevation_median_deg": float(np.median(elev_all)),
        "gaze_below_5deg_share": float(np.mean(elev_all < -5.0)),
        "gaze_below_20deg_share": float(np.mean(elev_all < -20.0)),
        "head_pitch_median_deg": float(np.median(head_all)),
        "obstacle_seen_share": float(np.mean(np.concatenate(seen))),
        "saccades_per_episode": float(np.mean(sacc)),
        "step_length_m_mean": float(np.nanmean(_lin(act_all[:, 0], 0.25, 0.95))),
        "lateral_offset_m_mean": float(np.nanmean(_lin(act_all[:, 1], -0.3, 0.3))),
        "toe_clearance_m_mean": float(np.nanmean(_lin(act_all[:, 2], 0.02, 0.45))),
        "gaze_action_abs_mean": float(np.nanmean(np.abs(np.clip(act_all[:, 3:5], -1, 1)))),
        "head_pitch_action_mean": float(np.nanmean(np.clip(act_all[:, 7], -1, 1))),
    }


def constant(action: list[float], episodes: int, seed: int) -> dict:
    """A constant action on the pinned courses (episode i: ``reset(seed=seed + i)``, as the evaluator):
    what a policy that ignores its observation gets."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    env = gym.make("ObstacleWalk-v0")
    a = np.asarray(action, dtype=np.float32)
    ok = trip = 0
    for i in range(episodes):
        env.reset(seed=seed + i)
        done = False
        while not done:
            _, _, terminated, truncated, info = env.step(a)
            done = terminated or truncated
        ok += bool(info["is_success"])
        trip += bool(info["tripped"])
    lo, hi = wilson(ok, episodes)
    return {"action": list(map(float, a)), "episodes": episodes, "success": ok / episodes,
            "success_ci95": [lo, hi], "tripped": trip / episodes}


def curves(run: Path, out: Path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rows = list(csv.DictReader((run / "progress.csv").open()))
    tr = {k: [] for k in ("min", "succ", "rew", "len")}
    ev = {k: [] for k in ("min", "succ", "rew", "len")}
    minutes = 0.0
    for r in rows:
        if r.get("time/time_elapsed"):
            minutes = float(r["time/time_elapsed"]) / 60.0
        if r.get("rollout/success_rate"):
            tr["min"].append(minutes)
            tr["succ"].append(float(r["rollout/success_rate"]))
            tr["rew"].append(float(r["rollout/ep_rew_mean"]))
            tr["len"].append(float(r["rollout/ep_len_mean"]))
        if r.get("eval/success_rate"):
            ev["min"].append(minutes)
            ev["succ"].append(float(r["eval/success_rate"]))
            ev["rew"].append(float(r["eval/mean_reward"]))
            ev["len"].append(float(r["eval/mean_ep_length"]))
    meta = json.loads((run / "ppo_meta.json").read_text()) if (run / "ppo_meta.json").exists() else {}
    fig = Figure(figsize=(14, 4.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 3)
    panels = (("succ", "success rate (no trip, no misstep)"),
              ("rew", "episode return (training: + 0.05/m progress shaping)"),
              ("len", "episode length (steps; 2000 = truncated)"))
    for ax, (key, label) in zip(axes, panels):
        ax.plot(tr["min"], tr[key], lw=1, alpha=0.6, label="training episodes (stochastic, last 100)")
        ax.plot(ev["min"], ev[key], "o-", ms=3, label="EvalCallback (deterministic, 20 held-out courses)")
        ax.set_xlabel("training wall time (min, 2 shared cores)")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].set_ylim(-0.02, 1.0)
    axes[0].legend(fontsize=8, loc="lower right")
    title = f"PPO on ObstacleWalk-v0, {run.name}"
    if meta:
        title += f": {meta['timesteps'] / 1e6:.2f} M transitions in {meta['train_wall_s'] / 60:.1f} min"
    fig.suptitle(title, fontsize=11)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("table")
    t.add_argument("traces", nargs="+", type=Path)
    t.add_argument("--out", type=Path)
    c = sub.add_parser("curves")
    c.add_argument("run", type=Path)
    c.add_argument("--out", type=Path, required=True)
    k = sub.add_parser("constant")
    k.add_argument("--action", required=True, help="8 comma-separated values in [-1, 1]")
    k.add_argument("--episodes", type=int, default=200)
    k.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.cmd == "constant":
        print(json.dumps(constant([float(v) for v in args.action.split(",")], args.episodes, args.seed)))
        return
    if args.cmd == "curves":
        curves(args.run, args.out)
        return
    rows = [table_row(p) for p in args.traces]
    for r in rows:
        print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()}))
    if args.out:
        args.out.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
