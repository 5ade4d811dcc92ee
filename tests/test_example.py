"""The planning examples' shared runner (affordplan.app.example.run_example), with the planner, the execution and
the pictures stood in for: its command line reaches each of them, it writes its pictures into --out, and its exit
status says whether the goal was reached."""

from __future__ import annotations

import math
import sys
import types

import numpy as np
import pytest

import affordplan as ap
from affordplan.app import example


class _Plan:
    def __init__(self, seen: dict, success: bool):
        self.seen, self.success = seen, success

    def execute(self, **kwargs):
        self.seen["execute"] = kwargs
        return types.SimpleNamespace(final_pose=np.eye(4), frames=["f0", "f1"], success=self.success)


@pytest.fixture
def fakes(monkeypatch):
    seen: dict = {"success": True}

    def predictor(obj, seed, weights_dir):
        seen["predictor"] = dict(obj=obj, seed=seed, weights_dir=weights_dir)
        return "predictor"

    def plan(obj, goal, **kwargs):
        seen["plan"] = kwargs
        return _Plan(seen, seen["success"])

    monkeypatch.setattr(example, "Predictor", predictor)
    monkeypatch.setattr(ap, "plan", plan)
    monkeypatch.setattr(example, "plot_plan", lambda p, path, execution: path.write_text("plan"))
    monkeypatch.setattr(example, "save_frames", lambda frames, path: path.write_text(",".join(frames)))
    return seen


class _Goal:
    def errors(self, obj, pose):
        return 0.012, math.radians(4.0), True


def _run(monkeypatch, argv: list[str]) -> int:
    monkeypatch.setattr(sys, "argv", ["example.py", *argv])
    return example.run_example("wall", "OBJ", _Goal(), {"xy": (0.5, 0.0)}, ["WALL"], "An example.")


def test_the_command_line_reaches_the_planner_and_the_execution(monkeypatch, tmp_path, fakes, capsys):
    out = tmp_path / "out"
    argv = ["--sim", "finger", "--out", str(out), "--seed", "4", "--max-primitives", "7", "--no-render",
            "--weights-dir", "cand"]
    assert _run(monkeypatch, argv) == 0
    assert fakes["predictor"] == dict(obj="OBJ", seed=4, weights_dir="cand")
    assert fakes["plan"] == dict(start={"xy": (0.5, 0.0)}, obstacles=["WALL"], seed=4, predictor="predictor")
    assert fakes["execute"] == dict(sim="finger", max_primitives=7, seed=4, render=None)
    assert (out / "plan.png").read_text() == "plan" and (out / "frames.png").read_text() == "f0,f1"
    text = capsys.readouterr().out
    assert "final: 1.2 cm from the goal, yaw error 4 deg, resting state right" in text
    assert f"wrote {out / 'plan.png'} and {out / 'frames.png'}" in text


def test_the_defaults_film_the_arm_and_a_missed_goal_exits_1(monkeypatch, tmp_path, fakes):
    monkeypatch.chdir(tmp_path)
    fakes["success"] = False
    assert _run(monkeypatch, []) == 1
    assert fakes["execute"] == dict(sim="arm", max_primitives=60, seed=0, render="overview")
    assert fakes["predictor"]["weights_dir"] is None
    assert (tmp_path / "affordplan-examples" / "wall" / "plan.png").exists()


def test_a_bad_option_is_a_usage_error(monkeypatch, fakes):
    with pytest.raises(SystemExit) as info:
        _run(monkeypatch, ["--sim", "gripper"])
    assert info.value.code == 2 and "plan" not in fakes
