"""load_object(size=None) keeps a mesh's own size; objects far from what the skills trained on are named."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh

import affordplan as ap
from affordplan.errors import InputError


def test_size_none_keeps_a_real_box_its_size():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a 12 cm box is within what the skills trained on: no warning
        box = ap.load_object(trimesh.creation.box((0.12, 0.08, 0.05)), size=None)
    assert np.allclose(sorted(box.mesh.extents), [0.05, 0.08, 0.12], atol=1e-6)
    assert np.allclose(sorted(ap.load_object(trimesh.creation.box((0.12, 0.08, 0.05))).mesh.extents),
                       [0.05 / 1.2, 0.08 / 1.2, 0.1], atol=1e-6)  # the default normalises to a 5 cm half-extent


def test_a_mesh_in_millimetres_kept_at_its_size_is_refused_saying_what_to_do():
    with pytest.raises(InputError, match="give size= in metres"):
        ap.load_object(trimesh.creation.box((80.0, 50.0, 30.0)), size=None)


def test_an_object_far_from_the_trained_ones_is_named():
    with pytest.warns(UserWarning, match="half-extent is 20.0 cm, its longest side is 20 times its shortest"):
        ap.load_object(trimesh.creation.box((0.4, 0.02, 0.02)), size=None)
