"""The failure memory (planner.memory): calls counted by state, skill and parameter bucket; spoiled roll spots."""

import math

import affordplan as ap
from planner.memory import FAILURES_TO_AVOID, ROLL_SPOT_RADIUS, FailureMemory, failure_key


def test_pushes_are_remembered_in_sectors_of_the_objects_frame():
    cube = ap.load_object("cube")
    turned = cube.resting_states[0].pose((0.5, 0.0), 0.5)
    # a push along +0.5 rad on the cube turned by 0.5 rad is a push along its own x axis: sector 0
    assert failure_key(cube, "push", {"direction": 0.5}, turned)[2] == 0
    assert failure_key(cube, "push", {"direction": 0.5 + math.pi / 2}, turned)[2] == 2
    assert failure_key(cube, "spin", {"angle": -0.3}, turned)[1:] == ("spin", -1)
    assert failure_key(cube, "roll", {"target": 3}, turned)[1:] == ("roll", 3)


def test_a_call_is_avoided_after_failing_twice_and_a_copy_records_apart():
    cube = ap.load_object("cube")
    T = cube.resting_states[0].pose((0.5, 0.0), 0.0)
    memory = FailureMemory(cube)
    assert not memory
    for n in range(1, FAILURES_TO_AVOID + 1):
        assert not memory.avoided("push", {"direction": 0.1}, T)
        assert memory.record("push", {"direction": 0.1}, T) == n
    assert memory.avoided("push", {"direction": 0.1}, T)
    assert memory.avoided("push", {"direction": 0.2}, T)  # the same 45 deg sector
    assert not memory.avoided("push", {"direction": 1.6}, T)
    copy = memory.copy()
    copy.record("spin", {"angle": 0.5}, T)
    copy.record("spin", {"angle": 0.4}, T)
    assert copy.count("spin", {"angle": 0.5}, T) == 2 and memory.count("spin", {"angle": 0.5}, T) == 0


def test_a_place_where_rolls_failed_twice_is_spoiled():
    cube = ap.load_object("cube")
    memory = FailureMemory(cube)
    memory.record("roll", {"target": 1}, cube.resting_states[0].pose((0.5, 0.0), 0.0))
    assert not memory.spoiled(0.5, 0.0)
    memory.record("roll", {"target": 2}, cube.resting_states[0].pose((0.52, 0.0), 0.0))
    assert memory.spoiled(0.51, 0.0)
    assert not memory.spoiled(0.5 + 2.5 * ROLL_SPOT_RADIUS, 0.0)
