"""Golden digests of whole episodes: proof that a refactor changed nothing.

Every registered id x {flat, dict} x a few seeds, driven by seeded uniform random actions, plus
each family's scripted agent on each of its ids (catches, the catch weld and the two-ball release;
trips and finishes of the walk; reaches), plus the
argument variants that take other code paths (joint control, shaped reward, visual delay with
plant recording). Each episode is reduced to one sha256 over its observations, rewards,
terminated/truncated flags and ``info`` (reset and every step), serialised deterministically.

Files (``tests/golden/``):

* ``digests.json``: ``{"versions": {...}, "cases": {case: sha256}}``; the versions of MuJoCo, numpy,
  SciPy and Gymnasium and the OpenBLAS core that made the digests (a failure names the ones that
  differ now).
* ``steps.json.gz``: for every case, a short hash of every step and of every key of every step
  (``obs[block]``, ``reward``, ``terminated``, ``truncated``, ``info[field]``), so a failure names the
  first differing step and key without storing the episodes (:func:`first_difference`).

Regenerate (only when a behaviour change is intended, and say so in the commit):
    python -m tests.golden.digests --write
"""

from __future__ import annotations

import gzip
import hashlib
import json
import os
import sys
from pathlib import Path

# The digests were made with OpenBLAS's Haswell kernels (visuomotor_gym._blas): choose them before numpy loads.
os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")

import numpy as np

GOLDEN_FILE = Path(__file__).with_name("digests.json")
STEPS_FILE = Path(__file__).with_name("steps.json.gz")
SEEDS = (0, 1, 2)
MAX_STEPS = 150
# steps.json.gz keeps STEP_HEX hex digits per step of a hash over all the step's keys (a changed step
# keeps it by chance once in 65536: the first differing step) and one hex digit per key and step (a
# changed key keeps it once in 16: the key named). Modelling choice: ~0.3 MB for 276 cases.
STEP_HEX = 4
# Each family's pinned baseline (its Family record's golden_agent) runs on each of its ids; a family
# with no golden agent is not pinned yet (a family joins once its env and baseline are settled: a digest
# of a behaviour still being tuned proves nothing). Extra (agent, id) cases come from golden_extra.
VARIANTS = {
    "joint": ("EyeCatch-v0", {"control": "joint"}),
    "shaped": ("EyeCatch-v0", {"reward": "shaped"}),
    "delay_record": ("EyeCatch-v0", {"visual_delay_s": 0.06, "record_plant": True}),
    "two_balls_shaped": ("EyeCatchTwoBalls-v0", {"reward": "shaped"}),
}


def _feed(h, value) -> None:
    """Hash ``value`` deterministically: arrays by dtype, shape and bytes; dicts in key order."""
    if isinstance(value, dict):
        for key in sorted(value):
            h.update(f"<{key}>".encode())
            _feed(h, value[key])
    elif isinstance(value, (list, tuple)):
        h.update(b"[")
        for item in value:
            _feed(h, item)
        h.update(b"]")
    elif isinstance(value, np.ndarray):
        h.update(f"{value.dtype.str}{value.shape}".encode())
        h.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (bool, np.bool_)):
        h.update(b"T" if value else b"F")
    elif isinstance(value, (int, np.integer)):
        h.update(f"i{int(value)}".encode())
    elif isinstance(value, (float, np.floating)):
        h.update(np.float64(value).tobytes())
    elif value is None:
        h.update(b"N")
    else:
        h.update(repr(value).encode())


def _hash(value) -> str:
    h = hashlib.sha256()
    _feed(h, value)
    return h.hexdigest()


def _step_keys(env, obs, reward, terminated, truncated, info) -> dict[str, str]:
    """The sha256 of each key of one step: observation blocks (flat observations split by
    ``observation_structure``), reward, flags, each info field."""
    out: dict[str, str] = {}
    if isinstance(obs, dict):
        for name in sorted(obs):
            out[f"obs[{name}]"] = _hash(obs[name])
    else:
        start = 0
        for name, size in env.unwrapped.observation_structure.items():
            out[f"obs[{name}]"] = _hash(obs[start:start + size])
            start += size
        if start != obs.shape[-1]:
            out["obs"] = _hash(obs)  # elements outside the named blocks
    if reward is not None:
        out["reward"] = _hash(float(reward))
        out["terminated"] = _hash(bool(terminated))
        out["truncated"] = _hash(bool(truncated))
    for key in sorted(info):
        out[f"info[{key}]"] = _hash(info[key])
    return out


def run_episode(env, seed: int, policy, trace: bool = False) -> tuple[str, list[dict[str, str]]]:
    """sha256 of one episode of ``env`` from ``reset(seed=seed)`` under ``policy(obs) -> action``, and
    (``trace``) the sha256 of every key of every step (reset = step 0)."""
    h = hashlib.sha256()
    steps: list[dict[str, str]] = []
    obs, info = env.reset(seed=seed)
    _feed(h, obs)
    _feed(h, info)
    if trace:
        steps.append(_step_keys(env, obs, None, None, None, info))
    for _ in range(MAX_STEPS):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        for item in (obs, float(reward), bool(terminated), bool(truncated), info):
            _feed(h, item)
        if trace:
            steps.append(_step_keys(env, obs, reward, terminated, truncated, info))
        if terminated or truncated:
            break
    return h.hexdigest(), steps


def episode_digest(env, seed: int, policy) -> str:
    """sha256 of one episode of ``env`` from ``reset(seed=seed)`` under ``policy(obs) -> action``."""
    return run_episode(env, seed, policy)[0]


def _random_policy(env, seed: int):
    rng = np.random.default_rng(1000 + seed)
    shape = env.action_space.shape
    return lambda obs: rng.uniform(-1.0, 1.0, shape).astype(np.float32)


def _agent_policy(spec: str, env_id: str, env):
    from visuomotor_gym.agents import make_agent

    agent = make_agent(spec, env_id, env.action_space.shape[0])
    state = None

    def act(obs):
        nonlocal state
        action, state = agent.predict(obs, state, None, True)
        return action

    return act


def case_table() -> dict[str, tuple[str, dict, str | None, int]]:
    """Every golden case by name: ``(env_id, make kwargs, agent or None for random actions, seed)``,
    in the order the digests are computed."""
    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.families import families, family_for
    from visuomotor_gym.registration import ENV_SPECS

    out: dict[str, tuple[str, dict, str | None, int]] = {}
    ids = [spec.id for spec in ENV_SPECS if family_for(spec.id).golden_agent is not None]
    for env_id in ids:
        for obs_mode in ("flat", "dict"):
            for seed in SEEDS:
                out[f"{env_id}/{obs_mode}/random/{seed}"] = (env_id, {"obs_mode": obs_mode}, None, seed)
    for name, (env_id, kwargs) in VARIANTS.items():
        for seed in SEEDS:
            out[f"{env_id}/{name}/random/{seed}"] = (env_id, dict(kwargs), None, seed)
    # Scripted agents: catches, the weld (the held ball moves with the hand), the two-ball release.
    agent_cases = [case for f in families() for case in f.golden_extra]
    agent_cases += [(family_for(i).golden_agent, i) for i in ids]
    for agent, env_id in agent_cases:
        for seed in SEEDS:
            out[f"{env_id}/agent:{agent}/{seed}"] = (env_id, {}, agent, seed)
    return out


def run_case(name: str, trace: bool = False, table=None) -> tuple[str, list[dict[str, str]]]:
    """The digest (and with ``trace`` the per-step key hashes) of one golden case, on a fresh env."""
    import gymnasium as gym

    env_id, kwargs, agent, seed = (table or case_table())[name]
    env = gym.make(env_id, **kwargs)
    policy = _random_policy(env, seed) if agent is None else _agent_policy(agent, env_id, env)
    try:
        return run_episode(env, seed, policy, trace)
    finally:
        env.close()


def compute() -> dict[str, str]:
    """All golden digests, keyed by a readable case name."""
    table = case_table()
    return {name: run_case(name, table=table)[0] for name in table}


def versions() -> dict[str, str | None]:
    """The library versions and the OpenBLAS kernel family that episodes depend on."""
    import gymnasium
    import mujoco
    import scipy

    from visuomotor_gym._blas import openblas_core

    return {"mujoco": mujoco.__version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "gymnasium": gymnasium.__version__, "openblas_core": openblas_core()}


def encode_trace(steps: list[dict[str, str]]) -> dict:
    """A trace as stored in ``steps.json``: ``step``, :data:`STEP_HEX` hex digits per step of a hash over
    all the step's keys; ``keys``, per key one hex digit per step of its own hash (``-``: the step
    lacks the key, e.g. reset has no reward)."""
    keys = sorted({k for step in steps for k in step})
    combined = "".join(_combined(step) for step in steps)
    return {"step": combined, "keys": {k: "".join(step[k][0] if k in step else "-" for step in steps) for k in keys}}


def _combined(step: dict[str, str]) -> str:
    return hashlib.sha256("|".join(f"{k}={step[k]}" for k in sorted(step)).encode()).hexdigest()[:STEP_HEX]


def first_difference(recorded: dict, steps: list[dict[str, str]]) -> str:
    """Where the episode ``steps`` (its per-key hashes, from :func:`run_episode`) first departs from the
    ``recorded`` trace (:func:`encode_trace`): the step and the keys, in words."""
    current = encode_trace(steps)
    n_old, n_new = len(recorded["step"]) // STEP_HEX, len(steps)
    for s in range(min(n_old, n_new)):
        span = slice(s * STEP_HEX, (s + 1) * STEP_HEX)
        if recorded["step"][span] == current["step"][span]:
            continue
        keys = sorted(set(recorded["keys"]) | set(current["keys"]))
        changed = [k for k in keys if recorded["keys"].get(k, "-" * n_old)[s] != current["keys"].get(k, "-" * n_new)[s]]
        where = ", ".join(changed) if changed else "a key whose one-digit hash did not change (1 in 16)"
        return f"first differs at step {s} (0 = reset) in {where}"
    if n_old != n_new:
        return f"identical for {min(n_old, n_new)} steps, then the episode ends at step {n_new - 1}, recorded {n_old - 1}"
    return "every per-step hash matches the recorded trace (a difference the short hashes cannot see)"


def read_traces() -> dict[str, dict]:
    with gzip.open(STEPS_FILE, "rt") as f:
        return json.load(f)


def write_traces(traces: dict[str, dict]) -> None:
    text = json.dumps(traces, sort_keys=True, separators=(",", ":")) + "\n"
    with open(STEPS_FILE, "wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as f:
        f.write(text.encode())  # mtime 0 and no name: the same traces give the same bytes


def load() -> dict:
    return json.loads(GOLDEN_FILE.read_text())


def main(argv: list[str]) -> int:
    table = case_table()
    results = {name: run_case(name, trace=True, table=table) for name in table}
    digests = {name: digest for name, (digest, _) in results.items()}
    if "--write" in argv:
        GOLDEN_FILE.write_text(json.dumps({"versions": versions(), "cases": digests}, indent=1, sort_keys=True) + "\n")
        write_traces({name: encode_trace(trace) for name, (_, trace) in results.items()})
        print(f"wrote {len(digests)} digests to {GOLDEN_FILE} and their per-step key hashes to {STEPS_FILE}")
        return 0
    golden = load()["cases"]
    changed = sorted(k for k in golden if digests.get(k) != golden[k])
    print(f"{len(golden) - len(changed)}/{len(golden)} unchanged" + (f"; changed: {changed}" if changed else ""))
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
