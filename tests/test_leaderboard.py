"""The leaderboard: ``vmgym leaderboard submit | check | build`` and every refusal of the check.

Refusal tests work on a temporary copy of the committed ``leaderboard/`` folder (and, for the
history rule, a temporary git repository), so they are independent of each other and xdist-safe.
Most of them skip re-scoring (it is exercised by its own tests and by the committed-leaderboard test).

The browser test opens the generated page in headless Chromium. It skips when no Chromium is
installed, unless ``VMGYM_REQUIRE_BROWSER=1`` (set by ``.ci/run`` and the leaderboard workflow, which
install it), where a missing browser fails.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from visuomotor_gym.bench.results import dumps_results
from visuomotor_gym.cli import main
from visuomotor_gym.leaderboard import browser
from visuomotor_gym.leaderboard.check import check_leaderboard
from visuomotor_gym.leaderboard.entries import dumps_record, load_leaderboard
from visuomotor_gym.leaderboard.history import history_problems
from visuomotor_gym.leaderboard.pages import render_pages
from visuomotor_gym.leaderboard.protocol import load_protocol, sample_seeds
from visuomotor_gym.metrics.stats import wilson_interval

REPO = Path(__file__).resolve().parents[1]
COMMITTED = REPO / "leaderboard"
KEY = "eyecatch-v6__EyeCatch-v0"  # current (not superseded) entries
POOR = "eyecatch-v5__EyeCatchPoorVision-v0"


# ---------------------------------------------------------------- helpers


@pytest.fixture
def lb(tmp_path) -> Path:
    """A private copy of the committed leaderboard folder."""
    dest = tmp_path / "leaderboard"
    shutil.copytree(COMMITTED, dest)
    return dest


def results_path(root: Path, key: str = KEY) -> Path:
    return root / "results" / f"{key}.json"


def record_path(root: Path, key: str = KEY) -> Path:
    return root / "results" / f"{key}.entry.json"


def read(path: Path) -> dict:
    return json.loads(path.read_text())


def write_results(path: Path, obj: dict) -> None:
    path.write_text(dumps_results(obj))


def write_record(path: Path, obj: dict) -> None:
    path.write_text(dumps_record(obj))


def rerecord_results_hash(root: Path, key: str = KEY) -> None:
    """What a careful forger does after editing a results file: record its new sha256."""
    import hashlib

    rec = read(record_path(root, key))
    rec["results"]["sha256"] = hashlib.sha256(results_path(root, key).read_bytes()).hexdigest()
    write_record(record_path(root, key), rec)


def check(root: Path, **kw):
    kw.setdefault("base", None)
    kw.setdefault("rescore", False)
    return check_leaderboard(root, **kw)


def messages(report, kind: str | None = None) -> list[str]:
    return [str(p) for p in report.problems if kind is None or p.kind == kind]


def assert_refused(report, kind: str, *fragments: str) -> str:
    """``report`` failed with a ``kind`` problem whose message holds every fragment; returns it."""
    assert not report.ok
    for msg in messages(report, kind):
        if all(f in msg for f in fragments):
            return msg
    raise AssertionError(f"no [{kind}] problem with {fragments}; problems:\n" + "\n".join(messages(report)))


def git(cwd: Path, *args: str) -> str:
    out = subprocess.run(
        ["git", "-c", "user.name=test", "-c", "user.email=test@example.com", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout


@pytest.fixture
def repo(tmp_path) -> Path:
    """A git repository whose ``main`` branch holds a copy of the committed leaderboard."""
    root = tmp_path / "repo"
    root.mkdir()
    git(root, "init", "-q", "-b", "main")
    shutil.copytree(COMMITTED, root / "leaderboard")
    git(root, "add", "-A")
    git(root, "commit", "-q", "-m", "leaderboard")
    return root / "leaderboard"


# ---------------------------------------------------------------- the committed leaderboard


def test_committed_leaderboard_passes_the_full_check():
    report = check_leaderboard(COMMITTED, base="auto")  # what .ci/run runs, re-scoring included
    assert report.ok, "\n".join(messages(report))
    assert report.entries >= 6
    assert report.rescored_entries >= 6 and report.rescored_episodes >= 6 * 12


def test_first_entries_cover_every_env_id_of_the_protocol():
    protocol = load_protocol(COMMITTED)
    board = load_leaderboard(COMMITTED)
    keys = {e.key for e in board.entries}
    from visuomotor_gym.registration import family_of

    for env in protocol.envs:
        assert (env.episodes, env.seed) == (200, 0)
        assert any(k.endswith(f"__{env.env_id}") for k in keys), f"no entry on {env.env_id}"
        if family_of(env.env_id) == "catch":  # the Eyecatch agent is the catch family's reference
            assert any(k.startswith("eyecatch") and k.endswith(f"__{env.env_id}") for k in keys)
    for entry in board.entries:
        if entry.name == "eyecatch":  # its policy file is its resolved parameters
            assert entry.policy is not None and (COMMITTED / entry.policy["file"]).is_file()
        assert len(entry.record["episodes"]) == 200


def test_pages_are_deterministic_and_current(lb):
    board = load_leaderboard(lb)
    first, second = render_pages(board), render_pages(load_leaderboard(lb))
    assert first == second
    for name, text in first.items():
        assert (COMMITTED / name).read_text() == text


# ---------------------------------------------------------------- refusals: results and records


def test_tampered_catch_rate_is_refused(lb):
    obj = read(results_path(lb))
    obj["catch_rate"] = 0.9  # caught stays 200/200
    write_results(results_path(lb), obj)
    report = check(lb)
    assert_refused(report, "results", "catch_rate = 0.9 differs from caught / episodes")
    assert_refused(report, "consistency", "sha256 of the results file", "changed after submission")


def test_consistently_tampered_counts_are_refused_by_the_episode_records(lb):
    """caught, rate and interval forged together, new hash recorded: the per-episode records disagree."""
    obj = read(results_path(lb, POOR))
    true_caught = obj["caught"]
    forged = true_caught + 16
    obj["caught"] = forged
    obj["catch_rate"] = forged / 200
    obj["catch_rate_ci95"] = list(wilson_interval(forged, 200))
    obj["success_rate"] = forged / 200  # on a catch id success is the catch: forged together
    if "success" in obj:
        obj["success"] = forged
    obj["success_rate_ci95"] = list(wilson_interval(forged, 200))
    write_results(results_path(lb, POOR), obj)
    rerecord_results_hash(lb, POOR)
    report = check(lb)
    assert not messages(report, "results")  # the forged file passes the schema and its semantics
    assert_refused(report, "consistency", f"caught = {forged} in the results", f"per-episode records give {true_caught}")


def test_missing_field_is_refused(lb):
    obj = read(results_path(lb))
    del obj["gaze_realism"]
    write_results(results_path(lb), obj)
    rec = read(record_path(lb, POOR))
    del rec["episodes"][3]["steps"]
    write_record(record_path(lb, POOR), rec)
    report = check(lb)
    assert_refused(report, "results", "$.gaze_realism: missing required field")
    assert_refused(report, "record", "$.episodes[3].steps: missing required field")


def test_unknown_env_id_is_refused(lb):
    for old, new in (
        (results_path(lb), results_path(lb, "eyecatch__EyeCatchMoon-v0")),
        (record_path(lb), record_path(lb, "eyecatch__EyeCatchMoon-v0")),
    ):
        old.rename(new)
    obj = read(results_path(lb, "eyecatch__EyeCatchMoon-v0"))
    obj["env_id"] = "EyeCatchMoon-v0"
    write_results(results_path(lb, "eyecatch__EyeCatchMoon-v0"), obj)
    report = check(lb)
    assert_refused(report, "results", "'EyeCatchMoon-v0' is not a registered environment id")


def test_env_id_outside_the_protocol_is_refused(lb):
    proto = read(lb / "protocol.json")
    proto["envs"] = [e for e in proto["envs"] if e["env_id"] != "EyeCatch-v0"]
    (lb / "protocol.json").write_text(json.dumps(proto, indent=2))
    report = check(lb, pages=False)
    assert_refused(report, "consistency", "env id 'EyeCatch-v0' has no protocol")


def test_off_protocol_run_is_refused(lb):
    proto = read(lb / "protocol.json")
    for e in proto["envs"]:
        e["episodes"] = 300
    (lb / "protocol.json").write_text(json.dumps(proto, indent=2))
    report = check(lb, pages=False)
    assert_refused(report, "consistency", "the protocol for EyeCatch-v0 is 300 episodes from seed 0")


def test_deterministic_agent_declared_stochastic_is_refused(lb):
    obj = read(results_path(lb))
    obj["agent_deterministic"] = False  # would dodge re-scoring
    write_results(results_path(lb), obj)
    rerecord_results_hash(lb)
    report = check(lb)
    assert_refused(report, "consistency", "agent_deterministic is false", "'eyecatch' is deterministic")


def test_provenance_without_commit_or_with_a_foreign_command_is_refused(lb):
    obj = read(results_path(lb))
    obj["provenance"]["git_sha"] = "unknown"
    obj["provenance"]["command"] = obj["provenance"]["command"].replace("EyeCatch-v0", "EyeCatchOracle-v0")
    write_results(results_path(lb), obj)
    rerecord_results_hash(lb)
    report = check(lb)
    assert_refused(report, "provenance", "git_sha is 'unknown'")
    assert_refused(report, "provenance", "--env 'EyeCatchOracle-v0'", "results are for 'EyeCatch-v0'")


def test_layout_refusals(lb):
    record_path(lb, POOR).unlink()
    (lb / "agents" / "stray.json").write_text("{}")
    (lb / "results" / "notes.txt").write_text("hi")
    report = check(lb, pages=False)
    assert_refused(report, "layout", "has no entry record")
    assert_refused(report, "layout", "stray.json", "no entry record references")
    assert_refused(report, "layout", "notes.txt", "unexpected file")


# ---------------------------------------------------------------- refusals: policy files


def test_policy_file_whose_hash_does_not_match_is_refused(lb):
    path = lb / "agents" / f"{KEY}.json"
    obj = read(path)
    obj["params"]["update_period_s"] = 0.25
    path.write_text(json.dumps(obj, indent=2) + "\n")
    report = check(lb)
    assert_refused(
        report, "policy", f"agents/{KEY}.json", "sha256 of the policy file", "changed after submission"
    )


def test_policy_file_the_spec_no_longer_exports_to_is_refused(lb):
    import hashlib

    path = lb / "agents" / f"{KEY}.json"
    obj = read(path)
    obj["params"]["update_period_s"] = 0.25
    path.write_text(json.dumps(obj, indent=2) + "\n")
    rec = read(record_path(lb))
    rec["policy"]["sha256"] = hashlib.sha256(path.read_bytes()).hexdigest()  # hash re-recorded
    write_record(record_path(lb), rec)
    report = check(lb)
    assert_refused(
        report, "policy", "the agent spec 'eyecatch' on EyeCatch-v0 no longer exports to this policy file"
    )


# ---------------------------------------------------------------- refusals: re-scoring


def test_rescore_disagreement_is_refused(lb):
    """A forgery the static rules cannot see: two seeds' outcomes swapped (every total unchanged)."""
    rec = read(record_path(lb))
    eps = rec["episodes"]
    a, b = 0, next(i for i, e in enumerate(eps) if e["steps"] != eps[0]["steps"])
    fields = [k for k in eps[a] if k != "seed"]
    for k in fields:
        eps[a][k], eps[b][k] = eps[b][k], eps[a][k]
    write_record(record_path(lb), rec)
    assert check(lb, pages=False).ok  # the totals still match the results
    report = check(lb, rescore=True, seeds=[a, b], only={KEY}, pages=False)
    assert report.rescored_episodes == 2
    msg = assert_refused(
        report, "rescore", f"re-scoring seed {a} disagrees with the recorded outcome", "steps: recorded"
    )
    assert KEY in msg


def test_rescore_sample_is_stratified_and_deterministic():
    seeds = list(range(200))
    s1 = sample_seeds(seeds, 12, "abc")
    assert s1 == sample_seeds(seeds, 12, "abc")
    assert s1 != sample_seeds(seeds, 12, "abd")
    assert len(set(s1)) == 12
    for j, s in enumerate(s1):  # one seed in each of 12 equal strata
        assert (j * 200) // 12 <= s < ((j + 1) * 200) // 12
    assert sample_seeds(seeds[:5], 12, "abc") == seeds[:5]


def test_superseded_entries_are_kept_but_not_rescored(lb):
    already = json.loads((lb / "superseded.json").read_text())["superseded"] if (lb / "superseded.json").exists() else {}
    (lb / "superseded.json").write_text(
        json.dumps(
            {
                "superseded": {
                    **already,
                    KEY: {"reason": "test: the agent changed", "by": "eyecatch__EyeCatch-v0"},
                    "nobody__EyeCatch-v0": {"reason": "x", "by": KEY},
                }
            }
        )
    )
    report = check(lb, rescore=True, seeds=[0], pages=False)
    assert any(KEY in n and "superseded" in n for n in report.notes)
    assert report.rescored_entries == len(load_leaderboard(lb).entries) - len(already) - 1
    assert_refused(report, "layout", "lists 'nobody__EyeCatch-v0', which is no entry")
    html = render_pages(load_leaderboard(lb))["index.html"]
    assert 'id="superseded-table"' in html and "test: the agent changed" in html


# ---------------------------------------------------------------- refusals: history (git)


def test_deleted_entry_is_refused(repo):
    results_path(repo).unlink()
    record_path(repo).unlink()
    report = check(repo, base="main")
    msg = assert_refused(
        report,
        "history",
        f"{KEY}.json",
        "was deleted, but it exists on main",
        "existing entries are immutable",
    )
    assert "git checkout main --" in msg


def test_rewritten_entry_is_refused(repo):
    path = results_path(repo, POOR)
    path.write_text(json.dumps(read(path), indent=4) + "\n")  # same numbers, other bytes
    report = check(repo, base="main")
    assert_refused(report, "history", f"{POOR}.json", "was rewritten", "existing entries are immutable")


def test_new_files_are_allowed_and_an_unknown_base_is_refused(repo):
    (repo / "agents" / "new__EyeCatch-v0.json").write_text("{}")
    found, note = history_problems(repo, "main", str)
    assert found == [] and "compared with main" in note
    report = check(repo, base="no-such-branch")
    assert_refused(report, "history", "base ref 'no-such-branch' not found")


def test_history_outside_git_is_refused_unless_skipped(lb):
    report = check(lb, base="auto")
    if (lb / ".git").exists() or subprocess.run(
        ["git", "-C", str(lb), "rev-parse"], capture_output=True, check=False
    ).returncode == 0:
        pytest.skip("the temporary folder is inside a git repository")
    assert_refused(report, "history", "is not inside a git repository")
    assert check(lb, base=None).ok


# ---------------------------------------------------------------- refusals: pages


def test_stale_page_is_refused(lb):
    page = lb / "index.html"
    page.write_text(page.read_text().replace("100.0 %", "100.1 %", 1))
    (lb / "README.md").unlink()
    report = check(lb)
    assert_refused(report, "pages", "index.html", "is stale", "vmgym leaderboard build")
    assert_refused(report, "pages", "README.md", "missing")
    assert main(["leaderboard", "build", "--dir", str(lb)]) == 0
    assert check(lb).ok


# ---------------------------------------------------------------- the command line


def test_cli_check_exit_codes_and_messages(lb, capsys):
    assert main(["leaderboard", "check", "--dir", str(lb), "--base", "none", "--no-rescore"]) == 0
    assert "PASSED" in capsys.readouterr().out
    obj = read(results_path(lb))
    obj["catch_rate"] = 0.5
    write_results(results_path(lb), obj)
    assert main(["leaderboard", "check", "--dir", str(lb), "--base", "none", "--no-rescore"]) == 1
    out = capsys.readouterr().out
    assert "FAILED" in out and "catch_rate = 0.5 differs from caught / episodes" in out
    assert main(["leaderboard", "check", "--dir", str(lb), "--sample", "zero"]) == 2


def _small_protocol(root: Path, env_ids: list[str], episodes: int = 3) -> None:
    (root / "results").mkdir(parents=True)
    proto = read(COMMITTED / "protocol.json")
    proto["envs"] = [dict(e, episodes=episodes) for e in proto["envs"] if e["env_id"] in env_ids]
    (root / "protocol.json").write_text(json.dumps(proto, indent=2))


def test_submit_writes_entries_that_pass_and_refuses_to_overwrite(tmp_path, capsys):
    root = tmp_path / "lb"
    _small_protocol(root, ["EyeCatch-v0", "EyeCatchOracle-v0"])
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch",
                "--env",
                "all",
                "--dir",
                str(root),
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "oracle",
                "--env",
                "EyeCatchOracle-v0",
                "--dir",
                str(root),
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "they pass the check" in out
    board = load_leaderboard(root)
    assert sorted(e.key for e in board.entries) == [
        "eyecatch__EyeCatch-v0",
        "eyecatch__EyeCatchOracle-v0",
        "oracle__EyeCatchOracle-v0",
    ]
    oracle = next(e for e in board.entries if e.name == "oracle")
    assert oracle.policy is None  # nothing to configure: re-scored from its spec
    assert (root / "agents" / "eyecatch__EyeCatch-v0.json").is_file()
    assert read(results_path(root, "eyecatch__EyeCatch-v0"))["provenance"]["command"].startswith(
        "vmgym leaderboard submit --agent eyecatch"
    )
    report = check_leaderboard(root, base=None, sample="all")
    assert report.ok, "\n".join(messages(report))
    assert report.rescored_episodes == 9
    # Entries are immutable; overrides need their own name.
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch",
                "--env",
                "EyeCatch-v0",
                "--dir",
                str(root),
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 2
    )
    assert "entries are immutable" in capsys.readouterr().err
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch:update_period_s=0.25",
                "--env",
                "EyeCatch-v0",
                "--dir",
                str(root),
                "--no-progress",
            ]
        )
        == 2  # refused before any episode runs
    )
    assert "give the entry its own --name" in capsys.readouterr().err
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch",
                "--env",
                "EyeCatchBounce-v0",
                "--dir",
                str(root),
                "--no-progress",
            ]
        )
        == 2
    )
    assert "has no protocol" in capsys.readouterr().err


def test_submit_from_results_requires_a_reproduction(tmp_path, capsys):
    root = tmp_path / "lb"
    _small_protocol(root, ["EyeCatchOracle-v0"], episodes=2)
    bench = tmp_path / "bench.json"
    assert (
        main(
            [
                "bench",
                "--agent",
                "eyecatch",
                "--env",
                "EyeCatchOracle-v0",
                "--episodes",
                "2",
                "--seed",
                "0",
                "--out",
                str(bench),
                "--no-progress",
            ]
        )
        == 0
    )
    forged = read(bench)
    forged["time_to_catch_s"]["mean"] += 0.1
    bad = tmp_path / "forged.json"
    write_results(bad, forged)
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch",
                "--env",
                "EyeCatchOracle-v0",
                "--dir",
                str(root),
                "--from-results",
                str(bad),
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 1
    )
    assert "does not reproduce on the protocol: time_to_catch_s" in capsys.readouterr().err
    assert (
        main(
            [
                "leaderboard",
                "submit",
                "--agent",
                "eyecatch",
                "--env",
                "EyeCatchOracle-v0",
                "--dir",
                str(root),
                "--from-results",
                str(bench),
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 0
    )
    assert results_path(root, "eyecatch__EyeCatchOracle-v0").read_bytes() == bench.read_bytes()


# ---------------------------------------------------------------- the page in a real browser

PROBE = """
<script>
window.addEventListener('load', () => {
  const box = el => { const r = el.getBoundingClientRect(); return [r.width, r.height]; };
  const out = {
    rows: document.querySelectorAll('#leaderboard-table tbody tr.entry').length,
    firstRow: Array.from(document.querySelectorAll('#leaderboard-table tbody tr.entry')[0].cells)
      .map(c => c.textContent),
    plots: Object.fromEntries(Array.from(document.querySelectorAll('svg.plot')).map(s => [s.id, box(s)])),
    points: Array.from(document.querySelectorAll('#plot-catch-rate circle.point')).map(c => box(c)),
    cells: document.querySelectorAll('#plot-realism g.cell').length,
    bars: document.querySelectorAll('#plot-latency g.latency').length,
    viewport: document.documentElement.clientWidth,
    scrollWidth: document.documentElement.scrollWidth,
    // every element of the page past the viewport's right or left edge (tag, id or class, right edge)
    outside: Array.from(document.body.querySelectorAll('*')).filter(el => {
      const r = el.getBoundingClientRect();
      return r.width > 0 && (r.right > document.documentElement.clientWidth + 0.5 || r.left < -0.5);
    }).map(el => [el.tagName, el.id || el.getAttribute('class') || '', el.getBoundingClientRect().right]),
    // SVG text or point outside its plot's box: a clipped label, legend entry or point
    clipped: Array.from(document.querySelectorAll('svg.plot')).flatMap(svg => {
      const s = svg.getBoundingClientRect();
      return Array.from(svg.querySelectorAll('text, circle')).filter(t => {
        const r = t.getBoundingClientRect();
        return r.left < s.left - 0.5 || r.right > s.right + 0.5 || r.top < s.top - 0.5 || r.bottom > s.bottom + 0.5;
      }).map(t => [svg.id, t.tagName, t.textContent]);
    }),
  };
  const pre = document.createElement('pre'); pre.id = 'probe'; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>
"""


def _need_browser() -> None:
    if browser.find_browser() is None:
        if os.environ.get("VMGYM_REQUIRE_BROWSER") == "1":
            pytest.fail("VMGYM_REQUIRE_BROWSER=1 but no Chromium found (apt-get install chromium)")
        pytest.skip("no Chromium (apt-get install chromium; CI sets VMGYM_REQUIRE_BROWSER=1 and installs it)")


def test_page_renders_in_a_headless_browser(tmp_path):
    _need_browser()
    import html as html_lib

    board = load_leaderboard(COMMITTED)
    n = len([e for e in board.valid_entries if e.superseded is None])
    page = (COMMITTED / "index.html").read_text()
    probed = tmp_path / "probed.html"
    probed.write_text(page.replace("</body>", PROBE + "</body>"))
    dom = browser.dump_dom(probed, width=1200, height=2600)
    start = dom.index('<pre id="probe">') + len('<pre id="probe">')
    probe = json.loads(html_lib.unescape(dom[start : dom.index("</pre>", start)]))
    assert probe["rows"] == n
    assert probe["firstRow"][1] == "EyeCatchOracle-v0" and "%" in probe["firstRow"][2]
    assert set(probe["plots"]) == {"plot-catch-rate", "plot-realism", "plot-latency"}
    for ident, (w, h) in probe["plots"].items():
        assert w > 300 and h > 100, ident  # laid out, not collapsed
    assert len(probe["points"]) == n and all(w > 0 and h > 0 for w, h in probe["points"])
    # the realism heat map: per current entry the overall score and one cell per component column (the
    # union of every family's components)
    components = {c for e in board.valid_entries if e.superseded is None for c in e.results["gaze_realism"]["components"]}
    assert probe["cells"] == n * (1 + len(components)) and probe["bars"] == n
    # The page fits the viewport: no element past its edges, no page-wide horizontal scroll,
    # no plot label or legend entry clipped by its plot.
    assert probe["viewport"] == 1200
    assert probe["outside"] == [], probe["outside"][:10]
    assert probe["scrollWidth"] <= probe["viewport"]
    assert probe["clipped"] == [], probe["clipped"][:10]

    # A screenshot of the unmodified page: the right size, and the plots' colours are on it.
    # tall enough to reach the realism heat map below the entry table
    png = browser.screenshot(COMMITTED / "index.html", tmp_path / "page.png", width=1200, height=8000)
    Image = pytest.importorskip("PIL.Image")

    image = Image.open(png).convert("RGB")
    assert image.size == (1200, 8000)
    colors = image.getcolors(maxcolors=1 << 20)
    count = {c: k for k, c in colors}

    def near(rgb, tol=12):
        return sum(k for c, k in count.items() if all(abs(c[i] - rgb[i]) <= tol for i in range(3)))

    assert near((0x00, 0x72, 0xB2)) > 200  # catch-rate points and intervals (first series colour)
    assert near((0x08, 0x51, 0x9C)) > 500  # realism cells scored 1
    assert len(colors) > 50  # text, table, plots: not a blank page


# ---------------------------------------------------------------- CI wiring


def test_ci_runs_the_check_with_a_required_browser():
    ci = (REPO / ".ci" / "run").read_text()
    assert "apt-get install -y -q chromium" in ci and "VMGYM_REQUIRE_BROWSER=1" in ci
    assert ci.index("make test") < ci.index("make leaderboard-check")
    assert "$(VENV)/bin/vmgym leaderboard check" in (REPO / "Makefile").read_text()


def test_workflow_is_an_unprivileged_pull_request_workflow():
    yaml = pytest.importorskip("yaml")

    text = (REPO / ".github" / "workflows" / "leaderboard.yml").read_text()
    flow = yaml.safe_load(text)
    triggers = flow[True]  # YAML 1.1 reads the key `on` as True
    assert "pull_request" in triggers and "pull_request_target" not in triggers
    assert flow["permissions"] == {"contents": "read"}
    steps = flow["jobs"]["check"]["steps"]
    runs = "\n".join(s.get("run", "") for s in steps)
    assert "vmgym leaderboard check --base" in runs and "tests/test_leaderboard.py" in runs
    checkout = next(s for s in steps if s.get("uses", "").startswith("actions/checkout"))
    assert checkout["with"]["persist-credentials"] is False
    assert flow["jobs"]["check"]["env"]["VMGYM_REQUIRE_BROWSER"] == "1"


# ---------------------------------------------------------------- stochastic agents


class _UnseededAgent:
    """Draws from NumPy's global generator: not reproducible from the evaluator's seeds."""

    def __init__(self, action_dim: int):
        self.action_dim = action_dim

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        import numpy as np

        return np.random.uniform(-1, 1, self.action_dim).astype(np.float32), state


def test_stochastic_agents_are_rescored_by_replaying_their_seeded_chunk(tmp_path, capsys):
    from visuomotor_gym.agents import register_agent

    root = tmp_path / "lb"
    _small_protocol(root, ["EyeCatchOracle-v0"], episodes=70)  # evaluator chunks of 2 episodes
    common = ["--env", "EyeCatchOracle-v0", "--dir", str(root), "--workers", "1", "--no-progress"]
    assert main(["leaderboard", "submit", "--agent", "random", *common]) == 0
    report = check(root, rescore=True, seeds=[1, 3, 69])  # second episode of their chunks: replayed
    assert report.ok, "\n".join(messages(report))
    assert "re-scored (seeded)" in (root / "README.md").read_text()

    rec_path = record_path(root, "random__EyeCatchOracle-v0")
    rec = read(rec_path)
    eps = rec["episodes"]
    for k in [k for k in eps[0] if k != "seed"]:  # swap seeds 0 and 1: every total unchanged
        eps[0][k], eps[1][k] = eps[1][k], eps[0][k]
    write_record(rec_path, rec)
    assert_refused(check(root, rescore=True, seeds=[1]), "rescore", "re-scoring seed 1 disagrees")

    register_agent(
        "test-unseeded",
        lambda env_id, action_dim, seed, **kw: _UnseededAgent(action_dim),
        "test only: global RNG",
        deterministic=False,
    )
    _small_protocol(tmp_path / "lb2", ["EyeCatchOracle-v0"], episodes=3)
    common[3] = str(tmp_path / "lb2")
    assert main(["leaderboard", "submit", "--agent", "test-unseeded", *common]) == 1  # submit's own check
    assert "re-scoring seed" in capsys.readouterr().err


# ---------------------------------------------------------------- safe policy files and the migration


def test_ppo_npz_actor_equals_the_sb3_model_on_many_observations():
    """The pickle-free actor rebuilt from JSON + arrays gives the SB3 model's actions bit for bit."""
    import io

    import numpy as np
    from stable_baselines3 import PPO
    from visuomotor_gym.baselines.ppo.agent import NpzActor, npz_from_model, prove_npz_equals_model, read_npz

    old = COMMITTED / "agents" / "ppo-intercept__EyeCatch-v0.zip"  # our own committed file: trusted here
    model = PPO.load(io.BytesIO(old.read_bytes()), device="cpu")
    meta = json.loads(__import__("zipfile").ZipFile(old).read("ppo_meta.json"))
    data = npz_from_model(model, meta)
    assert prove_npz_equals_model(data, model, n=3000, seed=1) == 3000
    committed = (COMMITTED / "agents" / "ppo-intercept-v2__EyeCatch-v0.npz").read_bytes()
    assert data == committed  # the committed policy file is this conversion, byte for byte
    actor = NpzActor(*read_npz(data))
    assert actor(np.zeros(actor.obs_dim, np.float32)).shape == (9,)
    model.policy.action_net.bias.data += 1e-3  # a different model: the proof must notice
    with pytest.raises(ValueError, match="differs from the SB3 model"):
        prove_npz_equals_model(data, model, n=50)


def _same(a, b, tol=1e-12):
    if isinstance(a, dict):
        return isinstance(b, dict) and set(a) == set(b) and all(_same(a[k], b[k], tol) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(_same(x, y, tol) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= tol
    return a == b


@pytest.mark.parametrize("old,new", [("ppo-intercept", "ppo-intercept-v2"), ("belief_mpc", "belief_mpc-v2")])
def test_migrated_entries_have_identical_outcomes(old, new):
    """The safe-format entries re-enter the superseded ones: every one of the 200 outcomes is identical
    (caught, diverged, steps, catch and first-saccade times exactly; miss distances within the protocol's
    distance tolerance: env changes after the old entries moved them by up to 1e-15 m for PPO and 3e-8 m
    for belief_mpc, whose iLQR amplifies last-bit differences)."""
    tol = load_protocol(COMMITTED).distance_tolerance_m
    board = load_leaderboard(COMMITTED)
    by_key = {e.key: e for e in board.entries}
    superseded = json.loads((COMMITTED / "superseded.json").read_text())["superseded"]
    # (A later entry may reuse the name, and a later redefinition of an env re-enters an agent under the
    # same new name: the format migration was of the catch family's entries only.)
    migrated = [e for e in board.entries if e.name == old and e.key in superseded and e.env_id.startswith("EyeCatch")]
    assert migrated
    for e in migrated:
        twin = by_key[f"{new}__{e.env_id}"]
        assert superseded[e.key]["by"] == twin.key
        assert twin.policy["format"] in ("ppo-npz", "belief-mpc-params")
        for x, y in zip(e.record["episodes"], twin.record["episodes"], strict=True):
            for k in ("seed", "caught", "diverged", "steps", "catch_time_s", "first_saccade_s"):
                assert x[k] == y[k], (x["seed"], k)
            assert _same(x["miss_distance_m"], y["miss_distance_m"], tol), x["seed"]
        for k in ("caught", "catch_rate", "catch_rate_ci95", "diverged", "reaction_times_s", "time_to_catch_s"):
            assert twin.results[k] == e.results[k], k
        for k in ("gaze_realism", "miss_distance_m"):
            assert _same(twin.results[k], e.results[k], tol), k


def test_check_never_unpickles(monkeypatch):
    """Re-scoring the current PPO entries calls neither pickle nor torch.load."""
    import pickle

    import torch

    def forbidden(*a, **k):
        raise AssertionError("the check unpickled something")

    monkeypatch.setattr(pickle, "load", forbidden)
    monkeypatch.setattr(pickle, "loads", forbidden)
    monkeypatch.setattr(torch, "load", forbidden)
    report = check_leaderboard(COMMITTED, base=None, rescore=True, seeds=[0, 1], only={
        "ppo-intercept-v4__EyeCatch-v0", "ppo-intercept-v3__EyeCatchOracle-v0"}, pages=False)
    assert report.ok, "\n".join(messages(report))
    assert report.rescored_episodes == 4


@pytest.mark.parametrize("env_id", ["EyeCatch-v0", "SteppingStones-v0", "ObstacleDodge-v0"])
def test_belief_mpc_params_round_trip_every_family(env_id):
    """The belief-mpc-params file of each family's belief_mpc agent loads back to the same agent class
    and parameters (tuples such as the dodge agent's candidate speeds come back as tuples)."""
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.leaderboard.policies import BELIEF_MPC_FORMAT, policy_format

    fmt = policy_format(BELIEF_MPC_FORMAT)
    agent = fmt.load(fmt.export("belief_mpc", env_id), env_id)
    import gymnasium as gym

    reference = make_agent("belief_mpc", env_id, gym.make(env_id).action_space.shape[0])
    assert type(agent) is type(reference) and agent.params == reference.params
    if env_id == "EyeCatch-v0":  # the loaded planner builds the same Eyecatch perception as the spec's
        assert agent._eyecatch_perception(1) is not None and reference._eyecatch_perception(1) is not None


def test_belief_mpc_params_reject_a_malformed_tuple():
    from visuomotor_gym.leaderboard.policies import BELIEF_MPC_FORMAT, policy_format

    fmt = policy_format(BELIEF_MPC_FORMAT)
    obj = json.loads(fmt.export("belief_mpc", "ObstacleDodge-v0"))
    for bad in (["fast", 1.3], [True, 1.3], 1.3):
        obj["params"]["speeds"] = bad
        with pytest.raises(ValueError, match=r"params\.speeds"):
            fmt.load(json.dumps(obj).encode(), "ObstacleDodge-v0")


def test_the_page_gain_is_success_minus_the_better_twin_entry():
    """The committed page's gaze gain of every baseline, recomputed here from the twins' own results files:
    success minus the better of the held twin (gaze_blind:<agent>) and the best static twin
    (static_gaze:<posture>:<agent>); every foveated id's baselines have both twins entered."""
    from visuomotor_gym.bench.evaluate import static_twin_base
    from visuomotor_gym.leaderboard.pages import _rows, twin_agents

    rows, _ = _rows(load_leaderboard(COMMITTED))
    with_static = 0
    for r in rows:
        if r.agent.startswith(("gaze_blind:", "static_gaze:")) or r.agent == "fixed_gaze":
            continue
        same = [t for t in rows if t.env_id == r.env_id and t.seeds == r.seeds]
        held = [t.entry.results["success_rate"] for t in same if t.agent in twin_agents(r.agent)]
        static = [t.entry.results["success_rate"] for t in same if static_twin_base(t.agent) == r.agent]
        assert (r.held_gain is None) == (not held)
        if held:
            assert r.held_gain == pytest.approx(r.entry.results["success_rate"] - held[0])
        if static:
            with_static += 1
            expected = r.entry.results["success_rate"] - max(static[0], held[0] if held else 0.0)
            assert r.gain == pytest.approx(expected), r.key
        else:
            assert r.gain is None, f"{r.key}: a gain without a static twin entry"
    foveated = ("EyeCatch-v0", "ShelfReach-v0", "ObstacleWalk-v0", "SteppingStones-v0", "ObstacleDodge-v0")
    assert with_static >= len(foveated)
    for env_id in foveated:
        assert any(r.env_id == env_id and r.gain is not None for r in rows), f"no static twin on {env_id}"


def test_belief_mpc_file_without_later_default_fields_is_the_same_policy():
    """A belief-MPC policy file committed before some parameters existed still matches the spec when the
    fields it lacks sit at their defaults (the loader fills them in); not when a lacking field's fresh
    value differs from its default, nor when a committed value differs."""
    import json

    from visuomotor_gym.leaderboard.policies import _belief_mpc_export, _belief_mpc_same

    env_id = "SteppingStones-v0"
    fresh = _belief_mpc_export("belief_mpc", env_id)
    obj = json.loads(fresh)

    def dump(o):
        return (json.dumps(o, indent=2, allow_nan=False) + "\n").encode("utf-8")

    old = {**obj, "params": {k: v for k, v in obj["params"].items() if k != "distrust_periphery"}}
    assert _belief_mpc_same(dump(old), fresh, env_id)
    assert not _belief_mpc_same(fresh, fresh, env_id)  # identical bytes are the caller's case, not this one
    moved = json.loads(fresh)
    moved["params"]["distrust_periphery"] = True  # the spec now resolves a non-default value
    assert not _belief_mpc_same(dump(old), dump(moved), env_id)
    changed = {**old, "params": {**old["params"], "w_tsk": old["params"]["w_tsk"] + 1.0}}
    assert not _belief_mpc_same(dump(changed), fresh, env_id)
    extra = {**obj, "params": {**obj["params"], "not_a_field": 1}}
    assert not _belief_mpc_same(dump(extra), fresh, env_id)


# ---------------------------------------------------------------- the eyecatch policy file and the env's eye


def test_eyecatch_policy_file_loads_with_the_envs_eye():
    """A replayed Eyecatch file models the eye of its env, as the spec path does: on EyeCatchPaper-v0 (whose
    vision_params differ from the ones the params alone imply) the loaded agent's VisionParams are the env's;
    a spec that overrides the assumed eye keeps its own. A file written before the loader did this (the
    former note) is the same policy only where the two eyes agree."""
    from visuomotor_gym.agents import make_agent
    from visuomotor_gym.leaderboard.policies import (
        EYECATCH_NOTE,
        EYECATCH_NOTE_BEFORE_EYE,
        _eyecatch_export,
        _eyecatch_load,
        _eyecatch_same,
    )
    from visuomotor_gym.registration import env_vision_params

    # every catch id's eye is now more than the params imply (the paper's static acuity; the one eye)
    for env_id, changes_eye in (("EyeCatchPaper-v0", True), ("EyeCatch-v0", True)):
        data = _eyecatch_export("eyecatch", env_id)
        assert json.loads(data)["note"] == EYECATCH_NOTE
        agent = _eyecatch_load(data, env_id)
        assert agent.vision == env_vision_params(env_id) == make_agent("eyecatch", env_id, 13).vision
        own = _eyecatch_load(_eyecatch_export("eyecatch", env_id), env_id)
        own.vision = type(own.vision)(noise_scale=own.params.vision_noise_scale, foveated=own.params.foveated)
        assert (own.vision != agent.vision) == changes_eye
        before = json.dumps({**json.loads(data), "note": EYECATCH_NOTE_BEFORE_EYE}, indent=2) + "\n"
        assert _eyecatch_same(before.encode(), data, env_id) == (not changes_eye)
    data = _eyecatch_export("eyecatch:vision_noise_scale=3.0", "EyeCatchPaper-v0")
    agent = _eyecatch_load(data, "EyeCatchPaper-v0")
    assert agent.vision.noise_scale == 3.0 and agent.vision != env_vision_params("EyeCatchPaper-v0")
    # a spec that overrides the assumed eye keeps its own: a file with the former note is the same policy
    before = json.dumps({**json.loads(data), "note": EYECATCH_NOTE_BEFORE_EYE}, indent=2) + "\n"
    assert _eyecatch_same(before.encode(), data, "EyeCatchPaper-v0")
