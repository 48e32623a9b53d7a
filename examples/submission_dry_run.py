"""A leaderboard submission, dry run: the whole `vmgym leaderboard submit` flow in a scratch folder.

Copies the leaderboard's protocol (leaderboard/protocol.json of a clone) into a scratch folder,
shortens the chosen env id's pinned seeds to --episodes (a real submission plays all of them: 200),
then submits: the agent plays the pinned seeds, the results file, the policy file and the entry
record are written, the pages are built and the entry's own check (re-scoring every seed) runs.
Nothing is written to the real leaderboard/. A real submission, from the root of a clone:

    vmgym leaderboard submit --agent eyecatch --env EyeCatch-v0 --name my-eyecatch --workers 2

    python examples/submission_dry_run.py [--agent eyecatch] [--env EyeCatch-v0] [--episodes 20]
                                          [--leaderboard leaderboard] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def main(argv=None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--agent", default="eyecatch", help="agent spec (vmgym agents)")
    parser.add_argument("--env", default="EyeCatch-v0", help="an env id of the protocol")
    parser.add_argument("--episodes", type=int, default=20, help="pinned seeds to play (0: the protocol's all)")
    parser.add_argument("--name", default="my-agent", help="the entry's name")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--leaderboard", default=str(REPO / "leaderboard"),
                        help="the leaderboard folder whose protocol.json to use (default: the clone's)")
    parser.add_argument("--out", default="outputs/examples/leaderboard-dry-run", help="scratch folder (replaced)")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")

    source = Path(args.leaderboard) / "protocol.json"
    if not source.is_file():
        raise SystemExit(f"--leaderboard: no protocol.json in {args.leaderboard} (the leaderboard lives in the "
                         "repository: run this from a clone, or give --leaderboard PATH)")
    protocol = json.loads(source.read_text(encoding="utf-8"))
    ids = [e["env_id"] for e in protocol["envs"]]
    if args.env not in ids:
        raise SystemExit(f"--env {args.env!r} is not in the protocol; it has {', '.join(ids)}")
    if args.episodes > 0:
        for e in protocol["envs"]:
            if e["env_id"] == args.env:
                e["episodes"] = min(e["episodes"], args.episodes)
        protocol["rescore"]["sample"] = min(protocol["rescore"]["sample"], args.episodes)

    scratch = Path(args.out)
    if scratch.exists():
        shutil.rmtree(scratch)
    scratch.mkdir(parents=True)
    (scratch / "protocol.json").write_text(json.dumps(protocol, indent=2) + "\n", encoding="utf-8")

    from visuomotor_gym.cli import main as vmgym

    status = vmgym(["leaderboard", "submit", "--agent", args.agent, "--env", args.env, "--name", args.name,
                    "--workers", str(args.workers), "--dir", str(scratch), "--no-progress"])
    if status != 0:
        raise SystemExit(f"the submission was refused (status {status}); see above")
    written = sorted(p.relative_to(scratch).as_posix() for p in scratch.rglob("*") if p.is_file())
    print("dry run: wrote " + ", ".join(written) + f" under {scratch}")
    return scratch


if __name__ == "__main__":
    main()
