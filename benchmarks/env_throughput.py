"""EyeCatch control steps per second against raw MuJoCo physics on the same model, same run.

The reference replays the very physics states the env visited: for every control step of the env
run it restores the recorded full physics state (``mj_setState``) and calls ``mj_step`` with the
same number of substeps. Both loops do identical contact work, so the ratio isolates what the env
adds (action checks, oculomotor plant, hand IK, vision model, observation, reward, info, wrappers).

Target (issue: EyeCatch-v0): ratio = env_steps_per_s / raw_steps_per_s >= 0.5, i.e. the env costs
at most 2x raw physics. Machines are noisy, so each side is timed ``--repeats`` times interleaved
and the best of each is compared. When the optional compiled kernels (``visuomotor_gym._native``)
are built, the same run also times the env on the pure-Python path (``ratio_pure_python_over_raw``):
the headline ratio is the path the env takes by default.

    python benchmarks/env_throughput.py --env EyeCatch-v0 --steps 3000 --repeats 5 [--json out.json]
"""

from __future__ import annotations

import argparse
import contextlib
import shlex
import sys
import time

import gymnasium as gym
import mujoco
import numpy as np

import visuomotor_gym  # noqa: F401  (registers the ids)
from visuomotor_gym import _native
from visuomotor_gym.bench.provenance import provenance, report_benchmark


def env_run(env_id: str, actions: np.ndarray, seed: int, record: bool, compiled: bool = True):
    """Step a ``gym.make`` env through ``actions`` (resetting on episode end); return (seconds, states).
    ``compiled=False``: the env is built on the pure-Python path."""
    with contextlib.nullcontext() if compiled else _native.disabled():
        env = gym.make(env_id)
    raw = env.unwrapped
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(raw.model, spec)
    states = np.empty((len(actions), size)) if record else None
    env.reset(seed=seed)
    start = time.perf_counter()
    for i, action in enumerate(actions):
        if record:
            mujoco.mj_getState(raw.model, raw.data, states[i], spec)
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - start
    n_substeps = raw.n_substeps
    model = raw.model
    env.close()
    return elapsed, states, model, n_substeps


def raw_run(model: mujoco.MjModel, states: np.ndarray, n_substeps: int) -> float:
    """Restore each recorded state and advance it ``n_substeps`` physics steps; return seconds."""
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    start = time.perf_counter()
    for state in states:
        mujoco.mj_setState(model, data, state, spec)
        mujoco.mj_step(model, data, nstep=n_substeps)
    return time.perf_counter() - start


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="EyeCatch-v0")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the result to this JSON file")
    args = parser.parse_args(argv)

    rng = np.random.default_rng(args.seed)
    actions = rng.uniform(-1.0, 1.0, size=(args.steps, gym.make(args.env).action_space.shape[0]))
    actions = actions.astype(np.float32)
    # Recorded once (recording costs time); timed runs below do not record.
    _, states, model, n_substeps = env_run(args.env, actions, args.seed, record=True)
    compiled = _native.enabled()
    env_times, raw_times, pure_times = [], [], []
    for _ in range(args.repeats):
        env_times.append(env_run(args.env, actions, args.seed, record=False)[0])
        raw_times.append(raw_run(model, states, n_substeps))
        if compiled:
            pure_times.append(env_run(args.env, actions, args.seed, record=False, compiled=False)[0])
    env_rate = args.steps / min(env_times)
    raw_rate = args.steps / min(raw_times)
    result = {
        "benchmark": "env_throughput",
        "env_id": args.env,
        "control_steps": args.steps,
        "substeps_per_control_step": n_substeps,
        "env_control_steps_per_s": round(env_rate, 1),
        "raw_mj_step_control_steps_per_s": round(raw_rate, 1),
        "ratio_env_over_raw": round(env_rate / raw_rate, 3),
        "target_ratio": 0.5,
        "meets_target": env_rate / raw_rate >= 0.5,
        "compiled_kernels": compiled,
        "ratio_pure_python_over_raw": round(args.steps / min(pure_times) / raw_rate, 3) if compiled else None,
        "provenance": provenance(shlex.join(["python", *sys.argv])),
    }
    return report_benchmark(result, args.json)


if __name__ == "__main__":
    main()
