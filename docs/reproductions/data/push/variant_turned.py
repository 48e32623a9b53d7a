"""``vmgym`` (or the static-posture search) on PushRecovery's fourth-pass candidate scene, in this process only.

Fourth pass of PushRecovery (``docs/reproductions/eom.md``, "Fourth pass"): the wall turned 0..30 deg per episode (``--yaw -20,45``: the wider range, files wide_*)
(``tasks.push_recovery.WALL_YAW_DEG``; the push follows its normal), so the cube the hand needs moves by tens of
cm and ~30 deg of gaze; the standing body's ankle response on (``body.standing.ANKLE_STRATEGY_GAIN`` 1); the
eye ``human_periphery(position_disarray=0.8)`` (the registered ids' ``vision_params``). The definition keeps
all three off. Run from the repository root, e.g.:

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/variant_turned.py bench \
        --agent eom_brace:fall_direction=true,hold_lean_gain=2,hold_lean_damp=0.1 --env PushRecoveryOracle-v0 \
        --episodes 200 --seed 0 --out turned_oracle200.json

``--yaw LO,HI`` (first argument) sets another yaw range (``--yaw 0,0``: the definition's wall).
"""

import sys

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.body import standing as sn
from visuomotor_gym.tasks import push_recovery as pr

if __name__ == "__main__":
    argv = sys.argv[1:]
    yaw = (0.0, 30.0)
    if argv[0] == "--yaw":
        yaw = tuple(float(v) for v in argv[1].split(","))
        argv = argv[2:]
    pr.WALL_YAW_DEG = yaw
    sn.ANKLE_STRATEGY_GAIN = 1.0
    for prefix in ("PushRecovery", "PushRecoveryOracle", "PushRecoveryFullView", "PushRecoveryDelayed",
                   "PushRecoveryPoorVision"):
        kw = gym.registry[f"{prefix}-v0"].kwargs
        kw["vision_params"] = {**(kw.get("vision_params") or {}), "position_disarray": 0.8}
    if argv[0] == "search":
        from visuomotor_gym import static_gaze

        sys.exit(static_gaze.main(argv))
    from visuomotor_gym.cli import main

    sys.exit(main(argv))
