"""A refusal of ``vmgym leaderboard check``: where, which rule, and a message saying what to do."""

from __future__ import annotations

from dataclasses import dataclass

# The rules, in the order the check reports them.
KINDS = (
    "protocol",
    "layout",
    "results",
    "record",
    "provenance",
    "consistency",
    "policy",
    "rescore",
    "history",
    "pages",
)


@dataclass(frozen=True)
class Problem:
    where: str  # a path relative to the leaderboard's parent folder, e.g. leaderboard/results/x.json
    kind: str  # one of KINDS
    message: str

    def __str__(self) -> str:
        return f"[{self.kind}] {self.where}: {self.message}"
