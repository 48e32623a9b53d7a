"""What a gated-gaze PPO policy learned (docs/baselines/ppo.md): catch, where the eye looks, and how often the
look gate is on, beside its frozen-gaze twin, the structure's fixed bases and Eyecatch.

Each agent plays the pinned throws (episode i: seed i) through the evaluator's own ``run_episode``
on the registered env, so catch rates equal ``vmgym bench``'s. Per agent: catch rate with its Wilson
95 % interval, the share of steps with the true ball within 2 / 5 / 10 deg of the line of sight (all
steps after reset, pooled over throws), saccades per throw, and, for ``ppo:`` policies with a look
gate, the share of steps the gate is on (> 0) and the head's mean |pitch| and |yaw| targets. Writes
JSON and prints a markdown table.

    python docs/baselines/ppo_gated.py --env EyeCatch-v0 --episodes 200 \\
        --agents ppo:POLICY.npz gaze_blind:ppo:POLICY.npz belief_intercept:gaze_action=gated \\
                 belief_intercept:gaze_action=gated,look=true eyecatch fixed_gaze --out gated.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from visuomotor_gym.agents import GazeBlind, make_agent
from visuomotor_gym.bench.evaluate import make_env
from visuomotor_gym.bench.trace import run_episode
from visuomotor_gym.metrics.summary import summarize

sys.path.insert(0, str(Path(__file__).parent))
from ppo_gaze import gaze_error_deg


class _Recorder:
    """Passes ``predict`` through and keeps the policy's own action (the look gate) of every step."""

    def __init__(self, policy):
        self.policy = policy
        self.inner = policy.base if isinstance(policy, GazeBlind) else policy
        self.policy_actions: list[np.ndarray] = []

    def reset(self):
        if hasattr(self.policy, "reset"):
            self.policy.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        out = self.policy.predict(observation, state=state, episode_start=episode_start, deterministic=deterministic)
        last = getattr(self.inner, "last_policy_action", None)
        if last is not None:
            self.policy_actions.append(np.array(last, dtype=float))
        return out


def median_curve(traces, grid) -> np.ndarray:
    """Median (over throws) angle between the line of sight and the ball at each time of ``grid``."""
    curves = [np.interp(grid, tr.t, gaze_error_deg(tr), right=np.nan) for tr in traces]
    import warnings

    with warnings.catch_warnings():  # late times no throw reaches are all-NaN columns
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmedian(np.array(curves), axis=0)


GRID = np.arange(0.0, 1.6, 0.02)


def measure(spec: str, env_id: str, episodes: int, seed: int = 0) -> dict:
    env = make_env(env_id)
    policy = _Recorder(make_agent(spec, env_id, action_dim=int(env.action_space.shape[0]), seed=seed))
    traces = [run_episode(env, policy, seed=seed + i, env_id=env_id, agent=spec) for i in range(episodes)]
    env.close()
    errors = np.concatenate([gaze_error_deg(tr)[1:] for tr in traces])
    s = summarize(traces)
    row = {
        "agent": spec,
        "episodes": episodes,
        "catch_rate": s["catch_rate"],
        "catch_rate_ci95": s["catch_rate_ci95"],
        "ball_within_2deg": float(np.mean(errors < 2.0)),
        "ball_within_5deg": float(np.mean(errors < 5.0)),
        "ball_within_10deg": float(np.mean(errors < 10.0)),
        "saccades_per_throw": float(np.mean([tr.saccade_onset.sum() for tr in traces])),
        "outcomes": [bool(tr.caught) for tr in traces],
        "median_angle_curve_deg": [None if math.isnan(v) else round(float(v), 4) for v in median_curve(traces, GRID)],
    }
    if policy.policy_actions:
        acts = np.array(policy.policy_actions)
        if acts.shape[1] == 10:
            row["gate_on_share"] = float(np.mean(acts[:, 9] > 0.0))
        row["head_yaw_abs_mean"] = float(np.mean(np.abs(np.clip(acts[:, 7], -1, 1))))
        row["head_pitch_abs_mean"] = float(np.mean(np.abs(np.clip(acts[:, 8], -1, 1))))
    return row


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="EyeCatch-v0")
    parser.add_argument("--agents", nargs="+", required=True)
    parser.add_argument("--replot", type=Path, default=None,
                        help="plot these agents' rows from an earlier --out JSON instead of playing them")
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--labels", nargs="*", default=None, help="one legend label per agent")
    parser.add_argument("--out", type=Path, required=True, help="JSON of the rows")
    parser.add_argument("--png", type=Path, default=None, help="also plot the median gaze angle against time")
    args = parser.parse_args(argv)
    if args.replot:
        saved = {r["agent"]: r for r in json.loads(args.replot.read_text())["rows"]}
        plot([saved[a] for a in args.agents], args.labels or args.agents, args.env, args.episodes, args.png or args.out)
        return
    rows = []
    for spec in args.agents:
        rows.append(measure(spec, args.env, args.episodes))
        r = rows[-1]
        print(f"{spec}: catch {r['catch_rate']:.3f} {r['catch_rate_ci95']}, within 5 deg {r['ball_within_5deg']:.3f}, "
              f"saccades {r['saccades_per_throw']:.2f}, gate {r.get('gate_on_share')}", flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"env_id": args.env, "episodes": args.episodes, "rows": rows}, indent=1) + "\n")
    print("| agent | catch [95 % CI] | ball within 2° | within 5° | within 10° | saccades / throw | gate on |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        lo, hi = r["catch_rate_ci95"]
        gate = r.get("gate_on_share")
        print(f"| `{r['agent']}` | {100 * r['catch_rate']:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}] | "
              f"{100 * r['ball_within_2deg']:.0f} % | {100 * r['ball_within_5deg']:.0f} % | "
              f"{100 * r['ball_within_10deg']:.0f} % | {r['saccades_per_throw']:.1f} | "
              f"{'–' if gate is None or math.isnan(gate) else f'{100 * gate:.0f} %'} |")
    if args.png:
        plot(rows, args.labels or args.agents, args.env, args.episodes, args.png)


def plot(rows, labels, env_id, episodes, out: Path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.5, 6.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for r, label in zip(rows, labels):
        curve = np.array([np.nan if v is None else v for v in r["median_angle_curve_deg"]], dtype=float)
        ax.plot(GRID, curve, label=f"{label} ({100 * r['catch_rate']:.1f} %, "
                                   f"{100 * r['ball_within_5deg']:.0f} % of steps within 5°)")
    ax.axhline(5.0, color="k", lw=0.8, ls="--")
    ax.set_xlabel("time since the throw (s)")
    ax.set_ylabel("median angle, line of sight to ball (deg)")
    ax.set_title(f"{env_id}: where the eye looks, {episodes} pinned throws")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncols=1, fontsize=7)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
