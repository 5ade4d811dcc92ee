"""The paired comparison of saved plan-bench runs (affordplan.app.bench.compare, `affordplan bench compare`)."""

import json

import pytest

from affordplan.app.bench.compare import compare
from affordplan.errors import InputError


def _run(seed: int, outcomes: list[tuple[bool, int]], objects: str = "validation", names=None) -> dict:
    """A saved run as `affordplan bench plan --json` prints it, with one affordplan task per (success, primitives)."""
    tasks = [dict(planner="affordplan", scene="open", success=ok, planning_time=0.1, primitives=n, replans=0,
                  task=i, object_name=(names or {}).get(i, f"obj{i}"), strokes=n + 1)
             for i, (ok, n) in enumerate(outcomes)]
    return dict(seed=seed, draw=0, objects=objects, max_primitives=40, summary=[], tasks=tasks)


def test_gained_and_lost_tasks_are_counted_pairwise_with_an_exact_sign_test():
    base = [_run(0, [(True, 10), (False, 40), (False, 40), (True, 8)]),
            _run(1, [(False, 40), (False, 40), (True, 12), (False, 40)])]
    candidate = [_run(0, [(True, 6), (True, 20), (True, 30), (True, 8)]),
                 _run(1, [(True, 15), (True, 25), (True, 14), (False, 40)])]
    c = compare(base, candidate)
    s = c.summary()
    assert s["tasks"] == 8 and s["base_reached"] == 3 and s["candidate_reached"] == 7
    assert len(c.gained) == 4 and not c.lost
    assert s["sign_test_p"] == pytest.approx(2 * 0.5 ** 4)  # four of four discordant tasks one way
    assert s["both_reached"] == 3
    assert s["both_mean_primitives"] == {"base": pytest.approx(10.0), "candidate": pytest.approx(28 / 3)}
    assert s["both_mean_strokes"]["candidate"] == pytest.approx(28 / 3 + 1)
    assert "4 gained, 0 lost" in c.report() and "seed 1 task 1 affordplan (obj1: 40 -> 25 primitives)" in c.report()
    # the same runs the other way round: the split and the test mirror
    back = compare(candidate, base)
    assert len(back.lost) == 4 and back.p_value() == pytest.approx(c.p_value())
    # a task only one side ran is left out
    assert compare(base[:1], candidate).summary()["tasks"] == 4


def test_runs_of_other_tasks_or_without_their_seed_are_refused():
    base = [_run(0, [(True, 10), (False, 40)])]
    with pytest.raises(InputError, match="not the same task"):
        compare(base, [_run(0, [(True, 10), (False, 40)], names={1: "another"})])
    with pytest.raises(InputError, match="not the same task"):
        compare(base, [_run(0, [(True, 10), (False, 40)], objects="mixed")])
    with pytest.raises(InputError, match="share no task"):
        compare(base, [_run(1, [(True, 10)])])
    with pytest.raises(InputError, match="given twice"):
        compare(base + base, base)
    with pytest.raises(InputError, match="with its seed"):
        compare([dict(base[0], seed=None)], base)
    with pytest.raises(InputError, match="both sides"):
        compare([], base)


def test_the_command_prints_the_comparison_and_refuses_a_bad_file_in_one_line(tmp_path, capsys):
    from affordplan.app.cli import main

    a, b, bad = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "bad.json"
    a.write_text(json.dumps(_run(0, [(True, 10), (False, 40)])))
    b.write_text(json.dumps(_run(0, [(True, 12), (True, 30)])))
    bad.write_text("{not json")
    assert main(["bench", "compare", "--base", str(a), "--candidate", str(b), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["gained"] == ["seed 0 task 1 affordplan (obj1: 40 -> 30 primitives)"] and out["lost"] == []
    assert main(["bench", "compare", "--base", str(a), "--candidate", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cannot read bench results" in err
