"""``vmgym leaderboard submit | check | build`` (wired into ``vmgym`` by :func:`register`).

    vmgym leaderboard submit --agent SPEC --env ID [--env ID ...|--env all] [--name NAME] [--workers K]
                             [--from-results FILE] [--dir leaderboard] [--no-build] [--no-progress]
    vmgym leaderboard check  [--dir leaderboard] [--base REF|none] [--sample N|all] [--seeds S,S,...]
                             [--no-rescore] [--no-pages]
    vmgym leaderboard build  [--dir leaderboard]

``check`` exits 0 when every rule passes and 1 with the list of refusals otherwise (2: bad
arguments). This module imports nothing heavy at import time: ``vmgym`` imports it on every call.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

DEFAULT_DIR = "leaderboard"


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``leaderboard`` (with ``submit``, ``check``, ``build``) to an argparse subparsers object."""
    p = subparsers.add_parser(
        "leaderboard",
        help="submit an agent to the leaderboard, check it (CI), rebuild its pages",
        description="The leaderboard in leaderboard/: results on the standard protocol, policy files with "
        "sha256, generated README.md and index.html, and the check CI runs.",
    )
    sub = p.add_subparsers(dest="leaderboard_command", required=True)

    s = sub.add_parser(
        "submit",
        help="play the standard protocol and write a new entry",
        description="Evaluate an agent on the standard protocol (leaderboard/protocol.json) and "
        "write its results file, policy file and entry record; then rebuild the "
        "pages and check the new entries.",
    )
    s.add_argument("--agent", required=True, help="agent spec: eyecatch, oracle, or name:param=value,...")
    s.add_argument(
        "--env",
        action="append",
        required=True,
        help="env id of the protocol (repeatable), or 'all' for every env id of the protocol",
    )
    s.add_argument(
        "--name", default=None, help="entry name (default: the agent name; required with overrides)"
    )
    s.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    s.add_argument(
        "--from-results",
        default=None,
        help="attach this existing `vmgym bench` results file (one env id): the protocol is "
        "re-played and must reproduce its scores; the file is kept byte for byte",
    )
    s.add_argument("--dir", default=DEFAULT_DIR, help="leaderboard folder (default: ./leaderboard)")
    s.add_argument("--no-build", action="store_true", help="do not rebuild README.md and index.html")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.set_defaults(func=main_submit)

    c = sub.add_parser(
        "check",
        help="validate, re-score and compare the leaderboard with main (what CI runs)",
        description="Validate every entry (schema, provenance, protocol, hashes), re-score "
        "every entry on a sample of its pinned seeds, refuse deleted or "
        "rewritten entries relative to the base ref, and refuse stale pages.",
    )
    c.add_argument("--dir", default=DEFAULT_DIR, help="leaderboard folder (default: ./leaderboard)")
    c.add_argument(
        "--base",
        default="auto",
        help="git ref existing entries are compared with (default: origin/main, else main, else "
        "HEAD); 'none' skips the history rule",
    )
    c.add_argument(
        "--sample", default=None, help="seeds re-scored per entry (default: the protocol's), or 'all'"
    )
    c.add_argument(
        "--seeds", default=None, help="re-score exactly these seeds (comma-separated) of every entry"
    )
    c.add_argument(
        "--no-rescore", action="store_true", help="skip re-scoring (quick local check; CI re-scores)"
    )
    c.add_argument("--no-pages", action="store_true", help="skip the stale-page rule")
    c.add_argument(
        "--workers", type=int, default=2, help="processes for re-scoring (default 2, CI's cores; 1: in-process)"
    )
    c.set_defaults(func=main_check)

    b = sub.add_parser(
        "build",
        help="regenerate leaderboard/README.md and leaderboard/index.html",
        description="Regenerate README.md and index.html from protocol.json and the entries.",
    )
    b.add_argument("--dir", default=DEFAULT_DIR, help="leaderboard folder (default: ./leaderboard)")
    b.set_defaults(func=main_build)
    return p


def _err(msg: str) -> None:
    print(f"error: {msg}", file=sys.stderr)


def print_report(report, out=None) -> None:
    out = out or sys.stdout
    for note in report.notes:
        print(f"  note: {note}", file=out)
    secs = report.seconds.get("total", 0.0)
    if report.ok:
        print(
            f"PASSED: {report.entries} entries valid, {report.rescored_entries} re-scored on "
            f"{report.rescored_episodes} seeds ({secs:.1f} s)",
            file=out,
        )
        return
    problems = report.sorted_problems()
    print(f"FAILED: {len(problems)} problem{'s' if len(problems) != 1 else ''} ({secs:.1f} s)", file=out)
    for p in problems:
        print(f"  {p}", file=out)


def main_check(args: argparse.Namespace) -> int:
    from visuomotor_gym.leaderboard.check import check_leaderboard

    sample = args.sample
    if sample is not None and sample != "all":
        try:
            sample = int(sample)
            if sample < 1:
                raise ValueError
        except ValueError:
            _err(f"--sample must be a positive integer or 'all', got {args.sample!r}")
            return 2
    seeds = None
    if args.seeds:
        try:
            seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
        except ValueError:
            _err(f"--seeds must be comma-separated integers, got {args.seeds!r}")
            return 2
    if args.workers < 1:
        _err(f"--workers must be >= 1, got {args.workers}")
        return 2
    if not Path(args.dir).is_dir():
        _err(f"--dir {args.dir} is not a folder (the leaderboard folder holds protocol.json)")
        return 2
    print(f"leaderboard check: {Path(args.dir)}")
    report = check_leaderboard(
        args.dir,
        base=args.base,
        rescore=not args.no_rescore,
        sample=sample,
        seeds=seeds,
        pages=not args.no_pages,
        progress=lambda m: print(f"  {m}", flush=True),
        workers=args.workers,
    )
    print_report(report)
    return 0 if report.ok else 1


def main_build(args: argparse.Namespace) -> int:
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import write_pages

    if not Path(args.dir).is_dir():
        _err(f"--dir {args.dir} is not a folder (the leaderboard folder holds protocol.json)")
        return 2
    lb = load_leaderboard(args.dir)
    if lb.problems or lb.protocol is None:
        _err("the leaderboard has problems; fix them before building the pages:")
        for p in lb.problems:
            print(f"  {p}", file=sys.stderr)
        return 1
    for path in write_pages(lb):
        print(f"wrote {path}")
    return 0


def _submit_input_problem(args: argparse.Namespace, envs: list[str], protocol) -> str | None:
    """One line saying what is wrong with ``submit``'s arguments, or None."""
    from visuomotor_gym.leaderboard.entries import check_name
    from visuomotor_gym.leaderboard.submit import SubmitError, default_name

    if args.workers < 1:
        return f"--workers must be >= 1, got {args.workers}"
    unknown = [e for e in envs if protocol.for_env(e) is None]
    if unknown:
        return (
            f"env id {unknown[0]!r} has no protocol in {Path(args.dir) / 'protocol.json'}; the leaderboard "
            f"accepts {', '.join(protocol.env_ids)} (or --env all)"
        )
    try:
        check_name(args.name if args.name is not None else default_name(args.agent))
    except (ValueError, SubmitError) as exc:
        return f"--name: {exc}"
    if args.from_results is not None and not Path(args.from_results).is_file():
        return f"--from-results {args.from_results} is not a file"
    from visuomotor_gym.leaderboard.entries import RECORD_SUFFIX, RESULTS_DIR, entry_key

    name = args.name if args.name is not None else default_name(args.agent)
    for env_id in envs:  # entries are immutable: refused here rather than after the policy export
        key = entry_key(name, env_id)
        record = Path(args.dir) / RESULTS_DIR / f"{key}{RECORD_SUFFIX}"
        results = Path(args.dir) / RESULTS_DIR / f"{key}.json"
        attaching = args.from_results is not None and Path(args.from_results).resolve() == results.resolve()
        if record.exists() or (results.exists() and not attaching):
            return f"entry {key} exists ({results.name}): entries are immutable; submit under another --name"
    from visuomotor_gym.bench.evaluate import validate_inputs

    first = protocol.for_env(envs[0])
    try:
        validate_inputs(args.agent, envs[0], first.episodes, first.seed, args.workers)
    except (TypeError, ValueError, OSError) as exc:
        return str(exc)
    return None


def main_submit(args: argparse.Namespace) -> int:
    from visuomotor_gym.leaderboard.check import check_leaderboard
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import write_pages
    from visuomotor_gym.leaderboard.protocol import ProtocolError, load_protocol
    from visuomotor_gym.leaderboard.submit import SubmitError, submit_one

    root = Path(args.dir)
    try:
        protocol = load_protocol(root)
    except ProtocolError as exc:
        _err(str(exc))
        return 2
    envs = list(protocol.env_ids) if args.env == ["all"] else args.env
    if "all" in envs and len(envs) > 1:
        _err("--env all cannot be combined with other env ids")
        return 2
    if args.from_results and len(envs) != 1:
        _err("--from-results attaches one results file: give exactly one --env")
        return 2
    problem = _submit_input_problem(args, envs, protocol)
    if problem:  # every bad input is refused here, before any episode runs
        _err(problem)
        return 2
    from visuomotor_gym.bench.provenance import git_state

    sha, dirty = git_state()
    if dirty is not False:
        print(
            f"warning: the checkout is {'dirty' if dirty else 'not a git checkout'} (git_sha {sha[:12]}): CI "
            f"refuses new entries produced from uncommitted code; commit first, then submit",
            file=sys.stderr,
        )
    keys: list[str] = []
    written: list[Path] = []
    for env_id in envs:
        start = time.perf_counter()
        try:
            sub = submit_one(
                root,
                args.agent,
                env_id,
                name=args.name,
                workers=args.workers,
                from_results=args.from_results,
                progress=not args.no_progress,
            )
        except (SubmitError, ValueError, FileExistsError) as exc:
            _err(str(exc))
            return 1
        keys.append(sub.key)
        written += sub.written
        for path in sub.written:
            print(f"wrote {path}")
        for path in sub.kept:
            print(f"kept  {path} (unchanged)")
        print(f"{sub.key}: {time.perf_counter() - start:.1f} s")
    if not args.no_build:
        lb = load_leaderboard(root)
        if lb.problems:
            _err("not rebuilding the pages: the leaderboard has problems:")
            for p in lb.problems:
                print(f"  {p}", file=sys.stderr)
            return 1
        for path in write_pages(lb):
            print(f"wrote {path}")
    # The new entries' own checks (re-scoring included); history is for CI, on the committed result.
    report = check_leaderboard(root, base=None, pages=not args.no_build, only=set(keys))
    mine = [p for p in report.problems if any(k in p.where for k in keys) or p.kind == "pages"]
    if mine:
        print("the new entries do not pass the leaderboard check:", file=sys.stderr)
        for p in mine:
            print(f"  {p}", file=sys.stderr)
        print(
            f"do not commit them: delete {', '.join(str(p) for p in written)} and rebuild the pages, "
            f"or fix the agent and submit again",
            file=sys.stderr,
        )
        return 1
    print(
        f"submitted {len(keys)} entr{'y' if len(keys) == 1 else 'ies'}; they pass the check. Commit "
        f"{root}/results, {root}/agents and the pages."
    )
    return 0
