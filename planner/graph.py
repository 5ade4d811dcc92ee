"""The resting-state graph: which face changes to make, and in what order.

Nodes are the object's resting states; a directed edge ``i -> j`` is a roll from state ``i`` to a
state ``j`` one roll away (:func:`primitives.params.roll_targets`), weighted by ``-log P(success)``
of the roll skill (clipped to ``[MIN_PROBABILITY, MAX_PROBABILITY]``). The cheapest route is then the
likeliest chain of rolls (success probabilities multiply along a route). A failed roll can be
down-weighted (:meth:`RestingStateGraph.penalise`), so the next route goes another way.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import networkx as nx

from affordplan.errors import InputError, PlanningError
from affordplan.objects.model import ObjectModel
from primitives.params import roll_targets

MIN_PROBABILITY = 1e-4  # floor on edge probabilities, so that -log stays finite
# Ceiling on edge probabilities. The planner rates each edge once, at one pose per state (the workspace centre,
# yaw 0); the cube's rolls are rated 0.97-0.997 there. Near 1 the search is blind to how many rolls a route
# takes, yet every roll is a primitive that can fail where the object really is (held-out rolls succeed 0.80
# overall) and shifts it some 6 cm: three rolls rated 0.996 beat one rated 0.988, and the die of the examples
# went round three faces to reach a neighbouring one. Capped, every roll costs at least -log 0.95.
MAX_PROBABILITY = 0.95


class RestingStateGraph:
    """Directed graph over resting states with roll edges weighted by ``-log P(success)``.

    Args:
        obj: the object.
        roll_probability: ``(i, j) -> P(a roll from state i ends in state j)``, asked edge by edge.
        rate_edges: instead, ``[(i, j), ...] -> [P, ...]``, asked once for every edge (one batched query of the
            success model rather than one per edge: a many-faced object has dozens).

    Raises:
        InputError: neither or both of ``roll_probability`` and ``rate_edges``.
    """

    def __init__(self, obj: ObjectModel, roll_probability: Callable[[int, int], float] | None = None, *,
                 rate_edges: Callable[[list[tuple[int, int]]], Sequence[float]] | None = None):
        if (roll_probability is None) == (rate_edges is None):
            raise InputError("give roll_probability or rate_edges, one of them")
        self.obj = obj
        self.graph = nx.DiGraph()
        for s in obj.resting_states:
            self.graph.add_node(s.index, probability=s.probability)
        edges = [(s.index, t) for s in obj.resting_states for t in roll_targets(obj, s.index)]
        rates = rate_edges(edges) if rate_edges is not None else [roll_probability(i, j) for i, j in edges]
        for (i, j), p in zip(edges, rates, strict=True):
            p = min(MAX_PROBABILITY, max(MIN_PROBABILITY, float(p)))
            self.graph.add_edge(i, j, p=p, weight=-math.log(p))

    def probability(self, i: int, j: int) -> float:
        return float(self.graph.edges[i, j]["p"])

    def penalise(self, i: int, j: int, factor: float = 0.25) -> None:
        """Multiply the success probability of roll ``i -> j`` by ``factor`` (after repeated failures)."""
        if self.graph.has_edge(i, j):
            e = self.graph.edges[i, j]
            e["p"] = max(MIN_PROBABILITY, e["p"] * factor)
            e["weight"] = -math.log(e["p"])

    def route(self, start: int, goal: int) -> list[int]:
        """States visited from ``start`` to ``goal`` (both included) on the likeliest chain of rolls."""
        if start == goal:
            return [start]
        try:
            return [int(s) for s in nx.shortest_path(self.graph, start, goal, weight="weight")]
        except nx.NetworkXNoPath:
            raise PlanningError(
                f"{self.obj.name}: no chain of rolls leads from resting state {start} to {goal}") from None

    def route_probability(self, route: list[int]) -> float:
        """Product of the rolls' success probabilities along ``route``."""
        return math.prod(self.probability(a, b) for a, b in zip(route, route[1:]))
