"""PushRecovery's fourth pass on seeds 0-39: the brace (ankle response, active hold) and the agent's vision options
on the wall turned per episode, with the one eye ``human_periphery(position_disarray=0.8)``.

Each row sets the task's and body's module constants in this process only (as ``explore_scene.py``, whose
``play`` loop it uses: the common evaluator's episode loop, seed i = episode i) and the registered ids'
``vision_params`` to ``{"position_disarray": 0.8}``. Run from the repository root:

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/explore_fourth.py \
        --out docs/reproductions/data/push/explore_fourth.json

About 10 minutes on one shared core. The agent specs are those of the commit that added this script: the
rows named ``eom_brace`` (and the options not named) use eom_brace's defaults of the third pass; the
redefinition that followed made this pass's options the defaults (``tests/test_push_recovery.py``'s
``THIRD_PASS`` spells the former ones out).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import gymnasium as gym

sys.path.insert(0, str(Path(__file__).parent))
from explore_scene import SEEDS, play

from visuomotor_gym.body import standing as sn
from visuomotor_gym.tasks import push_recovery as pr

BR = "eom_brace:fall_direction=true,hold_lean_gain=2,hold_lean_damp=0.1"  # the brace of the fourth pass
VIS = ",drop_crowded=true,fuse_max_ecc_deg=40"
AG = BR + VIS + ",choose_by_ray=true,verge_on_ray=true,hand_on_cut=true"  # + the vision options
POSTURES = ("az=-105,el=-25,neck_yaw=-60,neck_pitch=-45,fix=0.5", "az=-80,el=-25,neck_yaw=-50,neck_pitch=-45,fix=0.6",
            "az=-70,el=-30,neck_yaw=-45,neck_pitch=-45,fix=0.7")
ANKLE = {"ANKLE_STRATEGY_GAIN": 1.0}
FOV, ORA = "PushRecovery-v0", "PushRecoveryOracle-v0"
# (name, task constants, body constants, [(spec, env id)])
ROWS = [
    ("definition", {}, {}, [("eom_brace", ORA), ("eom_brace:hold_lean_gain=2,hold_lean_damp=0.1", ORA)]),
    ("definition + ankle response", {}, ANKLE,
     [("eom_brace", ORA), ("eom_brace:hold_lean_gain=2,hold_lean_damp=0.1", ORA), (BR, ORA), (BR, FOV)]),
    ("wall turned 0..30 deg + ankle response", {"WALL_YAW_DEG": (0.0, 30.0)}, ANKLE,
     [(BR, ORA), (BR, FOV), (BR + VIS, FOV), (BR + VIS + ",choose_by_ray=true", FOV),
      (BR + VIS + ",choose_by_ray=true,verge_on_ray=true", FOV), (AG, FOV),
      (AG + ",scan_blocks=2,wall_normal=true", FOV), (AG + ",use_hand=false", FOV), ("gaze_blind:" + AG, FOV)]
     + [(f"static_gaze:{p}:{AG}", FOV) for p in POSTURES]),
    ("wall turned -20..45 deg + ankle response", {"WALL_YAW_DEG": (-20.0, 45.0)}, ANKLE,
     [(BR, ORA), (AG, FOV)] + [(f"static_gaze:{p}:{AG}", FOV) for p in POSTURES[:2]]),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    for prefix in ("PushRecovery", "PushRecoveryOracle"):
        gym.registry[f"{prefix}-v0"].kwargs["vision_params"] = {"position_disarray": 0.8}
    rows = []
    for name, task_over, body_over, agents in ROWS:
        saved = {**{("pr", k): getattr(pr, k) for k in task_over}, **{("sn", k): getattr(sn, k) for k in body_over}}
        for k, v in task_over.items():
            setattr(pr, k, v)
        for k, v in body_over.items():
            setattr(sn, k, v)
        try:
            for spec, env_id in agents:
                t0 = time.time()
                n, wins = play(spec, env_id)
                rows.append({"variant": name, "task": task_over, "body": body_over, "agent": spec, "env_id": env_id,
                             "success": n, "episodes": len(wins), "per_seed": wins})
                print(f"{name:42s} {env_id:22s} {spec:70s} {n}/{len(wins)} ({time.time() - t0:.0f} s)", flush=True)
        finally:
            for (mod, k), v in saved.items():
                setattr(pr if mod == "pr" else sn, k, v)
    with open(a.out, "w") as f:
        json.dump({"seeds": [SEEDS[0], SEEDS[-1]], "eye": "human_periphery(position_disarray=0.8)", "rows": rows},
                  f, indent=1)


if __name__ == "__main__":
    main()
