"""Where ObstacleDodge's threats come from, per crowd preset (no physics: the sampler's straight-line
pedestrians against a walker going straight along +x at the nominal 1.3 m/s).

A pedestrian is a threat when it comes within 0.55 m of the walker's axis (pedestrian radius 0.25 m plus
about the walker's half-width; modelling choice for this count). Printed: the fraction of threats, and the
10th/50th/90th percentile of their absolute bearing 2 s before the closest approach (on a collision course
the bearing stays constant, so this is where a still eye would have to look). Used for the "wide" preset's
comment (visuomotor_gym/tasks/obstacle_dodge.py) and dodge_groups.md, section "wide".

    python docs/reproductions/data/terrain/dodge_wide_bearings.py [--seeds 1000]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from visuomotor_gym.tasks.obstacle_dodge import CROWD_PRESETS, NOMINAL_SPEED, sample_crowd

NEAR_M = 0.55
LEAD_S = 2.0
DT = 0.02


def threat_bearings(dist, seeds: int) -> tuple[float, np.ndarray]:
    threats, total, bearings = 0, 0, []
    for seed in range(seeds):
        crowd = sample_crowd(np.random.default_rng(seed), dist)
        t = np.arange(0.0, crowd.goal / NOMINAL_SPEED, DT)
        wx = NOMINAL_SPEED * t
        for onset, x0, y0, vx, vy, *_ in crowd.pedestrians:
            total += 1
            tt = np.clip(t - onset, 0.0, None)
            px, py = x0 + vx * tt, y0 + vy * tt
            d = np.where(t >= onset, np.hypot(px - wx, py), np.inf)
            k = int(np.argmin(d))
            if d[k] < NEAR_M:
                threats += 1
                j = max(k - int(round(LEAD_S / DT)), int(np.argmax(t >= onset)))
                bearings.append(abs(math.degrees(math.atan2(py[j], px[j] - wx[j]))))
    return threats / total, np.array(bearings)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=1000)
    args = parser.parse_args()
    for name in sorted(CROWD_PRESETS):
        frac, b = threat_bearings(CROWD_PRESETS[name], args.seeds)
        p10, p50, p90 = np.percentile(b, [10, 50, 90])
        print(
            f"{name:7s} threats {frac:.2f} of pedestrians; bearing 2 s before contact p10/p50/p90 "
            f"{p10:.0f}/{p50:.0f}/{p90:.0f} deg, beyond 60 deg {np.mean(b > 60):.2f}"
        )


if __name__ == "__main__":
    main()
