"""The random training family (affordplan.objects.family): seeded draws, disjoint splits, every kind builds."""

from __future__ import annotations

import numpy as np
import pytest

import affordplan as ap


def test_random_family_is_seeded_and_splits_differ():
    a, b = ap.random_object(3), ap.random_object(3)
    assert a.name == b.name and np.array_equal(a.mesh.vertices, b.mesh.vertices)
    train = {ap.random_object(i).mesh.volume for i in range(8)}
    test = {ap.random_object(i, "test").mesh.volume for i in range(8)}
    assert not train & test


@pytest.mark.parametrize("kind", ["box", "cylinder", "frustum", "capsule", "ellipsoid", "convex", "composite"])
def test_every_family_kind_builds(kind):
    obj = ap.random_object(0, kind=kind)
    assert kind in obj.name
    assert 0.04 - 1e-9 <= max(obj.mesh.extents) / 2 <= 0.06 + 1e-9  # 5 cm x U(0.8, 1.2)
    assert len(obj.resting_states) >= 1


def test_random_shapes_draw_every_kind_and_refuse_unknown_splits_and_kinds():
    from affordplan.objects.family import KINDS, random_shape

    draws = [random_shape(i) for i in range(60)]
    assert {kind for kind, _, _ in draws} == set(KINDS)  # 60 draws meet all seven kinds
    assert all(0.8 <= scale <= 1.2 for _, _, scale in draws)
    assert all(shape.mesh.is_watertight and all(p.is_convex for p in shape.parts) for _, shape, _ in draws[:10])
    kind, shape, scale = random_shape(5, kind="capsule")
    assert kind == "capsule" and random_shape(5, kind="capsule")[2] == scale  # forcing the kind keeps the draw seeded
    with pytest.raises(ValueError, match="unknown split"):
        random_shape(0, split="validation")
    with pytest.raises(ValueError, match="unknown kind"):
        random_shape(0, kind="torus")
