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
