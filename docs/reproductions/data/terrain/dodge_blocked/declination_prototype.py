"""Prototype, not merged (session 43; dodge_groups.md, "Two prototypes that lower the gain"): a ground-contact
range cue in the periphery. A pedestrian's distance read from the angular declination of its feet below the
horizon (Ooi, Wu & He 2001, Nature 414:197), with the eye ``H`` m above the ground, has the std ``(d**2 + H**2) / H``
times the angular std of a look at that place (the position law's lateral std / d); the depth std becomes the
inverse-variance combination of that and the disparity depth std, and the depth-rate std shrinks in the same
ratio. It monkeypatches ``vision.foveation._sigmas``, so it needs the pure-Python retina; the agents' beliefs
(``believed_sigmas``) see the same law, so they know their eye.

    VISUOMOTOR_GYM_PURE_PYTHON=1 python declination_prototype.py H KWARGS_JSON FIRST N OUT.json SPEC...
"""

import math
import runpy
import sys
from pathlib import Path

from visuomotor_gym.vision import foveation

EVAL = Path(__file__).resolve().parent.parent / "dodge_wide_eval.py"


def main() -> None:
    height = float(sys.argv[1])
    original = foveation._sigmas

    def with_declination(distance, eccentricity_rad, retinal_speed, params, fixation=None):
        s = original(distance, eccentricity_rad, retinal_speed, params, fixation)
        if not (params.foveated and params.periphery_on) or distance <= 0.0:
            return s
        declination = (distance * distance + height * height) / height * (s[1] / distance)
        depth = 1.0 / math.sqrt(1.0 / s[0] ** 2 + 1.0 / declination ** 2)
        return (depth, s[1], s[2], s[3] * depth / s[0], s[4], s[5])

    foveation._sigmas = with_declination
    sys.argv = [str(EVAL)] + sys.argv[2:]
    runpy.run_path(str(EVAL), run_name="__main__")


if __name__ == "__main__":
    main()
