"""Collecting what skill calls do (primitives.training.outcomes): the columns a collection records, and adding the
start state's drop probability to files collected before it was recorded."""

from __future__ import annotations

import numpy as np
import pytest

from affordplan.errors import InputError
from affordplan.objects.model import load_object, random_object
from primitives.training.outcomes import COLUMNS, annotate, collect, main, object_of, recorded_command


def test_object_names_load_procedural_and_catalogue_objects():
    assert object_of("train/3").name == random_object(3, "train").name
    assert object_of("cube").name == load_object("cube").name


def test_annotate_adds_each_rows_start_state_probability_and_keeps_the_rest(tmp_path):
    path = tmp_path / "push_outcome.npz"
    objects = np.asarray(["cube", "train/3"])
    rows = dict(p=np.array([0.2, 0.5, 0.9], np.float32), progress=np.array([0.1, 0.6, 1.2], np.float32),
                made_progress=np.array([True, True, True]), object=np.array([0, 1, 1], np.int16),
                state_before=np.array([0, 0, 1], np.int16), state_after=np.array([0, 1, 1], np.int16))
    np.savez_compressed(path, **rows, objects=objects, skill=np.asarray("push"), command=np.asarray("made here"))
    report = annotate(str(path), progress=False)
    assert report["rows"] == 3 and report["tipped"] == pytest.approx(1 / 3)
    with np.load(path, allow_pickle=False) as f:
        got = {k: np.array(f[k]) for k in f.files}
    cube, proc = load_object("cube"), random_object(3, "train")
    expected = [cube.resting_states[0].probability, proc.resting_states[0].probability,
                proc.resting_states[1].probability]
    assert got["state_probability"] == pytest.approx(expected, rel=1e-6)
    for k, v in rows.items():
        assert np.array_equal(got[k], v)
    assert str(got["command"]) == "made here" and not list(tmp_path.glob("*.tmp*"))


def test_annotate_refuses_a_file_it_cannot_read_on_the_command_line(tmp_path, capsys):
    path = tmp_path / "a.npz"
    np.savez(path, p=np.zeros(2))
    with pytest.raises(InputError, match="object"):
        annotate(str(path), progress=False)
    np.savez(path, objects=np.asarray(["cube"]), object=np.zeros(1, np.int16), state_before=np.zeros(1, np.int16))
    with pytest.raises(InputError, match="state_after"):
        annotate(str(path), progress=False)
    path.write_bytes(b"not an npz file")
    with pytest.raises(InputError, match="not a readable outcome file"):
        annotate(str(path), progress=False)
    assert main(["annotate", str(tmp_path / "missing.npz")]) == 2
    assert "no outcome file" in capsys.readouterr().err


def test_a_collection_records_every_column_with_the_start_states_drop_probability():
    from primitives.skills import load_skills

    data = collect("push", load_skills(), rollouts=2, objects="cube", seed=0, progress=False)
    assert set(COLUMNS) <= set(data) and len(data["p"]) == 2
    cube = load_object("cube")
    for s, prob in zip(data["state_before"], data["state_probability"]):
        assert prob == pytest.approx(cube.resting_states[int(s)].probability, rel=1e-6)


def test_the_recorded_command_keeps_no_folder_outside_the_working_directory(tmp_path):
    """An outcome file may ship: its recorded --out is relative inside the working directory, a bare file name
    outside it, and left as typed when it was relative already."""
    inside = tmp_path / "primitives" / "weights" / "push_outcome.npz"
    outside = "/elsewhere/scratch/push_outcome.npz"
    assert recorded_command(["collect", "push", "--out", str(inside)], cwd=tmp_path) == \
        "python -m primitives.training.outcomes collect push --out primitives/weights/push_outcome.npz"
    assert recorded_command(["collect", "push", f"--out={outside}", "--seed", "0"], cwd=tmp_path) == \
        "python -m primitives.training.outcomes collect push --out=push_outcome.npz --seed 0"
    assert recorded_command(["collect", "roll", "--out", "runs/r.npz"], cwd=tmp_path).endswith("--out runs/r.npz")
