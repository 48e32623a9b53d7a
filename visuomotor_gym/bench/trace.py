"""Per-episode traces: what the evaluator records while an agent plays one episode.

The policy is called with the observation only; the trace keeps the true state from ``info`` for
scoring. Row 0 of every per-step array is the state after ``reset`` (action and latency are NaN
there); row k is the state after the k-th ``step``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields

import numpy as np

from visuomotor_gym.agents import Policy

STEP_FIELDS = ("ball_pos", "ball_vel", "gaze_dir", "eye_pos", "head_dir", "hand_pos")
FLAG_FIELDS = ("in_saccade", "saccade_onset", "ball_visible")


@dataclass
class EpisodeTrace:
    """One episode. Arrays have one row per control step (row 0: after reset). World frame, SI units."""

    env_id: str
    agent: str
    seed: int
    dt: float  # control period, s
    t: np.ndarray  # (T,) s since the throw
    ball_pos: np.ndarray  # (T, 3) true ball centre
    ball_vel: np.ndarray  # (T, 3)
    gaze_dir: np.ndarray  # (T, 3) unit line of sight
    eye_pos: np.ndarray  # (T, 3)
    head_dir: np.ndarray  # (T, 3) forward axis of the head
    hand_pos: np.ndarray  # (T, 3) catch-site centre
    in_saccade: np.ndarray  # (T,) bool: a saccade is in flight at the end of the step
    saccade_onset: np.ndarray  # (T,) bool: a saccade started at the start of this step
    ball_visible: np.ndarray  # (T,) bool: the eye produced a visual sample this step
    action: np.ndarray  # (T, A); row 0 NaN
    latency_s: np.ndarray  # (T,) policy compute time for the action of this step; row 0 NaN
    caught: bool
    missed: bool
    diverged: bool
    truncated: bool
    release_pos: np.ndarray  # (3,)
    arrival_pos: np.ndarray  # (3,) sampled arrival point (approximate in the Bounce variant)
    flight_time: float  # s
    extras: dict = field(default_factory=dict)

    @property
    def steps(self) -> int:
        return len(self.t) - 1

    @property
    def catch_time(self) -> float:
        """Time of the catch (s), NaN if not caught."""
        return float(self.t[-1]) if self.caught else float("nan")

    def to_arrays(self, prefix: str = "") -> dict[str, np.ndarray]:
        """Flat name -> array mapping (for ``np.savez``)."""
        out = {}
        for f in fields(self):
            if f.name == "extras":
                continue
            out[prefix + f.name] = np.asarray(getattr(self, f.name))
        return out

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "") -> EpisodeTrace:
        kwargs = {}
        for f in fields(cls):
            if f.name == "extras":
                continue
            value = arrays[prefix + f.name]
            if f.name in ("env_id", "agent"):
                value = str(value)
            elif f.name == "seed":
                value = int(value)
            elif f.name in ("dt", "flight_time"):
                value = float(value)
            elif f.name in ("caught", "missed", "diverged", "truncated"):
                value = bool(value)
            kwargs[f.name] = value
        return cls(**kwargs)


def save_traces(path, traces: list[EpisodeTrace]) -> None:
    """Save episodes to one compressed ``.npz`` (keys ``ep{i}/{field}``)."""
    arrays = {"n_episodes": np.asarray(len(traces))}
    for i, tr in enumerate(traces):
        arrays.update(tr.to_arrays(prefix=f"ep{i}/"))
    np.savez_compressed(path, **arrays)


def load_traces(path) -> list[EpisodeTrace]:
    with np.load(path, allow_pickle=False) as data:
        n = int(data["n_episodes"])
        return [EpisodeTrace.from_arrays(data, prefix=f"ep{i}/") for i in range(n)]


def run_episode(env, policy: Policy, seed: int, env_id: str, agent: str) -> EpisodeTrace:
    """Play one episode; the policy sees observations only. Returns its trace."""
    obs, info = env.reset(seed=seed)
    if hasattr(policy, "reset"):
        policy.reset()
    rows = {k: [info[k]] for k in STEP_FIELDS}
    flags = {k: [bool(info[k])] for k in FLAG_FIELDS}
    t = [info["time"]]
    n_act = env.action_space.shape[0]
    actions = [np.full(n_act, np.nan)]
    latency = [np.nan]
    state = None
    episode_start = np.array([True])
    terminated = truncated = False
    while not (terminated or truncated):
        start = time.perf_counter()
        action, state = policy.predict(obs, state=state, episode_start=episode_start, deterministic=True)
        latency.append(time.perf_counter() - start)
        episode_start = np.array([False])
        obs, _, terminated, truncated, step_info = env.step(action)
        actions.append(np.asarray(action, dtype=float).reshape(-1))
        t.append(step_info["time"])
        for k in STEP_FIELDS:
            rows[k].append(step_info[k])
        for k in FLAG_FIELDS:
            flags[k].append(bool(step_info[k]))
        info = step_info
    return EpisodeTrace(
        env_id=env_id,
        agent=agent,
        seed=seed,
        dt=float(env.unwrapped.dt),
        t=np.asarray(t),
        **{k: np.asarray(v, dtype=float) for k, v in rows.items()},
        **{k: np.asarray(v, dtype=bool) for k, v in flags.items()},
        action=np.asarray(actions),
        latency_s=np.asarray(latency),
        caught=bool(info["is_success"]),
        missed=bool(info["missed"]),
        diverged=bool(info["physics_diverged"]),
        truncated=bool(truncated),
        release_pos=np.asarray(env.unwrapped.throw.release_pos),
        arrival_pos=np.asarray(env.unwrapped.throw.arrival_pos),
        flight_time=float(env.unwrapped.throw.flight_time),
    )
