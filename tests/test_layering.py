"""The import graph keeps the layers (DESIGN's layout rules): no cycles, nothing imports upward, and what the
run-time entry points reach imports no training or research module."""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("affordplan", "primitives", "planner")
# The application layer: affordplan.app, and the three command lines kept at their 0.23 names.
CLI_SHIMS = {"primitives.train", "primitives.evaluate", "primitives.success"}


def is_application(module: str) -> bool:
    return module == "affordplan.app" or module.startswith("affordplan.app.") or module in CLI_SHIMS


def is_training(module: str) -> bool:
    return module.startswith("primitives.training")


def is_research(module: str) -> bool:
    return module.startswith("primitives.research")


RUN_TIME_ENTRIES = ("affordplan", "primitives.skills", "planner.api", "planner.execute")
LAYER = {"affordplan": 0, "primitives": 1, "planner": 2}


def import_graph() -> nx.DiGraph:
    """Module -> module edges of every import in the three packages, at module level or inside functions
    (``from package import module`` is an edge to the module, not to the package)."""
    modules = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            modules[".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")] = path
    graph = nx.DiGraph()
    for name, path in modules.items():
        graph.add_node(name)
        tree = ast.parse(path.read_text())
        type_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If) and _is_type_checking(block.test)
                     for stmt in block.body for n in ast.walk(stmt)}
        for node in ast.walk(tree):
            if id(node) in type_only:  # ``if TYPE_CHECKING:`` imports never run
                continue
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                subs = [f"{node.module}.{a.name}" for a in node.names]
                targets = subs if all(t in modules for t in subs) else [node.module]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            graph.add_edges_from((name, t) for t in targets if t in modules and t != name)
    return graph


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _layer(module: str) -> int:
    return 3 if is_application(module) else LAYER[module.split(".")[0]]


def test_no_import_cycles():
    cycles = [sorted(c) for c in nx.strongly_connected_components(import_graph()) if len(c) > 1]
    assert cycles == []


FACADE = {("affordplan", "planner.api")}  # ap.plan(): imported when called, the one documented upward edge


def test_nothing_imports_a_higher_layer():
    """core (affordplan) <- primitives <- planner <- application (CLI, demo, benches, scene files, video, viewer)."""
    upward = sorted((a, b) for a, b in import_graph().edges if _layer(b) > _layer(a) and (a, b) not in FACADE)
    assert upward == []


def test_run_time_reaches_no_training_or_research_module():
    graph = import_graph()
    closure = set().union(*({e} | nx.descendants(graph, e) for e in RUN_TIME_ENTRIES))
    assert sorted(m for m in closure if is_training(m) or is_research(m)) == []


def test_nothing_outside_the_application_imports_it():
    """The CLI, demo, benches, scene files, video and viewer (affordplan.app) and the kept command-line names are
    imported by nothing else."""
    graph = import_graph()
    assert sorted((a, b) for a, b in graph.edges if is_application(b) and not is_application(a)) == []


def test_training_imports_no_research_module():
    graph = import_graph()
    assert sorted((a, b) for a, b in graph.edges if is_training(a) and is_research(b)) == []


def test_the_planner_reads_robot_constants_from_the_core_not_the_simulator():
    graph = import_graph()
    assert sorted((a, b) for a, b in graph.edges if a.startswith("planner") and b.startswith("affordplan.sim")
                  and b not in ("affordplan.sim.simulator", "affordplan.sim.scene", "affordplan.sim.sensor")) == []
