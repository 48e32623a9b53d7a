"""``vmgym bench`` (or the static-posture search) on PushRecovery's eighth-pass scene: the wall on a random side.

Eighth pass of PushRecovery (``docs/reproductions/eom.md``, "Eighth pass"): the prepared definition (wall turned 0..30
deg, ankle response on, the one eye ``human_periphery()``, the two-armed body) with the wall, its cubes and the push
mirrored to the body's left on half the episodes (``tasks.push_recovery.WALL_SIDE_RANDOM``). Set in this process
only, through the environment variables (defaults in brackets): ``PUSH_SIDE`` ``random``, ``right`` or ``left``
(``left``: every wall mirrored, a diagnostic) [random]; ``PUSH_HALF`` cube half-size range m [0.07,0.11];
``PUSH_GAP`` gap range m [0.12,0.30].

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/variant_side.py bench \
        --agent eom_brace --env PushRecoveryOracle-v0 --episodes 40 --seed 0 --out side_oracle40.json

``batch OUTDIR EPISODES NAME=AGENT@ENV ...`` runs several benches in one process (seeds 0..EPISODES-1), each to
``OUTDIR/NAME.json``.
"""

import os
import sys

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.body import standing as sn
from visuomotor_gym.tasks import push_recovery as pr


def _pair(name: str, default: str) -> tuple[float, float]:
    lo, hi = (float(v) for v in os.environ.get(name, default).split(","))
    return lo, hi


if __name__ == "__main__":
    argv = sys.argv[1:]
    if not hasattr(pr, "WALL_SIDE_RANDOM"):
        raise SystemExit("needs the two-armed body and tasks.push_recovery.WALL_SIDE_RANDOM (the branch's prepared tip)")
    side = os.environ.get("PUSH_SIDE", "random")
    if side not in ("random", "right", "left"):
        raise SystemExit(f"PUSH_SIDE must be random, right or left, got {side!r}")
    pr.WALL_SIDE_RANDOM = side == "random"
    if side == "left":  # every wall mirrored: the side draw always says left
        _draw = pr.PushRecoveryTask.reset_episode

        def _left(self, data, rng):
            pr.WALL_SIDE_RANDOM = True

            class _Rng:
                def __getattr__(self, k):
                    return getattr(rng, k)

                def random(self):
                    return 0.0
            _draw(self, data, _Rng())
        pr.PushRecoveryTask.reset_episode = _left
    pr.BLOCK_HALF_SIZE_M = _pair("PUSH_HALF", "0.07,0.11")
    pr.GAP_M = _pair("PUSH_GAP", "0.12,0.30")
    pr.WALL_YAW_DEG = _pair("PUSH_YAW", "0,30")
    sn.ANKLE_STRATEGY_GAIN = 1.0
    if argv[0] == "search":
        from visuomotor_gym import static_gaze

        sys.exit(static_gaze.main(argv))
    from visuomotor_gym.cli import main

    if argv[0] == "batch":
        outdir, episodes = argv[1], argv[2]
        os.makedirs(outdir, exist_ok=True)
        for item in argv[3:]:
            name, spec = item.split("=", 1)
            agent, env = spec.rsplit("@", 1)
            main(["bench", "--agent", agent, "--env", env, "--episodes", episodes, "--seed", "0",
                  "--out", os.path.join(outdir, name + ".json")])
        sys.exit(0)
    sys.exit(main(argv))
