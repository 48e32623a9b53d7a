"""``vmgym`` (or the static-posture search) on PushRecovery's fifth-pass candidate: a crowded row of cubes.

Fifth pass of PushRecovery (``docs/reproductions/eom.md``, "Fifth pass"): the fourth pass's scene (wall turned
0..30 deg, ankle response on, the one eye ``human_periphery()``) with the row of cubes made dense enough to
crowd (Bouma 1970): smaller cubes, narrower gaps, one row height. Set in this process only, through the
environment variables (defaults in brackets): ``PUSH_HALF`` cube half-size range m [0.04,0.05], ``PUSH_GAP``
gap range m [0.05,0.08], ``PUSH_ROW_JITTER`` per-cube height jitter m [0.02; "none": independent heights],
``PUSH_YAW`` wall yaw range deg [0,30], ``PUSH_FIRST_X`` first cube's x range m [-0.35,-0.05], ``PUSH_HEIGHT`` the
cube (row) height range m [1.00,1.35], ``PUSH_AZ`` the push's azimuth
half-range about the wall's normal deg [10]; ``PUSH_BACK`` the odd cubes set back by
this many m, out of reach [none]; ``PUSH_CLUTTER`` visual-only clutter cubes per cube (seventh
pass, ``tasks.push_recovery.CLUTTER_PER_CUBE``) [none], ``PUSH_CLUTTER_BEHIND`` their depth behind the wall
plane, m [0.05,0.15], ``PUSH_CLUTTER_SPREAD`` m [0.06]; ``PUSH_CROWDING=0`` the same eye
without crowding (a diagnostic). E.g.:

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/variant_crowded.py bench \
        --agent eom_brace:fall_direction=true,hold_lean_gain=2,hold_lean_damp=0.1 --env PushRecoveryOracle-v0 \
        --episodes 40 --seed 0 --out crowded_oracle40.json
"""

import os
import sys

import gymnasium as gym

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym.body import standing as sn
from visuomotor_gym.tasks import push_recovery as pr


def _pair(name: str, default: str) -> tuple[float, float]:
    lo, hi = (float(v) for v in os.environ.get(name, default).split(","))
    return lo, hi


if __name__ == "__main__":
    argv = sys.argv[1:]
    pr.WALL_YAW_DEG = _pair("PUSH_YAW", "0,30")
    pr.BLOCK_HALF_SIZE_M = _pair("PUSH_HALF", "0.04,0.05")
    pr.GAP_M = _pair("PUSH_GAP", "0.05,0.08")
    pr.PUSH_AZIMUTH_DEG = float(os.environ.get("PUSH_AZ", "10"))
    pr.BLOCK_HEIGHT_M = _pair("PUSH_HEIGHT", "1.00,1.35")
    pr.FIRST_BLOCK_X_M = _pair("PUSH_FIRST_X", "-0.35,-0.05")
    jitter = os.environ.get("PUSH_ROW_JITTER", "0.02")
    pr.ROW_HEIGHT_JITTER_M = None if jitter == "none" else float(jitter)
    back = os.environ.get("PUSH_BACK", "none")
    pr.BACK_ROW_M = None if back == "none" else float(back)
    clutter = os.environ.get("PUSH_CLUTTER", "none")
    pr.CLUTTER_PER_CUBE = None if clutter == "none" else int(clutter)
    pr.CLUTTER_BEHIND_M = _pair("PUSH_CLUTTER_BEHIND", "0.05,0.15")
    pr.CLUTTER_SPREAD_M = float(os.environ.get("PUSH_CLUTTER_SPREAD", "0.06"))
    sn.ANKLE_STRATEGY_GAIN = 1.0
    if os.environ.get("PUSH_CROWDING", "1") == "0":  # diagnostic: the same eye without crowding
        for prefix in ("PushRecovery", "PushRecoveryDelayed", "PushRecoveryPoorVision"):
            kw = gym.registry[f"{prefix}-v0"].kwargs
            kw["vision_params"] = {**(kw.get("vision_params") or {}), "crowding": False}
    if argv[0] == "search":
        from visuomotor_gym import static_gaze

        sys.exit(static_gaze.main(argv))
    from visuomotor_gym.cli import main

    sys.exit(main(argv))
