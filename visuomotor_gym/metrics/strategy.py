"""Measures that need a *moving* eye, shared by every family's realism table (version 2): how often the eye
saccades, how long it rests between saccades, and what share of its resting time lands on the task's
targets. Pure numpy on an :class:`~visuomotor_gym.bench.trace.EpisodeTrace` (``t``, ``dt``,
``saccade_onset``, ``in_saccade``); NaN where a measure is undefined.

A *fixation* here is what the plant does between saccades: a maximal run of rows with no saccade in
flight (neither ``saccade_onset`` nor ``in_saccade``). It includes pursuit and the vestibulo-ocular
stabilisation of a walker's gaze, as the "travel fixations" of the walking studies do (Patla & Vickers
1997: gaze "stable and travelling at the speed of whole body").

The human numbers these are scored against (``SACCADE_RATE_REFERENCE``, ``FIXATION_DURATION_REFERENCE``):

* fixations "last on average around 200-400 ms when viewing text, scenes or real environments" (Tatler &
  Land, in *Eye Movements from Laboratory to Life*, 2016, citing Land & Tatler 2009 and Rayner 1998);
* saccades "typically occur 3-4 times every second" (Richardson & Spivey 2004, *Encyclopedia of
  Biomaterials and Biomedical Engineering*, eye-tracking chapter); making tea, an object-related act of
  3.3 s "involved about 7 fixations", 2.1 per second (Land, Mennie & Rusted 1999, *Perception* 28:1311).
"""

from __future__ import annotations

import numpy as np

MIN_EPISODE_S = 0.5  # modelling choice: a rate over less than half a second is not a rate


def _resting(trace) -> np.ndarray:
    """(T,) rows with no saccade in flight: none started in the step, none still running at its end."""
    return ~(np.asarray(trace.in_saccade, dtype=bool) | np.asarray(trace.saccade_onset, dtype=bool))


def saccade_rate(trace) -> float:
    """Saccade onsets per second over the episode (0 for an eye that never saccades); NaN for an episode
    shorter than ``MIN_EPISODE_S``."""
    t = np.asarray(trace.t, dtype=float)
    duration = float(t[-1] - t[0]) if t.size else 0.0
    if duration < MIN_EPISODE_S:
        return float("nan")
    return float(np.count_nonzero(np.asarray(trace.saccade_onset, dtype=bool)[1:]) / duration)


def fixation_runs(trace) -> list[tuple[int, int]]:
    """``[(start, stop)]`` row ranges (stop exclusive) of the fixations bounded by a saccade on both sides:
    the rest before the first saccade and after the last one are cut off by the episode, not by the eye,
    so they are left out."""
    rest = _resting(trace)
    runs, start = [], None
    for k, flag in enumerate(rest.tolist()):
        if flag and start is None:
            start = k
        elif not flag and start is not None:
            runs.append((start, k))
            start = None
    # a run bounded by a saccade on both sides: it does not start at row 0 and it ended before the last row
    return [(a, b) for a, b in runs if a > 0]


def fixation_durations(trace) -> np.ndarray:
    """Durations (s) of the fixations bounded by saccades (may be empty)."""
    dt = float(trace.dt)
    return np.array([(b - a) * dt for a, b in fixation_runs(trace)], dtype=float)


def fixation_duration(trace) -> float:
    """Median duration (s) of the episode's fixations between saccades; NaN with fewer than two saccades."""
    d = fixation_durations(trace)
    return float(np.median(d)) if d.size else float("nan")


def fixation_share(trace, on_target: np.ndarray, rows: np.ndarray | None = None) -> float:
    """Share of the resting rows (no saccade in flight), among ``rows`` (a boolean mask, all rows when
    None), whose gaze is on a task target (``on_target``, a boolean per row). NaN when no row rests."""
    rest = _resting(trace)
    if rows is not None:
        rest = rest & np.asarray(rows, dtype=bool)
    if not rest.any():
        return float("nan")
    return float(np.mean(np.asarray(on_target, dtype=bool)[rest]))


def _entry(value, low, high, tolerance, unit, source, notes, group="moves") -> dict:
    return {"value": value, "low": low, "high": high, "tolerance": tolerance, "unit": unit, "source": source,
            "notes": notes, "group": group}


SACCADE_RATE_REFERENCE = _entry(
    3.0, 2.0, 4.0, 1.0, "saccades/s",
    "Richardson & Spivey 2004 (eye-tracking chapter, Encyclopedia of Biomaterials and Biomedical "
    "Engineering): saccades 'typically occur 3-4 times every second'; Land, Mennie & Rusted 1999, Perception "
    "28:1311: ~7 fixations per 3.3 s act while making tea (2.1/s). The range spans the two; the 1/s tolerance "
    "is our modelling choice (an eye that never saccades scores exp(-2) = 0.14).",
    "Saccade onsets per second of the episode (strategy.saccade_rate).")
FIXATION_DURATION_REFERENCE = _entry(
    0.3, 0.2, 0.4, 0.1, "s",
    "Tatler & Land 2016 (Eye Movements from Laboratory to Life), citing Land & Tatler 2009 and Rayner 1998: "
    "fixations last on average ~200-400 ms when viewing text, scenes or real environments. The 0.1 s "
    "tolerance is our modelling choice.",
    "Median over the episode of the saccade-free runs bounded by saccades on both sides "
    "(strategy.fixation_duration); undefined (scores 0) with fewer than two saccades.")
