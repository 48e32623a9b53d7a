"""Example figures of ``vmgym plot``, one per family, for docs/images/plots/ (palette PNGs < 200 KB).

    python docs/images/plots/make_examples.py docs/images/plots [ENV_ID ...]

Each figure is what ``vmgym plot --agent A --env ID --seed S`` writes, reduced to 256 colours
(Pillow, no dithering) to keep the repository small. ShelfReach uses seed 1 (faraway reaches the
object; on seed 0 it touches a back panel).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from PIL import Image

from visuomotor_gym.viz import commands
from visuomotor_gym.viz.plots import plot_episode

CASES = (("EyeCatch-v0", "eyecatch", 0), ("ShelfReach-v0", "faraway", 1), ("ObstacleWalk-v0", "iwao", 0),
         ("SteppingStones-v0", "lookahead", 0), ("ObstacleDodge-v0", "fajen_warren", 0))


def main(argv: list[str]) -> None:
    out, only = Path(argv[0]), set(argv[1:])
    for env_id, agent, seed in CASES:
        if only and env_id not in only:
            continue
        trace = commands._play(agent, env_id, seed)
        path = plot_episode(trace, out / commands.plot_filename(env_id, agent, seed))
        img = Image.open(path).convert("RGB")
        img.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)
        print(path, os.path.getsize(path) // 1000, "kB")


if __name__ == "__main__":
    main(sys.argv[1:] or ["docs/images/plots"])
