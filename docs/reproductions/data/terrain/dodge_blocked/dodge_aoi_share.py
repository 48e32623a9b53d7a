"""The pedestrian-fixated share scored with a body-sized area of interest instead of ``dodge_realism``'s 4 deg
circle (exploration, session 43; dodge_groups.md). A pedestrian counts as fixated when the line of sight passes
within ``r + s tan(m)`` of its body's axis (the vertical segment 0..1.75 m of ``envs_assets/dodge.xml``'s capsule,
``r`` = 0.25 m its radius, ``s`` the distance along the line of sight, ``m`` = 1 deg an eye tracker's accuracy)
for at least ``FIXATION_MIN_S`` while it is ahead of the eye; prints both scorings per spec.

    python dodge_aoi_share.py KWARGS_JSON FIRST N SPEC...
"""

import json
import math
import sys

import numpy as np

from visuomotor_gym.bench.evaluate import evaluate
from visuomotor_gym.metrics import dodge_realism as dr
from visuomotor_gym.static_gaze import registered_kwargs

ENV = "ObstacleDodge-v0"
TOP_M = 1.75
HALF_WIDTH_M = 0.25
MARGIN_DEG = 1.0


def first_fixations_aoi(trace) -> list:
    t = np.asarray(trace.t, float)
    eye, gaze = np.asarray(trace.eye_pos, float), np.asarray(trace.gaze_dir, float)
    ped = np.asarray(trace.pedestrian_pos, float)
    crowd = np.asarray(trace.pedestrians, float).reshape(-1, 9)
    need = max(int(round(dr.FIXATION_MIN_S / float(trace.dt))), 1)
    starts = []
    for i in range(crowd.shape[0]):
        p = ped[:, i, :]
        best, along = np.full(len(t), np.inf), np.zeros(len(t))
        for z in np.linspace(0.0, TOP_M, 15):  # points of the axis; the nearest to the line of sight
            q = np.stack([p[:, 0], p[:, 1], np.full(len(t), z)], axis=1) - eye
            s = np.einsum("ij,ij->i", q, gaze)
            perp = np.where(s > 0.0, np.linalg.norm(q - s[:, None] * gaze, axis=1), np.inf)
            nearer = np.nan_to_num(perp, nan=np.inf) < best
            best, along = np.where(nearer, perp, best), np.where(nearer, s, along)
        on = best <= HALF_WIDTH_M + along * math.tan(math.radians(MARGIN_DEG))
        on &= np.nan_to_num(p[:, 0] - eye[:, 0], nan=-1.0) > 0.0
        on &= t >= crowd[i, 0] - 1e-9
        starts.append(dr.first_run(on, need))
    return starts


def main() -> None:
    kwargs, seed, n = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    for spec in sys.argv[4:]:
        with registered_kwargs(ENV, kwargs):
            r = evaluate(spec, ENV, n, seed, workers=1)
        circle = dr.dodge_gaze_realism(r.traces)
        original, dr.first_fixations = dr.first_fixations, first_fixations_aoi
        try:
            aoi = dr.dodge_gaze_realism(r.traces)
        finally:
            dr.first_fixations = original
        for name, res in (("circle", circle), ("aoi", aoi)):
            print(spec, sum(bool(tr.success) for tr in r.traces), name, round(res["score"], 3),
                  {k: round(v["value"], 3) for k, v in res["components"].items()}, flush=True)


if __name__ == "__main__":
    main()
