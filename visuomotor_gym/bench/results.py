"""Benchmark results as JSON: build, validate, write and load.

A results file is one :func:`~visuomotor_gym.bench.evaluate.evaluate` run: the summary metrics of
:func:`visuomotor_gym.metrics.summarize`, the run's identity (env id, agent, pinned seeds) and its
provenance. ``results_schema.json`` (JSON Schema draft 2020-12, next to this module) fixes the
shape; :func:`validate_results` adds the checks a schema cannot express and reports every problem
at once, each with its JSON path (``$.catch_rate_ci95[0]``).
"""

from __future__ import annotations

import functools
import json
import math
import os
import tempfile
from importlib import resources
from pathlib import Path
from typing import Any

SCHEMA_VERSION = 1
SCHEMA_FILE = "results_schema.json"
SEED_RULE = "episode i uses seed + i"
TOLERANCE = 1e-9


class ResultsError(ValueError):
    """A results object or file is invalid; ``problems`` lists each problem with its JSON path."""

    def __init__(self, problems: list[str], source: str | None = None, headline: str | None = None):
        self.problems = list(problems)
        self.source = source
        where = f"{source}: " if source else ""
        if headline is not None:
            super().__init__(f"{where}{headline}")
            return
        lines = "\n".join(f"  - {p}" for p in self.problems)
        count = f"{len(self.problems)} problem{'s' if len(self.problems) != 1 else ''}"
        super().__init__(f"{where}invalid benchmark results ({count}):\n{lines}")


@functools.lru_cache(maxsize=1)
def load_schema() -> dict:
    """The results JSON Schema shipped with the package."""
    text = resources.files("visuomotor_gym.bench").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    return json.loads(text)


def build_results(eval_result, command: str | None, twin_result=None, static_result=None) -> dict:
    """The results object of an :class:`~visuomotor_gym.bench.evaluate.EvalResult` (validated).

    ``command`` is the command line recorded in the provenance (no personal paths, please).
    ``twin_result``: the agent's held (gaze-blind) twin on the same seeds, ``static_result`` its best
    static twin (adds ``gaze_gain``; see :func:`gaze_gain_block`).
    """
    from visuomotor_gym.bench.provenance import provenance

    s = eval_result.summary
    latency = {k: s["latency_ms"][k] for k in ("p50", "p95", "max")}
    period_ms = 1000.0 * float(eval_result.control_period_s)
    steps_per_s = eval_result.env_steps_per_s
    obj = {
        "schema_version": SCHEMA_VERSION,
        "env_id": eval_result.env_id,
        "agent": eval_result.agent,
        "agent_deterministic": bool(eval_result.agent_deterministic),
        "episodes": int(eval_result.episodes),
        "seed": int(eval_result.seed),
        "seeds": {"first": int(eval_result.seed), "last": int(eval_result.seed + eval_result.episodes - 1),
                  "rule": SEED_RULE},
        "caught": int(s["caught"]),
        "catch_rate": float(s["catch_rate"]),
        "catch_rate_ci95": [float(x) for x in s["catch_rate_ci95"]],
        "success": int(s["success"]),
        "success_rate": float(s["success_rate"]),
        "success_rate_ci95": [float(x) for x in s["success_rate_ci95"]],
        "gaze_realism": s["gaze_realism"],
        "latency_ms": latency,
        "control_period_ms": period_ms,
        "real_time": is_real_time(latency["p95"], period_ms),
        "reaction_times_s": s["reaction_times_s"],
        "miss_distance_m": s["miss_distance_m"],
        "time_to_catch_s": s["time_to_catch_s"],
        "diverged": s["diverged"],
        "run": {
            "workers": int(eval_result.workers),
            "wall_time_s": float(eval_result.wall_time_s),
            "env_steps": int(eval_result.env_steps),
            "env_steps_per_s": float(steps_per_s) if math.isfinite(steps_per_s) else None,
        },
        "provenance": provenance(command),
    }
    if "hand_path" in s:  # single-ball catch ids: hand paths against Faraway's model (metrics.catch_handpath)
        obj["hand_path"] = s["hand_path"]
    if twin_result is not None:
        obj["gaze_gain"] = gaze_gain_block(eval_result, twin_result, static_result)
    # Round-trip through JSON so the object holds plain JSON types only (no numpy scalars).
    obj = json.loads(json.dumps(obj, default=_json_default))
    validate_results(obj)
    return obj


def _twin_rate(result, reference) -> tuple[int, float, list[float]]:
    if (result.env_id, result.episodes, result.seed) != (reference.env_id, reference.episodes, reference.seed):
        raise ValueError(f"the twin {result.agent!r} must play the same env id and pinned seeds as the agent")
    rate = float(result.summary["success_rate"])
    return int(round(rate * result.episodes)), rate, [float(x) for x in result.summary["success_rate_ci95"]]


def gaze_gain_block(eval_result, twin_result, static_result=None) -> dict:
    """``gaze_gain`` of the results: both twins' success on the same pinned seeds, and the gain.

    The **gaze gain** is the success rate minus the better of the two twins': the held twin
    (``gaze_blind:<agent>``, gaze and head held where reset put them) and the best static twin
    (``static_gaze:<agent>``, one constant posture of eye and neck searched on design seeds). A small gain
    means a fixed posture does as well as the agent's eye movements: the env does not test *moving* the
    eye. ``held_difference`` keeps the held twin's difference under its own name. Without
    ``static_result`` the block is the legacy ``definition = "held"`` one (gain = held difference).
    """
    success = float(eval_result.summary["success_rate"])
    k, rate, ci = _twin_rate(twin_result, eval_result)
    block = {"twin_agent": twin_result.agent, "twin_successes": k, "twin_success_rate": rate,
             "twin_success_rate_ci95": ci}
    if static_result is None:
        return {**block, "definition": "held", "gain": success - rate}
    ks, rate_s, ci_s = _twin_rate(static_result, eval_result)
    return {**block, "static_twin_agent": static_result.agent, "static_twin_successes": ks,
            "static_twin_success_rate": rate_s, "static_twin_success_rate_ci95": ci_s,
            "definition": "best_twin", "held_difference": success - rate, "gain": success - max(rate, rate_s)}


def is_real_time(p95_ms: float | None, control_period_ms: float) -> bool:
    """Real time: the 95th percentile of the policy's compute time is below the control period."""
    return p95_ms is not None and p95_ms < control_period_ms


def _json_default(value):
    """numpy scalars and arrays -> Python numbers and lists (so summaries need not be pre-converted)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def _path(parts) -> str:
    out = "$"
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else f".{p}"
    return out


def _schema_problems(obj: Any) -> list[tuple[str, str]]:
    try:
        from jsonschema import Draft202012Validator
    except ImportError as exc:  # pragma: no cover - jsonschema is a dependency of the bench
        raise ImportError("validating results needs jsonschema (pip install 'jsonschema>=4.20')") from exc
    validator = Draft202012Validator(load_schema())
    problems = []
    for err in validator.iter_errors(obj):
        path = list(err.absolute_path)
        if err.validator == "required" and isinstance(err.instance, dict):
            for name in err.validator_value:
                if name not in err.instance:
                    problems.append((_path([*path, name]), "missing required field"))
            continue
        problems.append((_path(path), err.message))
    return problems


def _non_finite(value: Any, path: list) -> list[tuple[str, str]]:
    if isinstance(value, float) and not math.isfinite(value):
        return [(_path(path), f"{value} is not allowed (undefined values are null)")]
    if isinstance(value, dict):
        return [p for k, v in value.items() for p in _non_finite(v, [*path, k])]
    if isinstance(value, list):
        return [p for i, v in enumerate(value) for p in _non_finite(v, [*path, i])]
    return []


def _is_num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _semantic_problems(obj: dict) -> list[tuple[str, str]]:
    """Consistency checks a JSON Schema cannot express (each only where the fields are well typed)."""
    from visuomotor_gym.registration import ENV_IDS

    out = []
    env_id = obj.get("env_id")
    if isinstance(env_id, str) and env_id not in ENV_IDS:  # any family, not only catch
        out.append(("$.env_id", f"{env_id!r} is not a registered environment id "
                                 f"(known: {', '.join(ENV_IDS)})"))

    episodes, caught, seed = obj.get("episodes"), obj.get("caught"), obj.get("seed")
    rate = obj.get("catch_rate")
    episodes_ok = _is_int(episodes) and episodes >= 1
    if episodes_ok and _is_int(caught) and caught > episodes:
        out.append(("$.caught", f"caught = {caught} is more than episodes = {episodes}"))
    if _is_num(rate) and not 0.0 <= rate <= 1.0:
        out.append(("$.catch_rate", f"catch_rate = {rate} is outside [0, 1]"))
    if episodes_ok and _is_int(caught) and _is_num(rate) and abs(rate - caught / episodes) > TOLERANCE:
        out.append(("$.catch_rate", f"catch_rate = {rate} differs from caught / episodes = "
                                     f"{caught}/{episodes} = {caught / episodes}"))

    ci = obj.get("catch_rate_ci95")
    if isinstance(ci, list) and len(ci) == 2 and all(_is_num(x) for x in ci):
        low, high = ci
        if low > high:
            out.append(("$.catch_rate_ci95", f"low = {low} is above high = {high}"))
        if _is_num(rate) and not (low - TOLERANCE <= rate <= high + TOLERANCE):
            out.append(("$.catch_rate_ci95", f"interval [{low}, {high}] does not contain "
                                              f"catch_rate = {rate}"))
        counts_ok = episodes_ok and _is_int(caught) and 0 <= caught <= episodes
        expected = _wilson(caught, episodes) if counts_ok else None
        if expected is not None and any(abs(a - b) > TOLERANCE for a, b in zip(ci, expected)):
            out.append(("$.catch_rate_ci95", f"interval [{low}, {high}] is not the 95 % Wilson interval of "
                                              f"{caught}/{episodes}, [{expected[0]}, {expected[1]}]"))

    out += _success_problems(obj, episodes if episodes_ok else None, env_id)
    out += _gaze_gain_problems(obj, episodes if episodes_ok else None)

    seeds = obj.get("seeds")
    if isinstance(seeds, dict) and _is_int(seed) and episodes_ok:
        if _is_int(seeds.get("first")) and seeds["first"] != seed:
            out.append(("$.seeds.first", f"first = {seeds['first']} differs from seed = {seed}"))
        if _is_int(seeds.get("last")) and seeds["last"] != seed + episodes - 1:
            out.append(("$.seeds.last", f"last = {seeds['last']} differs from seed + episodes - 1 = "
                                         f"{seed + episodes - 1}"))

    diverged = obj.get("diverged")
    if episodes_ok and _is_int(diverged) and diverged > episodes:
        out.append(("$.diverged", f"diverged = {diverged} is more than episodes = {episodes}"))

    latency, period, real_time = obj.get("latency_ms"), obj.get("control_period_ms"), obj.get("real_time")
    if isinstance(latency, dict) and _is_num(period) and isinstance(real_time, bool):
        p95 = latency.get("p95")
        if (p95 is None or _is_num(p95)) and real_time != is_real_time(p95, period):
            out.append(("$.real_time", f"real_time = {str(real_time).lower()} but latency_ms.p95 = {p95} "
                                        f"and control_period_ms = {period}"))
        values = [latency.get(k) for k in ("p50", "p95", "max")]
        if all(_is_num(v) for v in values) and not values[0] <= values[1] <= values[2]:
            out.append(("$.latency_ms", f"expected p50 <= p95 <= max, got {values}"))

    run = obj.get("run")
    if isinstance(run, dict):
        steps, wall, per_s = run.get("env_steps"), run.get("wall_time_s"), run.get("env_steps_per_s")
        if _is_int(steps) and _is_num(wall) and wall > 0 and _is_num(per_s):
            expected_rate = steps / wall
            if abs(per_s - expected_rate) > TOLERANCE * max(1.0, expected_rate):
                out.append(("$.run.env_steps_per_s", f"env_steps_per_s = {per_s} differs from env_steps / "
                                                       f"wall_time_s = {steps}/{wall} = {expected_rate}"))
    return out


def _success_problems(obj: dict, episodes: int | None, env_id) -> list[tuple[str, str]]:
    """``success_rate`` (optional: results written before it lack the pair) is k / episodes for an
    integer k, ``success`` (optional, newer still) is k, the interval is the Wilson interval of k, and
    each of the family's own names of the success rate (its record's ``rate_aliases``: ``catch_rate``
    on a catch env id, where success is the catch) equals it."""
    from visuomotor_gym.families import family_for

    rate, ci = obj.get("success_rate"), obj.get("success_rate_ci95")
    if not _is_num(rate) or episodes is None:
        return []
    out = []
    k = round(rate * episodes)
    if abs(rate - k / episodes) > TOLERANCE:
        out.append(("$.success_rate", f"success_rate = {rate} is not a whole number of successes out of "
                                       f"episodes = {episodes}"))
    elif "success" in obj and obj["success"] != k:
        out.append(("$.success", f"success = {obj['success']} is not success_rate x episodes = {rate} x "
                                  f"{episodes} = {k}"))
    elif isinstance(ci, list) and len(ci) == 2 and all(_is_num(x) for x in ci) and 0 <= k <= episodes:
        expected = _wilson(k, episodes)
        if expected is not None and any(abs(a - b) > TOLERANCE for a, b in zip(ci, expected)):
            out.append(("$.success_rate_ci95", f"interval [{ci[0]}, {ci[1]}] is not the 95 % Wilson interval "
                                                f"of {k}/{episodes}, [{expected[0]}, {expected[1]}]"))
    try:
        record = family_for(env_id) if isinstance(env_id, str) else None
    except ValueError:  # an unknown id, reported on its own
        record = None
    for key in record.rate_aliases if record is not None else ():
        alias = obj.get(key)
        if _is_num(alias) and abs(rate - alias) > TOLERANCE:
            out.append(("$.success_rate", f"success_rate = {rate} differs from {key} = {alias}: on a "
                                           f"{record.name} env id ({env_id}) {key} is the success rate"))
    return out


def _twin_rate_problems(gain: dict, prefix: str, episodes: int) -> list[tuple[str, str]]:
    """One twin's rate is its successes / episodes, with their Wilson interval."""
    out = []
    k, rate, ci = (gain.get(f"{prefix}{n}") for n in ("successes", "success_rate", "success_rate_ci95"))
    if _is_int(k) and _is_num(rate):
        if k > episodes or abs(rate - k / episodes) > TOLERANCE:
            out.append((f"$.gaze_gain.{prefix}success_rate", f"{prefix}success_rate = {rate} is not "
                                                               f"{prefix}successes / episodes = {k}/{episodes}"))
        elif isinstance(ci, list) and len(ci) == 2 and all(_is_num(x) for x in ci):
            expected = _wilson(k, episodes)
            if expected is not None and any(abs(a - b) > TOLERANCE for a, b in zip(ci, expected)):
                out.append((f"$.gaze_gain.{prefix}success_rate_ci95", f"interval {ci} is not the Wilson interval "
                                                                       f"of {k}/{episodes}"))
    return out


def _gaze_gain_problems(obj: dict, episodes: int | None) -> list[tuple[str, str]]:
    """``gaze_gain`` (optional): each twin's rate is its successes / episodes with their Wilson interval;
    the gain is success_rate minus the better twin's (``definition = "best_twin"``) or, in results
    written before the static twin existed, minus the held twin's (``"held"``); ``held_difference`` is
    success_rate minus the held twin's. A claim that does not follow from the twins' counts is refused."""
    gain = obj.get("gaze_gain")
    if not isinstance(gain, dict) or episodes is None:
        return []
    out = _twin_rate_problems(gain, "twin_", episodes)
    static = "static_twin_agent" in gain
    if static:
        out += _twin_rate_problems(gain, "static_twin_", episodes)
    definition = gain.get("definition", "held")
    if definition == "best_twin" and not static:
        out.append(("$.gaze_gain.definition", "definition 'best_twin' needs the static twin (static_twin_* fields)"))
    elif definition == "held" and static:
        out.append(("$.gaze_gain.definition", "results with a static twin define the gain as 'best_twin' "
                                              "(success minus the better twin), not 'held'"))
    success, rate, rate_s, g = (obj.get("success_rate"), gain.get("twin_success_rate"),
                                gain.get("static_twin_success_rate"), gain.get("gain"))
    if not (_is_num(success) and _is_num(rate)):
        return out
    if static and _is_num(rate_s):
        expected, text = success - max(rate, rate_s), f"success_rate - max(twin, static twin) = {success} - max({rate}, {rate_s})"
        held = gain.get("held_difference")
        if _is_num(held) and abs(held - (success - rate)) > TOLERANCE:
            out.append(("$.gaze_gain.held_difference", f"held_difference = {held} differs from success_rate - "
                                                        f"twin_success_rate = {success} - {rate}"))
    else:
        expected, text = success - rate, f"success_rate - twin_success_rate = {success} - {rate}"
    if _is_num(g) and abs(g - expected) > TOLERANCE:
        out.append(("$.gaze_gain.gain", f"gain = {g} differs from {text}"))
    return out


def _wilson(k: int, n: int) -> tuple[float, float] | None:
    """The metrics package's Wilson interval (None if the metrics package is not importable)."""
    try:
        from visuomotor_gym.metrics import wilson_interval
    except ImportError:
        return None
    low, high = wilson_interval(k, n)
    return float(low), float(high)


def validate_results(obj: Any, source: str | None = None) -> None:
    """Raise :class:`ResultsError` listing every problem of ``obj`` (schema and semantics); else None."""
    if not isinstance(obj, dict):
        raise ResultsError([f"$: expected a JSON object, got {type(obj).__name__}"], source)
    problems = _schema_problems(obj) + _non_finite(obj, []) + _semantic_problems(obj)
    if problems:
        unique = sorted(set(problems))
        raise ResultsError([f"{path}: {msg}" for path, msg in unique], source)


def dumps_results(obj: dict) -> str:
    """The canonical text of a results file (2-space indent, trailing newline, no NaN)."""
    return json.dumps(obj, indent=2, allow_nan=False, default=_json_default) + "\n"


def write_results(path, obj: dict, force: bool = False) -> Path:
    """Validate ``obj`` and write it to ``path``; refuses to replace an existing file unless ``force``."""
    path = Path(path)
    validate_results(obj)
    text = dumps_results(obj)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not force:
        try:
            with open(path, "x", encoding="utf-8") as fh:  # exclusive create: no check-then-write race
                fh.write(text)
        except FileExistsError:
            raise FileExistsError(
                f"{path} already exists; refusing to overwrite it (use force=True, or --force on the "
                f"command line, to replace it)"
            ) from None
        return path
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _reject_constant(name: str):
    raise ValueError(f"{name} is not valid JSON")


def load_results(path) -> dict:
    """Read and validate a results file; malformed JSON or invalid content -> :class:`ResultsError`."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        obj = json.loads(text, parse_constant=_reject_constant)
    except ValueError as exc:  # json.JSONDecodeError is a ValueError
        raise ResultsError([f"$: malformed JSON: {exc}"], source=str(path),
                           headline=f"malformed JSON: {exc}") from exc
    validate_results(obj, source=str(path))
    return obj
