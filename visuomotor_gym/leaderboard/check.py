"""``vmgym leaderboard check``: every rule an entry must pass, each refusal with a message.

Rules (the ``kind`` of a :class:`~visuomotor_gym.leaderboard.problems.Problem`):

* ``protocol``: ``protocol.json`` passes ``protocol_schema.json`` (closed objects, tolerances at
  most 1 ms / 1 mm);
* ``layout``: every file under the folder is a regular file (no symbolic link anywhere, no special
  file; checked before anything is read, :func:`.entries.unsafe_paths`; a link the base already holds
  unchanged is a note); every file under ``results/`` is a results file or an entry record of a
  ``<name>__<env_id>`` entry, each with its partner; every file under ``agents/`` belongs to an entry,
  and an entry's policy file is ``agents/<name>__<env_id><suffix>``;
  ``superseded.json`` passes ``superseded_schema.json``, lists entries that exist, each superseded
  ``by`` an entry of the same agent on the same env id;
* ``results``: the results file passes the bench schema (closed at every level, ``run`` required)
  and its semantic checks (:func:`visuomotor_gym.bench.results.load_results`);
* ``record``: the entry record passes ``entry_schema.json`` (no control characters in any string); a
  *new* entry's name is not a look-alike of another entry's (:func:`confusable_problems`) and its agent
  spec is plain (:func:`agent_spec_problems`: a strict pattern; a path argument is a relative path
  inside the entry's own team's files);
* ``provenance``: the results name the commit they ran at, the command that produced them matches
  their agent, env id, episodes, seed and entry name, and the timestamp is not in the future. For a
  *new* entry (one that is not on the base ref) also: the commit exists in the history of the checked
  tree, the tree was clean, the run is not older than its commit, and the commit holds the agent and
  the policy file the entry claims (:func:`.history.claim_problems`);
* ``consistency``: the record matches its results file (sha256, name, env id, agent), the run follows
  the protocol for its env id (episodes, first seed), the per-episode outcomes are exactly the pinned
  seeds and reproduce the results' caught and diverged counts, time to catch, miss distance,
  first-saccade latency and env steps, and a deterministic agent is not declared stochastic;
* ``policy``: the policy file exists, its sha256 is the recorded one, its format is current (a retired
  format, such as the pickled ``sb3-ppo-zip``, only on superseded entries, and never loaded), and the
  agent spec still exports to exactly that file;
* ``rescore``: entries are re-played from their policy files, as the evaluator played them. A **new**
  entry is re-played on **every** pinned seed, and everything the results claim about play is
  recomputed from those episodes and compared (counts, success and catch rates with their intervals,
  gaze realism and its components, reaction times, miss distance, time to catch, env steps). Its
  latency is *measured* on those episodes, on this machine, and reported beside the self-reported
  figure (:attr:`CheckReport.latency`, a note per entry): it is not a pass/fail rule, since it depends
  on the machine and its load (a byte copy of an honest entry must pass on a busy runner). An
  **existing** entry (not superseded) is re-played on ``rescore.sample`` seeds, one per
  stratum, drawn from the base commit's sha and the entry key: fixed before any pull request, never
  from submitted bytes. Outcomes must agree (caught, diverged, steps exactly; times and distances
  within the protocol's tolerances);
* ``history``: no file of ``results/`` or ``agents/`` that exists at the base ref was deleted or
  rewritten; ``protocol.json`` is not weakened; ``superseded.json`` is append-only and lists only
  entries admitted on the base (:mod:`.history`);
* ``pages``: ``README.md`` and ``index.html`` are what ``vmgym leaderboard build`` generates.

Without a base (``--base none``) every entry counts as new (re-scored on every seed, superseded
entries skipped), and the rules that need git (history, the provenance commit) are skipped with a note.
"""

from __future__ import annotations

import hashlib
import re
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
    read_regular,
    summary_from_records,
)
from visuomotor_gym.leaderboard.problems import KINDS, Problem

POLICY_SUFFIX_RE = re.compile(r"\.[a-z0-9]{1,8}")
SUMMARY_TOLERANCE = 1e-9  # results fields recomputed from the records: same floats, same order
# What a new entry's results must say about play, recomputed from its re-scored episodes.
RECOMPUTED_FIELDS = (
    "episodes",
    "caught",
    "catch_rate",
    "catch_rate_ci95",
    "success",
    "success_rate",
    "success_rate_ci95",
    "diverged",
    "gaze_realism",
    "reaction_times_s",
    "miss_distance_m",
    "time_to_catch_s",
    "hand_path",
)


@dataclass
class CheckReport:
    problems: list[Problem] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    entries: int = 0
    rescored_entries: int = 0
    rescored_episodes: int = 0
    new_entries: list[str] = field(default_factory=list)  # keys of entries that are not on the base
    # key -> (self-reported latency p95 ms, p95 this check measured on the re-scored episodes, steps)
    latency: dict[str, tuple] = field(default_factory=dict)
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
    """Static provenance rules (every entry); :func:`admission_provenance_problems` adds git's."""
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
        return [*out, Problem(where, "provenance", f"provenance.command cannot be parsed: {exc}")]
    if argv[:2] == ["vmgym", "bench"]:
        expected = {
            "--agent": r["agent"],
            "--env": r["env_id"],
            "--episodes": str(r["episodes"]),
            "--seed": str(r["seed"]),
        }
    elif argv[:3] == ["vmgym", "leaderboard", "submit"]:
        expected = {"--agent": r["agent"], "--env": r["env_id"], "--name": entry.name}
    else:
        return [
            *out,
            Problem(
                where,
                "provenance",
                f"provenance.command {command!r} is neither `vmgym bench` nor `vmgym leaderboard submit`",
            ),
        ]
    given = {argv[i]: argv[i + 1] for i in range(len(argv) - 1) if argv[i].startswith("--")}
    for flag, value in expected.items():
        if given.get(flag) != value:
            out.append(
                Problem(
                    where,
                    "provenance",
                    f"provenance.command has {flag} {given.get(flag)!r} but the "
                    f"{'entry is named' if flag == '--name' else 'results are for'} {value!r}",
                )
            )
    return out


def admission_provenance_problems(lb: Leaderboard, entry: Entry) -> list[Problem]:
    """A new entry's provenance against git: a clean tree, a commit in the history of the checked
    tree (HEAD), and a run no older than that commit (:func:`.history.commit_problems`)."""
    from visuomotor_gym.leaderboard.history import claim_problems, commit_problems

    prov = entry.results["provenance"]
    where = lb.rel(entry.results_path)
    out = []
    if prov["git_dirty"] is not False:
        out.append(
            Problem(
                where,
                "provenance",
                f"provenance.git_dirty is {str(prov['git_dirty']).lower()}: a new entry must be produced "
                f"from a clean checkout (commit your changes, then submit), so that its git_sha is the "
                f"code that ran",
            )
        )
    if prov["git_sha"] != "unknown":
        found = commit_problems(lb.root, prov["git_sha"], prov["timestamp_utc"], where)
        out += found
        if not found:
            policy = None
            if entry.policy is not None and (lb.root / entry.policy["file"]) not in lb.links:
                try:
                    policy = read_regular(lb.root / entry.policy["file"])
                except ValueError:
                    policy = None  # reported by the policy rule
            out += claim_problems(lb.root, prov["git_sha"], entry.results["agent"], policy, where)
    return out


# A new entry's agent spec: a registered agent name, then ':'-separated arguments of plain characters
# (no spaces, quotes, brackets, '|', '<', '>', '!', '`': nothing Markdown or HTML reads). Length: the
# longest committed spec is 68 characters (modelling choice: 4x room).
SPEC_RE = re.compile(r"[a-z][a-z0-9_]*(:[A-Za-z0-9._/=,+-]+)*")
MAX_SPEC_LENGTH = 256
# A path argument (``ppo:<path>``): relative, each component starting with a letter or digit (no '..',
# no hidden files, no absolute path, no '~').
PATH_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*(/[A-Za-z0-9][A-Za-z0-9._-]*)*")
TWIN_PREFIX = "gaze-blind-"  # entry names of the held twins
STATIC_PREFIX = "static-gaze-"  # entry names of the best static twins
TWIN_PREFIXES = (TWIN_PREFIX, STATIC_PREFIX)


def team(name: str) -> str:
    """The agent an entry name belongs to: without a twin's prefix and the version suffix
    (``gaze-blind-ppo-gated-v2`` and ``static-gaze-ppo-gated`` -> ``ppo-gated``)."""
    return family(name.removeprefix(TWIN_PREFIX).removeprefix(STATIC_PREFIX))


def agent_spec_problems(entry: Entry, where: str) -> list[Problem]:
    """A new entry's agent spec is plain text (:data:`SPEC_RE`), and a path argument names the entry's
    own team's files: a relative path (:data:`PATH_RE`) whose ``<name>__<env_id>`` components (policy
    files are named so) all belong to the entry's team, and which holds at least one such component or
    a folder named for the team: an entry cannot present another team's policy as its own."""
    from visuomotor_gym.leaderboard.history import _agent_names

    agent = entry.results["agent"]
    if len(agent) > MAX_SPEC_LENGTH or not SPEC_RE.fullmatch(agent):
        return [
            Problem(
                where,
                "record",
                f"agent spec {agent[:80]!r} is not plain: a new entry's spec is <agent>[:<argument>...] of at most "
                f"{MAX_SPEC_LENGTH} letters, digits and . _ / = , + - (no spaces, quotes, brackets, '|', '<', '>')",
            )
        ]
    try:
        _names, path = _agent_names(agent)
    except ValueError:
        return []  # reported by the consistency rule
    if path is None:
        return []
    own = team(entry.name)
    if not PATH_RE.fullmatch(path):
        return [
            Problem(
                where,
                "record",
                f"the agent spec's path {path!r} must be relative, inside the repository (no '..', no hidden or "
                f"absolute paths)",
            )
        ]
    parts = path.split("/")
    claimed = {team(p.split("__")[0]) for p in parts if "__" in p}
    others = sorted(claimed - {own})
    if others or not (claimed or own in parts):
        return [
            Problem(
                where,
                "record",
                f"the agent spec's path {path!r} is not the entry's own: the entry {entry.name!r} belongs to "
                f"{own!r}, the path to {', '.join(map(repr, others)) if others else 'no team'}; name a file "
                f"<{own}...>__<env_id>.npz or one in a folder named {own!r}",
            )
        ]
    return []


# Look-alike characters folded into one skeleton (modelling choice, the ASCII subset of Unicode's
# confusables.txt that renders alike in the monospace and sans-serif fonts of GitHub and the page):
# I, l, 1 and | ; O, o and 0 ; rn and m ; vv and w ; and the separators - _ . ; case is ignored.
_FOLDS = (("rn", "m"), ("vv", "w"), ("I", "l"), ("1", "l"), ("|", "l"), ("0", "o"), ("_", "-"), (".", "-"))


def skeleton(name: str) -> str:
    """``name`` with look-alike characters folded: ``beIief_mpc`` and ``belief-mpc`` -> ``belief-mpc``."""
    s = name
    for a, b in _FOLDS[2:]:
        s = s.replace(a, b)
    s = s.lower()
    for a, b in _FOLDS[:2]:
        s = s.replace(a, b)
    return s


def confusable_problems(lb: Leaderboard, entry: Entry, where: str) -> list[Problem]:
    """A new entry's team may not look like another team (:func:`skeleton` of :func:`team` equal, the
    names different): ``beIief_mpc-v4`` next to ``belief_mpc`` is refused; ``belief_mpc-v4`` is a
    version of it and is not."""
    own = team(entry.name)
    for other in sorted({team(e.name) for e in lb.entries if e.key != entry.key}):
        if other != own and skeleton(other) == skeleton(own):
            return [
                Problem(
                    where,
                    "record",
                    f"entry name {entry.name!r} looks like the existing {other!r} (both read {skeleton(own)!r} "
                    f"with I/l/1, O/0, rn/m, case and - _ . folded): choose a name that cannot be mistaken for "
                    f"another agent's",
                )
            ]
    return []


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

    if "gaze_gain" in r:  # a claim about another agent's play, which this entry's replay cannot verify
        add(where_res, "gaze_gain is not accepted in leaderboard results: the leaderboard computes the gain "
                       "from the gaze-blind twin's own entry (submit gaze_blind:<agent> on the same env id)")
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
    if pol is not None:
        from visuomotor_gym.leaderboard.policies import policy_format

        recorded = policy_format(pol["format"])
        if recorded is not None and recorded.retired is not None and recorded.agent == name:
            if entry.superseded is None:
                return [
                    Problem(
                        where_rec,
                        "policy",
                        f"policy format {pol['format']!r} is retired and is never loaded: {recorded.retired}",
                    )
                ]
            return _hash_problems(lb, entry)  # kept and hash-checked while superseded; never loaded
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
        if entry.superseded is not None:
            return []  # entered before its agent had a policy format; kept, not re-scored
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
    found = _hash_problems(lb, entry)
    if found:
        return found
    if path in lb.links:
        return []
    data = read_regular(path)
    if export and fmt.reexport and entry.superseded is None:
        try:
            fresh = fmt.export(entry.results["agent"], entry.env_id)
        except Exception as exc:  # any failure to rebuild the spec is a refusal
            return [
                Problem(
                    where,
                    "policy",
                    f"the agent spec {entry.results['agent']!r} cannot be exported any more: {exc}",
                )
            ]
        if fresh != data and not (fmt.same_policy is not None and fmt.same_policy(data, fresh, entry.env_id)):
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


def _hash_problems(lb: Leaderboard, entry: Entry) -> list[Problem]:
    pol = entry.policy
    path = lb.root / pol["file"]
    where = lb.rel(path)
    suffix = pol["file"][len(f"{AGENTS_DIR}/{entry.key}"):]
    if not pol["file"].startswith(f"{AGENTS_DIR}/{entry.key}.") or not POLICY_SUFFIX_RE.fullmatch(suffix):
        return [
            Problem(
                lb.rel(entry.record_path),
                "policy",
                f"policy.file is {pol['file']!r}; an entry's policy file is {AGENTS_DIR}/{entry.key}.<ext> "
                f"(the name `vmgym leaderboard submit` writes)",
            )
        ]
    if path in lb.links:  # never read; the entry is not re-scored
        return [Problem(where, "policy", f"the entry {entry.key} records this policy file, which is not a regular file")]
    try:
        data = read_regular(path)
    except ValueError:
        return [Problem(where, "policy", f"missing: the entry {entry.key} records this policy file")]
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
    return []


def family(name: str) -> str:
    """An entry name without its version suffix: ``eyecatch-v2`` -> ``eyecatch``."""
    import re

    return re.sub(r"-v[0-9]+$", "", name)


def superseded_problems(lb: Leaderboard) -> list[Problem]:
    """Each listing is superseded ``by`` an entry of the same agent on the same env id: another agent's
    entry cannot be demoted (the same registered agent, and the same name up to a ``-v<N>`` suffix)."""
    from visuomotor_gym.agents import parse_agent_spec

    where = lb.rel(lb.root / "superseded.json")
    by_key = {e.key: e for e in lb.entries}
    out = []

    def agent_name(e):
        try:
            return parse_agent_spec(e.results["agent"])[0] if e.results else None
        except ValueError:
            return None

    for key, listing in sorted(lb.superseded.items()):
        old, new = by_key.get(key), by_key.get(listing["by"])
        if old is None:
            continue  # "lists ..., which is no entry" (layout)
        if new is None:
            out.append(Problem(where, "layout", f"{key!r} is superseded by {listing['by']!r}, which is no entry"))
            continue
        if new.key == old.key:
            out.append(Problem(where, "layout", f"{key!r} cannot supersede itself"))
            continue
        if new.env_id != old.env_id:
            out.append(
                Problem(where, "layout", f"{key!r} is superseded by {new.key!r}, an entry on another env id")
            )
        same_agent = agent_name(old) is not None and agent_name(old) == agent_name(new)
        if not same_agent or family(old.name) != family(new.name):
            out.append(
                Problem(
                    where,
                    "layout",
                    f"{key!r} (agent {agent_name(old)!r}) is superseded by {new.key!r} (agent "
                    f"{agent_name(new)!r}): an entry can only be superseded by a newer version of itself "
                    f"(the same registered agent and the name {family(old.name)!r} or "
                    f"{family(old.name)}-v<N>); another agent's entry cannot be demoted",
                )
            )
    return out


def orphan_problems(lb: Leaderboard) -> list[Problem]:
    agents = lb.root / AGENTS_DIR
    if not agents.is_dir() or agents in lb.links:
        return []
    used = {(e.policy or {}).get("file") for e in lb.entries if e.record is not None}
    return [
        Problem(lb.rel(p), "layout", "policy file that no entry record references")
        for p in sorted(agents.iterdir())
        if f"{AGENTS_DIR}/{p.name}" not in used and p not in lb.links
    ]


# ------------------------------------------------------------------------------ re-scoring


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


def _differences(path: str, claimed, fresh, tol: float) -> list[str]:
    """Where ``claimed`` (from a results file) differs from ``fresh`` (recomputed), as ``path: X vs Y``."""
    if isinstance(fresh, dict):
        if not isinstance(claimed, dict) or set(claimed) != set(fresh):
            return [f"{path}: results {claimed!r}, re-scored {fresh!r}"]
        return [d for k in fresh for d in _differences(f"{path}.{k}", claimed[k], fresh[k], tol)]
    if isinstance(fresh, list):
        if not isinstance(claimed, list) or len(claimed) != len(fresh):
            return [f"{path}: results {claimed!r}, re-scored {fresh!r}"]
        return [d for i, (a, b) in enumerate(zip(claimed, fresh)) for d in _differences(f"{path}[{i}]", a, b, tol)]
    if isinstance(fresh, bool) or fresh is None or isinstance(claimed, bool) or claimed is None:
        return [] if claimed == fresh else [f"{path}: results {claimed!r}, re-scored {fresh!r}"]
    if isinstance(fresh, (int, float)) and isinstance(claimed, (int, float)):
        return [] if abs(float(claimed) - float(fresh)) <= tol else [f"{path}: results {claimed!r}, re-scored {fresh!r}"]
    return [] if claimed == fresh else [f"{path}: results {claimed!r}, re-scored {fresh!r}"]


def summary_problems(lb: Leaderboard, entry: Entry, traces: list) -> list[Problem]:
    """A new entry's results, recomputed from its re-scored episodes (every pinned seed): every play
    field of :data:`RECOMPUTED_FIELDS`, env steps and control period (latency is measured, not
    compared: :func:`measured_latency`)."""
    from visuomotor_gym.metrics import summarize

    r = entry.results
    where = lb.rel(entry.results_path)
    fresh = summarize(traces)
    # Same floats from the same episodes; but re-played outcomes may drift within the protocol's
    # tolerances (software versions), and so may what is computed from them.
    p = lb.protocol
    tol = max(SUMMARY_TOLERANCE, p.time_tolerance_s, p.distance_tolerance_m)
    diffs = []
    for key in RECOMPUTED_FIELDS:
        if key not in r and key.startswith("success"):
            continue  # results written before success(_rate) existed: catch_rate (compared) is the success
        if key == "hand_path" and key not in r:
            continue  # optional (results written before it existed); when claimed it must be what re-scoring gives
        diffs += _differences(key, r.get(key), fresh[key], tol)
    steps = sum(int(t.steps) for t in traces)
    if r["run"]["env_steps"] != steps:
        diffs.append(f"run.env_steps: results {r['run']['env_steps']}, re-scored {steps}")
    period = 1000.0 * float(traces[0].dt)
    if abs(r["control_period_ms"] - period) > tol:
        diffs.append(f"control_period_ms: results {r['control_period_ms']}, re-scored {period}")
    out = []
    if diffs:
        shown = "; ".join(diffs[:6]) + (f"; and {len(diffs) - 6} more" if len(diffs) > 6 else "")
        out.append(
            Problem(
                where,
                "rescore",
                f"the results do not match their {len(traces)} re-scored episodes: {shown}"
                f"{_versions_note(r)}",
            )
        )
    return out


def measured_latency(entry: Entry, traces: list) -> tuple:
    """(self-reported latency p95, the p95 measured on ``traces`` on this machine, policy steps timed)."""
    from visuomotor_gym.metrics.summary import latency_summary

    lat = latency_summary(traces)
    return entry.results["latency_ms"]["p95"], lat["p95"], sum(int(t.steps) for t in traces)


def latency_note(key: str, figures: tuple) -> str:
    claimed, measured, steps = figures
    shown = "n/a" if claimed is None else f"{claimed:.3g} ms"
    return (
        f"{key}: latency p95 self-reported {shown}, measured by this check {measured:.3g} ms over {steps} "
        f"policy steps on this machine (shown, not a rule: machines and load differ)"
    )


@dataclass
class _Plan:
    entry: Entry
    seeds: list[int]
    full: bool  # every pinned seed: recompute the summary from the episodes


def _plan(lb: Leaderboard, entry: Entry, new: bool, base_sha: str | None, sample, seeds) -> _Plan:
    """Which seeds of ``entry`` to re-play (see the module doc)."""
    from visuomotor_gym.leaderboard.protocol import sample_seeds

    r = entry.results
    pinned = [r["seed"] + i for i in range(r["episodes"])]
    if seeds is not None:
        return _Plan(entry, list(seeds), False)
    if new or sample == "all":
        return _Plan(entry, pinned, True)
    k = lb.protocol.rescore_sample if sample is None else int(sample)
    return _Plan(entry, sample_seeds(pinned, k, f"{base_sha}:{entry.key}"), k >= len(pinned))


def sample_for(lb: Leaderboard, entry: Entry, base_sha: str, sample: int | None = None) -> list[int]:
    """The seeds an existing entry is re-scored on against the base commit ``base_sha``."""
    return _plan(lb, entry, False, base_sha, sample, None).seeds


def rescore_entries(
    lb: Leaderboard, plans: list[_Plan], workers: int = 1, say=None, latency: dict | None = None
) -> tuple[list[Problem], int]:
    """Re-play every plan (one pool for all), compare; returns (problems, episodes played). ``latency``
    (a dict) gets, per fully re-played entry, the figures of :func:`measured_latency`."""
    from visuomotor_gym.agents import is_deterministic
    from visuomotor_gym.leaderboard.rescore import chunk_jobs, run_jobs

    problems: list[Problem] = []
    jobs = []
    for plan in plans:
        e, r = plan.entry, plan.entry.results
        where = lb.rel(e.results_path)
        pinned = set(range(r["seed"], r["seed"] + r["episodes"]))
        unknown = [s for s in plan.seeds if s not in pinned]
        if unknown:
            problems.append(Problem(where, "rescore", f"seeds {unknown} are not among the entry's pinned seeds"))
            plan.seeds = [s for s in plan.seeds if s in pinned]
        data = read_regular(lb.root / e.policy["file"]) if e.policy is not None else None
        fmt = e.policy["format"] if e.policy is not None else None
        jobs += chunk_jobs(
            e.key, e.env_id, r["agent"], fmt, data, is_deterministic(r["agent"]), r["seed"], r["episodes"],
            plan.seeds, plan.full,
        )
    results = run_jobs(jobs, workers=workers)
    by_key: dict[str, list] = {}
    for job, res in zip(jobs, results, strict=True):
        by_key.setdefault(job.key, []).append(res)
    played = 0
    p = lb.protocol
    for plan in plans:
        e = plan.entry
        where = lb.rel(e.results_path)
        parts = by_key.get(e.key, [])
        errors = [res.error for res in parts if res.error]
        if errors:
            problems.append(Problem(where, "rescore", f"cannot re-play the entry: {errors[0]}"))
            if say:
                say(f"re-scored {e.key}: FAILED to re-play")
            continue
        fresh = {seed: rec for res in parts for seed, rec in res.records.items()}
        played += len(fresh)
        recorded = {ep["seed"]: ep for ep in e.record["episodes"]}
        found = []
        for s in plan.seeds:
            diffs = compare_records(recorded[s], fresh[s], p.time_tolerance_s, p.distance_tolerance_m)
            if diffs:
                found.append(
                    Problem(
                        where,
                        "rescore",
                        f"re-scoring seed {s} disagrees with the recorded outcome: "
                        f"{'; '.join(diffs)}{_versions_note(e.results)}",
                    )
                )
        if plan.full and not found:
            traces = sorted((t for res in parts for t in res.traces), key=lambda t: t.seed)
            found += summary_problems(lb, e, traces)
            if latency is not None and traces:
                latency[e.key] = measured_latency(e, traces)
        problems += found
        if say:
            what = "every pinned seed, summary recomputed" if plan.full else "sampled seeds"
            say(f"re-scored {e.key} on {len(plan.seeds)} seeds ({what}): {'DISAGREES' if found else 'agrees'}")
    return problems, played


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
    workers: int = 1,
) -> CheckReport:
    """Run every rule on the leaderboard at ``root``; returns a :class:`CheckReport`.

    ``base``: git ref the history rules compare with (``"auto"``: origin/main, main or HEAD; None or
    ``"none"``: skip them, and count every entry as new). ``sample``: re-score sample size of existing
    entries (None: the protocol's) or ``"all"``; ``seeds``: re-play exactly these seeds of every entry
    (debugging: no summary is recomputed). ``progress(str)`` gets a line per stage. ``only``:
    re-score only the entries with these keys (``submit`` checks its own). ``workers``: processes
    for re-scoring (1: in this process).
    """
    from visuomotor_gym.leaderboard import history
    from visuomotor_gym.leaderboard.pages import stale_page_problems

    say = progress or (lambda _msg: None)
    report = CheckReport()
    t0 = time.perf_counter()
    lb = load_leaderboard(root)
    report.problems += lb.problems
    report.entries = len(lb.entries)

    # The base: which entries are new, and the history rules.
    no_base = base is None or str(base).lower() == "none"
    b = None
    if no_base:
        report.notes.append(
            "history rules skipped (--base none): every entry counts as new (re-scored on every pinned "
            "seed); provenance commits are not checked against git"
        )
    else:
        b, found = history.load_base(lb.root, base, lb.rel)
        report.problems += found
    if b is not None and lb.links:  # links the base already holds unchanged block no pull request
        excused, notes = history.excused_links(b, lb.links)
        report.problems = [p for p in report.problems if p not in {lb.links[x] for x in excused}]
        lb.problems = [p for p in lb.problems if p not in {lb.links[x] for x in excused}]
        report.notes += notes
    existing = b.entry_keys if b is not None else set()
    new_keys = {e.key for e in lb.entries if e.key not in existing}
    report.new_entries = sorted(new_keys)

    static_ok: dict[str, bool] = {}
    for entry in lb.entries:
        report.problems += results_hash_problems(lb, entry)
    for entry in lb.valid_entries:
        before = len(report.problems)
        report.problems += provenance_problems(entry, lb.rel(entry.results_path))
        if b is not None and entry.key in new_keys:
            report.problems += admission_provenance_problems(lb, entry)
            report.problems += agent_spec_problems(entry, lb.rel(entry.results_path))
            report.problems += confusable_problems(lb, entry, lb.rel(entry.record_path))
        report.problems += consistency_problems(lb, entry)
        report.problems += policy_problems(lb, entry)
        static_ok[entry.key] = len(report.problems) == before and not results_hash_problems(lb, entry)
    report.problems += orphan_problems(lb)
    report.problems += superseded_problems(lb)
    report.seconds["validate"] = time.perf_counter() - t0
    say(
        f"validated {len(lb.entries)} entries ({len(lb.valid_entries)} loaded, "
        f"{len(new_keys)} new) in {report.seconds['validate']:.1f} s"
    )

    t1 = time.perf_counter()
    if rescore and lb.protocol is not None and (b is not None or no_base):
        plans = []
        for entry in lb.valid_entries:
            if only is not None and entry.key not in only:
                continue
            if entry.superseded is not None:
                report.notes.append(
                    f"{entry.key}: superseded by {entry.superseded['by']}, not re-scored ({entry.superseded['reason']})"
                )
                continue
            if not static_ok.get(entry.key):
                report.notes.append(f"{entry.key}: not re-scored (fix the problems above first)")
                continue
            plans.append(_plan(lb, entry, entry.key in new_keys, b.sha if b else None, sample, seeds))
        found, played = rescore_entries(lb, plans, workers=workers, say=say, latency=report.latency)
        report.problems += found
        report.notes += [latency_note(k, v) for k, v in sorted(report.latency.items())]
        report.rescored_entries = len(plans)
        report.rescored_episodes = played
    elif not rescore:
        report.notes.append("re-scoring skipped (--no-rescore)")
    else:
        report.notes.append("re-scoring skipped: the base ref is unusable (see the history problem)")
    report.seconds["rescore"] = time.perf_counter() - t1

    t2 = time.perf_counter()
    if b is not None:
        report.problems += history.immutability_problems(b, lb.rel)
        report.problems += history.protocol_history_problems(b, lb)
        report.problems += history.superseded_history_problems(b, lb)
        report.notes.append(
            f"history: {sum(len(v) for v in b.files.values())} committed file(s) compared with {b.ref} "
            f"({b.sha[:12]}); {len(new_keys)} new entr{'y' if len(new_keys) == 1 else 'ies'}"
            + (f" ({', '.join(sorted(new_keys))})" if new_keys else "")
        )
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
