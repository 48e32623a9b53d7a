"""Walker body alone: control steps per second of walking (scripted gait + physics) against raw MuJoCo
physics on the same model and substeps, same run.

The walk is a 20 m course with 10 cm bars every ~2 m, stepped over with a 20 cm toe clearance (so the
contact checks near obstacles, the watched substeps of ``LegContacts.step_physics``, are exercised, and
nothing trips); episodes restart at the end of the course. Each control step calls ``set_next_footstep``, ``advance`` and ``step_physics``. The
reference restores each recorded physics state (``mj_setState``) and calls ``mj_step`` with the same
substeps, as ``benchmarks/env_throughput.py`` does for the envs (which also times the pure-Python path
when the compiled kernels are built). The target for ObstacleWalk-v0 is
>= 0.5 of raw physics; this is the body's share of that budget. Best of ``--repeats`` interleaved runs.

The same run measures the whole env, ``ObstacleWalk-v0`` (``env.step``: gait, contact checks, eye,
head, retina, observation, task): the actions of the ``iwao`` agent are recorded first on courses from
seed 0 on (the agent's time is not counted), then replayed; the reference is raw ``mj_step`` from the
env's recorded physics states (same model, same 10 substeps).

    python benchmarks/walker_throughput.py --steps 3000 --repeats 5 [--json out.json]
"""

from __future__ import annotations

import argparse
import contextlib
import shlex
import sys
import time

import mujoco
import numpy as np

from visuomotor_gym.assets import asset_path
from visuomotor_gym.bench.provenance import provenance, report_benchmark
from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.gait import WalkerGait
from visuomotor_gym.tasks.walk_contacts import LegContacts
from visuomotor_gym.tasks.walk_scene import ObstaclePool

CONTROL_DT = 0.02  # the catch family's control period: 10 substeps of 2 ms
COURSE_M = 20.0
BARS_U = [2.925 + 1.95 * i for i in range(9)]  # midway between footholds 4+3i and 5+3i (nominal 0.65 m steps)
BAR_HEIGHT_M = 0.10
CLEARANCE_M = 0.20


def walker_run(steps: int, record: bool):
    """Walk ``steps`` control steps; return (seconds, recorded states or None, model, n_substeps, trips)."""
    model = mujoco.MjModel.from_xml_path(str(asset_path(wn.WALKER_SCENE)))
    data = mujoco.MjData(model)
    gait = WalkerGait(model)
    pool = ObstaclePool(model)
    contacts = LegContacts(model, gait, pool)
    n_substeps = round(CONTROL_DT / model.opt.timestep)
    pool.park_all(model, data)
    for i, u in enumerate(BARS_U):
        pool.place(model, data, i, u, 0.0, 0.05, 1.0, BAR_HEIGHT_M)
    gait.reset(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = np.empty((steps, mujoco.mj_stateSize(model, spec))) if record else None
    events = 0
    start = time.perf_counter()
    for i in range(steps):
        if record:
            mujoco.mj_getState(model, data, states[i], spec)
        gait.set_next_footstep(0.65, 0.0, CLEARANCE_M)
        gait.advance(data, CONTROL_DT)
        contacts.step_physics(model, data, n_substeps)
        if data.qpos[0] > COURSE_M:
            events += len(contacts.events)
            gait.reset(model, data)
            contacts.reset()
    elapsed = time.perf_counter() - start
    return elapsed, states, model, n_substeps, events + len(contacts.events)


def raw_run(model: mujoco.MjModel, states: np.ndarray, n_substeps: int) -> float:
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    start = time.perf_counter()
    for state in states:
        mujoco.mj_setState(model, data, state, spec)
        mujoco.mj_step(model, data, nstep=n_substeps)
    return time.perf_counter() - start


def env_record(steps: int):
    """iwao's actions and the physics states before each step, over ``steps`` control steps of
    ObstacleWalk-v0 (episodes restart with the next seed)."""
    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.agents import make_agent

    env = make_env()
    agent = make_agent("iwao", "ObstacleWalk-v0", 8)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = np.empty((steps, mujoco.mj_stateSize(env.model, spec)))
    episodes, seed = [], 0
    obs, _ = env.reset(seed=seed)
    agent.reset()
    actions: list = []
    for i in range(steps):
        mujoco.mj_getState(env.model, env.data, states[i], spec)
        action = agent.predict(obs)[0]
        actions.append(action)
        obs, _, term, trunc, _ = env.step(action)
        if term or trunc or i == steps - 1:
            episodes.append((seed, actions))
            seed, actions = seed + 1, []
            obs, _ = env.reset(seed=seed)
            agent.reset()
    return env, episodes, states


def make_env(compiled: bool = True):
    """ObstacleWalk-v0, unwrapped; ``compiled=False``: on the pure-Python path (visuomotor_gym._native)."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym import _native

    with contextlib.nullcontext() if compiled else _native.disabled():
        return gym.make("ObstacleWalk-v0").unwrapped


def env_replay(env, episodes) -> float:
    start = time.perf_counter()
    for seed, actions in episodes:
        env.reset(seed=seed)
        for action in actions:
            env.step(action)
    return time.perf_counter() - start


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--env-steps", type=int, default=None, help="ObstacleWalk-v0 control steps (default: --steps)")
    parser.add_argument("--json", help="also write the result to this JSON file")
    args = parser.parse_args(argv)

    _, states, model, n_substeps, events = walker_run(args.steps, record=True)
    walk_times, raw_times = [], []
    for _ in range(args.repeats):
        walk_times.append(walker_run(args.steps, record=False)[0])
        raw_times.append(raw_run(model, states, n_substeps))
    walk_rate = args.steps / min(walk_times)
    raw_rate = args.steps / min(raw_times)
    env_steps = args.env_steps or args.steps
    env, episodes, env_states = env_record(env_steps)
    from visuomotor_gym import _native

    compiled = _native.enabled()
    pure_env = make_env(compiled=False) if compiled else None
    env_times, env_raw_times, pure_times = [], [], []
    for _ in range(args.repeats):
        env_times.append(env_replay(env, episodes))
        env_raw_times.append(raw_run(env.model, env_states, env.n_substeps))
        if compiled:
            pure_times.append(env_replay(pure_env, episodes))
    env_rate = env_steps / min(env_times)  # resets included, as in an evaluation
    env_raw_rate = env_steps / min(env_raw_times)
    result = {
        "benchmark": "walker_throughput",
        "control_steps": args.steps,
        "substeps_per_control_step": n_substeps,
        "walker_control_steps_per_s": round(walk_rate, 1),
        "raw_mj_step_control_steps_per_s": round(raw_rate, 1),
        "ratio_walker_over_raw": round(walk_rate / raw_rate, 3),
        "simulated_seconds_per_wall_second": round(walk_rate * CONTROL_DT, 1),
        "trips_and_missteps": events,
        "env_id": "ObstacleWalk-v0",
        "env_control_steps": env_steps,
        "env_episodes": len(episodes),
        "env_control_steps_per_s": round(env_rate, 1),
        "env_raw_mj_step_control_steps_per_s": round(env_raw_rate, 1),
        "ratio_env_over_raw": round(env_rate / env_raw_rate, 3),
        "compiled_kernels": compiled,
        "ratio_pure_python_env_over_raw": round(env_steps / min(pure_times) / env_raw_rate, 3) if compiled else None,
        "provenance": provenance(shlex.join(["python", *sys.argv])),
    }
    return report_benchmark(result, args.json)


if __name__ == "__main__":
    main()
