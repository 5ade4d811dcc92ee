"""The import graph keeps the layers (DESIGN's layout rules): no cycles, nothing imports upward, and what the
run-time entry points reach imports no training or research module."""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("affordplan", "primitives", "planner")
APPLICATION = {"affordplan.cli", "affordplan.demo", "affordplan.bench", "affordplan.scene_file", "affordplan.video",
               "affordplan.viewer", "affordplan.render", "affordplan.robustness"}
RESEARCH = {f"primitives.{m}" for m in ("ceiling", "frame_ceiling", "sensitivity", "killtest", "compare_backends",
                                        "querybench", "sim2sim", "ship", "curves")}
TRAINING = {f"primitives.{m}" for m in ("train", "rollouts", "replay", "checkpoint", "evaluate", "hindsight")}
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
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                subs = [f"{node.module}.{a.name}" for a in node.names]
                targets = subs if all(t in modules for t in subs) else [node.module]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            graph.add_edges_from((name, t) for t in targets if t in modules and t != name)
    return graph


def _layer(module: str) -> int:
    return 3 if module in APPLICATION else LAYER[module.split(".")[0]]


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
    assert sorted(closure & (TRAINING | RESEARCH)) == []
