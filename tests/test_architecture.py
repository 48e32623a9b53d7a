"""The package reads top-down: leaf modules (maths, assets, plant, vision model, hand controller,
scenarios) < the embodiment core < bodies < tasks < the public env classes < everything that uses
envs (registration, agents, evaluator, metrics, plots, leaderboard, CLI). A module may import from
its own layer or below, never above, and module-level imports form no cycle."""

from __future__ import annotations

import ast
from pathlib import Path

import visuomotor_gym

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


def imports(path: Path, module: str, top_level_only: bool):
    """Dotted names imported by ``path`` (``from pkg import mod`` gives ``pkg.mod`` when mod is a module)."""
    known = {m for m, _ in modules()}
    tree = ast.parse(path.read_text())
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


def test_module_level_imports_have_no_cycle():
    graph = {}
    known = {m for m, _ in modules()}
    for module, path in modules():
        deps = set()
        for name in imports(path, module, top_level_only=True):
            while name and name not in known:  # "pkg.mod.attr" -> "pkg.mod"
                name = name.rsplit(".", 1)[0] if "." in name else ""
            if name and name != module and not module.startswith(name + "."):
                deps.add(name)
        graph[module] = deps
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for dep in graph.get(node, ()):
            if state.get(dep) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(dep):] + [dep]))
            if dep not in state:
                visit(dep)
        stack.pop()
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node)


def test_the_layer_table_is_not_vacuous():
    """Every layer holds modules, so the checks above check something."""
    found = {layer(m) for m, _ in modules()}
    assert found >= {0, 1, 2, 3, 4, TOP}
