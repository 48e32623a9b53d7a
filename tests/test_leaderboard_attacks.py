"""The leaderboard against a deliberate attacker (issue 16): every attack a pull request can make is refused.

Each test builds a small leaderboard in a temporary git repository (two env ids of 6 episodes, with
honest ``eyecatch`` and ``oracle`` entries committed on ``main``), applies one attack as a pull
request would (new files, edited files), and runs ``vmgym leaderboard check`` as CI runs it: against
``main``, with real re-scoring on the real envs (nothing of the evaluator is mocked). Honest
submissions made in the tests stand in for a clean checkout by recording the temporary repository's
own commit as their ``git_sha`` (``git_state`` is the only thing replaced, for the submitter).

The first eleven attacks were accepted before issue 16; the rest were refused already and stay so.
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


# ---------------------------------------------------------------- attacks accepted before issue 16


def test_01_fabricated_results_for_a_worse_agent(monkeypatch, pr):
    """The zero agent (0/6) claims 4 catches: records, counts, rates and intervals forged together."""
    key = honest_new_entry(monkeypatch, pr)
    res_path, rec_path = paths(pr, key)
    rec = read(rec_path)
    for ep in rec["episodes"][:4]:
        ep.update(caught=True, catch_time_s=1.0)
    rec_path.write_text(dumps_record(rec))
    s = summary_from_records(rec["episodes"])  # every total the static rules compare, forged to match
    edit_results(pr, key, lambda o: o.update(
        caught=4, catch_rate=4 / 6, catch_rate_ci95=list(wilson_interval(4, 6)), success_rate=4 / 6,
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
    key = honest_new_entry(monkeypatch, pr, agent="eyecatch", name="fast")
    edit_results(pr, key, lambda o: (o["latency_ms"].update(p50=0.001, p95=0.002, max=0.003),
                                     o.update(real_time=True)))
    refused(check(pr), "rescore", "latency_ms.p95 = 0.002 ms is more than 10x below")


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
    refused(report, "rescore", "cannot re-play the entry", "is not a plain .npy array")
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
        caught=2, catch_rate=2 / 6, catch_rate_ci95=list(wilson_interval(2, 6)), success_rate=2 / 6,
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
    with pytest.raises(PolicyFileError, match="unexpected member 'run.py'"):
        read_npz(buf.getvalue())
