"""Figures and videos of single episodes (needs the ``viz`` extra: matplotlib, imageio, imageio-ffmpeg).

* :mod:`visuomotor_gym.viz.plots`: the figure of an :class:`~visuomotor_gym.bench.trace.EpisodeTrace`
  of any family (:func:`plot_episode`, :func:`episode_figure`); the catch family's Eyecatch-style
  panels (gaze vs ball, Fig. 3/12; hand and eye tangential velocity, Fig. 4; 3-D ball and hand
  paths) and the numeric helpers behind them;
* :mod:`visuomotor_gym.viz.family_plots`: the reach, walk, stones and dodge figures (gaze point on
  the scene coloured by time, targets, hand or feet and footholds, saccades, time series);
* :mod:`visuomotor_gym.viz.video`: play one episode and write an MP4 (scene view beside the eye camera);
* :mod:`visuomotor_gym.viz.commands`: the ``vmgym plot`` and ``vmgym record`` subcommands.

Importing this package is cheap: matplotlib, imageio and MuJoCo are imported only when a plotting
or recording function is first used (the CLI imports :mod:`~visuomotor_gym.viz.commands` on every call).
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "plot_episode": "plots",
    "episode_figure": "plots",
    "gaze_points": "family_plots",
    "footholds": "family_plots",
    "plot_gaze_vs_ball": "plots",
    "plot_gaze_path": "plots",
    "plot_tangential_velocities": "plots",
    "plot_paths_3d": "plots",
    "gaze_ball_angles": "plots",
    "velocity_profiles": "plots",
    "record_episode": "video",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'visuomotor_gym.viz' has no attribute {name!r}")
    return getattr(importlib.import_module(f"visuomotor_gym.viz.{module}"), name)
