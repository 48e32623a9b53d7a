"""The gaze-gain table of every family's foveated id, read from the leaderboard's current entries.

For each baseline entry (not a twin) on a protocol id: its success rate, its held twin's
(``gaze_blind:<agent>``), its best static twin's (``static_gaze:<posture>:<agent>``, posture shown),
the gaze gain (success minus the better twin's) and the held-twin difference, and the gaze realism of
the three entries. Every number is a re-scored leaderboard entry's (200 pinned seeds)::

    python benchmarks/gaze_gain_table.py [--dir leaderboard] [--ids ObstacleWalk-v0,...]

Prints Markdown (the table of the README's "Baselines" section and of docs/gaze_gain.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

FOVEATED_IDS = ("EyeCatch-v0", "ShelfReach-v0", "ObstacleWalk-v0", "SteppingStones-v0", "ObstacleDodge-v0",
                "PushRecovery-v0")


def table(folder: Path, ids=FOVEATED_IDS) -> str:
    from visuomotor_gym.bench.evaluate import static_twin_base
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import _rows, fmt_gain, fmt_realism, pct, twin_agents

    rows, _ = _rows(load_leaderboard(folder))
    out = ["| id · agent | success | held twin | best static twin (posture: az, el, neck yaw, pitch) | gaze gain "
           "| held-twin difference | realism: agent / held / static |",
           "|---|---|---|---|---|---|---|"]
    for env_id in ids:
        here = [r for r in rows if r.env_id == env_id]
        for r in here:
            if r.agent.startswith(("gaze_blind:", "static_gaze:", "fixed_gaze")) or r.gain is None:
                continue
            held = next((t for t in here if t.agent in twin_agents(r.agent)), None)
            static = next((t for t in here if static_twin_base(t.agent) == r.agent), None)
            posture = static.agent.split(":")[1].replace("neck_yaw=", "").replace("neck_pitch=", "") if static else ""
            posture = ", ".join(p.split("=")[-1] for p in posture.split(",")[:4])
            out.append(
                f"| `{env_id}` · `{r.agent}` | {pct(r.rate)} | {pct(held.rate) if held else '–'} | "
                f"{pct(static.rate) + f' ({posture})' if static else '–'} | **{fmt_gain(r.gain)}** | "
                f"{fmt_gain(r.held_gain)} | {fmt_realism(r)} / {fmt_realism(held) if held else '–'} / "
                f"{fmt_realism(static) if static else '–'} |")
    return "\n".join(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", default="leaderboard")
    p.add_argument("--ids", default=",".join(FOVEATED_IDS))
    args = p.parse_args(argv)
    print(table(Path(args.dir), tuple(args.ids.split(","))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
