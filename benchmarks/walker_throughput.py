"""Walker body alone: control steps per second of walking (scripted gait + physics) against raw MuJoCo
physics on the same model and substeps, same run.

The walk is a 20 m course with 10 cm bars every ~2 m, stepped over with a 20 cm toe clearance (so the
per-substep contact checks near obstacles are exercised, and nothing trips); episodes restart at the
end of the course. Each control step calls ``set_next_footstep``, ``advance`` and ``step_physics``. The
reference restores each recorded physics state (``mj_setState``) and calls ``mj_step`` with the same
substeps, as ``benchmarks/env_throughput.py`` does for the envs. Issue 12 wants ObstacleWalk-v0 at
>= 0.5 of raw physics; this is the body's share of that budget. Best of ``--repeats`` interleaved runs.

    python benchmarks/walker_throughput.py --steps 3000 --repeats 5 [--json out.json]
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time

import mujoco
import numpy as np

from visuomotor_gym.assets import asset_path
from visuomotor_gym.bench.provenance import provenance, report_benchmark
from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.walker import WalkerGait

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
    n_substeps = round(CONTROL_DT / model.opt.timestep)
    gait.pool.park_all(model, data)
    for i, u in enumerate(BARS_U):
        gait.pool.place(model, data, i, u, 0.0, 0.05, 1.0, BAR_HEIGHT_M)
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
        gait.step_physics(model, data, n_substeps)
        if data.qpos[0] > COURSE_M:
            events += len(gait.events)
            gait.reset(model, data)
    elapsed = time.perf_counter() - start
    return elapsed, states, model, n_substeps, events + len(gait.events)


def raw_run(model: mujoco.MjModel, states: np.ndarray, n_substeps: int) -> float:
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    start = time.perf_counter()
    for state in states:
        mujoco.mj_setState(model, data, state, spec)
        mujoco.mj_step(model, data, nstep=n_substeps)
    return time.perf_counter() - start


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json", help="also write the result to this JSON file")
    args = parser.parse_args(argv)

    _, states, model, n_substeps, events = walker_run(args.steps, record=True)
    walk_times, raw_times = [], []
    for _ in range(args.repeats):
        walk_times.append(walker_run(args.steps, record=False)[0])
        raw_times.append(raw_run(model, states, n_substeps))
    walk_rate = args.steps / min(walk_times)
    raw_rate = args.steps / min(raw_times)
    result = {
        "benchmark": "walker_throughput",
        "control_steps": args.steps,
        "substeps_per_control_step": n_substeps,
        "walker_control_steps_per_s": round(walk_rate, 1),
        "raw_mj_step_control_steps_per_s": round(raw_rate, 1),
        "ratio_walker_over_raw": round(walk_rate / raw_rate, 3),
        "simulated_seconds_per_wall_second": round(walk_rate * CONTROL_DT, 1),
        "trips_and_missteps": events,
        "provenance": provenance(shlex.join(["python", *sys.argv])),
    }
    return report_benchmark(result, args.json)


if __name__ == "__main__":
    main()
