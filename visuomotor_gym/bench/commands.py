"""``vmgym bench``: evaluate an agent on pinned seeds, print the summary, write validated results.

    vmgym bench --agent oracle --env EyeCatchOracle-v0 --episodes 200 --seed 0 --out results.json \\
        [--workers K] [--traces traces.npz] [--force] [--no-progress]

Wired into ``vmgym`` by ``visuomotor_gym.cli`` through :func:`register`.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``bench`` subcommand to an ``argparse`` subparsers object; returns its parser."""
    p = subparsers.add_parser(
        "bench",
        help="evaluate an agent on pinned seeds and write validated results JSON",
        description="Evaluate an agent on pinned seeds (episode i uses seed + i), print the summary "
                    "and write results JSON validated against the results schema.",
    )
    p.add_argument("--agent", required=True,
                   help="agent spec: eyecatch, oracle, random, zero, or name:param=value,...")
    p.add_argument("--env", required=True, help="environment id (vmgym envs lists them)")
    p.add_argument("--episodes", type=int, required=True, help="number of episodes (>= 1)")
    p.add_argument("--seed", type=int, required=True, help="first seed (>= 0); episode i uses seed + i")
    p.add_argument("--out", required=True, help="results JSON file to write")
    p.add_argument("--workers", type=int, default=1, help="worker processes (default 1: in-process)")
    p.add_argument("--gaze-gain", action="store_true",
                   help="also play the agent's two twins on the same seeds, the held twin (gaze_blind:<agent>: "
                        "gaze and head held where reset put them) and the best static twin (static_gaze:<agent>: "
                        "one posture of eye and neck searched on design seeds), and record the gaze gain: "
                        "success minus the better twin's (and the held-twin difference)")
    p.add_argument("--static-twin", default=None, metavar="SPEC",
                   help="with --gaze-gain: the static twin to play instead of the searched posture, e.g. "
                        "static_gaze:az=0,el=-20,neck_yaw=0,neck_pitch=0,fix=2:iwao")
    p.add_argument("--backend", choices=("local", "ray"), default="local",
                   help="local: this process or a process pool of --workers (default); ray: Ray tasks on a "
                        "cluster (pip install 'visuomotor_gym[distributed]'), same per-seed outcomes")
    p.add_argument("--address", default=None,
                   help="with --backend ray: the cluster address (auto, ray://host:10001); default: start "
                        "a local cluster")
    p.add_argument("--traces", default=None, help="also write the per-episode traces to this .npz file")
    p.add_argument("--force", action="store_true", help="overwrite --out / --traces if they exist")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=main_bench)
    return p


def canonical_command(args: argparse.Namespace) -> str:
    """The command that reproduces the numbers (output paths reduced to file names: no personal paths)."""
    parts = ["vmgym", "bench", "--agent", args.agent, "--env", args.env, "--episodes", str(args.episodes),
             "--seed", str(args.seed), "--workers", str(args.workers), "--out", Path(args.out).name]
    if getattr(args, "backend", "local") != "local":
        parts[-2:-2] = ["--backend", args.backend]
    if getattr(args, "gaze_gain", False):
        parts[-2:-2] = ["--gaze-gain"]
        if getattr(args, "static_twin", None):
            parts[-2:-2] = ["--static-twin", args.static_twin]
    if args.traces:
        parts += ["--traces", Path(args.traces).name]
    return shlex.join(parts)


def _fmt(value, digits: int = 3) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.{digits}g}" if abs(value) < 1e-3 and value != 0 else f"{value:.{digits}f}"
    if isinstance(value, dict):
        return ", ".join(f"{k} {_fmt(v, digits)}" for k, v in value.items())
    if isinstance(value, list):
        return "[" + ", ".join(_fmt(v, digits) for v in value[:6]) + (", ...]" if len(value) > 6 else "]")
    return str(value)


def _mean_median(stats: dict) -> str:
    return f"mean {_fmt(stats.get('mean'))}  median {_fmt(stats.get('median'))}"


def _family_of(env_id: str):
    """The family record of ``env_id`` (its outcome labels, whether reaction times apply); the default
    family's for an id this version does not register (an old results file)."""
    from visuomotor_gym.families import default_family, family_for

    try:
        return family_for(env_id)
    except ValueError:
        return default_family()


def summary_rows(results: dict) -> list[tuple[str, str]]:
    """(metric, value) rows of the summary table, labelled in the env family's terms."""
    family = _family_of(results["env_id"])
    rate_label, time_label, miss_label = family.outcome_labels  # the results keep the catch key names
    # The family-neutral keys; results written before them carry only catch_rate (the same number there).
    rate = results.get("success_rate", results["catch_rate"])
    lo, hi = results.get("success_rate_ci95", results["catch_rate_ci95"])
    successes = results.get("success", results["caught"])
    gaze = results["gaze_realism"]
    lat = results["latency_ms"]
    rows = [
        (rate_label, f"{rate:.3f}  95% CI [{lo:.3f}, {hi:.3f}]  ({successes}/{results['episodes']})"),
        ("gaze realism", _fmt(gaze["score"])),
    ]
    gain = results.get("gaze_gain")
    if gain:
        tlo, thi = gain["twin_success_rate_ci95"]
        rows.append(("held twin", f"{gain['twin_success_rate']:.3f}  95% CI [{tlo:.3f}, {thi:.3f}]  "
                                  f"({gain['twin_agent']})"))
        if "static_twin_agent" in gain:
            slo, shi = gain["static_twin_success_rate_ci95"]
            rows += [
                ("best static twin", f"{gain['static_twin_success_rate']:.3f}  95% CI [{slo:.3f}, {shi:.3f}]  "
                                     f"({gain['static_twin_agent']})"),
                ("gaze gain", f"{gain['gain']:+.3f}  (success minus the better twin's, same seeds)"),
                ("held-twin difference", f"{gain['held_difference']:+.3f}  (success minus the held twin's)"),
            ]
        else:
            rows.append(("held-twin difference", f"{gain['gain']:+.3f}  (success minus the held twin's; "
                                                 f"no static twin in these results)"))
    for name, comp in gaze["components"].items():
        rows.append((f"  {name}", f"score {_fmt(comp.get('score'))}  (value {_fmt(comp.get('value'))})"))
    hand_path = results.get("hand_path")
    if hand_path:  # single-ball catch ids (metrics.catch_handpath): beside the gaze realism, not in it
        verdict = f"{hand_path['verdict'] or 'n/a'}  score {_fmt(hand_path['score'])}  "
        rows.append(("hand path", verdict + f"({hand_path['episodes']} transports vs Faraway's reach model)"))
        for name, comp in hand_path["components"].items():
            score = "not scored" if comp.get("score") is None else f"score {_fmt(comp['score'])}"
            rows.append((f"  {name}", f"{score}  (value {_fmt(comp.get('value'))})"))
    rows += [
        ("latency (ms)", f"p50 {_fmt(lat['p50'])}  p95 {_fmt(lat['p95'])}  max {_fmt(lat['max'])}"),
        ("real time", f"{_fmt(results['real_time'])}  "
                      f"(p95 < {results['control_period_ms']:g} ms control period)"),
    ]
    if family.reaction_from_t0:  # reaction to a throw or to the object's appearance at t = 0
        for kind, stats in results["reaction_times_s"].items():
            rows.append((f"reaction time, {kind.replace('_', ' ')} (s)", _mean_median(stats)))
    rows += [
        (time_label, _mean_median(results["time_to_catch_s"])),
        (miss_label, _mean_median(results["miss_distance_m"])),
        ("diverged", f"{results['diverged']} episode(s)"),
    ]
    run = results.get("run")
    if run:
        rows.append(("wall time", f"{run['wall_time_s']:.1f} s, {run['workers']} worker(s), "
                                  f"{_fmt(run.get('env_steps_per_s'), 0)} env steps/s"))
    return rows


def print_summary(results: dict, file=None) -> None:
    """Print the summary table (rich when available, plain text otherwise)."""
    title = f"{results['agent']} on {results['env_id']}: {results['episodes']} episodes, seeds " \
            f"{results['seeds']['first']}..{results['seeds']['last']}"
    rows = summary_rows(results)
    try:
        from rich.console import Console
        from rich.table import Table
    except ImportError:
        print(title, file=file)
        for name, value in rows:
            print(f"  {name:<22} {value}", file=file)
        return
    table = Table(title=title)
    table.add_column("metric")
    table.add_column("value")
    for name, value in rows:
        table.add_row(name, value)
    Console(file=file).print(table)


def output_path_problem(path: Path, flag: str) -> str | None:
    """Why ``path`` cannot be written as an output file (None: it can), checked before any episode runs.

    Refused: a directory; a path under a regular file; a folder that cannot be created or written (a
    read-only or virtual file system such as /proc, no permission); a name the OS refuses (too long).
    Writing is proven by creating and removing a temporary file next to the target.
    """
    import tempfile

    if path.exists() and path.is_dir():
        return f"{flag} {path} is a directory; give a file path, e.g. {path / 'results.json'}"
    parent = path.parent
    for ancestor in [parent, *parent.parents]:
        if ancestor.exists():
            if not ancestor.is_dir():
                return f"{flag} {path}: {ancestor} is a file, not a folder"
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=parent, prefix=f".{path.name[:40]}.", suffix=".probe"):
            pass
        if len(path.name.encode("utf-8", "surrogateescape")) > 255:
            return f"{flag} {path}: the file name is longer than 255 bytes"
    except OSError as exc:
        return f"{flag} {path}: cannot write there ({exc.strerror or exc})"
    return None


def _refuse_existing(paths: list[Path | None], force: bool) -> str | None:
    for path in paths:
        if path is not None and path.exists() and not force:
            return f"{path} already exists; refusing to overwrite it (pass --force to replace it)"
    return None


def main_bench(args: argparse.Namespace) -> int:
    """Run ``vmgym bench``; returns the exit status (0 ok, 1 results invalid or not written after the run, 2 an
    argument refused before it: bad values, an output that exists without ``--force``)."""
    from visuomotor_gym.bench.evaluate import evaluate, validate_inputs
    from visuomotor_gym.bench.results import ResultsError, build_results, write_results
    from visuomotor_gym.bench.trace import save_traces

    out = Path(args.out)
    traces_path = Path(args.traces) if args.traces else None
    if traces_path is not None and traces_path.suffix != ".npz":
        print(f"error: --traces must name a .npz file, got {traces_path}", file=sys.stderr)
        return 2
    for path, flag in ((out, "--out"), (traces_path, "--traces")):
        problem = output_path_problem(path, flag) if path is not None else None
        if problem:  # before any episode runs
            print(f"error: {problem}", file=sys.stderr)
            return 2
    refusal = _refuse_existing([out, traces_path], args.force)  # before spending time on the run
    if refusal:
        print(f"error: {refusal}", file=sys.stderr)
        return 2
    try:
        validate_inputs(args.agent, args.env, args.episodes, args.seed, args.workers)
        if args.address is not None and args.backend != "ray":
            raise ValueError("--address is only used with --backend ray")
        static = None
        if args.static_twin is not None and not args.gaze_gain:
            raise ValueError("--static-twin is only used with --gaze-gain")
        if args.gaze_gain:
            from visuomotor_gym.bench.evaluate import static_twin_base, static_twin_spec, twin_spec

            validate_inputs(twin_spec(args.agent), args.env, args.episodes, args.seed, args.workers)
            if args.static_twin is None:
                static = static_twin_spec(args.agent, args.env)
            else:
                if static_twin_base(args.static_twin) != args.agent:
                    raise ValueError(f"--static-twin {args.static_twin!r} is not a static twin of --agent "
                                     f"{args.agent!r}: write static_gaze:<posture>:{args.agent}")
                static = args.static_twin
            validate_inputs(static, args.env, args.episodes, args.seed, args.workers)
        if args.backend == "ray":
            import importlib.util

            if importlib.util.find_spec("ray") is None:
                raise ValueError("--backend ray needs Ray: pip install 'visuomotor_gym[distributed]'")
    except (ValueError, TypeError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    result = evaluate(args.agent, args.env, args.episodes, args.seed, workers=args.workers,
                      keep_traces=traces_path is not None, progress=not args.no_progress,
                      backend=args.backend, address=args.address)
    twin = static_twin = None
    if args.gaze_gain:
        from visuomotor_gym.bench.evaluate import twin_spec

        twin, static_twin = (
            evaluate(spec, args.env, args.episodes, args.seed, workers=args.workers, keep_traces=False,
                     progress=not args.no_progress, backend=args.backend, address=args.address)
            for spec in (twin_spec(args.agent), static))
    try:
        results = build_results(result, canonical_command(args), twin_result=twin, static_result=static_twin)
        print_summary(results)
        write_results(out, results, force=args.force)
    except (ResultsError, OSError) as exc:  # FileExistsError, or the disk failing after the run
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(f"wrote {out}")
    if traces_path is not None:
        traces_path.parent.mkdir(parents=True, exist_ok=True)
        save_traces(traces_path, result.traces)
        print(f"wrote {traces_path}")
    return 0
