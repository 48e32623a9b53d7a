"""Golden digests of whole episodes: proof that a refactor changed nothing.

Every registered id x {flat, dict} x a few seeds, driven by seeded uniform random actions, plus
each family's scripted agent on each of its ids (catches, the catch weld and the two-ball release;
trips and finishes of the walk; reaches), plus the
argument variants that take other code paths (joint control, shaped reward, visual delay with
plant recording). Each episode is reduced to one sha256 over its observations, rewards,
terminated/truncated flags and ``info`` (reset and every step), serialised deterministically.

Regenerate (only when a behaviour change is intended, and say so in the commit):
    python -m tests.golden.digests --write
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

# The digests were made with OpenBLAS's Haswell kernels (visuomotor_gym._blas): choose them before numpy loads.
os.environ.setdefault("OPENBLAS_CORETYPE", "Haswell")

import numpy as np  # noqa: E402

GOLDEN_FILE = Path(__file__).with_name("digests.json")
SEEDS = (0, 1, 2)
# Families whose episodes are pinned (a family joins once its env and baseline are settled: a digest of
# a behaviour still being tuned proves nothing).
GOLDEN_FAMILIES = ("catch", "reach", "walk", "stones", "dodge")
MAX_STEPS = 150


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


def episode_digest(env, seed: int, policy) -> str:
    """sha256 of one episode of ``env`` from ``reset(seed=seed)`` under ``policy(obs) -> action``."""
    h = hashlib.sha256()
    obs, info = env.reset(seed=seed)
    _feed(h, obs)
    _feed(h, info)
    for _ in range(MAX_STEPS):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        for item in (obs, float(reward), bool(terminated), bool(truncated), info):
            _feed(h, item)
        if terminated or truncated:
            break
    return h.hexdigest()


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


def compute() -> dict[str, str]:
    """All golden digests, keyed by a readable case name."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.registration import ENV_SPECS, family_of

    out: dict[str, str] = {}
    specs = [spec for spec in ENV_SPECS if family_of(spec.id) in GOLDEN_FAMILIES]
    for spec in specs:
        for obs_mode in ("flat", "dict"):
            env = gym.make(spec.id, obs_mode=obs_mode)
            for seed in SEEDS:
                out[f"{spec.id}/{obs_mode}/random/{seed}"] = episode_digest(env, seed, _random_policy(env, seed))
            env.close()
    variants = {
        "joint": ("EyeCatch-v0", {"control": "joint"}),
        "shaped": ("EyeCatch-v0", {"reward": "shaped"}),
        "delay_record": ("EyeCatch-v0", {"visual_delay_s": 0.06, "record_plant": True}),
        "two_balls_shaped": ("EyeCatchTwoBalls-v0", {"reward": "shaped"}),
    }
    for name, (env_id, kwargs) in variants.items():
        env = gym.make(env_id, **kwargs)
        for seed in SEEDS:
            out[f"{env_id}/{name}/random/{seed}"] = episode_digest(env, seed, _random_policy(env, seed))
        env.close()
    # Scripted agents: catches, the weld (the held ball moves with the hand), the two-ball release.
    # Each family's own baseline on each of its ids (catch: the Eyecatch agent, walk: iwao, reach: faraway).
    family_agent = {"catch": "eyecatch", "walk": "iwao", "reach": "faraway", "stones": "lookahead",
                    "dodge": "fajen_warren"}
    agent_cases = [("oracle", "EyeCatchOracle-v0")] + [
        (family_agent[family_of(spec.id)], spec.id) for spec in specs
    ]
    for agent, env_id in agent_cases:
        env = gym.make(env_id)
        for seed in SEEDS:
            out[f"{env_id}/agent:{agent}/{seed}"] = episode_digest(env, seed, _agent_policy(agent, env_id, env))
        env.close()
    return out


def main(argv: list[str]) -> int:
    digests = compute()
    if "--write" in argv:
        GOLDEN_FILE.write_text(json.dumps(digests, indent=1, sort_keys=True) + "\n")
        print(f"wrote {len(digests)} digests to {GOLDEN_FILE}")
        return 0
    golden = json.loads(GOLDEN_FILE.read_text())
    changed = sorted(k for k in golden if digests.get(k) != golden[k])
    print(f"{len(golden) - len(changed)}/{len(golden)} unchanged" + (f"; changed: {changed}" if changed else ""))
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
