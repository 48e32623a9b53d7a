"""Whole-episode golden digests (tests/golden/digests.py): a refactor must leave every one unchanged.

One test per case. A failure names the first differing step and key (observation block, reward, flag or
info field), found by replaying the case against its recorded per-step hashes
(``tests/golden/steps.json.gz``), and the library versions or OpenBLAS kernels that differ from those
recorded with the digests. If a behaviour change is intended, regenerate with
``python -m tests.golden.digests --write`` and say so in the commit.
"""

from __future__ import annotations

import warnings

import pytest
from golden import digests as golden

RECORDED = golden.load()
CASES = sorted(RECORDED["cases"])
_TABLE: dict = {}


def _table() -> dict:
    if not _TABLE:
        _TABLE.update(golden.case_table())
    return _TABLE


def _version_note() -> str:
    now = golden.versions()
    differ = {k: (RECORDED["versions"].get(k), v) for k, v in now.items() if RECORDED["versions"].get(k) != v}
    return "".join(f"; {k} {v} here, {old} recorded" for k, (old, v) in sorted(differ.items()))


def test_the_set_of_golden_cases_is_the_recorded_one():
    assert set(_table()) == set(RECORDED["cases"]), "the set of golden cases changed: regenerate deliberately"
    assert set(golden.read_traces()) == set(RECORDED["cases"]), "steps.json.gz does not cover the same cases"


def test_the_versions_that_made_the_digests_are_recorded():
    """The digests depend on MuJoCo, numpy, SciPy, Gymnasium and the OpenBLAS kernels: the file says which
    made them, and other versions here are named in a warning (and in any failure below)."""
    assert set(RECORDED["versions"]) == {"mujoco", "numpy", "scipy", "gymnasium", "openblas_core"}
    assert all(RECORDED["versions"][k] for k in ("mujoco", "numpy", "scipy", "gymnasium"))
    note = _version_note()
    if note:
        warnings.warn(f"golden digests were recorded with other versions{note}", stacklevel=1)


@pytest.mark.parametrize("case", CASES)
def test_golden_episode_is_unchanged(case):
    if case not in _table():
        pytest.fail(f"{case} is recorded but no longer a golden case")
    digest, _ = golden.run_case(case, table=_table())
    if digest == RECORDED["cases"][case]:
        return
    from visuomotor_gym._blas import kernel_note

    _, steps = golden.run_case(case, trace=True, table=_table())  # replay, this time hashing every key
    where = golden.first_difference(golden.read_traces()[case], steps)
    pytest.fail(f"{case} changed: {where}{kernel_note()}{_version_note()}")


def test_a_changed_episode_is_located_at_its_first_differing_step_and_key():
    """The locator itself: a trace with one info field altered at step 3 is reported at step 3, naming it."""
    case = "EyeCatch-v0/flat/random/0"
    _, steps = golden.run_case(case, trace=True, table=_table())
    recorded = golden.encode_trace(steps)
    assert golden.first_difference(recorded, steps).startswith("every per-step hash matches")
    altered = [dict(s) for s in steps]
    key = "info[hand_pos]"
    altered[3][key] = ("0" if altered[3][key][0] != "0" else "1") + altered[3][key][1:]
    assert golden.first_difference(recorded, altered) == f"first differs at step 3 (0 = reset) in {key}"
    assert "ends at step" in golden.first_difference(recorded, steps[:-2])


def test_the_golden_cases_cover_catches_and_the_two_ball_release():
    """The digests are only a proof if the episodes they hash exercise the catch, weld and release."""
    import gymnasium as gym
    import numpy as np

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent

    def run(agent_name, env_id, seed):
        env = gym.make(env_id)
        agent = make_agent(agent_name, env_id, env.action_space.shape[0])
        obs, info = env.reset(seed=seed)
        state, infos = None, [info]
        while True:
            action, state = agent.predict(obs, state, None, True)
            obs, _, terminated, truncated, info = env.step(np.asarray(action, dtype=np.float32))
            infos.append(info)
            if terminated or truncated:
                return infos

    assert any(run("oracle", "EyeCatchOracle-v0", s)[-1]["is_success"] for s in (0, 1, 2))
    two = [run("eyecatch", "EyeCatchTwoBalls-v0", s) for s in (0, 1, 2)]
    assert any(max(i.get("balls_caught", 0) for i in infos) >= 1 for infos in two)
