"""Scene and stance variants of PushRecovery-v0 tried in the third pass, on seeds 0-39.

Each variant overrides module constants of the task (``tasks/push_recovery.py``: the wall's yaw, distance,
heights, gaps, the push's azimuth spread) or of the body's automatic postural response
(``body/standing.py``) in this process only, then plays ``eom_brace`` (foveated and on the Oracle rung),
the legs-only agent and static twins (fixed postures) with the episode loop of the common evaluator
(seed i = episode i). Run from the repository root:

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/explore_scene.py \
        --out docs/reproductions/data/push/explore_scene.json

About 10 minutes on one shared core.
"""

from __future__ import annotations

import argparse
import json
import time

import gymnasium as gym
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.agents import make_agent
from visuomotor_gym.body import standing as sn
from visuomotor_gym.tasks import push_recovery as pr

SEEDS = range(40)
STATIC_SIDE = "static_gaze:az=-105,el=-25,neck_yaw=-60,neck_pitch=-45,fix=0.5:eom_brace"  # the searched posture
STATIC_LOW = "static_gaze:az=-90,el=-30,neck_yaw=-60,neck_pitch=-45,fix=0.7:eom_brace"
STATIC_FWD = "static_gaze:az=-80,el=-25,neck_yaw=-50,neck_pitch=-45,fix=0.6:eom_brace"
FALL = "eom_brace:fall_direction=true"
HIP = {"HIP_STRATEGY_GAIN": 4.0, "ANKLE_STRATEGY_GAIN": 1.0}
# (name, task constants, body constants, agents [(spec, env id)])
VARIANTS = [
    ("definition (wall beside the body)", {}, {},
     [(FALL, "PushRecoveryOracle-v0"), (FALL, "PushRecovery-v0"), (STATIC_SIDE.replace("eom_brace", FALL), "PushRecovery-v0")]),
    ("+ ankle/hip response (gain 4)", {}, HIP,
     [(FALL, "PushRecoveryOracle-v0"), (FALL, "PushRecovery-v0"), (FALL + ",use_hand=false", "PushRecovery-v0")]),
    ("+ lateral hip-roll response (gain 2)", {}, {"HIP_ROLL_GAIN": 2.0},
     [(FALL, "PushRecoveryOracle-v0")]),
    ("push azimuth +-25 deg", {"PUSH_AZIMUTH_DEG": 25.0}, {}, [(FALL, "PushRecoveryOracle-v0")]),
    ("push azimuth +-40 deg", {"PUSH_AZIMUTH_DEG": 40.0}, {}, [(FALL, "PushRecoveryOracle-v0")]),
    ("wall yaw 0..30 deg (forward-right)", {"WALL_YAW_DEG": (0.0, 30.0)}, {},
     [(FALL, "PushRecoveryOracle-v0"), (FALL, "PushRecovery-v0"),
      (STATIC_SIDE.replace("eom_brace", FALL), "PushRecovery-v0"), (STATIC_FWD.replace("eom_brace", FALL), "PushRecovery-v0")]),
    ("wall yaw 30..60 deg", {"WALL_YAW_DEG": (30.0, 60.0)}, {}, [(FALL, "PushRecoveryOracle-v0")]),
    ("wall yaw -30..0 deg (backward-right)", {"WALL_YAW_DEG": (-30.0, 0.0)}, {}, [(FALL, "PushRecoveryOracle-v0")]),
    ("wall yaw -10..35 deg", {"WALL_YAW_DEG": (-10.0, 35.0)}, {}, [(FALL, "PushRecoveryOracle-v0")]),
    ("wall yaw -10..35 deg + ankle/hip response", {"WALL_YAW_DEG": (-10.0, 35.0)}, HIP,
     [(FALL, "PushRecoveryOracle-v0"), (FALL + ",use_hand=false", "PushRecovery-v0")]),
    ("sparse cubes: gaps 0.3-0.5 m", {"GAP_M": (0.3, 0.5), "FIRST_BLOCK_X_M": (-0.7, -0.2)}, {},
     [(FALL, "PushRecoveryOracle-v0"), (FALL, "PushRecovery-v0"), (STATIC_SIDE.replace("eom_brace", FALL), "PushRecovery-v0"),
      (STATIC_LOW.replace("eom_brace", FALL), "PushRecovery-v0")]),
    ("wall 0.50-0.95 m, cubes 0.95-1.40 m high", {"WALL_DISTANCE_M": (0.5, 0.95), "BLOCK_HEIGHT_M": (0.95, 1.4)}, {},
     [(FALL, "PushRecoveryOracle-v0"), (FALL, "PushRecovery-v0"), (FALL + ",scan_blocks=2", "PushRecovery-v0"),
      (STATIC_SIDE.replace("eom_brace", FALL), "PushRecovery-v0"), (STATIC_LOW.replace("eom_brace", FALL), "PushRecovery-v0")]),
    ("wall 0.50-0.95 m away, fixate and verge on samples", {"WALL_DISTANCE_M": (0.5, 0.95), "BLOCK_HEIGHT_M": (0.95, 1.4)},
     {}, [(FALL + ",verge_on_sample=true", "PushRecovery-v0"), (FALL + ",scan_blocks=1,verge_on_sample=true", "PushRecovery-v0"),
          (FALL + ",scan_blocks=2,verge_on_sample=true", "PushRecovery-v0")]),
    ("definition, a straight 2 m/s reach (no alignment)", {}, {},
     [(FALL + ",approach_offset_m=0.0,align_m=1.0,approach_speed_m_s=2.0", "PushRecoveryOracle-v0"),
      (FALL + ",approach_offset_m=0.0,align_m=1.0,approach_speed_m_s=2.0", "PushRecovery-v0"),
      (STATIC_SIDE.replace("eom_brace", FALL + ",approach_offset_m=0.0,align_m=1.0,approach_speed_m_s=2.0"),
       "PushRecovery-v0")]),
    ("definition, fixate and verge on samples", {}, {},
     [(FALL + ",verge_on_sample=true", "PushRecovery-v0"), (FALL + ",scan_blocks=1,verge_on_sample=true", "PushRecovery-v0"),
      (FALL + ",scan_blocks=2", "PushRecovery-v0")]),
]


def play(spec: str, env_id: str) -> tuple[int, list[int]]:
    env = gym.make(env_id)
    agent = make_agent(spec, env_id, env.action_space.shape[0], seed=SEEDS[0])
    wins = []
    for seed in SEEDS:
        obs, info = env.reset(seed=seed)
        start = True
        while True:
            act, _ = agent.predict(obs, episode_start=np.array([start]))
            start = False
            obs, _r, term, trunc, info = env.step(act)
            if term or trunc:
                break
        wins.append(int(bool(info.get("is_success"))))
    env.close()
    return sum(wins), wins


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--append", action="store_true", help="add to the rows already in --out")
    ap.add_argument("--only", default=None, help="only the variants whose name contains this")
    a = ap.parse_args()
    rows = []
    if a.append:
        with open(a.out) as f:
            rows = json.load(f)["rows"]
    for name, task_over, body_over, agents in VARIANTS:
        if a.only is not None and a.only not in name:
            continue
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
                print(f"{name:45s} {env_id:24s} {spec:60s} {n}/{len(wins)} ({time.time() - t0:.0f} s)", flush=True)
        finally:
            for (mod, k), v in saved.items():
                setattr(pr if mod == "pr" else sn, k, v)
    with open(a.out, "w") as f:
        json.dump({"seeds": [SEEDS[0], SEEDS[-1]], "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
