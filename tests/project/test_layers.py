"""The import layers go one way (docs/architecture.md, "Layers"), read from the source with an
AST walk: every import counts, function-local ones included, so that a local import cannot
hide a cycle.

- `hexapod_envs` imports nothing from `agents`;
- no installed module (`hexapod_envs`, `agents`) imports a study (`experiments`), a script
  (`scripts`), the benchmarks or the tests;
- the pipeline is the top layer: the controllers, the `Policy` interface, model loading
  (`agents.ppo`) and what a run leaves on disk (`agents.run_files`) do not import it, except the
  modules in `PIPELINE_USERS`;
- no import cycle among the project's modules, except those listed in `KNOWN_CYCLES` (none
  now): a new one fails.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

from helpers.paths import REPO

INSTALLED = ("hexapod_envs", "agents")
PACKAGES = (*INSTALLED, "experiments")
NOT_INSTALLED = ("experiments", "scripts", "benchmarks", "tests")

PIPELINE_USERS = {
    "agents.export": "the hexapod-export command: above the pipeline",
}
"""Modules of `agents` outside `agents.pipeline` that may import it, and why."""

KNOWN_CYCLES: list[set[str]] = []
"""Import cycles that exist and are accepted for now (each the set of its modules). The cycle
agents.hybrid -> pipeline.evaluation -> ppo -> hybrid (with pipeline.envs, eval_config and
train_config) was broken by moving the env-kwarg helpers into `agents.env_kwargs`."""


@cache
def modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the project's packages."""
    found = {}
    for package in PACKAGES:
        for path in (REPO / package).rglob("*.py"):
            parts = list(path.relative_to(REPO).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join(parts)] = path
    return found


def imported_names(module: str, path: Path) -> list[tuple[str, int]]:
    """(dotted name, line) of every import in the module, at any depth; a relative import is
    resolved against the module's package; ``from a import b`` gives ``a.b``."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([node.module] if node.module else [])])
            names += [(f"{base}.{alias.name}", node.lineno) for alias in node.names]
    return names


def project_module(name: str) -> str | None:
    """The project module that an imported name lives in (its longest module prefix)."""
    while name:
        if name in modules():
            return name
        name = name.rpartition(".")[0]
    return None


@cache
def graph() -> dict[str, dict[str, int]]:
    """module -> {imported project module: first line}."""
    edges: dict[str, dict[str, int]] = {}
    for module, path in modules().items():
        for name, line in imported_names(module, path):
            target = project_module(name)
            if target is not None and target != module:
                edges.setdefault(module, {}).setdefault(target, line)
    return edges


def cycles() -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    edges, index, low, stack, on_stack, found = graph(), {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(component)

    for v in sorted(modules()):
        if v not in index:
            visit(v)
    return found


def _where(module: str, target: str) -> str:
    path = modules()[module].relative_to(REPO)
    return f"{path}:{graph()[module][target]} imports {target}"


def _offences(source_prefixes, target_test) -> list[str]:
    return [
        _where(module, target)
        for module, targets in graph().items()
        if module.split(".")[0] in source_prefixes
        for target in targets
        if target_test(module, target)
    ]


def test_the_walk_sees_the_project():
    assert {"hexapod_envs.envs.base", "agents.ppo", "agents.pipeline.evaluation"} <= set(modules())
    assert "experiments.reproduction.rows" in modules()
    assert "agents.policy" in graph()["agents.hybrid"]  # module-level import
    assert "agents.pipeline.cli" in graph()["agents.export"]
    assert (
        "agents.run_files.model_files" in graph()["agents.ppo"]
    )  # model loading, below the pipeline


def test_envs_import_nothing_from_agents():
    offences = _offences(("hexapod_envs",), lambda m, t: t.split(".")[0] == "agents")
    assert not offences, "\n".join(offences)


def test_installed_modules_import_no_study_script_benchmark_or_test():
    offences = []
    for module, path in modules().items():
        if module.split(".")[0] not in INSTALLED:
            continue
        for name, line in imported_names(module, path):
            if name.split(".")[0] in NOT_INSTALLED:
                offences.append(f"{path.relative_to(REPO)}:{line} imports {name}")
    assert not offences, "\n".join(offences)


def test_controllers_do_not_import_the_pipeline():
    def upward(module: str, target: str) -> bool:
        inside = module.startswith("agents.pipeline")
        return not inside and target.startswith("agents.pipeline") and module not in PIPELINE_USERS

    offences = _offences(("agents",), upward)
    assert not offences, "\n".join(offences)


def test_no_new_import_cycle():
    found = cycles()
    new = [c for c in found if c not in KNOWN_CYCLES]
    lines = []
    for component in new:
        lines.append(" <-> ".join(sorted(component)))
        for module in sorted(component):
            lines += [f"    {_where(module, t)}" for t in graph()[module] if t in component]
    assert not new, "import cycles:\n" + "\n".join(lines)
    gone = [c for c in KNOWN_CYCLES if c not in found]
    assert not gone, f"cycles no longer there, remove them from KNOWN_CYCLES: {gone}"
