"""The package reads top-down: leaf modules (maths, assets, plant, vision model, hand controller,
scenarios) < the embodiment core < bodies < tasks < the public env classes < everything that uses
envs (registration, agents, evaluator, metrics, plots, leaderboard, CLI). A module may import from
its own layer or below, never above, and imports -- at module level or deferred into a function body --
form no cycle (a deliberately deferred edge is named in ``DEFERRED_EDGES`` with its reason).

A family is one record (``visuomotor_gym.family.Family``) declared at the end of its env module: no
shared module holds a family table or compares a family name (``test_no_shared_module_names_a_family``),
and the records give back exactly the ids, kwargs and limits registered before them."""

from __future__ import annotations

import ast
import functools
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import pytest

import visuomotor_gym
from visuomotor_gym import registration
from visuomotor_gym.families import FAMILY_MODULES, families, family, family_for
from visuomotor_gym.family import BeliefMPC, ExtraEnv, Family

PACKAGE = Path(visuomotor_gym.__file__).parent

# Lowest first. A module's layer is the first prefix that matches its dotted name (most specific first).
LAYERS = {
    "visuomotor_gym.body.names": 0,  # a table of MuJoCo names, imports nothing
    "visuomotor_gym.body.walker_names": 0,
    "visuomotor_gym.geometry": 0,
    "visuomotor_gym.assets": 0,
    "visuomotor_gym.oculomotor": 0,
    "visuomotor_gym.vision": 0,
    "visuomotor_gym.control": 0,
    "visuomotor_gym.scenarios": 0,
    "visuomotor_gym.handpath": 0,
    "visuomotor_gym._native": 0,  # the optional compiled kernels: import nothing of the package
    "visuomotor_gym.core.args": 0,  # argument and parameter-field checks: import nothing of the package
    "visuomotor_gym.family": 0,  # the Family record: imports nothing of the package at module level
    "visuomotor_gym.core": 1,
    "visuomotor_gym.body": 2,
    "visuomotor_gym.tasks": 3,
    "visuomotor_gym.envs": 4,
}
TOP = 5  # registration, agents, bench, metrics, viz, leaderboard, cli, the package itself


def layer(module: str) -> int:
    for prefix in sorted(LAYERS, key=len, reverse=True):
        if module == prefix or module.startswith(prefix + "."):
            return LAYERS[prefix]
    return TOP


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


@functools.cache
def _known() -> frozenset[str]:
    return frozenset(m for m, _ in modules())


@functools.cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text())


def imports(path: Path, module: str, top_level_only: bool):
    """Dotted names imported by ``path`` (``from pkg import mod`` gives ``pkg.mod`` when mod is a module)."""
    known = _known()
    tree = _tree(path)
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            for alias in node.names:
                sub = f"{name}.{alias.name}"
                yield sub if sub in known else name


def test_no_module_imports_from_a_higher_layer():
    violations = []
    for module, path in modules():
        for name in imports(path, module, top_level_only=False):
            if name.startswith("visuomotor_gym") and layer(name) > layer(module):
                violations.append(f"{module} (layer {layer(module)}) imports {name} (layer {layer(name)})")
    assert not violations, "\n".join(violations)


def test_the_core_imports_no_task_env_or_body_module():
    for module, path in modules():
        if layer(module) == 1:
            for name in imports(path, module, top_level_only=False):
                assert not name.startswith(("visuomotor_gym.tasks", "visuomotor_gym.envs")), (module, name)
                assert not name.startswith("visuomotor_gym.body") or name == "visuomotor_gym.body.names", (module, name)


# Deferred imports (inside a function body) that close a cycle on purpose, each with its reason. The
# cycle test drops these edges and fails on any other cycle; an entry whose import is gone or moved to
# module level fails too, so the list cannot rot.
DEFERRED_EDGES = {
    ("visuomotor_gym.agents", "visuomotor_gym.static_gaze"):
        "the agent registry's factory of the static_gaze: wrapper, which is built on agents (make_agent)",
    ("visuomotor_gym.static_gaze", "visuomotor_gym.bench.evaluate"):
        "the posture search plays postures with the evaluator, which resolves static_gaze: specs",
    ("visuomotor_gym.leaderboard.check", "visuomotor_gym.leaderboard.pages"):
        "check's last rule compares the committed pages with a fresh build, and the pages name check's prefixes",
}


def _graph(top_level_only: bool) -> dict[str, set[str]]:
    graph = {}
    known = {m for m, _ in modules()}
    for module, path in modules():
        deps = set()
        for name in imports(path, module, top_level_only=top_level_only):
            while name and name not in known:  # "pkg.mod.attr" -> "pkg.mod"
                name = name.rsplit(".", 1)[0] if "." in name else ""
            if name and name != module and not module.startswith(name + "."):
                deps.add(name)
        graph[module] = deps
    return graph


def _assert_acyclic(graph: dict[str, set[str]]) -> None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for dep in sorted(graph.get(node, ())):
            if state.get(dep) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(dep):] + [dep]))
            if dep not in state:
                visit(dep)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)


def test_module_level_imports_have_no_cycle():
    _assert_acyclic(_graph(top_level_only=True))


def test_imports_including_deferred_ones_have_no_cycle():
    """``ast.walk`` over the whole module: an import inside a function body is an edge too (the metrics
    cycle summary -> catch_handpath -> ... -> summary hid there), except the reasoned DEFERRED_EDGES."""
    graph = _graph(top_level_only=False)
    top = _graph(top_level_only=True)
    for (src, dst), reason in DEFERRED_EDGES.items():
        assert dst in graph.get(src, ()), f"stale DEFERRED_EDGES entry {src} -> {dst} ({reason}): no such import"
        assert dst not in top.get(src, ()), f"{src} -> {dst} is a module-level import, not a deferred one"
        graph[src] = graph[src] - {dst}
    _assert_acyclic(graph)


def test_the_cycle_check_can_fail():
    with pytest.raises(AssertionError, match="import cycle: a -> b -> a"):
        _assert_acyclic({"a": {"b"}, "b": {"a"}})


def test_the_layer_table_is_not_vacuous():
    """Every layer holds modules, so the checks above check something."""
    found = {layer(m) for m, _ in modules()}
    assert found >= {0, 1, 2, 3, 4, TOP}


# ------------------------------------------------------------------ one Family record per family

# Modules that belong to one family (named for it): they may name their own family. Every other module
# of the package is shared and may not.
FAMILY_LAYERS = ("visuomotor_gym.envs.", "visuomotor_gym.tasks.", "visuomotor_gym.body.")
# Shared code outside the package that must read the records too (the family pages' generator).
SHARED_SCRIPTS = (PACKAGE.parent / "docs" / "gen_family_pages.py",)


def _is_family_module(module: str, names: set[str]) -> bool:
    if module.startswith(FAMILY_LAYERS):
        return True
    leaf = module.rsplit(".", 1)[-1]
    return module.startswith("visuomotor_gym.metrics.") and any(leaf.startswith(f"{n}_") for n in names)


def _family_literals(path: Path, names: set[str]) -> list[int]:
    """Lines of ``path`` where a string constant (not a docstring) is a family name: a comparison
    (``family == "walk"``, ``family in ("catch", "reach")``) or a table key (``"stones": ...``)."""
    tree = ast.parse(path.read_text())
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
        and node.body and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant)
    }
    return sorted(node.lineno for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names
                  and id(node) not in docstrings)


def test_no_shared_module_names_a_family():
    names = {f.name for f in families()}
    shared = [(module, path) for module, path in modules() if not _is_family_module(module, names)]
    shared += [(path.relative_to(PACKAGE.parent).as_posix(), path) for path in SHARED_SCRIPTS]
    found = [f"{module} lines {lines}" for module, path in shared if (lines := _family_literals(path, names))]
    assert not found, ("a shared module names a family (read its Family record instead):\n" + "\n".join(found))


def test_the_family_name_check_can_fail(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text('"""A docstring may say catch."""\n\nLABELS = {"stones": 1}\n\n\ndef f(family):\n'
                   '    return family == "walk"\n')
    assert _family_literals(bad, {f.name for f in families()}) == [3, 7]


# Every id registered before the Family records, as (id, entry point, kwargs, max_episode_steps, family):
# the records must give back exactly this list, in this order.
# The Eyecatch paper's eye: static acuity at any retinal speed and, since EyeCatch-v0's eye has the human
# periphery (CATCH_VISION, laid under every catch id's vision_params), every periphery field at its default.
PAPER_EYE = {'position_slip_knee_deg_s': math.inf, 'field_shape': 'cone', 'position_e2_deg': None, 'crowding': False, 'depth_pedestal_arcmin': None, 'position_disarray': 0.0, 'angular_lateral_noise': False}

REGISTERED_BEFORE_THE_RECORDS = (
    ('EyeCatchOracle-v0', 'catch:EyeCatchEnv', {'vision': 'oracle'}, 125, 'catch'),
    ('EyeCatchFullView-v0', 'catch:EyeCatchEnv', {'vision': 'full_view'}, 125, 'catch'),
    ('EyeCatch-v0', 'catch:EyeCatchEnv', {}, 125, 'catch'),
    ('EyeCatchDelayed-v0', 'catch:EyeCatchEnv', {'visual_delay_s': 0.1}, 125, 'catch'),
    ('EyeCatchPoorVision-v0', 'catch:EyeCatchEnv', {'vision_noise_scale': 2.0}, 125, 'catch'),
    ('EyeCatchBounce-v0', 'catch:EyeCatchEnv', {'bounce_wall': True}, 125, 'catch'),
    ('EyeCatchTwoBalls-v0', 'catch:EyeCatchEnv', {'n_balls': 2}, 150, 'catch'),
    ('EyeCatchPaper-v0', 'catch:EyeCatchEnv', {'vision_params': PAPER_EYE}, 125, 'catch'),
    ('EyeCatchPaperPoorVision-v0', 'catch:EyeCatchEnv', {'vision_params': PAPER_EYE, 'vision_noise_scale': 10.0}, 125, 'catch'),
    ('ObstacleWalkOracle-v0', 'walk:ObstacleWalkEnv', {'vision': 'oracle'}, 2000, 'walk'),
    ('ObstacleWalkFullView-v0', 'walk:ObstacleWalkEnv', {'vision': 'full_view'}, 2000, 'walk'),
    ('ObstacleWalk-v0', 'walk:ObstacleWalkEnv', {}, 2000, 'walk'),
    ('ObstacleWalkDelayed-v0', 'walk:ObstacleWalkEnv', {'visual_delay_s': 0.1}, 2000, 'walk'),
    ('ObstacleWalkPoorVision-v0', 'walk:ObstacleWalkEnv', {'vision_noise_scale': 2.0}, 2000, 'walk'),
    ('ShelfReachOracle-v0', 'reach:ShelfReachEnv', {'vision': 'oracle'}, 150, 'reach'),
    ('ShelfReachFullView-v0', 'reach:ShelfReachEnv', {'vision': 'full_view'}, 150, 'reach'),
    ('ShelfReach-v0', 'reach:ShelfReachEnv', {}, 150, 'reach'),
    ('ShelfReachDelayed-v0', 'reach:ShelfReachEnv', {'visual_delay_s': 0.1}, 150, 'reach'),
    ('ShelfReachPoorVision-v0', 'reach:ShelfReachEnv', {'vision_noise_scale': 2.0}, 150, 'reach'),
    ('ObstacleDodgeOracle-v0', 'dodge:ObstacleDodgeEnv', {'vision': 'oracle'}, 2000, 'dodge'),
    ('ObstacleDodgeFullView-v0', 'dodge:ObstacleDodgeEnv', {'vision': 'full_view'}, 2000, 'dodge'),
    ('ObstacleDodge-v0', 'dodge:ObstacleDodgeEnv', {}, 2000, 'dodge'),
    ('ObstacleDodgeDelayed-v0', 'dodge:ObstacleDodgeEnv', {'visual_delay_s': 0.1}, 2000, 'dodge'),
    ('ObstacleDodgePoorVision-v0', 'dodge:ObstacleDodgeEnv', {'vision_noise_scale': 2.0}, 2000, 'dodge'),
    ('SteppingStonesOracle-v0', 'stones:SteppingStonesEnv', {'vision': 'oracle'}, 1000, 'stones'),
    ('SteppingStonesFullView-v0', 'stones:SteppingStonesEnv', {'vision': 'full_view'}, 1000, 'stones'),
    ('SteppingStones-v0', 'stones:SteppingStonesEnv', {}, 1000, 'stones'),
    ('SteppingStonesDelayed-v0', 'stones:SteppingStonesEnv', {'visual_delay_s': 0.1}, 1000, 'stones'),
    ('SteppingStonesPoorVision-v0', 'stones:SteppingStonesEnv', {'vision_noise_scale': 2.0}, 1000, 'stones'),
    # The first family added on the records: its ids follow from its record alone.
    # PushRecovery's eleventh pass (the push at 1.0-2.0 s): 250 steps, 200 before.
    ('PushRecoveryOracle-v0', 'push:PushRecoveryEnv', {'vision': 'oracle'}, 250, 'push'),
    ('PushRecoveryFullView-v0', 'push:PushRecoveryEnv', {'vision': 'full_view'}, 250, 'push'),
    ('PushRecovery-v0', 'push:PushRecoveryEnv', {}, 250, 'push'),
    ('PushRecoveryDelayed-v0', 'push:PushRecoveryEnv', {'visual_delay_s': 0.1}, 250, 'push'),
    ('PushRecoveryPoorVision-v0', 'push:PushRecoveryEnv', {'vision_noise_scale': 2.0}, 250, 'push'),
)


def test_the_records_register_exactly_the_ids_of_before():
    got = tuple((s.id, s.entry_point.removeprefix("visuomotor_gym.envs."), s.kwargs, s.max_episode_steps, s.family)
                for s in registration.ENV_SPECS)
    assert got == REGISTERED_BEFORE_THE_RECORDS
    assert tuple(row[0] for row in REGISTERED_BEFORE_THE_RECORDS) == registration.ENV_IDS
    for env_id, entry_point, kwargs, steps, _ in REGISTERED_BEFORE_THE_RECORDS:
        spec = gym.spec(env_id)
        assert (spec.entry_point, spec.kwargs, spec.max_episode_steps) == (
            "visuomotor_gym.envs." + entry_point, kwargs, steps), env_id


def test_the_old_public_names_are_derived_from_the_records():
    assert [f.name for f in families()] == list(registration.FAMILIES)
    assert registration.CATCH_ENV_IDS == registration.FAMILIES["catch"] == visuomotor_gym.CATCH_ENV_IDS
    assert set(registration.WALKER_FAMILIES) == {"walk", "stones", "dodge"}
    for record in families():
        assert registration.FAMILIES[record.name] == tuple(e.id for e in record.env_entries())
        for env_id in registration.FAMILIES[record.name]:
            assert registration.family_of(env_id) == record.name and family_for(env_id) is record
            assert registration.family_of(f"visuomotor_gym:{env_id}") == record.name
    with pytest.raises(ValueError, match="unknown env id 'Nope-v0'; known ids: EyeCatchOracle-v0"):
        registration.family_of("Nope-v0")
    with pytest.raises(ValueError, match="unknown family 'swim'; known families: catch, walk"):
        family("swim")
    assert registration.POOR_VISION_SCALE == 2.0 and registration.VISUAL_DELAY_S == 0.1
    assert PAPER_EYE == registration.PAPER_VISION


def test_each_record_is_declared_at_the_end_of_its_env_module():
    for module in FAMILY_MODULES:
        path = PACKAGE.parent / (module.replace(".", "/") + ".py")
        assert module.startswith("visuomotor_gym.envs."), module
        tree = ast.parse(path.read_text())
        assigned = [node for node in tree.body if isinstance(node, ast.Assign)
                    and any(isinstance(t, ast.Name) and t.id == "FAMILY" for t in node.targets)]
        assert len(assigned) == 1, f"{module} declares FAMILY {len(assigned)} times"
        record = sys.modules[module].FAMILY
        assert record.entry_point.startswith(module + ":"), (module, record.entry_point)


def test_every_reference_of_a_record_resolves_to_what_its_readers_need():
    from visuomotor_gym.agents import agent_names
    from visuomotor_gym.family import resolve

    agents = set(agent_names())
    for record in families():
        assert callable(resolve(record.summariser)) and callable(resolve(record.miss_distance)), record.name
        assert isinstance(gym.spec(f"{record.prefix}-v0").entry_point, str)
        assert set(record.agents) <= agents, (record.name, set(record.agents) - agents)
        assert record.golden_agent is None or record.golden_agent in record.agents, record.name
        if record.belief_mpc is not None:
            assert "belief_mpc" in record.agents, record.name
            cls = resolve(record.belief_mpc.agent)
            assert hasattr(cls, "for_env") and isinstance(resolve(record.belief_mpc.params), type)
        else:
            assert "belief_mpc" not in record.agents, record.name


def test_importing_the_records_builds_no_mujoco_model():
    code = (
        "import mujoco\n"
        "class Refuse:\n"
        "    def __getattr__(self, name):\n"
        "        raise SystemExit('a MuJoCo model was built at import: mujoco.MjModel.' + name)\n"
        "mujoco.MjModel = Refuse()\n"
        "import visuomotor_gym\n"
        "from visuomotor_gym.families import families\n"
        "print(len(families()))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert out.returncode == 0, out.stderr[-2000:] + out.stdout[-2000:]
    assert out.stdout.strip() == str(len(FAMILY_MODULES))


def _record(**changes) -> Family:
    return replace(family("reach"), **changes)


@pytest.mark.parametrize("changes, error, match", [
    ({"name": "Reach"}, ValueError, r"Family.name must be a lower-case identifier"),
    ({"prefix": "shelf"}, ValueError, r"Family 'reach': prefix must be a CamelCase"),
    ({"entry_point": "ShelfReachEnv"}, ValueError, r"entry_point must be a 'visuomotor_gym.module:attribute'"),
    ({"max_episode_steps": 0}, ValueError, r"max_episode_steps must be a positive int, got 0"),
    ({"max_episode_steps": 1.5}, ValueError, r"max_episode_steps must be a positive int, got 1.5"),
    ({"oracle_sees": ""}, ValueError, r"oracle_sees must be a non-empty string"),
    ({"summariser": "visuomotor_gym.metrics.reach_realism.reach_summary"}, ValueError, r"summariser must be"),
    ({"miss_distance": None}, ValueError, r"miss_distance must be"),
    ({"outcome_labels": ("a", "b")}, ValueError, r"outcome_labels must be 3 non-empty strings"),
    ({"reaction_from_t0": 1}, TypeError, r"reaction_from_t0 must be a bool"),
    ({"vision_defaults": {"field_of_view_deg": 20.0}}, TypeError, r"vision_defaults must be a VisionParams"),
    ({"extra_envs": (ExtraEnv("ShelfReach-v0", {}, "again"),)}, ValueError, r"extra_envs repeat an id"),
    ({"extra_envs": [ExtraEnv("ShelfReachX-v0", {}, "x")]}, TypeError, r"extra_envs must be a tuple of ExtraEnv"),
    ({"agents": "faraway"}, TypeError, r"agents must be a tuple of agent names"),
    ({"golden_extra": (("faraway", "EyeCatch-v0"),)}, ValueError, r"golden_extra must be a tuple of \(agent"),
    ({"belief_mpc": "stones"}, TypeError, r"belief_mpc must be a BeliefMPC or None"),
])
def test_a_bad_record_names_its_field(changes, error, match):
    with pytest.raises(error, match=match):
        _record(**changes)


def test_bad_extra_env_and_belief_mpc_specs_name_their_field():
    with pytest.raises(ValueError, match=r"ExtraEnv\.id must be an id like"):
        ExtraEnv("bounce", {}, "x")
    with pytest.raises(ValueError, match=r"ExtraEnv.max_episode_steps of A-v0 must be a positive int or None"):
        ExtraEnv("A-v0", {}, "x", max_episode_steps=-1)
    with pytest.raises(ValueError, match=r"BeliefMPC\.params must be a 'visuomotor_gym\.module:attribute'"):
        BeliefMPC("visuomotor_gym.baselines.belief_mpc:BeliefMPCAgent", "BeliefMPCParams")


def test_the_metrics_scaffolding_is_a_leaf():
    """metrics.common imports no family module, registration or dispatcher: the summarisers import it."""
    path = PACKAGE / "metrics" / "common.py"
    names = {f.name for f in families()}
    for name in imports(path, "visuomotor_gym.metrics.common", top_level_only=False):
        leaf = name.rsplit(".", 1)[-1]
        assert not any(leaf.startswith(f"{n}_") for n in names), name
        assert name not in ("visuomotor_gym.registration", "visuomotor_gym.families", "visuomotor_gym.metrics.summary")
