"""The leaderboard against a deliberate attacker: every attack a pull request can make is refused.

Each test builds a small leaderboard in a temporary git repository (two env ids of 6 episodes, with
honest ``eyecatch`` and ``oracle`` entries committed on ``main``), applies one attack as a pull
request would (new files, edited files), and runs ``vmgym leaderboard check`` as CI runs it: against
``main``, with real re-scoring on the real envs (nothing of the evaluator is mocked). Honest
submissions made in the tests stand in for a clean checkout by recording the temporary repository's
own commit as their ``git_sha`` (``git_state`` is the only thing replaced, for the submitter).

The first eleven attacks were accepted by the first version of the check; the rest were refused already and
stay so. Tests 26-43 are the second round: links, the ppo-npz budget and headers, Markdown
injection, latency shown rather than ruled, names, provenance claims and new protocol rows.
"""

from __future__ import annotations

import base64
import hashlib
import io
import json
import pickle
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from visuomotor_gym.bench import provenance as provenance_module
from visuomotor_gym.bench.results import dumps_results
from visuomotor_gym.cli import main
from visuomotor_gym.leaderboard.check import check_leaderboard
from visuomotor_gym.leaderboard.entries import dumps_record, summary_from_records
from visuomotor_gym.metrics.stats import wilson_interval

REPO = Path(__file__).resolve().parents[1]
EPISODES = 6
ORACLE, FOVEATED = "EyeCatchOracle-v0", "EyeCatch-v0"


def git(cwd: Path, *args: str) -> str:
    out = subprocess.run(
        ["git", "-c", "user.name=test", "-c", "user.email=test@example.com", *args],
        cwd=cwd, capture_output=True, text=True, check=True,
    )
    return out.stdout.strip()


def submit(root: Path, agent: str, env: str, name: str | None = None) -> int:
    argv = ["leaderboard", "submit", "--agent", agent, "--env", env, "--dir", str(root), "--workers", "1",
            "--no-progress"]
    return main(argv + (["--name", name] if name else []))


def clean_checkout(monkeypatch, repo: Path) -> str:
    """Submissions record ``repo``'s HEAD as a clean checkout (the submitter's side of provenance)."""
    sha = git(repo, "rev-parse", "HEAD")
    monkeypatch.setattr(provenance_module, "git_state", lambda package_dir=None: (sha, False))
    return sha


@pytest.fixture(scope="module")
def base_repo(tmp_path_factory) -> Path:
    """A repository whose main holds a small protocol and honest eyecatch and oracle entries."""
    root = tmp_path_factory.mktemp("attacks") / "base"
    lb = root / "leaderboard"
    lb.mkdir(parents=True)
    proto = json.loads((REPO / "leaderboard" / "protocol.json").read_text())
    proto["envs"] = [dict(e, episodes=EPISODES) for e in proto["envs"] if e["env_id"] in (ORACLE, FOVEATED)]
    (lb / "protocol.json").write_text(json.dumps(proto, indent=2) + "\n")
    git(root, "init", "-q", "-b", "main")
    git(root, "add", "-A")
    git(root, "commit", "-q", "-m", "protocol")
    with pytest.MonkeyPatch.context() as mp:
        clean_checkout(mp, root)
        assert submit(lb, "eyecatch", "all") == 0
        assert submit(lb, "oracle", ORACLE) == 0
    git(root, "add", "-A")
    git(root, "commit", "-q", "-m", "honest entries")
    return root


@pytest.fixture
def pr(base_repo, tmp_path) -> Path:
    """A clone of the base repository: the pull request's working tree; returns its leaderboard."""
    work = tmp_path / "pr"
    git(tmp_path, "clone", "-q", str(base_repo), str(work))
    git(work, "checkout", "-q", "-B", "main", "origin/main")
    return work / "leaderboard"


def check(lb: Path, **kw):
    kw.setdefault("base", "main")
    kw.setdefault("workers", 1)
    return check_leaderboard(lb, **kw)


def refused(report, kind: str, *fragments: str) -> str:
    """``report`` failed with a ``kind`` problem whose message holds every fragment; returns it."""
    assert not report.ok, "accepted"
    for p in report.problems:
        if p.kind == kind and all(f in str(p) for f in fragments):
            return str(p)
    raise AssertionError(f"no [{kind}] problem with {fragments}:\n" + "\n".join(map(str, report.problems)))


def paths(lb: Path, key: str) -> tuple[Path, Path]:
    return lb / "results" / f"{key}.json", lb / "results" / f"{key}.entry.json"


def read(path: Path) -> dict:
    return json.loads(path.read_text())


def rehash(lb: Path, key: str) -> None:
    """What a careful forger does after editing a results file: record its new sha256 and rebuild pages."""
    res, rec_path = paths(lb, key)
    rec = read(rec_path)
    rec["results"]["sha256"] = hashlib.sha256(res.read_bytes()).hexdigest()
    rec_path.write_text(dumps_record(rec))
    main(["leaderboard", "build", "--dir", str(lb)])


def honest_new_entry(monkeypatch, lb: Path, agent="zero", env=ORACLE, name="attacker") -> str:
    clean_checkout(monkeypatch, lb.parent)
    assert submit(lb, agent, env, name) == 0
    return f"{name}__{env}"


def edit_results(lb: Path, key: str, change) -> None:
    res, _ = paths(lb, key)
    obj = read(res)
    change(obj)
    res.write_text(dumps_results(obj) if "run" in obj else json.dumps(obj, indent=2) + "\n")
    rehash(lb, key)


# ---------------------------------------------------------------- honest submissions are accepted


def test_the_base_and_an_honest_new_entry_pass(monkeypatch, pr):
    report = check(pr)
    assert report.ok, "\n".join(map(str, report.problems))
    assert report.new_entries == []
    key = honest_new_entry(monkeypatch, pr)
    report = check(pr)
    assert report.ok, "\n".join(map(str, report.problems))
    assert report.new_entries == [key]
    assert report.rescored_episodes == 3 * EPISODES + EPISODES  # existing: sample >= 6 seeds; new: all


# ---------------------------------------------------------------- attacks the first check accepted


def test_01_fabricated_results_for_a_worse_agent(monkeypatch, pr):
    """The zero agent (0/6) claims 4 catches: records, counts, rates and intervals forged together."""
    key = honest_new_entry(monkeypatch, pr)
    _res_path, rec_path = paths(pr, key)
    rec = read(rec_path)
    for ep in rec["episodes"][:4]:
        ep.update(caught=True, catch_time_s=1.0)
    rec_path.write_text(dumps_record(rec))
    s = summary_from_records(rec["episodes"])  # every total the static rules compare, forged to match
    edit_results(pr, key, lambda o: o.update(
        caught=4, catch_rate=4 / 6, catch_rate_ci95=list(wilson_interval(4, 6)), success=4, success_rate=4 / 6,
        success_rate_ci95=list(wilson_interval(4, 6)), time_to_catch_s=s["time_to_catch_s"],
        miss_distance_m=s["miss_distance_m"]))
    report = check(pr)
    assert not [p for p in report.problems if p.kind in ("results", "consistency")]  # a careful forgery
    refused(report, "rescore", key, "re-scoring seed 0 disagrees", "caught: recorded True, re-scored False")


def test_02_weakened_protocol(pr):
    proto = read(pr / "protocol.json")
    proto["rescore"] = {"sample": 1, "tolerance": {"time_s": 1e9, "distance_m": 1e9}}
    (pr / "protocol.json").write_text(json.dumps(proto))
    refused(check(pr, rescore=False), "protocol", "time_s: 1000000000.0 is greater than the maximum of 0.001")
    proto["rescore"] = {"sample": 1, "tolerance": {"time_s": 1e-3, "distance_m": 1e-3}}
    (pr / "protocol.json").write_text(json.dumps(proto))
    report = check(pr, rescore=False)
    refused(report, "history", "rescore.sample was lowered from 12 to 1")
    refused(report, "history", "rescore.tolerance.time_s was raised from 1e-06 to 0.001")
    proto["envs"][0]["episodes"] = 3
    (pr / "protocol.json").write_text(json.dumps(proto))
    refused(check(pr, rescore=False), "history", "episodes/seed changed from 6/0 to 3/0")


def test_03_fabricated_entry_hidden_in_superseded(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="eyecatch-v2")
    (pr / "superseded.json").write_text(json.dumps(
        {"superseded": {key: {"reason": "hide me", "by": f"eyecatch__{ORACLE}"}}}))
    report = check(pr, rescore=False)
    refused(report, "history", f"lists {key!r}, which is not an entry on main", "hide it from re-scoring")


def test_04_competitor_demoted(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    (pr / "superseded.json").write_text(json.dumps(
        {"superseded": {f"eyecatch__{ORACLE}": {"reason": "better", "by": key}}}))
    refused(check(pr, rescore=False), "layout", "another agent's entry cannot be demoted")
    (pr / "superseded.json").write_text(json.dumps({"superseded": {f"eyecatch__{ORACLE}": {"reason": "x"}}}))
    refused(check(pr, rescore=False), "layout", "by: missing required field")


def test_05_nested_extra_key(pr):
    key = f"eyecatch__{FOVEATED}"
    res_path, _ = paths(pr, key)
    obj = read(res_path)
    obj["gaze_realism"]["components"]["first_saccade_latency_s"]["verified_by"] = "me"
    obj["provenance"]["reviewer"] = "me"
    res_path.write_text(dumps_results(obj))
    report = check(pr, rescore=False)
    refused(report, "results", "Additional properties are not allowed ('verified_by' was unexpected)")
    refused(report, "results", "$.provenance: Additional properties are not allowed ('reviewer' was unexpected)")


def test_06_results_without_run_block(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    edit_results(pr, key, lambda o: o.pop("run"))
    refused(check(pr, rescore=False), "results", "$.run: missing required field")


@pytest.mark.parametrize(
    "field,value,fragment",
    [
        ("git_sha", "0" * 40, "is not a commit of this repository"),
        ("git_dirty", True, "git_dirty is true"),
        ("timestamp_utc", "1999-01-01T00:00:00Z", "is before commit"),
    ],
    ids=["07-zero-sha", "08-dirty-tree", "09-1999-timestamp"],
)
def test_07_09_fake_provenance(monkeypatch, pr, field, value, fragment):
    key = honest_new_entry(monkeypatch, pr)
    edit_results(pr, key, lambda o: o["provenance"].update({field: value}))
    refused(check(pr, rescore=False), "provenance", fragment)


def test_10_fake_latency(monkeypatch, pr):
    """Latency is self-reported and shown beside CI's own figure (a pass/fail rule once refused honest
    entries on a loaded machine): a claim of 0.002 ms is kept, and the check reports what it measured."""
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="fast")
    edit_results(pr, key, lambda o: (o["latency_ms"].update(p50=0.001, p95=0.002, max=0.003),
                                     o.update(real_time=True)))
    report = check(pr)
    assert report.ok, "\n".join(map(str, report.problems))
    claimed, measured, steps = report.latency[key]
    assert claimed == 0.002 and measured > claimed and steps > 0
    assert any(n.startswith(f"{key}: latency p95 self-reported 0.002 ms, measured by this check") for n in report.notes)


class _Payload:
    """Unpickling this creates a file: the stand-in for an attacker's code."""

    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def test_11_pickle_payload_in_a_policy_file(monkeypatch, pr, tmp_path):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="evil")
    marker = tmp_path / "pwned"
    payload = pickle.dumps(_Payload(marker))
    proof = tmp_path / "proof"  # the payload is live: unpickling it runs code
    pickle.loads(pickle.dumps(_Payload(proof))).close()
    assert proof.exists()
    _, rec_path = paths(pr, key)
    rec = read(rec_path)
    (pr / "agents" / f"{key}.json").unlink()

    # an SB3 zip whose data member carries the payload, as cloudpickle would load it
    data = {"policy_class": {":type:": "x", ":serialized:": base64.b64encode(payload).decode()}}
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("data", json.dumps(data))
    zip_path = pr / "agents" / f"{key}.zip"
    zip_path.write_bytes(buf.getvalue())
    rec["agent"] = "ppo:evil.zip"
    rec["policy"] = {"file": f"agents/{key}.zip", "format": "sb3-ppo-zip",
                     "sha256": hashlib.sha256(zip_path.read_bytes()).hexdigest()}
    rec_path.write_text(dumps_record(rec))
    edit_results(pr, key, lambda o: (o.update(agent="ppo:evil.zip"), o["provenance"].update(
        command=o["provenance"]["command"].replace("--agent eyecatch", "--agent ppo:evil.zip"))))
    report = check(pr)
    refused(report, "policy", "'sb3-ppo-zip' is retired and is never loaded")
    assert not marker.exists()

    # the same payload as an object array in a ppo-npz file: refused without unpickling
    zip_path.unlink()
    arr = io.BytesIO()
    np.save(arr, np.array([_Payload(marker)], dtype=object), allow_pickle=True)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("policy.json", json.dumps({"format": "ppo-npz", "format_version": 1}))
        zf.writestr("pi.0.weight.npy", arr.getvalue())
    npz = pr / "agents" / f"{key}.npz"
    npz.write_bytes(buf.getvalue())
    rec = read(rec_path)
    rec["policy"] = {"file": f"agents/{key}.npz", "format": "ppo-npz",
                     "sha256": hashlib.sha256(npz.read_bytes()).hexdigest()}
    rec_path.write_text(dumps_record(rec))
    rehash(pr, key)
    report = check(pr)
    refused(report, "record", "the agent spec's path 'evil.zip' is not the entry's own")  # admission refuses
    report = check(pr, base="none")  # without the admission rules: the loader itself refuses it
    refused(report, "rescore", "cannot re-play the entry", "array 'pi.0.weight.npy' has dtype object")
    assert not marker.exists()


# ---------------------------------------------------------------- attacks refused before, still refused


def test_12_tampered_catch_rate(pr):
    key = f"eyecatch__{ORACLE}"
    res_path, _ = paths(pr, key)
    obj = read(res_path)
    obj["catch_rate"] = 0.5
    res_path.write_text(dumps_results(obj))
    report = check(pr, rescore=False)
    refused(report, "results", "catch_rate = 0.5 differs from caught / episodes")
    refused(report, "consistency", "sha256 of the results file", "changed after submission")
    refused(report, "history", "was rewritten")


def test_13_consistently_forged_counts(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    edit_results(pr, key, lambda o: o.update(
        caught=2, catch_rate=2 / 6, catch_rate_ci95=list(wilson_interval(2, 6)), success=2, success_rate=2 / 6,
        success_rate_ci95=list(wilson_interval(2, 6))))
    refused(check(pr, rescore=False), "consistency", "caught = 2 in the results", "per-episode records give 0")


def test_14_swapped_episode_records(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", env=FOVEATED, name="swap")
    _, rec_path = paths(pr, key)
    rec = read(rec_path)
    eps = rec["episodes"]
    b = next(i for i, e in enumerate(eps) if e["steps"] != eps[0]["steps"])
    for k in [k for k in eps[0] if k != "seed"]:
        eps[0][k], eps[b][k] = eps[b][k], eps[0][k]
    rec_path.write_text(dumps_record(rec))
    refused(check(pr), "rescore", "re-scoring seed 0 disagrees", "steps: recorded")


def test_15_deleted_entry(pr):
    for p in paths(pr, f"oracle__{ORACLE}"):
        p.unlink()
    refused(check(pr, rescore=False), "history", "was deleted, but it exists on main")


def test_16_rewritten_entry(pr):
    res_path, _ = paths(pr, f"oracle__{ORACLE}")
    res_path.write_text(json.dumps(read(res_path), indent=4) + "\n")
    refused(check(pr, rescore=False), "history", "was rewritten")


def test_17_policy_file_changed(pr):
    path = pr / "agents" / f"eyecatch__{FOVEATED}.json"
    obj = read(path)
    obj["params"]["update_period_s"] = 0.25
    path.write_text(json.dumps(obj, indent=2) + "\n")
    refused(check(pr, rescore=False), "policy", "sha256 of the policy file", "changed after submission")


def test_18_policy_file_the_spec_does_not_export(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="tuned")
    path = pr / "agents" / f"{key}.json"
    obj = read(path)
    obj["params"]["update_period_s"] = 0.25
    path.write_text(json.dumps(obj, indent=2) + "\n")
    _, rec_path = paths(pr, key)
    rec = read(rec_path)
    rec["policy"]["sha256"] = hashlib.sha256(path.read_bytes()).hexdigest()
    rec_path.write_text(dumps_record(rec))
    refused(check(pr, rescore=False), "policy", "no longer exports to this policy file")


def test_19_deterministic_agent_declared_stochastic(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    edit_results(pr, key, lambda o: o.update(agent_deterministic=False))
    refused(check(pr, rescore=False), "consistency", "agent_deterministic is false")


def test_20_off_protocol_run(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    edit_results(pr, key, lambda o: o.update(seed=1, seeds=dict(o["seeds"], first=1, last=6)))
    refused(check(pr, rescore=False), "consistency", "is 6 episodes from seed 0; these results ran 6 from seed 1")


def test_21_unknown_env_id(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    for p in paths(pr, key):
        p.rename(p.with_name(p.name.replace(ORACLE, "EyeCatchMoon-v0")))
    res_path, _ = paths(pr, "attacker__EyeCatchMoon-v0")
    obj = read(res_path)
    obj["env_id"] = "EyeCatchMoon-v0"
    res_path.write_text(dumps_results(obj))
    refused(check(pr, rescore=False), "results", "'EyeCatchMoon-v0' is not a registered environment id")


def test_22_stale_pages(pr):
    page = pr / "index.html"
    page.write_text(page.read_text().replace("100.0 %", "100.1 %", 1))
    refused(check(pr, rescore=False), "pages", "index.html", "is stale")


# ---------------------------------------------------------------- further attacks


def test_23_forged_gaze_realism_and_success(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="realist")
    edit_results(pr, key, lambda o: o["gaze_realism"].update(score=0.99))
    refused(check(pr), "rescore", "do not match their 6 re-scored episodes", "gaze_realism.score: results 0.99")


def test_23b_forged_hand_path(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="straight")
    assert "hand_path" in read(paths(pr, key)[0]), "a catch entry's results carry the hand-path block"
    edit_results(pr, key, lambda o: o["hand_path"].update(verdict="human-like", score=0.99))
    refused(check(pr), "rescore", "do not match their 6 re-scored episodes", "hand_path.score: results 0.99")


def test_24_superseded_listing_removed_or_changed(pr, tmp_path):
    """On the committed leaderboard: superseded.json is append-only."""
    root = tmp_path / "repo"
    root.mkdir()
    git(root, "init", "-q", "-b", "main")
    shutil.copytree(REPO / "leaderboard", root / "leaderboard")
    git(root, "add", "-A")
    git(root, "commit", "-q", "-m", "leaderboard")
    lb = root / "leaderboard"
    obj = read(lb / "superseded.json")
    first = sorted(obj["superseded"])[0]
    obj["superseded"].pop(first)
    second = sorted(obj["superseded"])[0]
    obj["superseded"][second]["reason"] = "edited"
    (lb / "superseded.json").write_text(json.dumps(obj))
    report = check(lb, rescore=False, pages=False)
    refused(report, "history", f"the listing of {first!r} was removed")
    refused(report, "history", f"the reason of {second!r} changed")


def test_25_zip_bomb_and_foreign_members_in_a_policy_file():
    from visuomotor_gym.baselines.ppo.agent import PolicyFileError, read_npz

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("policy.json", "{}")
        zf.writestr("big.npy", b"\0" * (65 * 1024 * 1024))
    with pytest.raises(PolicyFileError, match="more than the 67108864 allowed"):
        read_npz(buf.getvalue())
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("policy.json", "{}")
        zf.writestr("run.py", "print(1)")
    with pytest.raises(PolicyFileError, match=r"unexpected member 'run\.py'"):
        read_npz(buf.getvalue())


# ---------------------------------------------------------------- second round


def _commit_all(repo: Path, message: str) -> str:
    git(repo, "add", "-A")
    git(repo, "commit", "-q", "-m", message)
    return git(repo, "rev-parse", "HEAD")


def test_26_symlinked_entry_is_refused_at_admission(monkeypatch, pr, tmp_path):
    """Results, record and policy committed as links to copies elsewhere: refused before anything is read."""
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="linked")
    elsewhere = tmp_path / "elsewhere"
    for p in (*paths(pr, key), pr / "agents" / f"{key}.json"):
        (elsewhere / p.parent.name).mkdir(parents=True, exist_ok=True)
        shutil.move(p, elsewhere / p.parent.name / p.name)
        p.symlink_to(elsewhere / p.parent.name / p.name)  # an absolute link
    report = check(pr)
    for p in (*paths(pr, key), pr / "agents" / f"{key}.json"):
        refused(report, "layout", p.name, "is a symbolic link", "never followed")
    assert key not in report.new_entries  # not loaded as an entry
    # the policy file alone as a link (results and record regular): never read, the entry not re-scored
    for p in paths(pr, key):
        p.unlink()
        shutil.copyfile(elsewhere / p.parent.name / p.name, p)
    report = check(pr)
    refused(report, "layout", f"{key}.json", "is a symbolic link")
    refused(report, "policy", "which is not a regular file")
    assert report.rescored_episodes == 3 * EPISODES  # the existing entries' samples only
    rel = pr / "results" / "rel.json"
    rel.symlink_to("../protocol.json")  # a relative link to a file inside the folder
    refused(check(pr, rescore=False), "layout", "rel.json", "is a symbolic link")


@pytest.mark.parametrize("file", ["agents/..", "agents/eyecatch__EyeCatch-v0.json", "agents/x\n.json"])
def test_26b_policy_file_path_is_the_entrys_own(monkeypatch, pr, file):
    """A record naming a folder, another entry's policy file, or a name with a newline: refused, never read."""
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="pointer")
    _, rec_path = paths(pr, key)
    rec = read(rec_path)
    rec["policy"]["file"] = file
    rec_path.write_text(dumps_record(rec))
    report = check(pr, rescore=False)
    assert not report.ok
    assert any(p.kind in ("policy", "record") and (f"policy.file is {file!r}" in p.message
                                                   or "control character" in p.message) for p in report.problems)


def test_27_symlinked_folder_and_fifo_are_refused(pr, tmp_path):
    copy = tmp_path / "agents-copy"
    shutil.copytree(pr / "agents", copy)
    shutil.rmtree(pr / "agents")
    (pr / "agents").symlink_to(copy)
    refused(check(pr, rescore=False), "layout", "agents", "is a symbolic link")
    (pr / "agents").unlink()
    shutil.copytree(copy, pr / "agents")
    import os

    os.mkfifo(pr / "results" / "pipe.json")  # would block a reader forever
    refused(check(pr, rescore=False), "layout", "pipe.json", "special file")


def test_28_committed_symlink_never_blocks_later_pull_requests(monkeypatch, pr, tmp_path):
    """A link merged by mistake: later PRs pass (compared as a link, not followed), and it may be deleted."""
    repo = pr.parent
    target = tmp_path / "copy.json"
    target.write_text("{}")
    link = pr / "results" / "ghost__EyeCatch-v0.json"
    link.symlink_to(target)
    _commit_all(repo, "a link merged by mistake")  # on main, the base of the next pull request
    report = check(pr, rescore=False)  # an unrelated later PR: nothing changed
    assert report.ok, "\n".join(map(str, report.problems))
    assert any("ghost__EyeCatch-v0.json is a symbolic link committed on main" in n for n in report.notes)
    target.write_text('{"changed": true}')  # the target changes: the link text does not, nothing is read
    assert check(pr, rescore=False).ok
    link.unlink()  # deleting it is allowed
    assert check(pr, rescore=False).ok


def test_29_history_compares_blobs_and_modes(pr):
    """A committed entry file replaced by a link to a byte copy of itself, or made executable: refused."""
    import os

    res, _ = paths(pr, f"oracle__{ORACLE}")
    copy = res.with_name("copy.txt")
    shutil.copyfile(res, copy)
    res.unlink()
    res.symlink_to(copy.name)
    report = check(pr, rescore=False)
    refused(report, "history", "was replaced by a symbolic link")
    res.unlink()
    shutil.move(copy, res)
    os.chmod(res, 0o755)
    refused(check(pr, rescore=False), "history", "was rewritten")


def _ppo_record_and_arrays():
    from visuomotor_gym.baselines.ppo.agent import read_npz

    return read_npz((REPO / "leaderboard" / "agents" / "ppo-gated__EyeCatch-v0.npz").read_bytes())


def test_30_ppo_npz_network_budget():
    """One 2000x2000 array referenced by many layers, too many layers, too wide: refused from the headers."""
    from visuomotor_gym.baselines.ppo.agent import PolicyFileError, PPOAgent, _write_npz

    record, _ = _ppo_record_and_arrays()
    big = {"w": np.zeros((2000, 2000), np.float32), "b": np.zeros(2000, np.float32)}
    rec = json.loads(json.dumps(record))
    rec["network"]["layers"] = [{"weight": "w", "bias": "b", "activation": "tanh"}] * 10
    data = _write_npz(rec, big)
    assert len(data) < 100_000  # a small file...
    with pytest.raises(PolicyFileError, match="referenced more than once"):
        PPOAgent.from_npz(data, FOVEATED)  # ...refused before any layer is built
    rec["network"]["layers"] = [{"weight": "w", "bias": "b", "activation": "tanh"}]
    with pytest.raises(PolicyFileError, match=r"4000000 allowed|FLOPs per action"):
        PPOAgent.from_npz(_write_npz(rec, {"w": np.zeros((1999, 2048), np.float32),
                                           "b": np.zeros(1999, np.float32)}), FOVEATED)
    many = {}
    layers = []
    for i in range(17):
        many[f"w{i}"], many[f"b{i}"] = np.zeros((2, 2), np.float32), np.zeros(2, np.float32)
        layers.append({"weight": f"w{i}", "bias": f"b{i}", "activation": None})
    rec["network"]["layers"] = layers
    with pytest.raises(PolicyFileError, match="17 layers, more than the 16 allowed"):
        PPOAgent.from_npz(_write_npz(rec, many), FOVEATED)


def _npz_with_member(record: dict, name: str, payload: bytes) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("policy.json", json.dumps(record))
        zf.writestr(name, payload)
    return buf.getvalue()


@pytest.mark.parametrize(
    "header,fragment",
    [
        ({"descr": "<f4", "fortran_order": False, "shape": (2**20, 2**21)}, "8796093022208 bytes) but the member holds 64"),
        ({"descr": "<f4", "fortran_order": False, "shape": (2**43,)}, "at most 2 dimensions of at most"),
        ({"descr": "<f4", "fortran_order": False, "shape": (1024, 1024)}, "declares shape (1024, 1024)"),
        ({"descr": "<f4", "fortran_order": False, "shape": (2, 2, 2)}, "at most 2 dimensions"),
        ({"descr": "<i8", "fortran_order": False, "shape": (2,)}, "only float32/float64"),
        ({"descr": "<f4", "fortran_order": True, "shape": (2, 2)}, "Fortran order"),
    ],
    ids=["8-TiB", "32-TiB-vector", "larger-than-member", "3-D", "int", "fortran"],
)
def test_31_npy_headers_checked_before_reading(header, fragment):
    from visuomotor_gym.baselines.ppo.agent import PolicyFileError, PPOAgent

    record, _ = _ppo_record_and_arrays()
    hdr = io.BytesIO()
    np.lib.format.write_array_header_1_0(hdr, header)
    data = _npz_with_member(record, "x.npy", hdr.getvalue() + b"\0" * 64)
    with pytest.raises(PolicyFileError, match=fragment.replace("(", r"\(").replace(")", r"\)")) as info:
        PPOAgent.from_npz(data, FOVEATED)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "key,value,fragment",
    [
        ("clip_obs", "nan", "$.meta.clip_obs must be a finite float"),
        ("clip_obs", -1.0, "$.meta.clip_obs must be a finite float"),
        ("epsilon", 1e9, "$.meta.epsilon"),
        ("belief", "yes", "$.meta.belief must be true or false"),
        ("hand_action", "teleport", "hand_action must be one of"),
        ("obs_var", None, "$.meta.obs_var must"),
    ],
)
def test_32_ppo_npz_meta_is_typed(key, value, fragment):
    from visuomotor_gym.baselines.ppo.agent import PolicyFileError, PPOAgent, _write_npz

    record, arrays = _ppo_record_and_arrays()
    rec = json.loads(json.dumps(record))
    rec["meta"][key] = value if value is not None else [-1.0] * len(rec["meta"]["obs_var"])
    with pytest.raises(PolicyFileError) as info:
        PPOAgent.from_npz(_write_npz(rec, arrays), FOVEATED)
    assert fragment in str(info.value) and "\n" not in str(info.value)
    assert PPOAgent.from_npz(_write_npz(record, arrays), FOVEATED) is not None  # the honest file loads


def test_33_every_npz_loader_failure_is_a_one_line_policy_file_error():
    from visuomotor_gym.baselines.ppo.agent import PolicyFileError, PPOAgent

    record, _ = _ppo_record_and_arrays()
    for data in (b"", b"PK\x03\x04garbage", _npz_with_member(record, "x.npy", b"\x93NUMPY\x01\x00{'descr':"),
                 _npz_with_member({"format": "ppo-npz", "format_version": 1, "network": {"layers": "x"}},
                                  "x.npy", b"")):
        with pytest.raises(PolicyFileError) as info:
            PPOAgent.from_npz(data, FOVEATED)
        assert "\n" not in str(info.value)


# ---- Markdown / HTML injection


def _render_markdown(text: str):
    """The HTML GitHub-flavoured Markdown gives ``text`` (markdown-it-py's GFM-like preset: tables, raw
    HTML allowed as on GitHub), and its tokens."""
    mdit = pytest.importorskip("markdown_it")
    md = mdit.MarkdownIt("gfm-like", {"html": True, "linkify": False})
    return md.render(text), md.parse(text)


EVIL = "x\n| forged | row |\n![](https://evil.example/p.png) <img src=x onerror=alert(1)> <script>alert(1)</script> [click](https://evil.example) https://evil.example www.evil.example `code` me@evil.example"


def test_34_markdown_injection_is_escaped_in_the_readme(monkeypatch, pr):
    """A malicious agent spec and superseded reason, rendered: no new row, no image, link, HTML or autolink."""
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import md_code, md_text, render_readme

    lb = load_leaderboard(pr)
    entry = next(e for e in lb.entries if e.key == f"eyecatch__{FOVEATED}")
    entry.results["agent"] = "eyecatch:" + EVIL
    entry.superseded = {"reason": EVIL, "by": f"oracle__{ORACLE}"}
    text = render_readme(lb)
    assert "<script" not in text and "<img" not in text and "](https://" not in text
    html_out, tokens = _render_markdown(text)
    for tag in ("<img", "<script", "<a href=\"https://evil", "<a href=\"http"):
        assert tag not in html_out, tag
    rows = [t for t in tokens if t.type == "tr_open"]
    header_rows = 2  # the two tables' headers
    assert len(rows) == len(lb.valid_entries) + header_rows  # no forged row
    inline = [c for t in tokens if t.type == "inline" for c in (t.children or [])]
    assert not [c for c in inline if c.type in ("image", "html_inline")]
    links = [c.attrs.get("href") for c in inline if c.type == "link_open"]
    assert all(str(h).startswith("agents/") or h == "protocol.json" or h == "index.html" for h in links), links
    # autolinks (GitHub links bare https:// and www.) are broken by a zero-width space
    for md in (md_text(EVIL), md_code(EVIL)):
        assert "\n" not in md
    assert "https://" not in md_text(EVIL) and "www.evil" not in md_text(EVIL)


def test_35_html_page_escapes_the_same_entry(pr):
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import render_html

    lb = load_leaderboard(pr)
    entry = next(e for e in lb.entries if e.key == f"eyecatch__{FOVEATED}")
    entry.results["agent"] = "eyecatch:" + EVIL
    page = render_html(lb)
    assert "<script>alert" not in page and "<img src=x" not in page and "&lt;script&gt;" in page


@pytest.mark.parametrize(
    "spec,fragment",
    [
        ("eyecatch:x=<img src=x>", "is not plain"),
        ("eyecatch:x=a b", "is not plain"),
        ("ppo:/etc/passwd", "must be relative"),
        ("ppo:../outside/attacker__EyeCatch-v0.npz", "must be relative"),
        ("ppo:leaderboard/agents/eyecatch__EyeCatch-v0.npz", "is not the entry's own"),
        ("ppo:baselines/ppo/policies/model.npz", "is not the entry's own"),
    ],
)
def test_36_agent_spec_is_plain_and_names_the_entrys_own_files(spec, fragment):
    from visuomotor_gym.leaderboard.check import agent_spec_problems
    from visuomotor_gym.leaderboard.entries import Entry

    entry = Entry("attacker__EyeCatch-v0", "attacker", FOVEATED, Path("r.json"), Path("r.entry.json"),
                  results={"agent": spec})
    found = agent_spec_problems(entry, "r.json")
    assert found and fragment in found[0].message, found
    for honest, name in (("ppo:baselines/ppo/policies/ppo-gated__EyeCatch-v0.npz", "ppo-gated"),
                         ("gaze_blind:ppo:baselines/ppo/policies/ppo-gated__EyeCatch-v0.npz", "gaze-blind-ppo-gated"),
                         ("ppo:leaderboard/agents/ppo-intercept-v2__EyeCatch-v0.npz", "ppo-intercept-v3"),
                         ("ppo:runs/attacker/model.npz", "attacker"),
                         ("eyecatch:update_period_s=0.25", "eyecatch-slow")):
        e = Entry(f"{name}__EyeCatch-v0", name, FOVEATED, Path("r.json"), Path("r.entry.json"), results={"agent": honest})
        assert agent_spec_problems(e, "r.json") == [], honest


# ---- latency: shown, not a rule


def test_37_latency_is_measured_and_shown_not_ruled(monkeypatch, pr):
    """A byte copy of an honest entry on a loaded machine is accepted; CI's figure is reported beside the claim."""
    import time as time_module

    from visuomotor_gym.bench import trace as trace_module

    real = time_module.perf_counter
    calls = {"n": 0}

    def slow():  # every policy step appears to take 2 s more: a (very) heavily loaded runner
        calls["n"] += 1
        return real() + 2.0 * calls["n"]

    monkeypatch.setattr(trace_module.time, "perf_counter", slow)
    report = check(pr, base="none", only={f"eyecatch__{FOVEATED}"})
    assert report.ok, "\n".join(map(str, report.problems))
    figures = report.latency[f"eyecatch__{FOVEATED}"]
    assert figures[1] > 10 * figures[0]  # CI measured more than 10x the claim: still accepted
    assert any("latency p95 self-reported" in n and "measured by this check" in n for n in report.notes)


# ---- names, provenance, protocol


def test_38_name_with_trailing_newline_is_refused():
    from visuomotor_gym.leaderboard.entries import check_name

    with pytest.raises(ValueError, match="must start with a letter or digit"):
        check_name("attacker\n")
    assert check_name("attacker") == "attacker"


def test_39_trailing_newline_in_a_record_is_refused(monkeypatch, pr):
    key = honest_new_entry(monkeypatch, pr)
    _, rec_path = paths(pr, key)
    rec = read(rec_path)
    rec["name"] = "attacker\n"
    rec_path.write_text(dumps_record(rec))
    refused(check(pr, rescore=False), "record", "control character")


@pytest.mark.parametrize("name", ["eyecatcn", "EyeCatch", "0racle", "oracIe-v4", "gaze-blind-0racle", "Eyecatch-v9"])
def test_40_look_alike_names_are_refused(monkeypatch, pr, name):
    from visuomotor_gym.leaderboard.check import skeleton

    clean_checkout(monkeypatch, pr.parent)
    if name == "eyecatcn":  # not a look-alike: h and n differ
        assert skeleton(name) != skeleton("eyecatch")
        return
    assert submit(pr, "zero", ORACLE, name) == 0
    refused(check(pr, rescore=False), "record", f"entry name {name!r} looks like the existing")


def test_40b_look_alike_skeletons():
    from visuomotor_gym.leaderboard.check import skeleton, team

    assert skeleton(team("beIief_mpc-v4")) == skeleton("belief_mpc")
    assert skeleton("rnodel") == skeleton("model") and skeleton("l0ok") == skeleton("look")
    assert team("belief_mpc-v4") == "belief_mpc"  # a version of the same agent: not a look-alike


def test_41_provenance_naming_an_unrelated_commit_is_refused(monkeypatch, pr):
    """The commit must hold the agent's registration (and a ppo file its policy)."""
    repo = pr.parent
    first = git(repo, "rev-list", "--max-parents=0", "HEAD")
    (repo / "visuomotor_gym").mkdir()
    (repo / "visuomotor_gym" / "agents.py").write_text('register_agent("zero", ...)\nregister_agent("eyecatch", ...)\n')
    _commit_all(repo, "agents")
    key = honest_new_entry(monkeypatch, pr)
    assert check(pr, rescore=False).ok  # the honest entry: its commit registers "zero"
    edit_results(pr, key, lambda o: o["provenance"].update(git_sha=first, timestamp_utc=o["provenance"]["timestamp_utc"]))
    refused(check(pr, rescore=False), "provenance", "does not hold the agent 'zero'")


def test_42_ppo_entry_must_be_in_its_commit(monkeypatch, pr):
    repo = pr.parent
    src = REPO / "leaderboard" / "agents" / "ppo-gated__EyeCatch-v0.npz"
    dest = repo / "policies" / "ppo-gated__EyeCatch-v0.npz"
    dest.parent.mkdir()
    shutil.copyfile(src, dest)
    before = git(repo, "rev-parse", "HEAD")
    _commit_all(repo, "the policy")
    monkeypatch.chdir(repo)
    key = honest_new_entry(monkeypatch, pr, agent="ppo:policies/ppo-gated__EyeCatch-v0.npz", env=FOVEATED,
                           name="ppo-gated")
    report = check(pr, rescore=False)
    assert report.ok, "\n".join(map(str, report.problems))
    edit_results(pr, key, lambda o: o["provenance"].update(git_sha=before))
    refused(check(pr, rescore=False), "provenance", "which is not a file of commit")


def test_43_new_protocol_row_needs_the_protocols_minimum_episodes(pr):
    proto = read(pr / "protocol.json")
    proto["envs"].append({"env_id": "EyeCatchBounce-v0", "episodes": 1, "seed": 0, "sees": "x"})
    (pr / "protocol.json").write_text(json.dumps(proto))
    refused(check(pr, rescore=False, pages=False), "history", "'EyeCatchBounce-v0' has 1 episodes", "minimum, 6")
    proto["envs"][-1]["episodes"] = EPISODES
    (pr / "protocol.json").write_text(json.dumps(proto))
    assert not [p for p in check(pr, rescore=False, pages=False).problems if p.kind == "history"]
