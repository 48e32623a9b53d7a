"""Re-scoring: play an entry's policy again on its pinned seeds, exactly as the evaluator played them.

The evaluator (:mod:`visuomotor_gym.bench.evaluate`) cuts the pinned seeds into chunks whose layout
depends on the episode count only, builds one agent per chunk (seeded with the chunk's first seed)
and plays the chunk's episodes in order with :func:`~visuomotor_gym.bench.trace.run_episode`. A
:class:`Job` is one such chunk of one entry, with the agent built from the entry's *policy file*
(never from anything else the submitter wrote) or, for agents with nothing to configure, from its
spec. Deterministic agents play only the wanted seeds of the chunk (they behave after ``reset()`` as
fresh); stochastic ones replay their chunk from its start up to the last wanted seed.

Jobs run in this process (``workers=1``) or over a spawn process pool; the pool exchanges only the
check's own objects (the job, outcome records and traces); the policy bytes travel as ``bytes``
and are parsed by the format's pickle-free ``load`` inside the worker.
"""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

_ENVS: dict = {}  # one env per env id per process, reused across jobs (as the evaluator's workers do)


@dataclass
class Job:
    key: str  # the entry's key
    env_id: str
    agent: str  # the results' agent spec
    policy_format: str | None  # the entry's policy format (None: built from the spec)
    policy: bytes | None  # the policy file's bytes
    deterministic: bool
    chunk: list[int]  # the evaluator chunk's seeds, in order
    wanted: list[int]  # the seeds whose outcomes are wanted (a subset of ``chunk``)
    keep_traces: bool = False


@dataclass
class JobResult:
    key: str
    records: dict[int, dict] = field(default_factory=dict)  # seed -> outcome record
    traces: list = field(default_factory=list)  # EpisodeTrace of the wanted seeds (keep_traces)
    error: str | None = None


def _env(env_id: str):
    from visuomotor_gym.bench.evaluate import make_env

    if env_id not in _ENVS:
        _ENVS[env_id] = make_env(env_id)
    return _ENVS[env_id]


def build_policy(job: Job, action_dim: int):
    """The agent of ``job``: from its policy file through the format's loader, else from the spec."""
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.leaderboard.policies import policy_format

    if job.policy_format is not None:
        fmt = policy_format(job.policy_format)
        if fmt is None or fmt.retired is not None:
            raise ValueError(f"policy format {job.policy_format!r} cannot be loaded")
        return fmt.load(job.policy, job.env_id)
    return make_agent(job.agent, job.env_id, action_dim=action_dim, seed=int(job.chunk[0]))


def run_job(job: Job) -> JobResult:
    """Play one chunk; a failure is returned as ``error`` (the check reports it as a refusal)."""
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.leaderboard.entries import episode_record

    out = JobResult(job.key)
    try:
        env = _env(job.env_id)
        policy = build_policy(job, int(env.action_space.shape[0]))
        wanted = set(job.wanted)
        last = max(job.chunk.index(s) for s in wanted)
        for seed in job.chunk[: last + 1]:
            if job.deterministic and seed not in wanted:
                continue
            trace = run_episode(env, policy, seed=int(seed), env_id=job.env_id, agent=job.agent)
            if seed in wanted:
                out.records[seed] = episode_record(trace)
                if job.keep_traces:
                    out.traces.append(trace)
    except Exception as exc:  # a policy that cannot be re-played is refused, not a crash
        out.error = f"{type(exc).__name__}: {exc}"
    return out


def run_jobs(jobs: list[Job], workers: int = 1, progress=None) -> list[JobResult]:
    """Results of ``jobs`` in order; ``workers > 1`` spreads them over a spawn process pool.
    ``progress(job, result)`` is called as each job finishes (in order)."""
    if workers <= 1 or len(jobs) <= 1:
        out = []
        for job in jobs:
            out.append(run_job(job))
            if progress is not None:
                progress(job, out[-1])
        return out
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=ctx) as pool:
        out = []
        for job, result in zip(jobs, pool.map(run_job, jobs, chunksize=1), strict=True):
            out.append(result)
            if progress is not None:
                progress(job, result)
        return out


def chunk_jobs(key, env_id, agent, policy_format, policy, deterministic, seed, episodes, wanted, keep_traces):
    """The jobs that re-play ``wanted`` (a subset of the pinned seeds) in the evaluator's chunks."""
    from visuomotor_gym.bench.evaluate import episode_chunks

    wanted = set(wanted)
    jobs = []
    for chunk in episode_chunks(episodes):
        seeds = [seed + i for i in chunk]
        mine = [s for s in seeds if s in wanted]
        if mine:
            jobs.append(Job(key, env_id, agent, policy_format, policy, deterministic, seeds, mine, keep_traces))
    return jobs
