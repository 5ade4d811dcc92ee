"""The resting-state graph (planner.graph): the likeliest chain of rolls, capped probabilities, penalties."""

import pytest

import affordplan as ap
from planner.graph import RestingStateGraph
from primitives import params as skill_params


def test_graph_prefers_the_likelier_route():
    cube = ap.load_object("cube")
    direct, via = 1, 2
    assert direct in skill_params.roll_targets(cube, 0) and via in skill_params.roll_targets(cube, 0)
    probs = {(0, direct): 0.2, (0, via): 0.9, (via, direct): 0.9}
    graph = RestingStateGraph(cube, lambda i, j: probs.get((i, j), 0.05))
    assert graph.route(0, direct) == [0, via, direct]  # 0.81 beats 0.2
    assert graph.route_probability([0, via, direct]) == pytest.approx(0.81)
    graph.penalise(0, via, factor=0.1)
    assert graph.route(0, direct) == [0, direct]  # 0.2 now beats 0.081
    opposite = next(s for s in range(6) if s != 0 and s not in skill_params.roll_targets(cube, 0))
    assert len(graph.route(0, opposite)) == 3  # the opposite face takes two rolls


def test_graph_takes_the_fewest_rolls_when_the_model_rates_them_all_near_certain():
    """Rolls rated 0.996 and 0.988 are all capped at MAX_PROBABILITY: one roll beats three."""
    from planner.graph import MAX_PROBABILITY

    cube = ap.load_object("cube")
    direct = skill_params.roll_targets(cube, 0)[0]
    graph = RestingStateGraph(cube, lambda i, j: 0.988 if (i, j) == (0, direct) else 0.996)
    assert graph.route(0, direct) == [0, direct]
    assert graph.probability(0, direct) == MAX_PROBABILITY


def test_edges_rated_in_one_batch_match_edges_rated_one_by_one():
    from affordplan.errors import InputError

    cube = ap.load_object("cube")
    rate = lambda i, j: 0.1 + 0.8 * ((3 * i + j) % 7) / 7  # noqa: E731
    asked = []

    def rate_edges(edges):
        asked.append(len(edges))
        return [rate(i, j) for i, j in edges]

    one_by_one, batched = RestingStateGraph(cube, rate), RestingStateGraph(cube, rate_edges=rate_edges)
    assert asked == [one_by_one.graph.number_of_edges()]  # a single call for every edge
    assert dict(one_by_one.graph.edges) == dict(batched.graph.edges)
    with pytest.raises(InputError):
        RestingStateGraph(cube)
    with pytest.raises(InputError):
        RestingStateGraph(cube, rate, rate_edges=rate_edges)
