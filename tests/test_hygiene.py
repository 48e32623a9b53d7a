"""Source hygiene: the code cites papers by author and year, never by a tag a reader cannot follow.

A comment or docstring that says "seed 002", "issue 13" or "DESIGN section 4" points at the project's
internal notes (the order the source papers were handed in, the issue tracker, the design brief), none
of which ships with the repository. Cite the paper (Faraway et al. 2007, Sec. 4; Iwao et al., Sec.
4.2.3), say what the tag meant (a modelling choice, the first definition of a version, a docs page),
or drop it. The ruff check runs in ``make test`` (so in CI), not here.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("visuomotor_gym", "baselines", "benchmarks", "tests", "docs", "examples")
# Internal tags: a source paper's hand-in number, an issue number, a section of the design brief.
UNFOLLOWABLE = re.compile(r"seed 00[0-9]|issue [0-9]+|DESIGN(\.md)? (section|sec\.|§)", re.IGNORECASE)


def _offences(text: str) -> list[tuple[int, str]]:
    return [(n, line.strip()) for n, line in enumerate(text.splitlines(), 1) if UNFOLLOWABLE.search(line)]


def _sources() -> list[Path]:
    files = sorted(p for d in SCANNED for p in (ROOT / d).rglob("*.py") if p != Path(__file__).resolve())
    assert len(files) > 50, f"found only {len(files)} .py files under {SCANNED}: wrong root {ROOT}?"
    return files


def test_no_unfollowable_citation_tags():
    found = []
    for path in _sources():
        for n, line in _offences(path.read_text(encoding="utf-8")):
            found.append(f"{path.relative_to(ROOT)}:{n}: {line}")
    assert not found, "cite the paper (author year, section), not an internal tag:\n" + "\n".join(found)


@pytest.mark.parametrize("line", [
    "# seed 002 Sec. 4: the median reach",
    '"""The stones task (Issue 13): cross a gap."""',
    "the gaze-blind twin of DESIGN section 4",
    "``gaze_blind=True`` is the gaze-blind twin (DESIGN.md Sec. 2)",
])
def test_the_check_catches_each_tag(line):
    assert _offences(line) == [(1, line.strip())]


@pytest.mark.parametrize("line", [
    "# Faraway et al. (2007), Sec. 4: the median reach",
    "seed = 002  # an rng seed is not a paper",
    "for seed in seeds: issue_id = 3",
    "DESIGN_SEED = 100_000  # design seeds 100000-100039",
])
def test_the_check_passes_paper_citations(line):
    assert _offences(line) == []
