"""The demo and scene runs (affordplan.app.demo.run_scene): a weights folder's skills, a refused primitive budget."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from affordplan.app.scene_file import demo_scene
from affordplan.errors import InputError


def test_a_scene_runs_the_skills_of_a_weights_folder(tmp_path):
    from affordplan.app.demo import run_scene
    from primitives.weights_file import SHIPPED_DIR as WEIGHTS_DIR

    kept = Path(__file__).resolve().parents[1] / "candidates" / "push_0.18"
    lines: list[str] = []
    run = run_scene(demo_scene(), tmp_path, sim="finger", max_primitives=1, video=False, progress=False,
                    echo=lines.append, weights_dir=kept)
    skills = run.plan.planner.predictor.skills
    assert skills["push"].success_model.net.n_decision == 13  # the folder's push, fitted before the lever arm
    assert skills["roll"]._searched_weights == WEIGHTS_DIR / "roll_success_searched.pt"  # none there: shipped
    assert run.execution.n_primitives == 1
    assert any(str(kept) in line for line in lines)
    assert json.loads((tmp_path / "summary.json").read_text())["weights"] == str(kept)
    with pytest.raises(InputError, match="not a folder"):  # refused before anything is planned
        run_scene(demo_scene(), tmp_path / "other", sim="finger", video=False, progress=False,
                  echo=lines.append, weights_dir=tmp_path / "missing")
    assert not (tmp_path / "other" / "summary.json").exists()


@pytest.mark.parametrize("max_primitives", [0, 1.5, True])
def test_run_scene_refuses_a_primitive_budget_that_is_not_a_whole_number(max_primitives, tmp_path):
    from affordplan.app.demo import run_scene

    with pytest.raises(InputError, match="max_primitives must be a whole number >= 1"):
        run_scene(demo_scene(), tmp_path, max_primitives=max_primitives, video=False, progress=False)
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_the_demos_key_frames_are_labelled_by_primitive_a_push_of_several_strokes_as_one():
    """frames.png's labels count primitives (what the execution log counts), not the strokes a push makes."""
    from types import SimpleNamespace

    import numpy as np

    import affordplan as ap
    from affordplan.app.demo import _Watch
    from planner.execute import LogEntry

    cube = ap.load_object("cube")
    sim = ap.Simulator(cube, seed=0)
    T = sim.reset(0, (0.5, 0.0), 0.0)
    recorder = SimpleNamespace(take=lambda: (lambda: None), frames=[])
    watch = _Watch(cube, sim, recorder, max_primitives=5, label="finger", progress=False)
    sim.physics_steps += 300  # three strokes of one push
    watch.after_primitive(LogEntry(0, "push", {"direction": 0.0}, True, True, T, T, strokes=3))
    watch.after_primitive(LogEntry(1, "roll", {"target": 1}, False, False, T, T))  # refused: nothing simulated
    sim.physics_steps += 100
    watch.after_primitive(LogEntry(2, "spin", {"angle": 0.5}, True, True, T, T))
    assert [label for label, _ in watch.keyframes] == ["start", "after primitive 1, 3 strokes", "after primitive 3"]
    assert watch.executed == 3 and not watch.off_table
    assert np.allclose(sim.object_pose(), T, atol=1e-3)
    watch.close()
