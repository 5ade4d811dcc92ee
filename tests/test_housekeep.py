"""HACMan's household meshes: shipped, split as HACMan split them, loaded without CoACD."""

from __future__ import annotations

import pytest

import affordplan as ap
from affordplan.errors import InputError, MeshError
from affordplan.objects import decompose, housekeep


def test_the_splits_are_hacmans_and_training_never_sees_a_test_object():
    assert [len(housekeep.names(s)) for s in ("train", "unseen_instance", "unseen_class", "not_in_split")] == \
        [72, 10, 15, 43]
    assert len(housekeep.names()) == 140
    unseen = set(housekeep.names("unseen"))
    training, validation = set(housekeep.names("training")), set(housekeep.names("validation"))
    assert len(unseen) == 25 and not unseen & training and not unseen & validation
    assert not training & validation and validation <= set(housekeep.names("train"))
    assert set(housekeep.names("unseen_thick")) <= unseen
    with pytest.raises(InputError, match="split"):
        housekeep.names("everything")


def test_a_household_mesh_loads_by_name_with_its_shipped_parts(monkeypatch):
    def no_coacd(*args, **kwargs):
        raise AssertionError("CoACD ran for a shipped mesh")

    monkeypatch.setattr(decompose, "_coacd", no_coacd)
    mug = ap.load_object("housekeep/mug_025_mug_M")
    assert mug.name == "housekeep/mug_025_mug_M" and len(mug.parts) > 1
    assert max(mug.mesh.extents) == pytest.approx(0.1, rel=1e-6)
    small = ap.load_object("housekeep/mug_025_mug_M", size=0.03)  # parts scale with the object
    assert max(small.parts[0].extents) == pytest.approx(0.6 * max(mug.parts[0].extents), rel=1e-6)


def test_the_provenance_note_ships_with_the_meshes():
    text = (housekeep.data_dir() / "PROVENANCE.md").read_text()
    assert "HACMan" in text and "CC BY" in text


def test_an_unknown_household_name_is_a_mesh_error():
    with pytest.raises(MeshError, match="housekeep.names"):
        ap.load_object("housekeep/no_such_thing")
