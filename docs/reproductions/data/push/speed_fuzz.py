"""PushRecovery-v0: env speed against raw mj_step, and a 1e5-step random-action fuzz (NaN, MuJoCo warnings).

    OPENBLAS_CORETYPE=Haswell MUJOCO_GL=egl python docs/reproductions/data/push/speed_fuzz.py [FUZZ_STEPS]
"""

import json
import sys
import time

import gymnasium as gym
import mujoco
import numpy as np

import visuomotor_gym  # noqa: F401

env = gym.make("PushRecovery-v0").unwrapped
rng = np.random.default_rng(0)
# speed: zero actions over whole episodes, seeds 0.., 3000 control steps
env.reset(seed=0)
n = 0
t0 = time.perf_counter()
a = np.zeros(env.action_space.shape[0], np.float32)
while n < 3000:
    _o, _r, term, trunc, _i = env.step(a)
    n += 1
    if term or trunc:
        env.reset(seed=n)
t_env = (time.perf_counter() - t0) / n
m, d = env.model, mujoco.MjData(env.model)
mujoco.mj_resetData(m, d)
env.body.reset_pose(d)
mujoco.mj_forward(m, d)
t0 = time.perf_counter()
for _ in range(3000):
    mujoco.mj_step(m, d, env.n_substeps)
t_raw = (time.perf_counter() - t0) / 3000
out = {"env_step_ms": 1e3 * t_env, "raw_mj_step_x10_ms": 1e3 * t_raw, "ratio_raw_over_env": t_raw / t_env}
print(json.dumps(out))
# fuzz
limit = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
steps, episodes, bad = 0, 0, 0
warn0 = 0
env.reset(seed=10_000)
while steps < limit:
    obs, _r, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape[0]).astype(np.float32))
    steps += 1
    if not np.all(np.isfinite(obs)) or info["physics_diverged"]:
        bad += 1
    if term or trunc:
        warn0 += sum(w.number for w in env.data.warning)
        episodes += 1
        env.reset(seed=10_000 + episodes)
warn0 += sum(w.number for w in env.data.warning)
out.update({"fuzz_steps": steps, "fuzz_episodes": episodes, "non_finite_or_diverged": bad, "mujoco_warnings": warn0})
print(json.dumps(out))
