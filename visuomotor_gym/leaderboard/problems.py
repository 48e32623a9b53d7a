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


def load_schema(name: str) -> dict:
    """A JSON Schema shipped next to this module (``entry_schema.json``, ``protocol_schema.json``...)."""
    import json
    from importlib import resources

    return json.loads(resources.files("visuomotor_gym.leaderboard").joinpath(name).read_text("utf-8"))


def schema_problems(obj, schema: dict) -> list[str]:
    """Every violation of ``schema`` by ``obj``, each as ``$.json.path: message`` (sorted, unique)."""
    from jsonschema import Draft202012Validator

    out = []
    for err in Draft202012Validator(schema).iter_errors(obj):
        path = "$" + "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in err.absolute_path)
        if err.validator == "required" and isinstance(err.instance, dict):
            out += [f"{path}.{n}: missing required field" for n in err.validator_value if n not in err.instance]
        elif err.validator == "additionalProperties" and isinstance(err.instance, dict):
            allowed = set(err.schema.get("properties", {}))
            extra = sorted(k for k in err.instance if k not in allowed)
            out.append(f"{path}: unknown key(s) {extra} (allowed: {sorted(allowed)})")
        else:
            out.append(f"{path}: {err.message}")
    return sorted(set(out))
