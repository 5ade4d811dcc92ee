"""Procedural shapes (affordplan.objects.shapes): convex pieces with the volumes geometry gives them, unions that are
one watertight solid, and the catalogue's construction shapes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

import affordplan as ap
from affordplan.objects import shapes


def _polygon_area(r: float, n: int) -> float:
    """Area of the regular ``n``-gon inscribed in a circle of radius ``r``."""
    return 0.5 * n * r * r * math.sin(2 * math.pi / n)


def test_a_frustum_is_the_convex_solid_between_two_rings():
    cylinder = shapes.frustum(0.02, 0.02, 0.01, 0.05)
    assert cylinder.is_convex and cylinder.is_watertight
    assert cylinder.volume == pytest.approx(_polygon_area(0.02, shapes.SECTIONS) * 0.04)
    assert cylinder.bounds[:, 2] == pytest.approx([0.01, 0.05])
    cone_cut = shapes.frustum(0.03, 0.01, 0.0, 0.06, sections=64)
    a0, a1 = _polygon_area(0.03, 64), _polygon_area(0.01, 64)
    assert cone_cut.volume == pytest.approx(0.06 / 3 * (a0 + a1 + math.sqrt(a0 * a1)))  # a frustum's volume
    top = cone_cut.vertices[cone_cut.vertices[:, 2] > 0.03]
    assert np.linalg.norm(top[:, :2], axis=1) == pytest.approx(np.full(len(top), 0.01))


def test_annular_wedges_tile_a_hollow_wall_into_one_watertight_solid():
    wedges = shapes.annular_wedges(0.03, 0.04, 0.0, 0.03, 0.04, 0.05, sections=16)
    assert len(wedges) == 16 and all(w.is_convex for w in wedges)
    ring = shapes.union(wedges)
    assert ring.mesh.is_watertight and ring.mesh.body_count == 1
    annulus = (_polygon_area(0.04, 16) - _polygon_area(0.03, 16)) * 0.05
    assert ring.mesh.volume == pytest.approx(annulus, rel=0.02)  # the wedges' chords, not the circles
    assert ring.mesh.volume < 0.6 * ring.mesh.convex_hull.volume  # hollow: the hull fills the hole
    apart = shapes.annular_wedges(0.03, 0.04, 0.0, 0.03, 0.04, 0.05, sections=16, overlap=0.0)
    assert sum(w.volume for w in apart) == pytest.approx(annulus, rel=1e-6)  # no overlap: they tile it exactly


def test_a_union_keeps_convex_parts_and_is_the_solid_they_cover():
    a = shapes.box((0.1, 0.1, 0.1))
    b = shapes.box((0.1, 0.1, 0.1), center=(0.05, 0.0, 0.0))  # half inside a
    shape = shapes.union([a, b])
    assert shape.parts == (a, b)
    assert shape.mesh.volume == pytest.approx(0.15 * 0.1 * 0.1)
    single = shapes.union([a])
    assert single.mesh is not a and single.mesh.volume == pytest.approx(a.volume)  # a copy, not the part
    l_shape = trimesh.boolean.union([shapes.box((0.2, 0.05, 0.05)), shapes.box((0.05, 0.2, 0.05))],
                                    engine="manifold")
    assert not l_shape.is_convex
    (part,) = shapes.union([l_shape]).parts  # a part must be convex: its hull stands in
    assert part.is_convex and part.volume == pytest.approx(l_shape.convex_hull.volume)


def test_tube_segments_follow_the_path_with_the_radius():
    path = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0], [0.1, 0.1, 0.1]])
    pieces = shapes.tube_segments(path, 0.01, ring=24)
    assert len(pieces) == 3 and all(p.is_convex for p in pieces)
    for piece, p0, p1 in zip(pieces, path[:-1], path[1:]):
        assert piece.volume == pytest.approx(_polygon_area(0.01, 24) * np.linalg.norm(p1 - p0))
        d = (p1 - p0) / np.linalg.norm(p1 - p0)
        side = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 0.0, 1.0])
        side /= np.linalg.norm(side)
        centre = 0.5 * (p0 + p1)
        inside, outside = piece.contains([centre + 0.008 * side, centre + 0.012 * side])
        assert inside and not outside  # 1 cm from the axis all round


@pytest.mark.parametrize("name", sorted(shapes.CATALOGUE))
def test_catalogue_shapes_are_watertight_unions_of_their_convex_parts(name):
    shape = shapes.CATALOGUE[name]()
    assert shape.mesh.is_watertight and shape.mesh.body_count == 1
    assert all(p.is_convex for p in shape.parts)
    assert sum(p.volume for p in shape.parts) >= shape.mesh.volume * (1 - 1e-6)  # parts cover it (overlapping)


def test_the_catalogue_is_the_shapes_module_s():
    assert sorted(ap.catalogue()) == sorted(shapes.CATALOGUE)
    assert shapes.cube().mesh.volume == pytest.approx(1e-3)
    assert shapes.lunch_box().mesh.extents == pytest.approx([0.2, 0.14, 0.06])
