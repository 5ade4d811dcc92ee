"""Mesh checks and repairs (affordplan.objects.repair), called directly: the unit frame, soups and open edges,
thickness, the solid standing for a surface (filled, merged or hulled, with a warning) and the bounded hull."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh

from affordplan.errors import MeshError
from affordplan.objects import repair


def _box(extents, center=(0.0, 0.0, 0.0)) -> trimesh.Trimesh:
    return trimesh.creation.box(extents, transform=trimesh.transformations.translation_matrix(center))


def _solid(mesh) -> tuple[repair.Solid, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        made = repair.solid(mesh, "m")
    return made, [str(w.message) for w in caught]


def test_clean_puts_any_units_in_the_unit_frame():
    millimetres = _box((2000.0, 1000.0, 500.0), center=(300.0, -40.0, 7.0))
    out = repair.clean(millimetres, "box")
    assert out.extents == pytest.approx([1.0, 0.5, 0.25])
    assert out.bounds.mean(axis=0) == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)  # centred on its bounding box
    assert out.is_watertight and out.volume == pytest.approx(0.125)
    assert millimetres.extents == pytest.approx([2000.0, 1000.0, 500.0])  # a copy: the input is left alone


def test_clean_drops_degenerate_faces_and_unused_vertices():
    box = _box((1.0, 1.0, 1.0))
    vertices = np.vstack([box.vertices, [[5.0, 5.0, 5.0]]])  # an unused vertex, far away
    faces = np.vstack([box.faces, [[0, 0, 1]]])  # a face with no area
    out = repair.clean(trimesh.Trimesh(vertices, faces, process=False), "box")
    assert len(out.faces) == 12 and len(out.vertices) == 8
    assert out.is_watertight and out.extents == pytest.approx(np.full(3, out.extents[0]))  # the cube, still whole


@pytest.mark.parametrize("vertices, faces, words", [
    (np.zeros((0, 3)), np.zeros((0, 3), int), "empty"),
    ([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]], [[0, 1, 2]], "1 vertices with NaN"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], "malformed faces"),
    ([[0.5, 0.5, 0.5]] * 3, [[0, 1, 2]], "all its vertices are at one point"),
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]], "every face is degenerate"),
])
def test_clean_names_what_cannot_be_a_mesh(vertices, faces, words):
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces), process=False)
    with pytest.raises(MeshError, match=words):
        repair.clean(mesh, "m")


def test_open_edges_tell_a_soup_from_a_holed_surface():
    box = _box((1.0, 1.0, 1.0))
    assert repair.open_edge_fraction(box) == 0.0 and not repair.is_soup(box)
    holed = trimesh.Trimesh(box.vertices, box.faces[:-1], process=False)  # one triangle missing
    assert 0.0 < repair.open_edge_fraction(holed) < repair.SOUP_OPEN_EDGES and not repair.is_soup(holed)
    rng = np.random.default_rng(0)
    soup = trimesh.Trimesh(rng.random((60, 3)), np.arange(60).reshape(20, 3), process=False)  # loose triangles
    assert repair.open_edge_fraction(soup) == 1.0 and repair.is_soup(soup)


def test_thickness_is_the_thinnest_width():
    assert repair.thickness(_box((1.0, 0.5, 0.02))) == pytest.approx(0.02)
    turned = _box((1.0, 0.5, 0.1))
    turned.apply_transform(trimesh.transformations.rotation_matrix(0.7, [1.0, 1.0, 0.0]))
    assert repair.thickness(turned.convex_hull) == pytest.approx(0.1, rel=1e-6)  # in any orientation


def test_a_closed_surface_is_its_own_solid_without_a_warning():
    made, messages = _solid(_box((1.0, 0.5, 0.25)))
    assert made.closed and not made.soup and made.volume is made.surface and not messages


def test_a_hole_is_filled_with_a_warning():
    box = _box((1.0, 0.5, 0.25))
    holed = trimesh.Trimesh(box.vertices, box.faces[:-1], process=False)
    made, messages = _solid(holed)
    assert made.closed and made.volume.volume == pytest.approx(0.125)
    assert any("holes were filled" in m for m in messages)


def test_overlapping_bodies_are_merged_into_their_union_with_a_warning():
    two = trimesh.util.concatenate([_box((1.0, 0.4, 0.4)), _box((0.4, 1.0, 0.4))])  # a plus sign, overlapping
    assert two.volume == pytest.approx(2 * 0.16)
    made, messages = _solid(two)
    assert made.closed and made.volume.volume == pytest.approx(2 * 0.16 - 0.4 * 0.4 * 0.4)  # the overlap once
    assert any("merged by a boolean union" in m for m in messages)


def test_a_soup_stands_in_by_its_hull():
    rng = np.random.default_rng(1)
    points = rng.normal(size=(90, 3))
    soup = trimesh.Trimesh(points, np.arange(90).reshape(30, 3), process=False)
    made, messages = _solid(soup)
    assert made.soup and not made.closed
    assert made.volume.is_convex and made.volume.volume == pytest.approx(trimesh.convex.convex_hull(points).volume)
    assert any("triangle soup" in m for m in messages)


@pytest.mark.parametrize("extents, words", [((1.0, 1.0, 0.005), "is flat"), ((1.0, 1.0, 1e-6), "zero volume")])
def test_flat_meshes_are_refused(extents, words):
    with pytest.raises(MeshError, match=words):
        repair.solid(_box(extents), "m")


def test_a_detailed_hull_is_bounded_to_its_face_budget():
    ball = trimesh.creation.icosphere(subdivisions=5)  # 20 480 faces on its hull
    hull = ball.convex_hull
    bounded = repair.bounded_hull(ball, max_faces=500)
    assert len(bounded.faces) <= 550 and bounded.is_convex
    assert 0.98 * hull.volume < bounded.volume <= hull.volume * (1 + 1e-9)  # a slightly smaller polytope
    small = _box((1.0, 1.0, 1.0))
    assert len(repair.bounded_hull(small).faces) == 12  # within the budget: the hull as is


def test_first_line_keeps_the_type_and_the_first_line():
    assert repair.first_line(ValueError("qhull failed\npages of detail\n...")) == "ValueError: qhull failed"
    assert repair.first_line(RuntimeError()) == "RuntimeError"
