"""``vmgym`` with PushRecovery-v0's eye given the retinotopic positional disarray, in this process only.

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/bench_disarray.py 0.8 \
        bench --agent eom_brace --env PushRecovery-v0 --episodes 200 --seed 0 --gaze-gain \
        --out docs/reproductions/data/push/eom_brace_gaze_gain_200_disarray08.json

The registered id's ``vision_params`` becomes ``{"position_disarray": SHARE}`` over the family's eye
(``human_periphery()``), so the env, the agent's model of its eye (``env_vision_params``) and both twins
share it. About 3 minutes on one core.
"""

import sys

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.cli import main

if __name__ == "__main__":
    share = float(sys.argv[1])
    gym.registry["PushRecovery-v0"].kwargs["vision_params"] = {"position_disarray": share}
    sys.exit(main(sys.argv[2:]))
