"""Figures and numbers of docs/reproductions/iwao.md: head and eye pitch per gait cycle of the ``iwao``
agent on ObstacleWalk-v0 (Iwao et al., Fig. 6-8 and Eq. 1-10) and its gaze on the ground
plane over one course.

    MUJOCO_GL=egl python docs/reproductions/iwao_figures.py [--episodes 10]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import make_agent
from visuomotor_gym.bench.trace import run_episode

HERE = Path(__file__).resolve().parent
IMAGES = HERE / "images"
ENV_ID = "ObstacleWalk-v0"
BINS = 25  # one per control step of a 0.5 s step


def pitches(trace):
    """(gaze, head, eye-in-head) pitch below the horizontal, degrees, per step."""
    gaze = np.degrees(-np.arcsin(np.clip(trace.gaze_dir[:, 2], -1, 1)))
    head = np.degrees(-np.arcsin(np.clip(trace.head_dir[:, 2], -1, 1)))
    return gaze, head, gaze - head


def per_cycle(trace, agent_log):
    """Rows of (phase bin, gaze, head, eye, looking at an obstacle) for every step after the first second."""
    gaze, head, eye = pitches(trace)
    phase = np.asarray(trace.step_phase)
    target = np.full(len(phase), -1)
    for k, (_, tid, _, _) in enumerate(agent_log):
        if k + 1 < len(target):
            target[k + 1] = tid
    keep = trace.t >= 1.0
    b = np.minimum((phase * BINS).round().astype(int), BINS - 1)
    return np.stack([b, gaze, head, eye, target >= 0], axis=1)[keep]


def main(argv=None):
    parser = argparse.ArgumentParser()
    parser.add_argument("--episodes", type=int, default=10)
    args = parser.parse_args(argv)
    env = gym.make(ENV_ID)
    agent = make_agent("iwao", ENV_ID, 8)
    rows, traces = [], []
    for seed in range(args.episodes):
        tr = run_episode(env, agent, seed, ENV_ID, "iwao")
        traces.append(tr)
        rows.append(per_cycle(tr, agent.log))
    rows = np.concatenate(rows)

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    phase = (np.arange(BINS) + 0.0) / BINS
    numbers = {}
    for ax, obstacle, title in ((axes[0], 1, "cycles aimed at an obstacle"), (axes[1], 0, "travel cycles (no obstacle known ahead)")):
        sel = rows[rows[:, 4] == obstacle]
        for col, name, color in ((2, "head", "tab:blue"), (3, "eye in head", "tab:orange"), (1, "gaze", "k")):
            mean = np.array([sel[sel[:, 0] == b, col].mean() if np.any(sel[:, 0] == b) else np.nan for b in range(BINS)])
            sd = np.array([sel[sel[:, 0] == b, col].std() if np.any(sel[:, 0] == b) else np.nan for b in range(BINS)])
            ax.plot(phase, mean, color=color, label=name)
            ax.fill_between(phase, mean - sd, mean + sd, color=color, alpha=0.15)
            numbers[f"{'obstacle' if obstacle else 'travel'}_{name.replace(' ', '_')}_peak_phase"] = float(phase[np.nanargmax(mean)])
            numbers[f"{'obstacle' if obstacle else 'travel'}_{name.replace(' ', '_')}_peak_deg"] = float(np.nanmax(mean))
            numbers[f"{'obstacle' if obstacle else 'travel'}_{name.replace(' ', '_')}_min_deg"] = float(np.nanmin(mean))
        ax.set_title(f"{title} ({int(len(sel) / BINS)} cycles)")
        ax.set_xlabel("phase of the step (0 = heel strike)")
        ax.axvline(0.5, color="grey", lw=0.5, ls="--")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("pitch below the horizontal (deg)")
    axes[0].legend()
    fig.suptitle("iwao on ObstacleWalk-v0: head and eye pitch per gait cycle (mean ± sd), cf. Iwao et al. Fig. 6-8")
    fig.tight_layout()
    IMAGES.mkdir(exist_ok=True)
    fig.savefig(IMAGES / "iwao_pitch_per_cycle.png", dpi=110)

    tr = traces[0]
    fig, ax = plt.subplots(figsize=(12, 3.2))
    for x, y, depth, width, height, kind in np.asarray(tr.obstacles):
        ax.add_patch(plt.Rectangle((x - depth / 2, y - width / 2), depth, width,
                                   color=("tab:red", "tab:orange", "k")[int(kind)], alpha=0.5))
        ax.text(x, y + width / 2 + 0.05, f"{height * 100:.0f} cm", ha="center", fontsize=7)
    eye, gaze = tr.eye_pos, tr.gaze_dir
    s = np.where(gaze[:, 2] < -1e-3, -eye[:, 2] / gaze[:, 2], np.nan)
    ground = eye[:, :2] + s[:, None] * gaze[:, :2]
    near = np.isfinite(s) & (ground[:, 0] - eye[:, 0] < 12)
    ax.scatter(ground[near, 0], ground[near, 1], c=tr.t[near], s=4, cmap="viridis", label="gaze on the floor")
    feet = np.asarray(tr.feet_pos)
    ax.plot(feet[:, 0, 0], feet[:, 0, 1], ".", ms=1, color="tab:blue", label="left sole")
    ax.plot(feet[:, 1, 0], feet[:, 1, 1], ".", ms=1, color="tab:green", label="right sole")
    ax.axvline(float(tr.course_length), color="tab:green")
    ax.set_xlim(-0.5, float(tr.course_length) + 1)
    ax.set_ylim(-1.2, 1.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the path (m)")
    ax.set_title(f"seed 0: gaze on the ground plane (colour = time), obstacles, soles; success={tr.success}")
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    fig.savefig(IMAGES / "iwao_gaze_ground.png", dpi=110)
    numbers["episodes"] = args.episodes
    numbers["successes"] = int(sum(t.success for t in traces))
    (HERE / "iwao_numbers.json").write_text(json.dumps(numbers, indent=1) + "\n")
    print(json.dumps(numbers, indent=1))


if __name__ == "__main__":
    main()
