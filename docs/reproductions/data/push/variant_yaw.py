"""``vmgym`` (or the static-posture search) on PushRecovery with the wall turned 0..30 deg forward, in this
process only (``tasks.push_recovery.WALL_YAW_DEG``; the definition keeps it at 0). Third pass of PushRecovery:

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/variant_yaw.py bench \
        --agent eom_brace:fall_direction=true --env PushRecovery-v0 --episodes 200 --seed 0 --out yaw30_eom200.json
    (the same with --env PushRecoveryOracle-v0, and --agent eom_brace:fall_direction=true,use_hand=false)
    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/variant_yaw.py search \
        --env PushRecovery-v0 --agent eom_brace:fall_direction=true --coarse-step 30 --coarse-episodes 12 \
        --pinned 200 --out yaw30_static_search.json
"""

import sys

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.tasks import push_recovery as pr

if __name__ == "__main__":
    pr.WALL_YAW_DEG = (0.0, 30.0)
    if sys.argv[1] == "search":
        from visuomotor_gym import static_gaze

        sys.exit(static_gaze.main(sys.argv[1:]))
    from visuomotor_gym.cli import main

    sys.exit(main(sys.argv[1:]))
