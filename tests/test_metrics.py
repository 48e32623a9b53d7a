"""Tests of visuomotor_gym.metrics on synthetic episode traces with known answers.

The traces are built directly as :class:`EpisodeTrace` objects (no simulation): a ballistic ball, a
gaze that is either fixed or locked on the ball, saccades at chosen onset times, a head and a hand
moved by chosen profiles (minimum-jerk submovements, Eyecatch Eq. 15-16).
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from visuomotor_gym import metrics as M
from visuomotor_gym.bench.trace import EpisodeTrace

DT = 0.02
G = np.array([0.0, 0.0, -9.81])
EYE = np.array([0.0, 0.0, 1.13])
RELEASE = np.array([5.0, 0.3, 1.5])
ARRIVAL = np.array([0.35, -0.25, 1.0])
FLIGHT = 1.0  # s; apex of this throw at v0z / g = 0.449 s, sampled at the row t = 0.44 s

COMPONENTS = (
    "first_saccade_latency_s",
    "catchup_saccade_interval_s",
    "pursuit_share_after_apex",
    "ball_foveation",
    "head_contribution",
    "saccade_hand_synchrony",
)


# --- synthetic traces ----------------------------------------------------------------------------
def ball_path(t: np.ndarray, release=RELEASE, arrival=ARRIVAL, flight=FLIGHT):
    """Ballistic ball from ``release`` (t = 0) to ``arrival`` (t = flight): positions, velocities."""
    v0 = (arrival - release - 0.5 * G * flight**2) / flight
    pos = release + np.outer(t, v0) + 0.5 * np.outer(t**2, G)
    vel = v0 + np.outer(t, G)
    return pos, vel


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def direction(az_deg, el_deg):
    """World direction from azimuth (about z, from +x toward +y) and elevation (deg); broadcasts."""
    az, el = np.radians(az_deg), np.radians(el_deg)
    x, y, z = np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el))
    return np.stack([x, y, z], axis=-1)


def min_jerk(t, t0, duration):
    """Minimum-jerk position profile 0 -> 1 (Eyecatch Eq. 15 integrated): 10 s^3 - 15 s^4 + 6 s^5."""
    s = np.clip((np.asarray(t) - t0) / duration, 0.0, 1.0)
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def hand_from_submovements(t, submovements, start=(0.2, -0.25, 0.9)):
    """Hand path as a superposition (Eyecatch Eq. 16) of ``(onset, duration, displacement)`` submovements."""
    p = np.tile(np.asarray(start, dtype=float), (len(t), 1))
    for t0, duration, b in submovements:
        p += np.outer(min_jerk(t, t0, duration), b)
    return p


def make_trace(
    *,
    duration=FLIGHT,
    saccades=(),
    saccade_rows=2,
    gaze=None,
    head=None,
    hand=None,
    latency_s=None,
    caught=True,
    diverged=False,
) -> EpisodeTrace:
    """An :class:`EpisodeTrace` with chosen arrays.

    ``saccades``: onset times (s); onset ``s`` flags row ``k = round(s / dt) + 1`` (the saccade starts at the
    start of step k, at ``t[k] - dt``), and ``in_saccade`` is set on ``saccade_rows`` rows from there.
    ``gaze``: None (fixed on the release point), "ball" (exactly at the ball on every row), or a (T, 3)
    array. ``head``: None (straight ahead, +x) or a (T, 3) array. ``hand``: None (still) or (T, 3).
    """
    t = np.round(np.arange(0.0, duration + 1e-9, DT), 10)
    n = len(t)
    ball, ball_vel = ball_path(t)
    eye = np.tile(EYE, (n, 1))
    if gaze is None:
        gaze = np.tile(unit(RELEASE - EYE), (n, 1))
    elif isinstance(gaze, str) and gaze == "ball":
        gaze = unit(ball - eye)
    onset = np.zeros(n, dtype=bool)
    in_sacc = np.zeros(n, dtype=bool)
    for s in saccades:
        k = int(round(s / DT)) + 1
        onset[k] = True
        in_sacc[k : k + saccade_rows] = True
    if latency_s is None:
        latency_s = np.full(n, 1e-3)
    latency_s = np.asarray(latency_s, dtype=float).copy()
    latency_s[0] = np.nan
    action = np.zeros((n, 6))
    action[0] = np.nan
    return EpisodeTrace(
        env_id="EyeCatch-v0",
        agent="synthetic",
        seed=0,
        dt=DT,
        t=t,
        gaze_dir=np.asarray(gaze, dtype=float),
        eye_pos=eye,
        head_dir=np.tile([1.0, 0.0, 0.0], (n, 1)) if head is None else np.asarray(head, dtype=float),
        in_saccade=in_sacc,
        saccade_onset=onset,
        action=action,
        latency_s=latency_s,
        success=caught and not diverged,
        diverged=diverged,
        truncated=False,
        task={
            "ball_pos": ball,
            "ball_vel": ball_vel,
            "hand_pos": np.tile([0.2, -0.25, 0.9], (n, 1)) if hand is None else np.asarray(hand, dtype=float),
            "ball_visible": ~in_sacc,
            "missed": not caught and not diverged,
            "release_pos": RELEASE.copy(),
            "arrival_pos": ARRIVAL.copy(),
            "flight_time": FLIGHT,
        },
    )


# --- saccade timing --------------------------------------------------------------------------------
def test_saccade_onsets_give_known_latency_and_intervals():
    tr = make_trace(saccades=(0.10, 0.30, 0.54, 0.90), gaze="ball")
    np.testing.assert_allclose(M.saccade_onset_times(tr), [0.10, 0.30, 0.54, 0.90], atol=1e-9)
    assert M.first_saccade_latency(tr) == pytest.approx(0.10)
    np.testing.assert_allclose(M.saccade_intervals(tr), [0.20, 0.24, 0.36], atol=1e-9)
    # Catch-up: intervals that start at or before the apex (0.44 s): 0.20 (from 0.10) and 0.24 (from 0.30).
    assert M.catchup_saccade_interval(tr) == pytest.approx(0.22)
    # the same onsets with the eye left on the thrower: no saccade lands on the ball, no catch-up interval
    assert math.isnan(M.catchup_saccade_interval(make_trace(saccades=(0.10, 0.30, 0.54, 0.90))))


def test_ball_apex_time_is_the_highest_sample():
    tr = make_trace()
    v0z = (ARRIVAL[2] - RELEASE[2] + 0.5 * 9.81 * FLIGHT**2) / FLIGHT
    assert M.ball_apex_time(tr) == pytest.approx(0.44)
    assert abs(M.ball_apex_time(tr) - v0z / 9.81) <= DT


def test_no_saccade_gives_nan_timing():
    tr = make_trace()
    assert math.isnan(M.first_saccade_latency(tr))
    assert M.saccade_intervals(tr).size == 0
    assert math.isnan(M.catchup_saccade_interval(tr))
    # a single saccade: a latency but no interval
    tr = make_trace(saccades=(0.2,))
    assert M.first_saccade_latency(tr) == pytest.approx(0.2)
    assert math.isnan(M.catchup_saccade_interval(tr))


# --- foveation and pursuit -------------------------------------------------------------------------
def locked_gaze_after(t_lock: float) -> np.ndarray:
    """Gaze fixed on the release point before ``t_lock``, exactly on the ball from ``t_lock`` on."""
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    ball, _ = ball_path(t)
    gaze = unit(ball - EYE)
    gaze[t < t_lock - 1e-9] = unit(RELEASE - EYE)
    return gaze


def test_gaze_on_the_ball_from_a_human_first_saccade_gives_foveation_one():
    # A first saccade at 0.20 s (human latency) that lands by 0.24 s: on the ball for the whole window,
    # which starts at 0.25 s for every agent.
    tr = make_trace(saccades=(0.20,), saccade_rows=1, gaze=locked_gaze_after(0.22))
    assert M.ball_foveation(tr) == pytest.approx(1.0)
    # Counting from the release would include the rows where the gaze stays on the release point.
    ecc = M.ball_eccentricity_deg(tr)
    assert np.mean(ecc <= 5.0) < 0.95


def test_foveation_window_is_the_same_for_every_agent():
    """A late first saccade no longer moves the window: it costs the rows the ball was off the fovea."""
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    early = make_trace(saccades=(0.20,), saccade_rows=1, gaze=locked_gaze_after(0.22))
    late = make_trace(saccades=(0.48,), saccade_rows=1, gaze=locked_gaze_after(0.50))
    window = t >= 0.25 - 1e-9
    ecc = M.ball_eccentricity_deg(late)
    assert M.ball_foveation(late) == pytest.approx(np.mean(ecc[window] <= 5.0))
    assert M.ball_foveation(late) < M.ball_foveation(early) - 0.1


def test_foveation_counts_rows_off_the_ball():
    gaze = locked_gaze_after(0.22)
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    off = (t > 0.59) & (t < 0.69)  # 5 rows with the gaze 10 deg below the ball
    az, el = np.degrees(np.arctan2(gaze[off, 1], gaze[off, 0])), np.degrees(np.arcsin(gaze[off, 2]))
    gaze[off] = direction(az, el - 10.0)
    tr = make_trace(saccades=(0.20,), saccade_rows=1, gaze=gaze)
    n_counted = int(np.sum(t >= 0.25 - 1e-9))
    assert off.sum() == 5
    assert M.ball_foveation(tr) == pytest.approx(1.0 - 5 / n_counted)


def test_foveation_without_saccade():
    tr = make_trace(gaze="ball")
    assert M.ball_foveation(tr) == pytest.approx(1.0)
    tr = make_trace()  # gaze left on the release point: the ball leaves the fovea within a few rows
    assert M.ball_foveation(tr) < 0.2


def test_pursuit_share_after_apex():
    tr = make_trace(gaze="ball")
    assert M.pursuit_share_after_apex(tr) == pytest.approx(1.0)
    t = tr.t
    after = int(np.sum(t > M.ball_apex_time(tr) + 1e-9))
    # one saccade after the apex, in flight for 2 rows (onset row + next): those rows are not pursuit
    tr = make_trace(gaze="ball", saccades=(0.70,), saccade_rows=2)
    assert M.pursuit_share_after_apex(tr) == pytest.approx(1.0 - 2 / after)
    # a saccade before the apex does not count
    tr = make_trace(gaze="ball", saccades=(0.20,), saccade_rows=2)
    assert M.pursuit_share_after_apex(tr) == pytest.approx(1.0)
    # gaze left behind: no pursuit
    assert M.pursuit_share_after_apex(make_trace()) == pytest.approx(0.0)


# --- head ------------------------------------------------------------------------------------------
def sweep_up(max_el_deg: float) -> np.ndarray:
    """Gaze straight ahead rising linearly from 0 to ``max_el_deg`` elevation over the episode."""
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    return direction(0.0, max_el_deg * t / t[-1]), max_el_deg * t / t[-1]


def test_head_contribution_follows_the_dead_zone_law():
    gaze, el = sweep_up(51.0)  # 51 deg: no sample falls on a 25 deg boundary
    # Head still while the gaze goes to 51 deg: every demand row (gaze > 25 deg) is non-compliant.
    assert M.head_contribution(make_trace(gaze=gaze)) == pytest.approx(0.0)
    # Head obeying Eyecatch Eq. 17: it turns by max(0, gaze - 20 deg), so the eye stays at <= 20 deg.
    law_head = direction(0.0, np.maximum(0.0, el - 20.0))
    assert M.head_contribution(make_trace(gaze=gaze, head=law_head)) == pytest.approx(1.0)
    # Head turning half as much as needed: compliant only while the excess is within the tolerance.
    half = direction(0.0, 0.5 * np.maximum(0.0, el - 20.0))
    demand = el > 25.0
    expected = np.mean((el - 0.5 * np.maximum(0.0, el - 20.0))[demand] <= 25.0 + 1e-9)
    assert 0.0 < expected < 1.0
    assert M.head_contribution(make_trace(gaze=gaze, head=half)) == pytest.approx(expected)


def test_head_contribution_undefined_inside_the_dead_zone():
    gaze, _ = sweep_up(18.0)
    assert math.isnan(M.head_contribution(make_trace(gaze=gaze)))


# --- hand ------------------------------------------------------------------------------------------
SUBMOVEMENTS = (  # (onset s, duration s, displacement m): superposed and touching, changing direction
    (0.10, 0.24, np.array([0.10, -0.10, 0.10])),
    (0.34, 0.26, np.array([0.08, 0.06, -0.04])),
    (0.60, 0.20, np.array([-0.04, -0.08, 0.06])),
    (0.80, 0.18, np.array([0.06, 0.02, 0.05])),
)


def test_hand_submovement_onsets_recovered_within_one_step():
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    tr = make_trace(hand=hand_from_submovements(t, SUBMOVEMENTS))
    onsets = M.hand_submovement_onsets(tr)
    truth = np.array([s[0] for s in SUBMOVEMENTS])
    assert onsets.shape == truth.shape, onsets
    assert np.all(np.abs(onsets - truth) <= DT + 1e-9), (onsets, truth)
    assert onsets[0] == pytest.approx(truth[0])  # from rest the speed minimum is exactly at the onset


def test_hand_submovement_onsets_ignore_tremor_and_bound_overlap():
    rng = np.random.default_rng(0)
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    hand = hand_from_submovements(t, SUBMOVEMENTS) + rng.normal(0.0, 1e-4, (len(t), 3))  # 0.1 mm jitter
    onsets = M.hand_submovement_onsets(make_trace(hand=hand))
    assert np.all(np.abs(onsets - [s[0] for s in SUBMOVEMENTS]) <= DT + 1e-9)
    still = make_trace(hand=np.array([0.2, -0.25, 0.9]) + rng.normal(0.0, 1e-4, (len(t), 3)))
    assert M.hand_submovement_onsets(still).size == 0
    assert math.isnan(M.saccade_hand_synchrony(still))
    # Overlapping submovements: the onset comes no earlier than the truth and no later than the end of
    # the previous submovement (+ one step), as documented.
    overlapping = ((0.10, 0.30, np.array([0.1, -0.1, 0.1])), (0.34, 0.30, np.array([0.1, 0.08, -0.05])))
    onsets = M.hand_submovement_onsets(make_trace(hand=hand_from_submovements(t, overlapping)))
    assert onsets.size == 2
    assert 0.34 - 1e-9 <= onsets[1] <= 0.40 + DT + 1e-9


def test_saccade_hand_synchrony():
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    hand = hand_from_submovements(t, SUBMOVEMENTS)
    onsets = [s[0] for s in SUBMOVEMENTS]
    assert M.saccade_hand_synchrony(make_trace(hand=hand, saccades=onsets)) == pytest.approx(1.0)
    late = [s + 0.10 for s in onsets]  # saccades 100 ms after each hand onset: outside the +-60 ms window
    assert M.saccade_hand_synchrony(make_trace(hand=hand, saccades=late)) == pytest.approx(0.0)
    # saccades only at the first two hand onsets
    assert M.saccade_hand_synchrony(make_trace(hand=hand, saccades=onsets[:2])) == pytest.approx(0.5)
    # hand submovements but no saccade at all
    assert M.saccade_hand_synchrony(make_trace(hand=hand)) == 0.0


@pytest.mark.parametrize("t0", [0.21, 0.20, 0.233])
def test_hand_peak_speed_of_a_min_jerk_submovement(t0):
    distance, duration = 0.4, 0.4
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    hand = hand_from_submovements(t, [(t0, duration, np.array([0.0, -0.6, 0.8]) * distance)])
    # Eyecatch Eq. 15: peak of 30 s^2 (1 - s)^2 * distance / duration is 1.875 distance / duration;
    # per-step finite differences see the mean over 20 ms around the peak (< 1 % low here).
    assert M.hand_peak_speed(make_trace(hand=hand)) == pytest.approx(1.875 * distance / duration, rel=0.01)


def test_reaction_times_and_miss_distance():
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    hand = hand_from_submovements(t, [(0.20, 0.4, np.array([0.0, 0.0, 0.4]))])
    tr = make_trace(hand=hand, saccades=(0.24, 0.44))
    rt = M.reaction_times(tr)
    assert rt["first_saccade_s"] == pytest.approx(0.24)
    # 1.875 * 30 s^2 (1-s)^2 > 0.1 m/s from s ~ 0.06 (24 ms after onset): the first faster step ends at 0.24 s
    assert rt["hand_onset_s"] == pytest.approx(0.24)
    assert math.isnan(M.reaction_times(make_trace())["hand_onset_s"])
    # the ball ends at ARRIVAL; a hand held 10 cm beside it: closest approach 0.1 m
    still = make_trace(hand=np.tile(ARRIVAL + [0.0, 0.1, 0.0], (len(t), 1)))
    assert M.miss_distance(still) == pytest.approx(0.1, abs=1e-9)


# --- Wilson interval -------------------------------------------------------------------------------
@pytest.mark.parametrize("k,n", [(0, 1), (1, 1), (0, 10), (3, 10), (10, 10), (49, 100), (98, 100), (1, 1000)])
@pytest.mark.parametrize("confidence", [0.95, 0.9])
def test_wilson_interval_matches_scipy(k, n, confidence):
    stats = pytest.importorskip("scipy.stats")
    ref = stats.binomtest(k, n).proportion_ci(confidence_level=confidence, method="wilson")
    low, high = M.wilson_interval(k, n, confidence)
    assert low == pytest.approx(ref.low, abs=1e-12)
    assert high == pytest.approx(ref.high, abs=1e-12)


def test_wilson_interval_edge_cases():
    assert M.wilson_interval(0, 0) == (0.0, 1.0)
    low, high = M.wilson_interval(0, 20)
    assert low == 0.0 and 0.0 < high < 0.2
    with pytest.raises(ValueError):
        M.wilson_interval(5, 3)
    with pytest.raises(ValueError):
        M.wilson_interval(1, 3, confidence=1.5)


# --- reference table and scoring -------------------------------------------------------------------
def test_reference_table_has_every_component_with_a_source():
    ref = M.load_reference()
    assert set(ref) == set(COMPONENTS) == set(M.COMPONENT_MEASURES)
    for name, entry in ref.items():
        for key in ("value", "low", "high", "unit", "source", "notes"):
            assert key in entry, (name, key)
        assert isinstance(entry["source"], str) and entry["source"].strip(), name
        assert isinstance(entry["unit"], str) and entry["unit"].strip(), name
        assert entry["low"] <= entry["value"] <= entry["high"], name
        assert entry.get("tolerance", entry["high"] - entry["low"]) > 0, name


def test_reference_numbers_from_the_papers():
    ref = M.load_reference()
    assert ref["catchup_saccade_interval_s"]["value"] == 0.2  # Eyecatch 4.1, Fig. 4; Eom 4.1
    assert "hand_peak_speed_m_s" not in ref  # the hand controller caps it at 2 m/s (Eyecatch 4.3): not scored
    assert "Young and Stark 1963" in ref["catchup_saccade_interval_s"]["source"]
    assert "Eq. 17" in ref["head_contribution"]["source"]
    assert "Fig. 4" in ref["saccade_hand_synchrony"]["source"]


@pytest.mark.parametrize("name", COMPONENTS)
def test_score_is_one_inside_the_range_and_falls_outside(name):
    ref = M.load_reference()
    entry = ref[name]
    low, high = entry["low"], entry["high"]
    tol = entry.get("tolerance", high - low)
    for v in np.linspace(low, high, 5):
        assert M.score_component(name, v, ref) == 1.0
    below = [M.score_component(name, low - d, ref) for d in (0.25 * tol, tol, 2 * tol, 4 * tol)]
    above = [M.score_component(name, high + d, ref) for d in (0.25 * tol, tol, 2 * tol, 4 * tol)]
    for scores in (below, above):
        assert all(0.0 <= s < 1.0 for s in scores)
        assert all(a > b for a, b in itertools.pairwise(scores))
        assert scores[1] == pytest.approx(math.exp(-0.5))
        assert scores[-1] < 1e-3
    assert math.isnan(M.score_component(name, float("nan"), ref))


def test_score_component_rejects_unknown_names():
    with pytest.raises(KeyError):
        M.score_component("blink_rate", 1.0)


def test_gaze_realism_scores_undefined_components_zero_and_takes_the_weaker_group():
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    tr = make_trace(gaze="ball", saccades=(0.2,), hand=hand_from_submovements(t, SUBMOVEMENTS))
    ref = M.load_reference()
    out = M.gaze_realism([tr, tr], ref)
    assert set(out["components"]) == set(COMPONENTS)
    comps = out["components"]
    # one saccade only: no interval; the component is undefined and scores 0 (it is not left out)
    assert math.isnan(comps["catchup_saccade_interval_s"]["value"])
    assert comps["catchup_saccade_interval_s"]["episodes"] == 0
    assert comps["catchup_saccade_interval_s"]["score"] == 0.0
    assert comps["first_saccade_latency_s"]["value"] == pytest.approx(0.2)
    assert comps["first_saccade_latency_s"]["score"] == 1.0
    # head fixed while the gaze follows the ball down to the hand (39 deg below straight ahead): 0
    assert comps["head_contribution"]["value"] == pytest.approx(0.0)
    assert comps["pursuit_share_after_apex"]["value"] == pytest.approx(1.0)
    groups = {}
    for name, c in comps.items():
        groups.setdefault(ref[name]["group"], []).append(c["score"])
    assert set(groups) == {"moves", "where"}
    assert out["score"] == pytest.approx(min(np.mean(v) for v in groups.values()))
    assert 0.0 <= out["score"] <= 1.0
    for name, c in comps.items():
        if not math.isnan(c["value"]):
            assert c["score"] == pytest.approx(M.score_component(name, c["value"], ref))


def test_gaze_realism_value_is_the_mean_over_episodes():
    a = make_trace(saccades=(0.2,))
    b = make_trace(saccades=(0.3,))
    out = M.gaze_realism([a, b, make_trace()])  # the third never saccades: excluded from the latency mean
    assert out["components"]["first_saccade_latency_s"]["value"] == pytest.approx(0.25)
    assert out["components"]["first_saccade_latency_s"]["episodes"] == 2
    # its score is scaled by the share of episodes that define it (2 of 3)
    assert out["components"]["first_saccade_latency_s"]["score"] == pytest.approx(math.exp(-0.5) * 2 / 3)


# --- summary -----------------------------------------------------------------------------------------
def test_summarize_is_json_serialisable_with_documented_keys():
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    hand = hand_from_submovements(t, SUBMOVEMENTS)
    lat = np.arange(len(t)) * 1e-3  # 0, 1, 2, ... ms (row 0 becomes NaN)
    traces = [
        make_trace(gaze="ball", saccades=(0.2, 0.4), hand=np.tile(ARRIVAL, (len(t), 1)), latency_s=lat),
        make_trace(gaze="ball", saccades=(0.3,), hand=hand, latency_s=lat, caught=False),
        make_trace(caught=False, latency_s=lat),  # no saccade, hand still
        make_trace(caught=False, diverged=True, latency_s=lat),
    ]
    s = M.summarize(traces)
    text = json.dumps(s, allow_nan=False)
    assert json.loads(text) == s
    assert set(s) >= {
        "episodes", "caught", "catch_rate", "catch_rate_ci95", "gaze_realism", "latency_ms",
        "reaction_times_s", "miss_distance_m", "time_to_catch_s", "diverged",
    }
    assert s["episodes"] == 4 and s["caught"] == 1 and s["diverged"] == 1
    assert s["catch_rate"] == pytest.approx(0.25)
    assert s["catch_rate_ci95"] == pytest.approx(list(M.wilson_interval(1, 4)))
    assert set(s["gaze_realism"]) == {"score", "components", "version"} and s["gaze_realism"]["version"] == 2
    assert set(s["gaze_realism"]["components"]) == set(COMPONENTS)
    assert set(s["latency_ms"]) == {"p50", "p95", "max"}
    assert s["latency_ms"]["max"] == pytest.approx(1e3 * lat[-1])
    assert s["latency_ms"]["p50"] == pytest.approx(np.median(1e3 * lat[1:]))
    assert set(s["reaction_times_s"]) == {"first_saccade", "hand_onset"}
    assert s["reaction_times_s"]["first_saccade"] == pytest.approx({"mean": 0.25, "median": 0.25})
    assert s["time_to_catch_s"] == pytest.approx({"mean": FLIGHT, "median": FLIGHT})
    # miss distance over the two non-caught, non-diverged episodes (the caught one, 0 m, is left out)
    missed = [M.miss_distance(tr) for tr in traces[1:3]]
    assert min(missed) > 0.05
    assert s["miss_distance_m"] == pytest.approx({"mean": np.mean(missed), "median": np.median(missed)})
    for v in (s["catch_rate"], s["gaze_realism"]["score"], s["latency_ms"]["p95"]):
        assert isinstance(v, float)


def test_summarize_uses_none_for_undefined():
    s = M.summarize([make_trace(caught=False)])
    json.dumps(s, allow_nan=False)
    assert s["time_to_catch_s"] == {"mean": None, "median": None}
    assert s["reaction_times_s"]["first_saccade"] == {"mean": None, "median": None}
    assert s["gaze_realism"]["components"]["first_saccade_latency_s"]["value"] is None
    empty = M.summarize([])
    json.dumps(empty, allow_nan=False)
    assert empty["episodes"] == 0 and empty["catch_rate"] is None and empty["catch_rate_ci95"] == [0.0, 1.0]
    assert empty["gaze_realism"]["score"] is None
    assert empty["latency_ms"] == {"p50": None, "p95": None, "max": None}


def test_summarize_on_a_simulated_episode():
    """Smoke test on a real trace: the metrics accept what the evaluator records."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    env = gym.make("EyeCatch-v0")
    try:
        policy = make_agent("zero", "EyeCatch-v0", env.action_space.shape[0], seed=0)
        tr = run_episode(env, policy, seed=0, env_id="EyeCatch-v0", agent="zero")
    finally:
        env.close()
    s = M.summarize([tr])
    json.dumps(s, allow_nan=False)
    assert s["episodes"] == 1
    score = s["gaze_realism"]["score"]
    assert score is None or 0.0 <= score <= 1.0


# --- catch hand paths against Faraway's reach model (metrics.catch_handpath) ------------------------------
HAND_REST = np.array([0.2, -0.25, 0.9])
# Interception points of a catching hand (to the front, right, above, low): a set of transports, so the
# medians are over paths of several directions and lengths (0.19 to 0.42 m).
CATCH_POINTS = ((0.45, -0.1, 1.25), (0.35, -0.4, 1.1), (0.55, -0.2, 0.95), (0.3, 0.05, 1.3), (0.5, -0.45, 1.2))


def transport_trace(path_kind: str, catch_point, *, start=0.2, duration=0.6, caught=True, gaze=None):
    """A trace whose catch site rests at HAND_REST, moves to ``catch_point`` from ``start`` over ``duration``
    (s) along ``path_kind`` ("faraway": handpath.faraway_path; "straight": straight with minimum-jerk
    timing; "revised": first towards a point 20 cm off, then on to the catch point), then waits there."""
    from visuomotor_gym import handpath

    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    end = np.asarray(catch_point, dtype=float)
    k0, k1 = round(start / DT), round((start + duration) / DT)
    n = k1 - k0 + 1
    if path_kind == "faraway":
        move = handpath.faraway_path(HAND_REST, end, n)
    elif path_kind == "straight":
        move = handpath.minimum_jerk_path(HAND_REST, end, n)
    elif path_kind == "revised":
        wrong = end + np.array([0.0, 0.2, -0.05])
        half = n // 2
        move = np.vstack([handpath.minimum_jerk_path(HAND_REST, wrong, half),
                          handpath.minimum_jerk_path(wrong, end, n - half + 1)[1:]])
    else:
        raise ValueError(path_kind)
    hand = np.vstack([np.tile(HAND_REST, (k0, 1)), move, np.tile(end, (len(t) - k1 - 1, 1))])
    return make_trace(hand=hand, gaze=gaze, caught=caught)


def catch_paths(kind, **kw):
    return [transport_trace(kind, p, **kw) for p in CATCH_POINTS]


def test_catch_hand_path_of_faraway_transports_is_human_like():
    from visuomotor_gym import handpath
    from visuomotor_gym.metrics import catch_handpath as C

    out = C.catch_hand_path(catch_paths("faraway"))
    comps = out["components"]
    assert out["verdict"] == "human-like" and out["episodes"] == len(CATCH_POINTS)
    assert comps["faraway_distance_cm"]["value"] < 1.0  # onset/offset detection trims a few mm only
    assert comps["curvature_index"]["value"] == pytest.approx(1.0, abs=0.1)
    assert comps["peak_speed_time"]["value"] == pytest.approx(handpath.beta_peak_time(), abs=0.05)
    for name in ("faraway_distance_cm", "curvature_index", "peak_speed_time"):
        assert comps[name]["score"] == 1.0
    assert comps["gaze_hand_lead_s"]["score"] != comps["gaze_hand_lead_s"]["score"]  # NaN: not scored


def test_catch_hand_path_of_straight_transports_is_straight_line_like():
    from visuomotor_gym.metrics import catch_handpath as C

    out = C.catch_hand_path(catch_paths("straight"))
    comps = out["components"]
    assert out["verdict"] == "straight-line-like"
    assert abs(comps["curvature_index"]["value"]) < 0.01
    # A straight path is close to Faraway's (~4-6.4 cm at 56.7 cm: docs/reproductions/faraway.md): the
    # distance alone would call it human-like; the curvature index tells them apart.
    assert 3.0 < comps["faraway_distance_cm"]["value"] < C.HUMAN_LIKE_MAX_CM
    assert comps["curvature_index"]["score"] < 0.7
    assert comps["peak_speed_time"]["value"] == pytest.approx(0.5, abs=0.05)  # minimum jerk peaks mid-way


def test_catch_hand_path_of_revised_transports_is_unlike_a_single_reach():
    from visuomotor_gym.metrics import catch_handpath as C

    out = C.catch_hand_path(catch_paths("revised"))
    assert out["verdict"] == "unlike a single reach"
    assert out["components"]["faraway_distance_cm"]["value"] > C.UNLIKE_REACH_MIN_CM
    assert out["components"]["faraway_distance_cm"]["score"] < 0.01


def test_catch_transport_segment_leaves_out_the_wait_and_ends_a_miss_at_the_closest_approach():
    from visuomotor_gym.metrics import catch_handpath as C

    tr = transport_trace("faraway", CATCH_POINTS[0], start=0.2, duration=0.5)
    onset, arrival, end = C.catch_reach_segment(tr)
    assert end == len(tr.t) - 1  # caught: the last step
    assert 10 <= onset <= 12 and 32 <= arrival <= 35  # the move spans rows 10..35; the wait is left out
    # not caught: the transport heads for the hand's position at the ball's closest approach
    missed = transport_trace("faraway", CATCH_POINTS[0], caught=False)
    gap = np.linalg.norm(missed.ball_pos - missed.hand_pos, axis=1)
    assert C.catch_reach_segment(missed)[2] == int(np.argmin(gap))


def test_catch_hand_path_missing_data_gives_undefined_values_not_errors():
    from visuomotor_gym.metrics import catch_handpath as C

    still = make_trace()  # the hand never moves
    assert C.catch_reach_segment(still) is None
    assert all(math.isnan(v) for v in C.catch_hand_path_measures(still).values())
    nan_hand = transport_trace("faraway", CATCH_POINTS[0])
    nan_hand.task["hand_pos"] = nan_hand.hand_pos.copy()
    nan_hand.task["hand_pos"][5] = np.nan
    no_hand = transport_trace("faraway", CATCH_POINTS[0])
    del no_hand.task["hand_pos"]
    short = transport_trace("faraway", HAND_REST + [0.03, 0.0, 0.0])  # 3 cm: not a reach
    for tr in (nan_hand, no_hand, short):
        assert all(math.isnan(v) for v in C.catch_hand_path_measures(tr).values())
    out = C.catch_hand_path([still, nan_hand, no_hand, short])
    assert out["episodes"] == 0 and out["verdict"] is None and math.isnan(out["score"])
    assert all(c["episodes"] == 0 and math.isnan(c["value"]) for c in out["components"].values())
    assert C.catch_hand_path([])["verdict"] is None
    # summarize: a catch id reports the block (None where undefined), JSON-safe; a two-ball id does not
    s = M.summarize([still])
    json.dumps(s, allow_nan=False)
    assert s["hand_path"]["verdict"] is None and s["hand_path"]["score"] is None
    two = transport_trace("faraway", CATCH_POINTS[0])
    two.env_id = "EyeCatchTwoBalls-v0"
    assert "hand_path" not in M.summarize([two])


def test_catch_hand_path_gaze_hand_lead():
    from visuomotor_gym.metrics import catch_handpath as C

    tracking = C.catch_hand_path_measures(transport_trace("faraway", CATCH_POINTS[0], gaze="ball"))
    assert math.isnan(tracking["gaze_hand_lead_s"]) and tracking["gaze_ahead_share"] == 0.0
    # gaze jumps to the interception point at t = 0.3 s and stays: it leads the hand's arrival
    t = np.round(np.arange(0.0, FLIGHT + 1e-9, DT), 10)
    gaze = np.tile(unit(RELEASE - EYE), (len(t), 1))
    gaze[t >= 0.3 - 1e-9] = unit(np.asarray(CATCH_POINTS[0]) - EYE)
    tr = transport_trace("faraway", CATCH_POINTS[0], gaze=gaze)
    _, arrival, _ = C.catch_reach_segment(tr)
    m = C.catch_hand_path_measures(tr)
    assert m["gaze_hand_lead_s"] == pytest.approx(t[arrival] - 0.3)
    assert m["gaze_ahead_share"] == 1.0


def test_catch_hand_path_is_deterministic_and_order_free():
    from visuomotor_gym.metrics import catch_handpath as C

    traces = catch_paths("faraway") + catch_paths("revised")
    a = json.dumps(M.to_json_safe(C.catch_hand_path(traces)), sort_keys=True)
    b = json.dumps(M.to_json_safe(C.catch_hand_path(list(reversed(traces)))), sort_keys=True)
    assert a == b == json.dumps(M.to_json_safe(C.catch_hand_path(traces)), sort_keys=True)


def test_catch_hand_path_reference_is_sourced_and_leaves_gaze_realism_alone():
    from visuomotor_gym.metrics import catch_handpath as C

    for name, entry in C.CATCH_HANDPATH_REFERENCE.items():
        assert entry["source"] and entry["unit"] and entry["notes"], name
        if entry.get("scored", True):
            assert entry["low"] <= entry["value"] <= entry["high"] and entry["tolerance"] > 0, name
        else:
            assert "not scored" in entry["source"].lower(), name
    # the catch family's gaze realism keeps its own components and score
    traces = catch_paths("faraway")
    s = M.summarize(traces)
    assert set(s["gaze_realism"]["components"]) == set(COMPONENTS)
    assert s["gaze_realism"] == M.to_json_safe(M.gaze_realism(traces))


def test_catch_hand_path_in_the_results_of_a_simulated_run():
    from visuomotor_gym.bench.commands import summary_rows
    from visuomotor_gym.bench.evaluate import evaluate
    from visuomotor_gym.bench.results import ResultsError, build_results, validate_results

    res = evaluate("eyecatch", "EyeCatch-v0", episodes=2, seed=0)
    obj = build_results(res, command="vmgym bench --agent eyecatch --env EyeCatch-v0 --episodes 2")
    hp = obj["hand_path"]
    assert hp["episodes"] == 2 and hp["verdict"] is not None
    assert hp == M.to_json_safe(res.summary["hand_path"])
    again = evaluate("eyecatch", "EyeCatch-v0", episodes=2, seed=0)
    assert again.summary["hand_path"] == res.summary["hand_path"]  # deterministic
    rows = dict(summary_rows(obj))  # what vmgym bench prints
    assert rows["hand path"].startswith(hp["verdict"]) and "gaze_hand_lead_s" in "".join(rows)
    bad = json.loads(json.dumps(obj))
    bad["hand_path"]["verdict"] = "great"
    with pytest.raises(ResultsError, match="hand_path"):
        validate_results(bad)
    # The family-neutral count: written, checked, and optional (results written before it lack it).
    assert obj["success"] == obj["caught"] == round(obj["success_rate"] * obj["episodes"])
    assert rows["catch rate"].endswith(f"({obj['success']}/2)")
    wrong = json.loads(json.dumps(obj))
    wrong["success"] = obj["success"] + 1
    with pytest.raises(ResultsError, match=r"\$.success: success = .* is not success_rate x episodes"):
        validate_results(wrong)
    older = json.loads(json.dumps(obj))
    del older["success"]
    validate_results(older)


# --- the family dispatch (metrics.summary reads each family's record; metrics.common is the scaffolding) ----
@pytest.fixture(scope="module")
def reach_traces():
    """Two real ShelfReach-v0 episodes of the faraway baseline: seed 1 reaches, seed 0 fails."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.bench.trace import run_episode

    env = gym.make("ShelfReach-v0")
    try:
        out = []
        for seed, agent in ((1, "faraway"), (7, "faraway:gaze_blind=true")):  # 7: the held eye misses
            policy = make_agent(agent, "ShelfReach-v0", env.action_space.shape[0], seed=seed)
            out.append(run_episode(env, policy, seed=seed, env_id="ShelfReach-v0", agent=agent))
    finally:
        env.close()
    return out


def test_reach_summary_is_goal_summary_plus_the_hand_onset(reach_traces):
    from visuomotor_gym.metrics.common import goal_summary
    from visuomotor_gym.metrics.hand import hand_onset_time
    from visuomotor_gym.metrics.reach_realism import closest_distance, reach_realism, reach_summary
    from visuomotor_gym.metrics.stats import mean_median

    assert [bool(tr.success) for tr in reach_traces] == [True, False]  # both branches of the outcome
    reach = M.to_json_safe(reach_summary(reach_traces))
    goal = M.to_json_safe(goal_summary(reach_traces, reach_realism, closest_distance))
    hand = M.to_json_safe(mean_median([hand_onset_time(tr) for tr in reach_traces]))
    assert hand["mean"] is not None  # the one field that differs is defined on reach
    assert goal["reaction_times_s"]["hand_onset"] == {"mean": None, "median": None}
    goal["reaction_times_s"]["hand_onset"] = hand
    assert reach == goal and list(reach) == list(goal)
    assert M.summarize(reach_traces) == reach  # the dispatcher reads the reach record's summariser
    assert reach["miss_distance_m"]["mean"] == pytest.approx(closest_distance(reach_traces[1]))


def test_the_dispatcher_reads_each_familys_record(reach_traces):
    from visuomotor_gym.metrics.outcome import miss_distance
    from visuomotor_gym.metrics.reach_realism import closest_distance
    from visuomotor_gym.metrics.summary import episode_miss_distance

    assert episode_miss_distance(reach_traces[1]) == closest_distance(reach_traces[1])
    catch = make_trace(caught=False)  # env_id "EyeCatch-v0"
    assert episode_miss_distance(catch) == miss_distance(catch)
    unknown = make_trace(caught=False)
    unknown.env_id = "EyeCatchRetired-v0"  # an old results file's id: read as the default (catch) family
    as_catch = M.summarize([catch])
    assert "hand_path" in as_catch  # single-ball catch ids only
    as_catch.pop("hand_path")
    assert M.summarize([unknown]) == as_catch
    assert episode_miss_distance(unknown) == miss_distance(unknown)


def test_every_summary_has_the_same_keys(reach_traces):
    catch = M.summarize([make_trace(caught=True), make_trace(caught=False)])
    reach = M.summarize(reach_traces)
    catch.pop("hand_path", None)
    assert list(catch) == list(reach)
    assert reach["success"] == reach["caught"] == 1 and reach["catch_rate"] == reach["success_rate"] == 0.5
    assert catch["success"] == catch["caught"] == 1
