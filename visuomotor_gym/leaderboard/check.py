"""``vmgym leaderboard check``: every rule an entry must pass, each refusal with a message.

Rules (the ``kind`` of a :class:`~visuomotor_gym.leaderboard.problems.Problem`):

* ``protocol``: ``protocol.json`` is readable and well formed;
* ``layout``: every file under ``results/`` is a results file or an entry record of a
  ``<name>__<env_id>`` entry, each with its partner; every file under ``agents/`` belongs to an entry;
* ``results``: the results file passes the bench schema and its semantic checks
  (:func:`visuomotor_gym.bench.results.load_results`: missing fields, unknown env id, a catch rate
  that is not caught / episodes, a wrong Wilson interval...);
* ``record``: the entry record passes ``entry_schema.json``;
* ``provenance``: the results name the commit they ran at, the command that produced them matches
  their agent, env id, episodes and seed, and the timestamp is not in the future;
* ``consistency``: the record matches its results file (sha256, name, env id, agent), the run follows
  the protocol for its env id (episodes, first seed), the per-episode outcomes are exactly the pinned
  seeds and reproduce the results' caught and diverged counts, time to catch, miss distance,
  first-saccade latency and env steps, and a deterministic agent is not declared stochastic;
* ``policy``: the policy file exists, its sha256 is the recorded one, and the agent spec still exports
  to exactly that file;
* ``rescore``: every entry (but superseded ones) re-played on a sample of its pinned seeds gives the
  recorded outcomes (caught, diverged, steps exactly; times and distances within the protocol's
  tolerances). Deterministic agents are re-played seed by seed; stochastic ones are seeded per chunk by
  the evaluator, so their chunk is replayed up to the seed (an agent that is not seed-reproducible is
  refused);
* ``history``: no file of ``results/`` or ``agents/`` that exists at the base ref was deleted or
  rewritten;
* ``pages``: ``README.md`` and ``index.html`` are what ``vmgym leaderboard build`` generates.
"""

from __future__ import annotations

import hashlib
import shlex
import time
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone

from visuomotor_gym.leaderboard.entries import (
    AGENTS_DIR,
    RESULTS_DIR,
    Entry,
    Leaderboard,
    load_leaderboard,
    summary_from_records,
)
from visuomotor_gym.leaderboard.problems import KINDS, Problem

SUMMARY_TOLERANCE = 1e-9  # results fields recomputed from the records: same floats, same order


@dataclass
class CheckReport:
    problems: list[Problem] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    entries: int = 0
    rescored_entries: int = 0
    rescored_episodes: int = 0
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not self.problems

    def sorted_problems(self) -> list[Problem]:
        order = {k: i for i, k in enumerate(KINDS)}
        return sorted(self.problems, key=lambda p: (order.get(p.kind, 99), p.where, p.message))


def _close(a, b, tol: float) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return abs(float(a) - float(b)) <= tol


# ------------------------------------------------------------------------------ static rules


def provenance_problems(entry: Entry, where: str) -> list[Problem]:
    r = entry.results
    prov = r["provenance"]
    out = []
    if prov["git_sha"] == "unknown":
        out.append(
            Problem(
                where,
                "provenance",
                "provenance.git_sha is 'unknown': an entry must name the commit "
                "it ran at (submit from a git checkout)",
            )
        )
    stamp = datetime.strptime(prov["timestamp_utc"][:19], "%Y-%m-%dT%H:%M:%S").replace(tzinfo=timezone.utc)
    if stamp > datetime.now(timezone.utc) + timedelta(days=1):
        out.append(
            Problem(where, "provenance", f"provenance.timestamp_utc {prov['timestamp_utc']} is in the future")
        )
    command = prov["command"]
    if not command:
        out.append(
            Problem(
                where, "provenance", "provenance.command is missing: an entry must say how it was produced"
            )
        )
        return out
    try:
        argv = shlex.split(command)
    except ValueError as exc:
        return out + [Problem(where, "provenance", f"provenance.command cannot be parsed: {exc}")]
    if argv[:2] == ["vmgym", "bench"]:
        expected = {
            "--agent": r["agent"],
            "--env": r["env_id"],
            "--episodes": str(r["episodes"]),
            "--seed": str(r["seed"]),
        }
    elif argv[:3] == ["vmgym", "leaderboard", "submit"]:
        expected = {"--agent": r["agent"], "--env": r["env_id"]}
    else:
        return out + [
            Problem(
                where,
                "provenance",
                f"provenance.command {command!r} is neither `vmgym bench` nor `vmgym leaderboard submit`",
            )
        ]
    given = {argv[i]: argv[i + 1] for i in range(len(argv) - 1) if argv[i].startswith("--")}
    for flag, value in expected.items():
        if given.get(flag) != value:
            out.append(
                Problem(
                    where,
                    "provenance",
                    f"provenance.command has {flag} {given.get(flag)!r} but the results are for {value!r}",
                )
            )
    return out


def results_hash_problems(lb: Leaderboard, entry: Entry) -> list[Problem]:
    """The results file is the one the entry record was written for (checked even when it is invalid)."""
    if entry.results_bytes is None or entry.record is None:
        return []
    actual = hashlib.sha256(entry.results_bytes).hexdigest()
    recorded = entry.record["results"]["sha256"]
    if recorded == actual:
        return []
    return [
        Problem(
            lb.rel(entry.results_path),
            "consistency",
            f"sha256 of the results file is {actual[:16]}..., but its entry record "
            f"{entry.record_path.name} records {recorded[:16]}...: the results file was changed after "
            f"submission (tampered numbers?); results are only written by `vmgym leaderboard submit`",
        )
    ]


def consistency_problems(lb: Leaderboard, entry: Entry) -> list[Problem]:
    from visuomotor_gym.agents import is_deterministic, parse_agent_spec

    r, rec = entry.results, entry.record
    where_rec, where_res = lb.rel(entry.record_path), lb.rel(entry.results_path)
    out = []

    def add(where, msg):
        out.append(Problem(where, "consistency", msg))

    expected_file = f"{RESULTS_DIR}/{entry.results_path.name}"
    if rec["results"]["file"] != expected_file:
        add(where_rec, f"results.file is {rec['results']['file']!r}, expected {expected_file!r}")
    if rec["name"] != entry.name:
        add(where_rec, f"name is {rec['name']!r} but the file is named for {entry.name!r}")
    for label, value in (("entry record", rec["env_id"]), ("results file", r["env_id"])):
        if value != entry.env_id:
            add(
                where_rec if label == "entry record" else where_res,
                f"env_id in the {label} is {value!r} but the file is named for {entry.env_id!r}",
            )
    if rec["agent"] != r["agent"]:
        add(where_rec, f"agent is {rec['agent']!r} but the results file's agent is {r['agent']!r}")

    try:
        name, _ = parse_agent_spec(r["agent"])
    except ValueError as exc:
        add(
            where_res,
            f"agent {r['agent']!r}: {exc} (an entry's agent must be registered so it can be re-scored)",
        )
    else:
        if bool(r["agent_deterministic"]) != bool(is_deterministic(r["agent"])):
            add(
                where_res,
                f"agent_deterministic is {str(r['agent_deterministic']).lower()}, but the agent "
                f"registry says {name!r} is {'' if is_deterministic(r['agent']) else 'not '}"
                f"deterministic",
            )

    proto = lb.protocol.for_env(r["env_id"]) if lb.protocol is not None else None
    if lb.protocol is not None and proto is None:
        add(
            where_res,
            f"env id {r['env_id']!r} has no protocol in {lb.rel(lb.root / 'protocol.json')}; the "
            f"leaderboard accepts {', '.join(lb.protocol.env_ids)}",
        )
    elif proto is not None and (r["episodes"], r["seed"]) != (proto.episodes, proto.seed):
        add(
            where_res,
            f"the protocol for {proto.env_id} is {proto.episodes} episodes from seed {proto.seed}; "
            f"these results ran {r['episodes']} from seed {r['seed']}",
        )

    eps = rec["episodes"]
    seeds = [e["seed"] for e in eps]
    pinned = [r["seed"] + i for i in range(r["episodes"])]
    if seeds != pinned:
        add(
            where_rec,
            f"the episode records are for seeds {_seed_span(seeds)}, not the pinned seeds "
            f"{pinned[0]}..{pinned[-1]} of the results, in order",
        )
        return out
    for e in eps:
        if e["caught"] != (e["catch_time_s"] is not None):
            add(
                where_rec,
                f"seed {e['seed']}: caught is {str(e['caught']).lower()} but catch_time_s is "
                f"{e['catch_time_s']}",
            )
    s = summary_from_records(eps)
    checks = [
        ("caught", s["caught"], r["caught"]),
        ("diverged", s["diverged"], r["diverged"]),
        ("time_to_catch_s.mean", s["time_to_catch_s"]["mean"], r["time_to_catch_s"]["mean"]),
        ("time_to_catch_s.median", s["time_to_catch_s"]["median"], r["time_to_catch_s"]["median"]),
        ("miss_distance_m.mean", s["miss_distance_m"]["mean"], r["miss_distance_m"]["mean"]),
        ("miss_distance_m.median", s["miss_distance_m"]["median"], r["miss_distance_m"]["median"]),
        (
            "reaction_times_s.first_saccade.mean",
            s["first_saccade_s"]["mean"],
            r["reaction_times_s"]["first_saccade"]["mean"],
        ),
        (
            "reaction_times_s.first_saccade.median",
            s["first_saccade_s"]["median"],
            r["reaction_times_s"]["first_saccade"]["median"],
        ),
    ]
    if isinstance(r.get("run"), dict) and "env_steps" in r["run"]:
        checks.append(("run.env_steps", s["env_steps"], r["run"]["env_steps"]))
    for label, from_records, in_results in checks:
        if not _close(from_records, in_results, SUMMARY_TOLERANCE):
            add(
                where_res,
                f"{label} = {in_results} in the results, but the entry's per-episode records give "
                f"{from_records}: the results do not match the episodes they claim",
            )
    return out


def _seed_span(seeds: list[int]) -> str:
    if not seeds:
        return "(none)"
    return f"{seeds[0]}..{seeds[-1]} ({len(seeds)} records)"


def policy_problems(lb: Leaderboard, entry: Entry, export: bool = True) -> list[Problem]:
    from visuomotor_gym.agents import parse_agent_spec
    from visuomotor_gym.leaderboard.policies import format_for_agent

    out = []
    where_rec = lb.rel(entry.record_path)
    pol = entry.policy
    try:
        name, _ = parse_agent_spec(entry.results["agent"])
    except ValueError:
        return out  # reported by the consistency rule
    fmt = format_for_agent(name)
    if fmt is None:
        if pol is not None:
            out.append(
                Problem(
                    where_rec,
                    "policy",
                    f"agent {name!r} has no policy-file format, yet the entry names {pol['file']}",
                )
            )
        return out
    if pol is None:
        return [
            Problem(
                where_rec,
                "policy",
                f"agent {name!r} needs a policy file ({fmt.name}), but the entry has none",
            )
        ]
    if pol["format"] != fmt.name:
        out.append(Problem(where_rec, "policy", f"policy format is {pol['format']!r}, expected {fmt.name!r}"))
        return out
    path = lb.root / pol["file"]
    where = lb.rel(path)
    if not path.is_file():
        return [Problem(where, "policy", f"missing: the entry {entry.key} records this policy file")]
    data = path.read_bytes()
    actual = hashlib.sha256(data).hexdigest()
    if actual != pol["sha256"]:
        return [
            Problem(
                where,
                "policy",
                f"sha256 of the policy file is {actual[:16]}..., but its entry "
                f"{entry.record_path.name} records {pol['sha256'][:16]}...: the policy "
                f"file changed after submission",
            )
        ]
    if export and fmt.reexport and entry.superseded is None:
        try:
            fresh = fmt.export(entry.results["agent"], entry.env_id)
        except Exception as exc:  # noqa: BLE001 - any failure to rebuild the spec is a refusal
            return [
                Problem(
                    where,
                    "policy",
                    f"the agent spec {entry.results['agent']!r} cannot be exported any more: {exc}",
                )
            ]
        if fresh != data:
            out.append(
                Problem(
                    where,
                    "policy",
                    f"the agent spec {entry.results['agent']!r} on {entry.env_id} no "
                    f"longer exports to this policy file (the agent's code or defaults "
                    f"changed?): a changed agent needs a new entry name, and this one "
                    f"belongs in superseded.json",
                )
            )
    return out


def orphan_problems(lb: Leaderboard) -> list[Problem]:
    agents = lb.root / AGENTS_DIR
    if not agents.is_dir():
        return []
    used = {(e.policy or {}).get("file") for e in lb.entries if e.record is not None}
    return [
        Problem(lb.rel(p), "layout", "policy file that no entry record references")
        for p in sorted(agents.iterdir())
        if f"{AGENTS_DIR}/{p.name}" not in used
    ]


# ------------------------------------------------------------------------------ re-scoring


def _chunk_start(seed: int, episodes: int, target: int) -> int:
    """First seed of the evaluator's chunk holding ``target`` (its agent was built with that seed)."""
    from visuomotor_gym.bench.evaluate import episode_chunks

    for chunk in episode_chunks(episodes):
        if seed + chunk.start <= target < seed + chunk.stop:
            return seed + chunk.start
    raise ValueError(f"seed {target} is not among the {episodes} pinned seeds from {seed}")


def rescore_entry(lb: Leaderboard, entry: Entry, seeds: list[int]) -> list[dict]:
    """Play ``entry``'s agent (from its policy file, else its spec) on ``seeds``; one record per seed.

    A deterministic agent gets a fresh policy per seed (it behaves after ``reset()`` as fresh). A
    stochastic agent is seeded per chunk by the evaluator (``make_agent(seed=<chunk's first seed>)``,
    one stream through the chunk), so its chunk is replayed from the start up to the seed: a seeded
    agent reproduces; one that draws from elsewhere does not, and is refused.
    """
    from visuomotor_gym.agents import is_deterministic, make_agent, parse_agent_spec
    from visuomotor_gym.bench.evaluate import make_env
    from visuomotor_gym.bench.trace import run_episode
    from visuomotor_gym.leaderboard.entries import episode_record
    from visuomotor_gym.leaderboard.policies import format_for_agent

    r = entry.results
    name, _ = parse_agent_spec(r["agent"])
    fmt = format_for_agent(name)
    data = (lb.root / entry.policy["file"]).read_bytes() if entry.policy is not None else None
    deterministic = is_deterministic(r["agent"])
    env = make_env(entry.env_id)
    try:
        records = []
        for s in seeds:
            start = _chunk_start(r["seed"], r["episodes"], s)
            if fmt is not None and data is not None:
                policy = fmt.load(data, entry.env_id)
            else:
                action_dim = int(env.action_space.shape[0])
                policy = make_agent(r["agent"], entry.env_id, action_dim=action_dim, seed=start)
            for earlier in range(s if deterministic else start, s + 1):
                trace = run_episode(env, policy, seed=int(earlier), env_id=entry.env_id, agent=r["agent"])
            records.append(episode_record(trace))
        return records
    finally:
        env.close()


def _versions_note(results: dict) -> str:
    import platform

    from visuomotor_gym.bench.provenance import _version

    prov = results["provenance"]
    now = {
        "mujoco": _version("mujoco"),
        "numpy": _version("numpy"),
        "gymnasium": _version("gymnasium"),
        "machine": platform.machine(),
    }
    diff = [f"{k} {prov.get(k)} -> {v}" for k, v in now.items() if prov.get(k) != v]
    return f" (this check runs with different software: {', '.join(diff)})" if diff else ""


def compare_records(recorded: dict, fresh: dict, time_tol: float, dist_tol: float) -> list[str]:
    """Differences between a recorded and a re-scored episode, as ``field: recorded X, re-scored Y``."""
    out = []
    for k in ("caught", "diverged", "steps"):
        if recorded[k] != fresh[k]:
            out.append(f"{k}: recorded {recorded[k]}, re-scored {fresh[k]}")
    for k, tol in (("catch_time_s", time_tol), ("first_saccade_s", time_tol), ("miss_distance_m", dist_tol)):
        if not _close(recorded[k], fresh[k], tol):
            out.append(f"{k}: recorded {recorded[k]}, re-scored {fresh[k]}")
    return out


def rescore_problems(lb: Leaderboard, entry: Entry, seeds: list[int]) -> list[Problem]:
    by_seed = {e["seed"]: e for e in entry.record["episodes"]}
    where = lb.rel(entry.results_path)
    unknown = [s for s in seeds if s not in by_seed]
    if unknown:
        return [Problem(where, "rescore", f"seeds {unknown} are not among the entry's pinned seeds")]
    try:
        fresh = rescore_entry(lb, entry, seeds)
    except Exception as exc:  # noqa: BLE001 - a policy that cannot be re-played is refused
        return [Problem(where, "rescore", f"cannot re-play the entry: {type(exc).__name__}: {exc}")]
    out = []
    p = lb.protocol
    for s, rec in zip(seeds, fresh, strict=True):
        diffs = compare_records(by_seed[s], rec, p.time_tolerance_s, p.distance_tolerance_m)
        if diffs:
            out.append(
                Problem(
                    where,
                    "rescore",
                    f"re-scoring seed {s} disagrees with the recorded outcome: "
                    f"{'; '.join(diffs)}{_versions_note(entry.results)}",
                )
            )
    return out


def sample_for(lb: Leaderboard, entry: Entry, sample: int | str | None, seeds: list[int] | None) -> list[int]:
    """The seeds to re-play: ``seeds`` if given, all pinned seeds for ``sample == "all"``, else the
    protocol's stratified sample (``sample`` overrides its size)."""
    from visuomotor_gym.leaderboard.protocol import sample_seeds

    r = entry.results
    pinned = [r["seed"] + i for i in range(r["episodes"])]
    if seeds is not None:
        return list(seeds)
    if sample == "all":
        return pinned
    k = lb.protocol.rescore_sample if sample is None else int(sample)
    return sample_seeds(pinned, k, entry.record["results"]["sha256"])


# ------------------------------------------------------------------------------ the check


def check_leaderboard(
    root,
    base: str | None = "auto",
    rescore: bool = True,
    sample: int | str | None = None,
    seeds: list[int] | None = None,
    pages: bool = True,
    progress=None,
    only: set[str] | None = None,
) -> CheckReport:
    """Run every rule on the leaderboard at ``root``; returns a :class:`CheckReport`.

    ``base``: git ref the history rule compares with (``"auto"``: origin/main, main or HEAD; None or
    ``"none"``: skip the rule). ``sample``: re-score sample size (None: the protocol's) or ``"all"``;
    ``seeds``: re-play exactly these seeds of every entry. ``progress(str)`` gets a
    line per stage. ``only``: re-score only the entries with these keys (``submit`` checks its own).
    """
    from visuomotor_gym.leaderboard.history import history_problems
    from visuomotor_gym.leaderboard.pages import stale_page_problems

    say = progress or (lambda _msg: None)
    report = CheckReport()
    t0 = time.perf_counter()
    lb = load_leaderboard(root)
    report.problems += lb.problems
    report.entries = len(lb.entries)
    static_ok: dict[str, bool] = {}
    for entry in lb.entries:
        report.problems += results_hash_problems(lb, entry)
    for entry in lb.valid_entries:
        before = len(report.problems)
        report.problems += provenance_problems(entry, lb.rel(entry.results_path))
        report.problems += consistency_problems(lb, entry)
        report.problems += policy_problems(lb, entry)
        static_ok[entry.key] = len(report.problems) == before and not results_hash_problems(lb, entry)
    report.problems += orphan_problems(lb)
    report.seconds["validate"] = time.perf_counter() - t0
    say(
        f"validated {len(lb.entries)} entries ({len(lb.valid_entries)} loaded) "
        f"in {report.seconds['validate']:.1f} s"
    )

    t1 = time.perf_counter()
    if rescore and lb.protocol is not None:
        for entry in lb.valid_entries:
            if only is not None and entry.key not in only:
                continue
            if entry.superseded is not None:
                report.notes.append(f"{entry.key}: superseded, not re-scored ({entry.superseded['reason']})")
                continue
            if not static_ok.get(entry.key):
                report.notes.append(f"{entry.key}: not re-scored (fix the problems above first)")
                continue
            chosen = sample_for(lb, entry, sample, seeds)
            t = time.perf_counter()
            found = rescore_problems(lb, entry, chosen)
            report.problems += found
            report.rescored_entries += 1
            report.rescored_episodes += len(chosen)
            say(
                f"re-scored {entry.key} on {len(chosen)} seeds in {time.perf_counter() - t:.1f} s: "
                f"{'DISAGREES' if found else 'agrees'}"
            )
    elif not rescore:
        report.notes.append("re-scoring skipped (--no-rescore)")
    report.seconds["rescore"] = time.perf_counter() - t1

    t2 = time.perf_counter()
    if base is None or str(base).lower() == "none":
        report.notes.append("history rule skipped (--base none)")
    else:
        found, note = history_problems(lb.root, base, lb.rel)
        report.problems += found
        if note:
            report.notes.append(f"history: {note}")
    report.seconds["history"] = time.perf_counter() - t2

    t3 = time.perf_counter()
    if pages and lb.problems:
        report.notes.append(
            "pages not compared: some entries do not load (fix them, then `vmgym leaderboard build`)"
        )
    elif pages:
        report.problems += stale_page_problems(lb)
    report.seconds["pages"] = time.perf_counter() - t3
    report.seconds["total"] = time.perf_counter() - t0
    return report
