"""Physics fuzz (a small run of ``affordplan bench robustness``): no crash, no NaN pose escapes."""

from __future__ import annotations

import argparse
import json

import pytest

import affordplan as ap
from affordplan.app import robustness
from affordplan.errors import InputError

GUARDS = {"nan", "unstable", "left_workspace", "speed", "sank", "off_table"}  # affordplan.sim.guards


@pytest.fixture(scope="module")
def fuzz() -> robustness.RobustnessResult:
    return robustness.run(60, seed=0, progress=False)


def test_fuzz_never_crashes_and_lets_no_nan_through(fuzz):
    assert fuzz.crashed == 0, fuzz.crash_examples
    assert fuzz.nan_escaped == 0


def test_fuzz_counts_add_up(fuzz):
    assert fuzz.accounted == fuzz.primitives == 60
    assert sum(fuzz.kinds.values()) == sum(fuzz.starts.values()) == 60
    assert set(fuzz.invalid) <= GUARDS  # every valid=False is named by a guard
    assert sum(fuzz.invalid_by_kind.values()) == fuzz.invalid_total
    assert sum(sum(g.values()) for g in fuzz.invalid_by_start.values()) == fuzz.invalid_total
    assert fuzz.rejected == fuzz.kinds["non_finite"]  # every NaN / inf input refused, none accepted
    assert fuzz.objects == ap.catalogue()  # every catalogue object took its turn
    assert fuzz.valid > 0 and fuzz.invalid_total > 0  # both bins are exercised by this seed


def test_nothing_implausible_is_marked_valid_from_a_settled_start(fuzz):
    assert not [k for k in fuzz.suspect if "(rest start)" in k], fuzz.suspect


def test_fuzz_is_deterministic():
    a = robustness.run(16, seed=3, objects=["mug", "tape"], progress=False).as_dict()
    b = robustness.run(16, seed=3, objects=["mug", "tape"], progress=False).as_dict()
    for d in (a, b):
        d.pop("wall_s"), d.pop("primitives_per_s")
    assert a == b


def test_bad_arguments():
    with pytest.raises(InputError, match="primitives must be a whole number >= 1, got 0"):
        robustness.run(0, progress=False)
    with pytest.raises(InputError, match="got 2.5"):
        robustness.run(2.5, progress=False)
    with pytest.raises(InputError):
        robustness.run(5, sim="hand", progress=False)


def test_cli_subcommand_prints_json(capsys):
    parser = argparse.ArgumentParser(prog="affordplan bench")
    register = parser.add_subparsers(dest="bench", required=True)
    robustness.register_cli(register)
    args = parser.parse_args(["robustness", "--primitives", "8", "--object", "cube", "--seed", "1", "--json"])
    assert args.func(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["primitives"] == 8 and report["crashed"] == 0 and report["nan_escaped"] == 0 and report["ok"]
    assert report["sim"] == "finger" and report["objects"] == ["cube"]
