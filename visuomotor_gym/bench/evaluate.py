"""The evaluator: play an agent on pinned seeds, over a local process pool, and summarise.

Seeds are pinned: episode ``i`` (0-based) of ``evaluate(..., episodes=N, seed=S)`` resets the
environment with seed ``S + i`` (:func:`episode_seeds`), so ``(env_id, seed, episodes)`` names the
exact set of throws on every rung of the observability ladder.

Episodes are cut into contiguous chunks whose layout depends on ``episodes`` only
(:func:`episode_chunks`), never on the number of workers. Each chunk builds its agent once with
``make_agent(agent, env_id, action_dim, seed=<seed of the chunk's first episode>)`` and reuses it for
its episodes (calling ``policy.reset()`` between episodes when the policy has one); each worker
process makes the environment once (``gymnasium.make(env_id)``) and reuses it across its chunks.
Chunks are collected back in seed order, so a deterministic agent gives identical traces for any
``workers``, and so does a seeded stochastic agent (its stream restarts at every chunk).

``workers=1`` runs in-process; ``workers>1`` (capped at the number of chunks) uses a
``ProcessPoolExecutor`` with the "spawn" start method (safe from a CLI, pytest, notebooks and
threads; workers import ``visuomotor_gym`` fresh).
"""

from __future__ import annotations

import math
import multiprocessing
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field

from visuomotor_gym.bench.trace import EpisodeTrace, run_episode

MAX_CHUNK_EPISODES = 16  # upper bound on episodes per chunk (one agent instance per chunk)
TARGET_CHUNKS = 64  # small runs are cut finer so that every worker gets work


@dataclass
class EvalResult:
    """What :func:`evaluate` returns: the run's identity, its per-episode traces and the summary."""

    agent: str
    env_id: str
    episodes: int
    seed: int  # episode i used seed + i
    agent_deterministic: bool
    control_period_s: float  # the env's control period (dt); "real time" compares latency with it
    summary: dict  # visuomotor_gym.metrics.summarize(traces)
    traces: list[EpisodeTrace] = field(default_factory=list)  # empty when keep_traces=False
    workers: int = 1
    wall_time_s: float = 0.0  # rollouts only (pool start included), not the summary
    env_steps: int = 0  # control steps over all episodes

    @property
    def seeds(self) -> list[int]:
        return episode_seeds(self.seed, self.episodes)

    @property
    def env_steps_per_s(self) -> float:
        return self.env_steps / self.wall_time_s if self.wall_time_s > 0 else float("nan")


def episode_seeds(seed: int, episodes: int) -> list[int]:
    """The pinned seeds of a run: episode ``i`` uses ``seed + i``."""
    return [seed + i for i in range(episodes)]


def episode_chunks(episodes: int) -> list[range]:
    """Contiguous episode-index chunks; the layout depends on ``episodes`` only (not on workers)."""
    size = min(MAX_CHUNK_EPISODES, max(1, math.ceil(episodes / TARGET_CHUNKS)))
    return [range(start, min(start + size, episodes)) for start in range(0, episodes, size)]


def _known_env_ids() -> tuple[str, ...]:
    from visuomotor_gym.registration import ENV_IDS

    return ENV_IDS


def check_env_id(env_id: str) -> str:
    """Return the registered id (a ``visuomotor_gym:`` prefix is accepted), or raise ValueError."""
    if not isinstance(env_id, str):
        raise TypeError(f"env_id must be a string, got {type(env_id).__name__}")
    bare = env_id.removeprefix("visuomotor_gym:")
    known = _known_env_ids()
    if bare not in known:
        raise ValueError(f"unknown env id {env_id!r}; known ids: {', '.join(known)}")
    return bare


def _check_int(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return value


def validate_inputs(agent: str, env_id: str, episodes: int, seed: int, workers: int = 1) -> str:
    """Check the arguments of :func:`evaluate` and build the agent once; returns the bare env id.

    Raises ValueError / TypeError with a message naming the problem (unknown env id -> the known
    ids; unknown agent -> the known agents; bad agent overrides -> the agent's own error), so that
    mistakes surface here rather than inside a worker process.
    """
    from visuomotor_gym.agents import make_agent, parse_agent_spec

    env_id = check_env_id(env_id)
    if not isinstance(agent, str):
        raise TypeError(f"agent must be a string spec such as 'eyecatch', got {agent!r}")
    parse_agent_spec(agent)  # unknown agent -> ValueError listing the known agents
    _check_int("episodes", episodes, 1)
    _check_int("seed", seed, 0)  # gymnasium seeds must be non-negative
    _check_int("workers", workers, 1)
    env = make_env(env_id)
    try:
        try:
            policy = make_agent(agent, env_id, action_dim=int(env.action_space.shape[0]), seed=seed)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"cannot build agent {agent!r} for {env_id}: {exc}") from exc
        _probe(policy, agent, env, env_id, seed)
    finally:
        env.close()
    return env_id


def _probe(policy, agent: str, env, env_id: str, seed: int) -> None:
    """One action on the first observation (a throwaway agent and env: the run builds its own), so that an
    agent that cannot act on this env's observations (a policy trained on another family...) is refused
    here, in one line, rather than in a worker's traceback."""
    import numpy as np

    obs, _ = env.reset(seed=seed)
    try:
        if hasattr(policy, "reset"):
            policy.reset()
        action, _ = policy.predict(obs, state=None, episode_start=np.ones(1, dtype=bool), deterministic=True)
        action = np.asarray(action, dtype=float)
        if action.shape != env.action_space.shape:
            raise ValueError(f"its action has shape {action.shape}, the env takes {env.action_space.shape}")
    except Exception as exc:  # whatever the agent raises becomes the one-line refusal
        from visuomotor_gym.registration import family_of

        raise ValueError(f"agent {agent!r} cannot act on {env_id} ({family_of(env_id)} family): "
                         f"{type(exc).__name__}: {exc}".replace("\n", " ")) from exc


def make_env(env_id: str):
    """``gymnasium.make(env_id)`` after registering the ids (a spawned worker starts bare)."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    return gym.make(env_id)


# Pool workers only: one environment per worker process, reused across the chunks it runs.
_WORKER_ENVS: dict = {}


def _worker_env(env_id: str):
    if env_id not in _WORKER_ENVS:
        _WORKER_ENVS[env_id] = make_env(env_id)
    return _WORKER_ENVS[env_id]


def run_chunk(agent: str, env_id: str, seeds: list[int], env=None) -> list[EpisodeTrace]:
    """Play ``seeds`` in order with one agent built for the chunk (seeded with ``seeds[0]``).

    ``env`` defaults to this worker process's cached environment for ``env_id``.
    """
    from visuomotor_gym.agents import make_agent

    env = _worker_env(env_id) if env is None else env
    policy = make_agent(agent, env_id, action_dim=int(env.action_space.shape[0]), seed=int(seeds[0]))
    return [run_episode(env, policy, seed=int(s), env_id=env_id, agent=agent) for s in seeds]


def _progress_bar(enabled: bool, description: str, total: int):
    """A rich progress bar (or None when disabled or rich is missing)."""
    if not enabled:
        return None
    try:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )
    except ImportError:
        return None
    progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                        TimeElapsedColumn(), TimeRemainingColumn(), transient=False)
    progress.add_task(description, total=total)
    return progress


def _run_in_process(agent, env_id, chunks, seeds, progress) -> list[list[EpisodeTrace]]:
    results = []
    env = make_env(env_id)
    try:
        for chunk in chunks:
            results.append(run_chunk(agent, env_id, [seeds[i] for i in chunk], env=env))
            if progress is not None:
                progress.advance(progress.task_ids[0], len(chunk))
    finally:
        env.close()
    return results


def _run_in_pool(agent, env_id, chunks, seeds, workers, progress) -> list[list[EpisodeTrace]]:
    results: list = [None] * len(chunks)
    ctx = multiprocessing.get_context("spawn")
    executor = ProcessPoolExecutor(max_workers=workers, mp_context=ctx)
    try:
        pending = {executor.submit(run_chunk, agent, env_id, [seeds[i] for i in chunk]): k
                   for k, chunk in enumerate(chunks)}
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                k = pending.pop(future)
                results[k] = future.result()  # re-raises a worker's exception here
                if progress is not None:
                    progress.advance(progress.task_ids[0], len(chunks[k]))
    except BaseException:
        executor.shutdown(wait=True, cancel_futures=True)
        raise
    executor.shutdown(wait=True)
    return results


BACKENDS = ("local", "ray")


def twin_spec(agent: str) -> str:
    """The gaze-blind twin of an agent spec: the same agent with its gaze and head held
    (``gaze_blind:<spec>``; ``fixed_gaze`` is already the twin of ``eyecatch``)."""
    if agent == "fixed_gaze" or agent.startswith(("gaze_blind:", "static_gaze:")):
        raise ValueError(f"{agent!r} is already a gaze-blind agent: it has no twin")
    return f"gaze_blind:{agent}"


TWIN_WRAPPERS = ("gaze_blind", "static_gaze")


def static_twin_spec(agent: str, env_id: str) -> str:
    """The best static twin of an agent spec on ``env_id``: the same agent with its gaze, vergence and head
    replaced by the constant posture searched for it (``static_gaze:<posture>:<spec>``, the posture written
    out so the spec replays the same whatever the postures file says later; :mod:`visuomotor_gym.static_gaze`).
    Raises ValueError when ``agent`` is already a twin or no posture was searched for it on ``env_id``."""
    if agent == "fixed_gaze" or agent.partition(":")[0] in TWIN_WRAPPERS:
        raise ValueError(f"{agent!r} is already a twin (held or static gaze): it has no twin")
    from visuomotor_gym.static_gaze import resolve_spec

    return resolve_spec(f"static_gaze:{agent}", env_id)


def static_twin_base(spec: str) -> str | None:
    """The agent whose static twin ``spec`` is (``static_gaze:[posture:]<agent>`` -> ``<agent>``), else None."""
    from visuomotor_gym.agents import parse_agent_spec

    if not spec.startswith("static_gaze:"):
        return None
    try:
        return parse_agent_spec(spec)[1]["base"]
    except ValueError:  # not a spec this version parses (an old entry's unknown agent)
        return None


def _run_on_ray(agent, env_id, chunks, seeds, address, progress) -> list[list[EpisodeTrace]]:
    """Spread the chunks over Ray tasks (one CPU each) on a local or remote cluster.

    The chunks, their seeds and the one-agent-per-chunk rule are the local pool's, so a deterministic
    agent gives the same per-seed outcomes. Workers must be able to import ``visuomotor_gym`` (true for
    a local cluster started from this environment; on a remote cluster install the package there or
    pass a ``runtime_env`` through ``ray.init`` before calling).
    """
    try:
        import ray
    except ImportError as exc:
        raise RuntimeError("backend='ray' needs Ray: pip install 'visuomotor_gym[distributed]'") from exc
    started_here = not ray.is_initialized()
    if started_here:
        ray.init(address=address, log_to_driver=False, include_dashboard=False, configure_logging=False)
    try:
        remote_chunk = ray.remote(num_cpus=1)(run_chunk)
        refs = [remote_chunk.remote(agent, env_id, [seeds[i] for i in chunk]) for chunk in chunks]
        index = {ref: k for k, ref in enumerate(refs)}
        results: list = [None] * len(refs)
        pending = list(refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            k = index[done[0]]
            results[k] = ray.get(done[0])  # re-raises a task's exception here
            if progress is not None:
                progress.advance(progress.task_ids[0], len(chunks[k]))
        return results
    finally:
        if started_here:
            ray.shutdown()


def evaluate(
    agent: str,
    env_id: str,
    episodes: int,
    seed: int,
    workers: int = 1,
    keep_traces: bool = True,
    progress: bool = False,
    backend: str = "local",
    address: str | None = None,
) -> EvalResult:
    """Play ``agent`` for ``episodes`` episodes of ``env_id`` on seeds ``seed .. seed+episodes-1``.

    Args:
        agent: agent spec for :func:`visuomotor_gym.agents.make_agent` (``"eyecatch"``,
            ``"oracle"``, ``"eyecatch:param=value"``...).
        env_id: a catch environment id (``vmgym envs`` lists them).
        episodes: number of episodes (>= 1).
        seed: first seed (>= 0); episode ``i`` resets with ``seed + i``.
        workers: processes to spread chunks of episodes over; 1 runs in this process.
        keep_traces: keep the per-episode traces in the result (the summary is computed either way).
        progress: show a rich progress bar.
        backend: ``"local"`` (this process, or a process pool of ``workers``) or ``"ray"`` (Ray tasks
            on the cluster at ``address``; ``None`` starts a local one; ``workers`` is then ignored:
            Ray schedules one task per chunk on the cluster's CPUs). Per-seed outcomes are identical.
        address: Ray cluster address (``"auto"``, ``"ray://host:10001"``...), ``backend="ray"`` only.

    Raises:
        ValueError / TypeError: unknown env id or agent, agent overrides the agent rejects,
        episodes < 1, seed < 0, workers < 1 (see :func:`validate_inputs`).
    """
    from visuomotor_gym.agents import is_deterministic

    env_id = validate_inputs(agent, env_id, episodes, seed, workers)
    if backend not in BACKENDS:
        raise ValueError(f"backend={backend!r} is not one of {list(BACKENDS)}")
    if address is not None and backend != "ray":
        raise ValueError("address is only used with backend='ray'")
    from visuomotor_gym.metrics import summarize  # imported up front: fail before the rollouts

    seeds = episode_seeds(seed, episodes)
    chunks = episode_chunks(episodes)
    workers = min(workers, len(chunks))
    bar = _progress_bar(progress, f"{agent} on {env_id}", episodes)
    start = time.perf_counter()
    if bar is not None:
        bar.start()
    try:
        if backend == "ray":
            parts = _run_on_ray(agent, env_id, chunks, seeds, address, bar)
        elif workers == 1:
            parts = _run_in_process(agent, env_id, chunks, seeds, bar)
        else:
            parts = _run_in_pool(agent, env_id, chunks, seeds, workers, bar)
    finally:
        if bar is not None:
            bar.stop()
    wall = time.perf_counter() - start
    traces = [tr for part in parts for tr in part]
    if [tr.seed for tr in traces] != seeds:  # cannot happen: chunks are stored by index
        raise RuntimeError("episodes came back out of seed order")
    return EvalResult(
        agent=agent,
        env_id=env_id,
        episodes=episodes,
        seed=seed,
        agent_deterministic=bool(is_deterministic(agent)),
        control_period_s=float(traces[0].dt),
        summary=summarize(traces),
        traces=traces if keep_traces else [],
        workers=workers,
        wall_time_s=wall,
        env_steps=sum(tr.steps for tr in traces),
    )
