"""Record the episode traces the realism table is measured on (realism version 2,
docs/gaze_gain.md "Realism a still eye cannot pass").

For one env id and one agent spec, plays pinned seeds ``0..N-1`` and saves the traces with
:func:`visuomotor_gym.bench.trace.save_traces`. The agent is an ordinary spec (``iwao``,
``gaze_blind:iwao``, ``static_gaze:iwao`` where registered) or ``random_gaze:<spec>``: that agent's
body actions with uniform random gaze and head actions (seeded), the "random gaze" of the table.
``static_gaze:az=..,el=..[,neck_yaw=..,neck_pitch=..]:<spec>`` is that agent's static twin held at that
posture, built from ``visuomotor_gym.static_gaze`` (or, before it is merged, from the module file named
by the environment variable ``STATIC_GAZE_MODULE``).

    python benchmarks/realism_traces.py ObstacleWalk-v0 iwao 20 out/walk_iwao.npz
    python benchmarks/realism_traces.py ObstacleWalk-v0 random_gaze:iwao 20 out/walk_random.npz

Then score a file with ``python benchmarks/realism_traces.py --score out/*.npz``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np


class RandomGaze:
    """``base``'s actions with the gaze and head blocks replaced by uniform random actions in [-1, 1]."""

    BLOCKS = ("gaze", "head")

    def __init__(self, base, action_structure: dict[str, int], seed: int):
        self.base = base
        self.rng = np.random.default_rng(seed)
        self.mask = np.zeros(sum(action_structure.values()), dtype=bool)
        start = 0
        for name, size in action_structure.items():
            if name in self.BLOCKS:
                self.mask[start:start + size] = True
            start += size

    def reset(self):
        if hasattr(self.base, "reset"):
            self.base.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        action, state = self.base.predict(observation, state=state, episode_start=episode_start,
                                          deterministic=deterministic)
        action = np.array(action, dtype=np.float32, copy=True)
        action[..., self.mask] = self.rng.uniform(-1.0, 1.0, size=int(self.mask.sum()))
        return action, state


def _static_gaze_module():
    import importlib
    import importlib.util
    import os

    try:
        return importlib.import_module("visuomotor_gym.static_gaze")
    except ImportError:
        path = os.environ.get("STATIC_GAZE_MODULE")
        if not path:
            raise
        spec = importlib.util.spec_from_file_location("static_gaze_module", path)
        module = importlib.util.module_from_spec(spec)
        sys.modules["static_gaze_module"] = module  # dataclasses look their module up there
        spec.loader.exec_module(module)
        return module


def static_gaze(spec: str, env_id: str, dim: int, seed: int):
    """``static_gaze:az=..,el=..:<agent spec>`` -> the static twin (posture given explicitly)."""
    from visuomotor_gym.agents import make_agent

    options, _, base = spec.removeprefix("static_gaze:").partition(":")
    sg = _static_gaze_module()
    posture = sg.Posture(**{k: float(v) for k, v in (kv.split("=") for kv in options.split(","))})
    return sg.StaticGaze(make_agent(base, env_id, dim, seed=seed), posture, sg.env_geometry(env_id))


def record(env_id: str, agent: str, episodes: int, path: str) -> None:
    from visuomotor_gym.agents import env_action_structure, make_agent
    from visuomotor_gym.bench.evaluate import make_env
    from visuomotor_gym.bench.trace import run_episode, save_traces

    env = make_env(env_id)
    dim = int(env.action_space.shape[0])
    traces = []
    start = time.time()
    for seed in range(episodes):
        if agent.startswith("random_gaze:"):
            policy = RandomGaze(make_agent(agent.removeprefix("random_gaze:"), env_id, dim, seed=seed),
                                env_action_structure(env_id), seed=seed)
        elif agent.startswith("static_gaze:") and "=" in agent.split(":")[1]:
            policy = static_gaze(agent, env_id, dim, seed)
        else:
            policy = make_agent(agent, env_id, dim, seed=seed)
        traces.append(run_episode(env, policy, seed=seed, env_id=env_id, agent=agent))
    save_traces(path, traces)
    ok = sum(tr.success for tr in traces)
    print(f"{env_id} {agent}: {ok}/{episodes} succeeded, {time.time() - start:.0f} s -> {path}", flush=True)


def family_reference(env_id: str) -> dict:
    """The realism table of an env id's family."""
    from visuomotor_gym.registration import family_of

    family = family_of(env_id)
    if family == "catch":
        from visuomotor_gym.metrics.realism import load_reference

        return load_reference()
    module, name = {"reach": ("reach_realism", "REACH_REFERENCE"), "walk": ("walk_realism", "WALK_REFERENCE"),
                    "stones": ("stones_realism", "STONES_REFERENCE"), "dodge": ("dodge_realism", "DODGE_REFERENCE"),
                    "push": ("push_realism", "PUSH_REFERENCE")}[family]
    import importlib

    return getattr(importlib.import_module(f"visuomotor_gym.metrics.{module}"), name)


def score(paths: list[str]) -> None:
    from visuomotor_gym.bench.trace import load_traces
    from visuomotor_gym.metrics.realism import group_scores
    from visuomotor_gym.metrics.summary import summarize

    for path in paths:
        traces = load_traces(path)
        s = summarize(traces)
        real = s["gaze_realism"]
        comps = {k: (None if v["value"] is None else round(v["value"], 3), None if v["score"] is None else
                     round(v["score"], 2), v["episodes"]) for k, v in real["components"].items()}
        sc = real["score"]
        groups = group_scores(real, family_reference(traces[0].env_id))
        print(f"{path}: success {s['success_rate']:.2f} realism {sc if sc is None else round(sc, 3)} groups "
              + " ".join(f"{g} {v:.2f}" for g, v in groups.items()))
        print("   ", json.dumps(comps))


if __name__ == "__main__":
    if sys.argv[1:2] == ["--score"]:
        score(sys.argv[2:])
    else:
        p = argparse.ArgumentParser()
        p.add_argument("env_id")
        p.add_argument("agent")
        p.add_argument("episodes", type=int)
        p.add_argument("path")
        a = p.parse_args()
        record(a.env_id, a.agent, a.episodes, a.path)
