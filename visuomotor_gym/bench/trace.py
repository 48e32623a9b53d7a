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

# Recorded for every family (the eye and head are the same in every body).
STEP_FIELDS = ("gaze_dir", "eye_pos", "head_dir")
FLAG_FIELDS = ("in_saccade", "saccade_onset")
_SCALAR_KINDS = {"env_id": str, "agent": str, "seed": int, "dt": float,
                 "success": bool, "diverged": bool, "truncated": bool}


@dataclass
class EpisodeTrace:
    """One episode. Arrays have one row per control step (row 0: after reset). World frame, SI units.

    The fields every family records are attributes; the task's own fields (declared by the env's
    ``trace_fields()``: the catch family records ``ball_pos``, ``ball_vel``, ``hand_pos``,
    ``ball_visible`` per step and ``release_pos``, ``arrival_pos``, ``flight_time``, ``missed`` per
    episode) live in ``task`` and read as attributes too (``trace.ball_pos``).
    """

    env_id: str
    agent: str
    seed: int
    dt: float  # control period, s
    t: np.ndarray  # (T,) s since the episode started
    gaze_dir: np.ndarray  # (T, 3) unit line of sight
    eye_pos: np.ndarray  # (T, 3)
    head_dir: np.ndarray  # (T, 3) forward axis of the head
    in_saccade: np.ndarray  # (T,) bool: a saccade is in flight at the end of the step
    saccade_onset: np.ndarray  # (T,) bool: a saccade started at the start of this step
    action: np.ndarray  # (T, A); row 0 NaN
    latency_s: np.ndarray  # (T,) policy compute time for the action of this step; row 0 NaN
    success: bool  # info["is_success"] at the end
    diverged: bool
    truncated: bool
    task: dict = field(default_factory=dict)  # the task's fields (see the class docstring)
    extras: dict = field(default_factory=dict)

    def __getattr__(self, name: str):
        task = self.__dict__.get("task")
        if task is not None and name in task:
            return task[name]
        raise AttributeError(f"{type(self).__name__} of {self.__dict__.get('env_id')!r} has no field {name!r}")

    @property
    def caught(self) -> bool:
        """The catch family's name for success (every ball caught)."""
        return self.success

    @property
    def steps(self) -> int:
        return len(self.t) - 1

    @property
    def catch_time(self) -> float:
        """Time of the catch (s), NaN if not caught."""
        return float(self.t[-1]) if self.success else float("nan")

    def to_arrays(self, prefix: str = "") -> dict[str, np.ndarray]:
        """Flat name -> array mapping (for ``np.savez``); task fields under ``task/``."""
        out = {}
        for f in fields(self):
            if f.name == "extras":
                continue
            if f.name == "task":
                for name, value in self.task.items():
                    out[f"{prefix}task/{name}"] = np.asarray(value)
                continue
            out[prefix + f.name] = np.asarray(getattr(self, f.name))
        return out

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "") -> EpisodeTrace:
        kwargs = {}
        for f in fields(cls):
            if f.name in ("extras", "task"):
                continue
            value = arrays[prefix + f.name]
            kind = _SCALAR_KINDS.get(f.name)
            kwargs[f.name] = kind(value) if kind is not None else value
        task_prefix = f"{prefix}task/"
        task = {}
        for key in arrays:
            if key.startswith(task_prefix):
                value = arrays[key]
                task[key[len(task_prefix):]] = value.item() if value.ndim == 0 else value
        return cls(**kwargs, task=task)


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
    step_fields, flag_fields = env.unwrapped.trace_fields()
    obs, info = env.reset(seed=seed)
    episode_fields = env.unwrapped.trace_episode_fields()
    if hasattr(policy, "reset"):
        policy.reset()
    rows = {k: [info[k]] for k in STEP_FIELDS + tuple(step_fields)}
    flags = {k: [bool(info[k])] for k in FLAG_FIELDS + tuple(flag_fields)}
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
        for k, column in rows.items():
            column.append(step_info[k])
        for k, column in flags.items():
            column.append(bool(step_info[k]))
        info = step_info
    arrays = {k: np.asarray(v, dtype=float) for k, v in rows.items()}
    arrays.update({k: np.asarray(v, dtype=bool) for k, v in flags.items()})
    task = {k: arrays.pop(k) for k in tuple(step_fields) + tuple(flag_fields)}
    task.update(episode_fields)
    task.update(env.unwrapped.trace_final_fields(info))
    return EpisodeTrace(
        env_id=env_id,
        agent=agent,
        seed=seed,
        dt=float(env.unwrapped.dt),
        t=np.asarray(t),
        **arrays,
        action=np.asarray(actions),
        latency_s=np.asarray(latency),
        success=bool(info["is_success"]),
        diverged=bool(info["physics_diverged"]),
        truncated=bool(truncated),
        task=task,
    )
