"""Write one documentation page per environment family (``docs/families/<family>.md``).

Everything on a page comes from the code and the data, never typed by hand:

* the registered ids of the family (``visuomotor_gym.registration.ENV_SPECS``): rung, arguments,
  episode limit, and the action and observation shapes of an env built from each id;
* the action blocks of the family's foveated id (``action_structure``);
* the env class's docstring (description, action and observation index tables -- the observation
  table is itself generated from the layout --, rewards, starting state, episode end, arguments,
  version history);
* the current leaderboard entries on the family's ids (``leaderboard/``), with gaze gains;
* the linked pages and a picture, where one exists under ``docs/``: the family record's
  ``doc_links`` and ``doc_pictures`` (:class:`visuomotor_gym.family.Family`).

    python docs/gen_family_pages.py           # write the pages
    python docs/gen_family_pages.py --check   # exit 1 if a committed page differs (tests/test_docs.py)

``make docs`` runs it before ``mkdocs build --strict``.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
OUT = DOCS / "families"
LEADERBOARD = ROOT / "leaderboard"


def page_facts(record) -> tuple[str, str, tuple, tuple]:
    """A family's page title, foveated id, linked pages (title, path relative to docs/) and candidate
    pictures (path relative to docs/, caption; the first that exists is shown), from its record."""
    return (f"{record.name.capitalize()}: {record.prefix}", f"{record.prefix}-v0", record.doc_links,
            record.doc_pictures)


def _env_class(entry_point: str):
    module, name = entry_point.split(":")
    return getattr(importlib.import_module(module), name)


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _kwargs(kwargs: dict) -> str:
    if not kwargs:
        return "–"
    return ", ".join(f"`{k}={v!r}`" for k, v in kwargs.items())


def _ids_table(specs) -> list[str]:
    import gymnasium as gym

    rows = ["| id | what the eye gives | arguments | max steps | action | observation |",
            "|---|---|---|---|---|---|"]
    for spec in specs:
        env = gym.make(spec.id)
        try:
            act, obs = env.action_space.shape, env.observation_space.shape
        finally:
            env.close()
        rows.append(f"| `{spec.id}` | {_cell(spec.description)} | {_cell(_kwargs(spec.kwargs))} | "
                    f"{spec.max_episode_steps} | `{act}` | `{obs}` |")
    return rows


def _action_blocks(env_id: str) -> list[str]:
    import gymnasium as gym

    env = gym.make(env_id)
    try:
        actions = dict(env.unwrapped.action_structure)
    finally:
        env.close()
    lines = ["| action block | indices | size |", "|---|---|---|"]
    start = 0
    for name, size in actions.items():
        index = f"{start}" if size == 1 else f"{start}-{start + size - 1}"
        lines.append(f"| `{name}` | {index} | {size} |")
        start += size
    return lines


def _leaderboard_rows(env_ids) -> list[str]:
    """Current (not superseded) entries on ``env_ids``, as the leaderboard page orders and scores them
    (:mod:`visuomotor_gym.leaderboard.pages`): the gaze gain against the better of the held and the best
    static twin, and the held-twin difference."""
    if not (LEADERBOARD / "protocol.json").is_file():
        return []
    from visuomotor_gym.leaderboard.entries import load_leaderboard
    from visuomotor_gym.leaderboard.pages import _rows, fmt_gain, fmt_rate, fmt_realism

    current, _ = _rows(load_leaderboard(LEADERBOARD))
    current = [r for r in current if r.env_id in env_ids]
    if not current:
        return []
    order = list(env_ids)
    current.sort(key=lambda r: (order.index(r.env_id), -r.rate, r.name))
    rows = ["| agent (spec) | env id | success [95 % CI] | gaze gain | held-twin difference | gaze realism "
            "| latency p95 | episodes |",
            "|---|---|---|---|---|---|---|---|"]
    for r in current:
        p95 = r.latency["p95"]
        rows.append(
            f"| `{r.name}` (`{_cell(r.agent)}`) | `{r.env_id}` | {fmt_rate(r)} | {fmt_gain(r.gain)} | "
            f"{fmt_gain(r.held_gain)} | {fmt_realism(r)} | {'–' if p95 is None else f'{p95:.2f} ms'} | {r.episodes} |"
        )
    return rows


def _dedent(doc: str) -> str:
    """The docstring without its indentation, taken from its section headings (``    ## Rewards``):
    tables substituted into a docstring may not be indented (inspect.cleandoc would keep it all)."""
    lines = doc.expandtabs().splitlines()
    heads = [len(line) - len(line.lstrip()) for line in lines if line.lstrip().startswith("## ")]
    indent = min(heads) if heads else 0
    out = [line[min(indent, len(line) - len(line.lstrip())):] for line in lines]
    return inspect.cleandoc("\n".join(out))


def family_page(family: str) -> str:
    """The Markdown of one family's page."""
    import visuomotor_gym  # noqa: F401  (registers the ids)
    from visuomotor_gym.families import family as family_record
    from visuomotor_gym.registration import ENV_SPECS

    title, main_id, pages, pictures = page_facts(family_record(family))
    specs = [s for s in ENV_SPECS if s.family == family]
    cls = _env_class(specs[0].entry_point)
    doc = _dedent(cls.__doc__ or "")
    lines = [
        ("<!-- Generated by docs/gen_family_pages.py from the env class's docstring, the registry and "
        "leaderboard/: do not edit. `make docs-pages` rewrites it; tests/test_docs.py fails when it is stale. -->"),
        "",
        f"# {title}",
        "",
        f"`{cls.__module__}.{cls.__name__}` · foveated id `{main_id}` · "
        + " · ".join(f"[{t}](../{p})" for t, p in pages),
        "",
    ]
    for path, caption in pictures:
        if (DOCS / path).is_file():
            lines += [f"![{caption}](../{path})", "", f"*{caption}.*", ""]
            break
    lines += [
        "```python",
        "import gymnasium as gym",
        "import visuomotor_gym  # registers the ids",
        "",
        f'env = gym.make("{main_id}")  # "visuomotor_gym:{main_id}" in subprocess workers',
        "obs, info = env.reset(seed=0)",
        "obs, reward, terminated, truncated, info = env.step(env.action_space.sample())",
        "```",
        "",
        "## Registered ids",
        "",
        ("Every rung has the same physics and scenario sampler: a seed gives the same scenario on each. "
        "Shapes are those of an env built from the id (flat observations, the default)."),
        "",
        *_ids_table(specs),
        "",
        f"## Action blocks of `{main_id}`",
        "",
        ("From `env.unwrapped.action_structure` (what each index means: Action Space below). The "
        "observation's index table (Observation Space below) is generated from the layout the env "
        'declares, as `env.unwrapped.observation_structure` gives it; with `obs_mode="dict"` the '
        "observation is a `Dict` of the same blocks."),
        "",
        *_action_blocks(main_id),
        "",
        f"## Reference (`{cls.__name__}` docstring)",
        "",
    ]
    # The docstring's sections become subsections of the reference.
    for line in doc.splitlines():
        lines.append("#" + line if line.startswith("## ") else line)
    lines.append("")
    board = _leaderboard_rows([s.id for s in specs])
    lines += ["## Baselines on the leaderboard", ""]
    if board:
        lines += [
            ("Current entries of the [leaderboard](../evaluation.md#the-leaderboard) on this family's ids "
            "(pinned seeds, `vmgym bench`'s evaluator). *Gaze gain*: success minus that of the better of the "
            "agent's two twins on the same seeds, the held twin (`gaze_blind:<agent>`: gaze and head held where "
            "reset put them) and the best static twin (`static_gaze:<posture>:<agent>`: one posture of eye and "
            "neck searched on design seeds); `–` without a static twin entry. *Held-twin difference*: success "
            "minus the held twin's. *(v1)*: realism scored with the first definition."),
            "",
            *board,
            "",
        ]
    else:
        lines += ["No leaderboard entry on this family's ids yet.", ""]
    return "\n".join(lines).rstrip() + "\n"


def pages() -> dict[Path, str]:
    from visuomotor_gym.families import families

    return {OUT / f"{record.name}.md": family_page(record.name) for record in families()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a committed page is stale; write nothing")
    args = parser.parse_args(argv)
    stale = []
    for path, text in pages().items():
        current = path.read_text(encoding="utf-8") if path.is_file() else None
        if current != text:
            stale.append(path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else str(path))
            if not args.check:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(text, encoding="utf-8")
    if args.check and stale:
        print("stale family pages (run `make docs-pages`): " + ", ".join(stale), file=sys.stderr)
        return 1
    print(("stale: " if args.check else "written: ") + (", ".join(stale) or "none"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
