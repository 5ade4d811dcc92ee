"""The push ceiling's scripted candidates (on the centre line, facing the push, straight on a cube), and the
command lines of the ceiling, the evaluation and the success models on bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import InputError
from primitives import rewards
from primitives.research import ceiling
from primitives.research.ceiling import CLOUD_POINTS, candidates_for, push_candidates


def test_candidates_face_the_push_and_hug_the_centre_line(cube):
    sim = ap.Simulator(cube, seed=0)
    T = sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.3)
    points, normals = sim.point_cloud(CLOUD_POINTS)
    direction = math.radians(100.0)
    d = np.array([math.cos(direction), math.sin(direction), 0.0])
    cands = push_candidates(points, normals, T[:3, 3], direction, 2, (0.6, 1.0), (0.0,))
    assert len(cands) == 4 * 2 * 2  # four height bands, two contacts, two strokes
    rel = np.array([c.contact for c in cands]) - T[:3, 3]
    assert np.all(np.array([c.normal for c in cands]) @ d < -0.5)
    assert np.all(np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) < 0.01)  # within 1 cm of the line through the COM
    assert np.allclose([c.motion[:2] / np.linalg.norm(c.motion[:2]) for c in cands], d[:2])


def test_aimed_candidates_push_along_the_turned_direction(cube):
    """With aims, each turn of the asked direction gets the straight candidates' set, along the turned push and
    through the centre of mass along it; an aim outside (0, 15) deg is refused."""
    sim = ap.Simulator(cube, seed=0)
    T = sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.3)
    params = {"direction": math.radians(100.0)}
    straight = candidates_for(sim, params, np.random.default_rng(0))
    aim = math.radians(10.0)
    aimed = candidates_for(sim, params, np.random.default_rng(0), aims=(aim,))
    assert len(aimed) == 3 * len(straight)
    headings = np.degrees([math.atan2(c.motion[1], c.motion[0]) for c in aimed])
    assert sorted({round(h, 6) for h in headings}) == [90.0, 100.0, 110.0]
    for c in aimed:
        d = c.motion[:2] / np.linalg.norm(c.motion[:2])
        rel = c.contact[:2] - T[:2, 3]
        assert abs(rel[0] * d[1] - rel[1] * d[0]) < 0.01  # within 1 cm of the line through the COM along it
        assert c.normal[:2] @ d < -0.5
    for bad in (0.0, math.radians(15.0), math.nan):
        with pytest.raises(InputError, match="aims"):
            ceiling.push_ceiling(starts=1, aims=(bad,), progress=False)


def test_each_candidate_names_its_rule_once_per_start(cube):
    """A rule (aim, band, rank, stroke, press) picks at most one push per start, so each rule's tally over the
    starts is that rule's own success; the labels carry the aim."""
    sim = ap.Simulator(cube, seed=0)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.3)
    aimed = candidates_for(sim, {"direction": 0.4}, np.random.default_rng(0), aims=(math.radians(5.0),))
    rules = [c.rule for c in aimed]
    assert len(set(rules)) == len(rules)
    assert {r.split(",")[0] for r in rules} == {"aim +0 deg", "aim +5 deg", "aim -5 deg"}
    seed_objective = candidates_for(sim, None, np.random.default_rng(0))
    assert len({c.rule for c in seed_objective}) == len(seed_objective)


def test_rules_are_ranked_by_their_success_over_all_starts():
    result = ceiling.CeilingResult(starts=4, params="random", any_success=3, candidate_success=[0.5, 0.25, 0.0, 0.75],
                                   rule_success={"a": 1, "b": 3, "c": 2})
    assert result.rules_ranked() == [("b", 0.75), ("c", 0.5), ("a", 0.25)]
    d = result.as_dict()
    assert d["best_rule"] == "b" and d["best_rule_success"] == 0.75 and d["ceiling"] == 0.75
    assert list(d["rule_success"]) == ["b", "c", "a"] and d["mean_candidate_success"] == 0.375
    assert "0.750  b" in result.report() and "mean over starts: 0.375" in result.report()
    assert ceiling.CeilingResult(starts=1, params="random").mean_candidate_success == 0.0


def test_a_centre_line_push_moves_the_cube_straight(cube):
    sim = ap.Simulator(cube, seed=0)
    sim.reset(resting_state=0, xy=(0.5, 0.0), yaw=0.0)
    params = {"direction": 0.0}
    # lowest band, nearest the line, 0.7 of the stroke, level
    best = candidates_for(sim, params, np.random.default_rng(0))[2]
    out = sim.execute(best.contact, best.motion, normal=best.normal)
    m = rewards.motion(out.pose_before, out.pose_after)
    assert 0.05 <= m.p[0] <= 0.09 and abs(m.p[1]) < 0.01
    assert m.theta_deg < 5.0
    assert rewards.success("push", out.pose_before, out.pose_after, params, cube)


def test_bad_command_lines_get_a_clear_error_not_a_traceback(tmp_path, capsys):
    """Missing weights or a mesh that does not load: one line on stderr, exit status 2; no starts: a usage error."""
    from primitives.training import evaluate, success

    missing = str(tmp_path / "nope.pt")
    assert ceiling.main(["--starts", "1", "--weights", missing]) == 2
    assert "no weights at" in capsys.readouterr().err
    assert evaluate.main(["push", "--trials", "1", "--weights", missing]) == 2
    assert "no weights at" in capsys.readouterr().err
    broken = tmp_path / "broken.obj"
    broken.write_text("not a mesh")
    assert evaluate.main(["push", "--trials", "1", "--objects", str(broken)]) == 2
    assert "primitives.training.evaluate: error:" in capsys.readouterr().err
    assert success.main(["evaluate", "spin", "--model", missing, "--rollouts", "1", "--out", str(tmp_path)]) == 2
    assert "no success model at" in capsys.readouterr().err
    for main, argv in ((ceiling.main, ["--starts", "0"]), (evaluate.main, ["push", "--trials", "0"]),
                       (success.main, ["train", "spin", "--rollouts", "0"])):
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        assert exit_info.value.code == 2
