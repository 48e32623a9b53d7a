"""belief_mpc on SteppingStones-v0: Eom's static-object belief, the gaze plan, a real episode."""

from __future__ import annotations

import math
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
from visuomotor_gym.baselines.belief_mpc.belief import covariance_step
from visuomotor_gym.baselines.belief_mpc.stone_belief import (
    plan_gaze,
    plane_variance,
    schedules,
    static_sigma_step,
)
from visuomotor_gym.baselines.belief_mpc.stones import StonesBeliefMPCAgent, StonesBeliefMPCParams

import visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import make_agent
from visuomotor_gym.vision.foveation import DEG, VisionParams

ENV = "SteppingStones-v0"
VISION = VisionParams(field_of_view_deg=20.0)  # the walk family's field


# --- the belief ---------------------------------------------------------------------------------
def test_static_sigma_step_is_the_scalar_kalman_update_and_eoms_eq4_with_h_0():
    sp, q = 0.02, 1e-4
    for r in (1e-6, 1e-3, 0.5):
        a = sp + q
        expected = a * r / (a + r)  # scalar Kalman: prior a, measurement variance r
        assert static_sigma_step(sp, r, q) == pytest.approx(expected, rel=1e-12)
        eom = covariance_step(np.array([sp, 0.0, 0.0]), np.array(r), 0.0, q)  # Appendix A, F = I
        assert eom[0] == pytest.approx(expected, rel=1e-12) and eom[2] == 0.0
    assert static_sigma_step(sp, math.inf, q) == pytest.approx(sp + q)  # not seen: prediction only


def test_covariance_shrinks_with_foveal_samples_and_stays_large_in_the_periphery():
    d, dep, slip = 2.5, 0.6, 0.0
    fovea = float(plane_variance(d, 0.0, slip, dep, VISION))
    periph = float(plane_variance(d, 12 * DEG, slip, dep, VISION))
    outside = float(plane_variance(d, 25 * DEG, slip, dep, VISION))
    assert fovea < periph / 20.0 and math.isinf(outside)
    sp_f = sp_p = sp_o = 0.03
    for _ in range(10):
        sp_f = static_sigma_step(sp_f, fovea, 0.0)
        sp_p = static_sigma_step(sp_p, periph, 0.0)
        sp_o = static_sigma_step(sp_o, outside, 0.0)
    # information adds up: 1/sp_n = 1/sp_0 + n/r
    assert 1.0 / sp_f == pytest.approx(1.0 / 0.03 + 10.0 / fovea, rel=1e-9)
    assert sp_f < sp_p < sp_o == 0.03
    # retinal slip blurs (the env's lateral std x slip / knee above 2.5 deg/s)
    assert float(plane_variance(d, 0.0, 40 * DEG, dep, VISION)) > 50 * fovea


def test_unfoveated_vision_sees_everywhere_with_the_full_shape():
    flat = VisionParams(foveated=False)
    r = plane_variance(np.full((3, 1, 2), 2.0), np.full((3, 2, 2), 0.7), np.zeros((3, 2, 2)), np.full((3, 1, 2), 0.6), flat)
    assert r.shape == (3, 2, 2) and np.all(np.isfinite(r))
    assert np.allclose(r, float(plane_variance(2.0, 0.0, 0.0, 0.6, flat)))


# --- the gaze plan ------------------------------------------------------------------------------
# far apart sideways (> 20 deg between any two, seen from the eye): a stone is seen only when fixated
STONES = np.array([[2.2, 1.2], [3.35, -1.0], [4.6, 0.8]])
EYE = np.array([1.0, 0.0, 1.6])
VEL = np.array([1.3, 0.0, 0.0])
GAZE = np.array([0.75, 0.0, -0.66]) / np.linalg.norm([0.75, 0.0, -0.66])


def _plan(sp0, commit, current=-1):
    return plan_gaze(STONES, np.asarray(sp0, float), EYE, VEL, GAZE, np.asarray(commit, float), current, 0.0, VISION,
                     h=0.1, n=12, dt=0.02, q_node=9e-5, w_uct=1.0, w_tsk=10.0, plane_z=-0.005, refractory_s=0.2)


@pytest.mark.parametrize("most", [0, 1, 2])
def test_gaze_goes_to_the_most_uncertain_stone(most):
    sp0 = np.full(3, 1e-4)
    sp0[most] = 2e-2
    plan = _plan(sp0, [np.inf] * 3)
    assert plan.targets[0] == most
    assert plan.sp[-1, most] < 1e-3  # the plan shrinks it


def test_the_stones_of_the_gaze_test_are_outside_each_others_field():
    for t in np.linspace(0.0, 1.2, 7):  # the eye walks on through the window
        eye = EYE + t * VEL
        rel = np.column_stack([STONES - eye[:2], np.full(3, -0.005 - eye[2])])
        u = rel / np.linalg.norm(rel, axis=1)[:, None]
        ang = np.degrees(np.arccos(np.clip(u @ u.T, -1, 1)))
        assert ang[np.triu_indices(3, 1)].min() > 20.0


def test_a_gaze_that_sees_two_stones_can_beat_fixating_the_uncertain_one():
    """Eom's summed uncertainty: with two stones 11 deg apart, fixating the near-certain far one
    keeps the uncertain near one in the periphery, and both shrink (not a rule: the cost decides)."""
    stones = np.array([[2.6, 0.1], [3.35, -0.1]])
    plan = plan_gaze(stones, np.array([2e-2, 1e-4]), EYE, VEL, GAZE, np.array([np.inf, np.inf]), -1, 0.0, VISION,
                     h=0.1, n=12, dt=0.02, q_node=9e-5, w_uct=1.0, w_tsk=10.0, plane_z=-0.005, refractory_s=0.2)
    assert plan.sp[-1, 0] < 1e-3 and plan.sp[-1, 1] < 1e-3


def test_a_soon_committed_stone_wins_over_an_equally_uncertain_later_one():
    sp0 = [1e-3, 1e-3, 1e-3]
    assert _plan(sp0, [np.inf, 0.3, np.inf]).targets[0] == 1
    assert _plan(sp0, [np.inf, np.inf, 0.3]).targets[0] == 2
    # a committed foothold's stone leaves the cost: its uncertainty after the commitment changes nothing
    late = _plan(sp0, [0.05, np.inf, np.inf])
    assert late.targets[0] != 0


def test_schedules_respect_the_saccade_refractory_period():
    S = schedules(3, 12, 0, 2, 2, 2)
    for row, sw in zip(S.targets, S.switch):
        ks = np.flatnonzero(sw)
        assert row[0] == 0 and (ks.size == 0 or ks[0] >= 2)  # the plant cannot start one before node 2
        assert np.all(np.diff(ks) >= 2) and ks.size <= 2
        changes = np.flatnonzero(np.diff(row)) + 1
        assert np.array_equal(changes, ks)


# --- the agent on the env -----------------------------------------------------------------------
def _run(spec, seed, steps):
    env = gym.make(ENV)
    agent = make_agent(spec, ENV, env.action_space.shape[0], seed=seed)
    obs, _ = env.reset(seed=seed)
    actions, info = [], {}
    for _ in range(steps):
        a, _ = agent.predict(obs)
        actions.append(np.asarray(a).copy())
        obs, _, term, trunc, info = env.step(a)
        if term or trunc:
            break
    env.close()
    return agent, np.array(actions), info


def test_dispatch_on_the_family():
    env = gym.make(ENV)
    agent = make_agent("belief_mpc", ENV, env.action_space.shape[0])
    env.close()
    assert isinstance(agent, StonesBeliefMPCAgent)
    from visuomotor_gym.registration import env_vision_params

    assert agent.vision == env_vision_params(ENV) and agent.vision.crowding  # the env's own vision (the periphery)
    with pytest.raises(TypeError):
        make_agent("belief_mpc:no_such=1", ENV, 9)
    assert make_agent("belief_mpc:w_tsk=0", ENV, 9).params.w_tsk == 0.0
    with pytest.raises(ValueError):
        StonesBeliefMPCParams(window_s=0.1)


def test_short_episode_looks_down_lands_on_stones_and_shrinks_the_belief():
    agent, actions, info = _run("belief_mpc", 3, 200)  # 4 s: the slab and the first stones
    assert not info["fell"] and info["stones_landed"] >= 2
    assert np.all(np.abs(actions) <= 1.0)
    assert np.any(actions[:, 5] < -0.05)  # the eye is sent down toward the stones
    fixated = {e["fixate"] for e in agent.plan_log}
    assert len(fixated) >= 4
    for i in range(4):  # every stone looked at: its compact covariance far below the course prior
        assert agent.sigma[i] < agent.params.prior_var_m2 / 20.0
    assert max(agent.solve_ms) < 1e3


def test_determinism_and_the_gaze_blind_twin():
    _, a1, _ = _run("belief_mpc", 5, 80)
    _, a2, _ = _run("belief_mpc", 5, 80)
    assert np.array_equal(a1, a2)
    _, b, _ = _run("gaze_blind:belief_mpc", 5, 80)
    assert np.all(b[:, 4:6] == 0.0) and np.all(b[:, 7:9] == 0.0)


# --- ObstacleDodge-v0 (experimental) -----------------------------------------------------------
def test_dodge_compact_step_in_information_form_is_eoms_eq4():
    from visuomotor_gym.baselines.belief_mpc.dodge import compact_step_information

    sig = np.array([[0.3, 0.5, 0.1], [2.0, 1.0, -0.2]])
    for r in (np.array([1e-3, 0.7]), np.array([np.inf, 0.05])):
        ref = covariance_step(sig, r, 0.1, 0.05)
        sp, sv, spv = compact_step_information(sig[:, 0], sig[:, 1], sig[:, 2], 1.0 / r, 0.1, 0.05)
        assert np.allclose(np.stack([sp, sv, spv], axis=1), ref, rtol=1e-12, atol=0)


def test_dodge_dispatch_and_a_short_episode():
    from visuomotor_gym.baselines.belief_mpc.dodge import DodgeBeliefMPCAgent

    env = gym.make("ObstacleDodge-v0")
    agent = make_agent("belief_mpc", "ObstacleDodge-v0", env.action_space.shape[0])
    assert isinstance(agent, DodgeBeliefMPCAgent) and agent.plan_vision == env.unwrapped.vision_params
    obs, _ = env.reset(seed=1)
    for _ in range(120):
        a, _ = agent.predict(obs)
        assert np.all(np.isfinite(a)) and np.all(np.abs(a) <= 1.0)
        obs, _, term, trunc, _info = env.step(a)
        if term or trunc:
            break
    env.close()
    kinds = {e["target"][0] for e in agent.plan_log}
    assert "search" in kinds  # pedestrians not seen yet are searched for, as the uncertainty term asks


def test_dodge_determinism():
    def run():
        env = gym.make("ObstacleDodge-v0")
        agent = make_agent("belief_mpc", "ObstacleDodge-v0", env.action_space.shape[0])
        obs, _ = env.reset(seed=7)
        out = []
        for _ in range(60):
            a, _ = agent.predict(obs)
            out.append(np.asarray(a).copy())
            obs, *_ = env.step(a)
        env.close()
        return np.array(out)

    assert np.array_equal(run(), run())


def _dodge_choices(spec: str, seed: int = 1, steps: int = 400):
    """Per gaze choice of a dodge belief_mpc episode: (chosen key, the slots fajen_warren would look at)."""
    env = gym.make("ObstacleDodge-v0")
    agent = make_agent(spec, "ObstacleDodge-v0", env.action_space.shape[0])
    seen = []
    choose = agent._choose

    agent._saccade_log = []

    def recording(threats, t):
        allowed = {k for k, _tca, _d, _p, relevant in threats if relevant and agent._ahead(agent.filters[k])}
        key = choose(threats, t)
        seen.append((key, allowed))
        agent._saccade_log.append((t, agent._in_saccade, key))
        return key

    agent._choose = recording
    obs, _ = env.reset(seed=seed)
    for _ in range(steps):
        a, _ = agent.predict(obs)
        obs, _, term, trunc, _ = env.step(a)
        if term or trunc:
            break
    env.close()
    return agent, seen


def test_dodge_planner_looks_only_at_fajen_warrens_pedestrians_and_verges():
    """relevant_only (the default): every pedestrian the plan fixates is one fajen_warren's gaze rule would
    look at (approaching or ahead within its bearing limit); without it the plan also fixates others."""
    agent, seen = _dodge_choices("belief_mpc")
    peds = [(key[1], allowed) for key, allowed in seen if key is not None and key[0] == "ped"]
    assert peds and all(k in allowed for k, allowed in peds)
    assert agent.params.verge and agent.params.relevant_only and agent.params.threat_weight == 10.0
    # min_fixation_s: once a saccade has landed, the plan keeps its object for at least 0.2 s
    landed = [i for i in range(1, len(agent._saccade_log)) if agent._saccade_log[i - 1][1] and not agent._saccade_log[i][1]]
    assert landed
    for i in landed:
        t0, _, key0 = agent._saccade_log[i]
        for t, in_sacc, key in agent._saccade_log[i:]:
            if t - t0 >= agent.params.min_fixation_s - 1e-9 or in_sacc:
                break
            assert key == key0 or key0 is None
    # seed 0: on seed 1 the plan without the rule happens to fixate only allowed pedestrians since fajen_warren's
    # perception guards (min_depth_m, max_speed_m_s) changed its estimates
    _, seen_all = _dodge_choices("belief_mpc:relevant_only=false,threat_weight=0,min_fixation_s=0", seed=0)
    assert any(key[1] not in allowed for key, allowed in seen_all if key is not None and key[0] == "ped")


def test_dodge_first_look_picks_the_earliest_unfixated_near_miss_pedestrian():
    """first_look (opt-in): of the candidate pedestrians not fixated yet, known for at least notice_s and (with
    first_look_dmin_m) predicted to pass within that distance, the one seen first; None without one, or when
    off."""
    env = gym.make("ObstacleDodge-v0")
    spec = "belief_mpc:first_look=true,first_look_dmin_m=1.5"
    agent = make_agent(spec, "ObstacleDodge-v0", env.action_space.shape[0])
    env.close()
    agent.reset()
    for k, t_first in enumerate((2.0, 1.0, 1.5, 2.95)):
        agent.filters[k].t_first = t_first
    keys = [("ped", 0), ("ped", 1), ("ped", 2), ("ped", 3), ("search", 40.0)]
    closest = {0: 0.4, 1: 3.0, 2: 1.2, 3: 0.1}
    # pedestrian 1 was seen first but will miss by 3 m; 3 is known for 0.05 s < notice_s (0.15 s)
    assert agent._first_look(keys, closest, 3.0) == 2
    agent._fixated.add(2)
    assert agent._first_look(keys, closest, 3.0) == 0
    agent._fixated.add(0)
    assert agent._first_look(keys, closest, 3.0) is None
    assert agent._first_look(keys, closest, 3.2) == 3  # now known for 0.25 s
    agent._fixated.clear()
    agent.params = replace(agent.params, first_look_dmin_m=None)
    assert agent._first_look(keys, closest, 3.0) == 1  # every one: the one seen first
    agent.params = replace(agent.params, first_look=False)
    assert agent._first_look(keys, closest, 3.0) is None


def test_dodge_first_look_fixates_newcomers_sooner():
    """On a crowd where the uncertainty plan alone holds a near threat for seconds (seed 100002 of the
    "wide_collision" crowd: three pedestrians appear at 2.2-3.7 s and are first fixated after 6 s), first looks
    bring the first fixation of each to within about a second of its appearance."""
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.metrics.dodge_realism import first_fixations

    def latencies(spec):
        env = gym.make("ObstacleDodge-v0", crowd_distribution="wide_collision")
        agent = make_agent(spec, "ObstacleDodge-v0", env.action_space.shape[0], seed=100002)
        trace = run_episode(env, agent, 100002, "ObstacleDodge-v0", spec)
        env.close()
        onsets = np.asarray(trace.pedestrians, dtype=float).reshape(-1, 9)[:, 0]
        return [trace.t[s] - onsets[i] if s is not None else np.inf for i, s in enumerate(first_fixations(trace))]

    plan_only, first = latencies("belief_mpc"), latencies("belief_mpc:first_look=true")
    assert max(plan_only[1:]) > 2.5
    assert max(first) < 1.5
