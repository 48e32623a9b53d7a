"""The registry of task families: the one list of family modules.

Each module in :data:`FAMILY_MODULES` ends with ``FAMILY = Family(...)``
(:class:`visuomotor_gym.family.Family`); a new family adds its env module here and nowhere else
(docs/adding_a_family.md). The order is the registration order of ``visuomotor_gym.ENV_IDS``.
Importing a family module imports its env class and builds no MuJoCo model.
"""

from __future__ import annotations

import importlib
from functools import cache

from visuomotor_gym.family import Family

FAMILY_MODULES = (
    "visuomotor_gym.envs.catch",
    "visuomotor_gym.envs.walk",
    "visuomotor_gym.envs.reach",
    "visuomotor_gym.envs.dodge",
    "visuomotor_gym.envs.stones",
    "visuomotor_gym.envs.push",
)


@cache
def families() -> tuple[Family, ...]:
    """Every family's record, in :data:`FAMILY_MODULES` order (names and ids checked unique)."""
    records = []
    for module in FAMILY_MODULES:
        record = getattr(importlib.import_module(module), "FAMILY", None)
        if not isinstance(record, Family):
            raise TypeError(f"family module {module} must end with FAMILY = Family(...), found {record!r}")
        records.append(record)
    names = [f.name for f in records]
    if len(set(names)) != len(names):
        raise ValueError(f"two family modules declare the same family name: {names}")
    ids = [e.id for f in records for e in f.env_entries()]
    if len(set(ids)) != len(ids):
        raise ValueError(f"two families register the same id: {sorted({i for i in ids if ids.count(i) > 1})}")
    return tuple(records)


def family(name: str) -> Family:
    """The record of the family called ``name``; ValueError naming the known families otherwise."""
    for record in families():
        if record.name == name:
            return record
    raise ValueError(f"unknown family {name!r}; known families: {', '.join(f.name for f in families())}")


def default_family() -> Family:
    """The record that results of an id this version does not register are read with (an old results
    file): the first family's, the catch family (the package's first, whose result keys every family's
    summary keeps)."""
    return families()[0]


@cache
def _by_id() -> dict[str, Family]:
    return {entry.id: record for record in families() for entry in record.env_entries()}


def family_for(env_id: str) -> Family:
    """The record of the family a registered id belongs to (``"visuomotor_gym:"`` prefix allowed);
    ValueError for an unknown id. (``registration.family_of`` returns its name.)"""
    bare = str(env_id).removeprefix("visuomotor_gym:")
    record = _by_id().get(bare)
    if record is None:
        raise ValueError(f"unknown env id {env_id!r}; known ids: {', '.join(_by_id())}")
    return record
