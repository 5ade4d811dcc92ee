"""The surface samples a pusher can touch: inner faces dropped, inward normals turned out."""

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from affordplan.errors import InputError
from affordplan.objects.exposed import (
    BURIED_DEPTH,
    HOLE_RADIUS,
    SHARED_FACE,
    depth_in_parts,
    exposed_boundary,
    exposed_samples,
    hole_fill,
)
from affordplan.objects.model import ObjectModel, random_object

SIDE = 0.08  # metres


def _object(mesh: trimesh.Trimesh, parts) -> ObjectModel:
    return ObjectModel("probe", mesh, parts, mass=0.1, inertia=np.eye(3) * 1e-4)


def _outward_ok(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Whether each normal of a sample of the centred cube of side SIDE points out of the face it lies on."""
    axis = np.argmax(np.abs(points), axis=1)
    rows = np.arange(len(points))
    return np.sign(points[rows, axis]) * normals[rows, axis] > 0.99


def test_depth_in_parts_is_positive_inside_zero_on_the_boundary_and_negative_outside():
    cube = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    depth = depth_in_parts([cube], np.array([[0.0, 0.0, 0.0], [SIDE / 2, 0.0, 0.0], [SIDE, 0.0, 0.0]]))
    assert depth == pytest.approx([SIDE / 2, 0.0, -SIDE / 2], abs=1e-9)


def test_a_shell_inside_the_body_gets_no_samples():
    outer = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    inner = trimesh.creation.box(extents=(SIDE / 2, SIDE / 2, SIDE / 2))  # a label's inner shell, say
    obj = _object(trimesh.util.concatenate([outer, inner]), [outer])
    points, normals = obj.surface_samples(2048, seed=0)
    assert len(points) == 2048
    # every sample lies on the outer cube's faces, none on the inner one
    assert np.allclose(np.max(np.abs(points), axis=1), SIDE / 2, atol=1e-6)
    assert _outward_ok(points, normals).all()
    # the raw mesh would have put a fifth of them inside (the inner shell has a quarter of the outer's area)
    raw, _ = trimesh.sample.sample_surface(obj.mesh, 2048, seed=0)
    assert np.mean(depth_in_parts(obj.parts, raw) > BURIED_DEPTH) > 0.1


def test_faces_wound_inwards_get_outward_normals():
    cube = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    faces = cube.faces.copy()
    faces[::2] = faces[::2, ::-1]  # every other triangle wound the wrong way, as in some scanned meshes
    bad = trimesh.Trimesh(cube.vertices, faces, process=False)
    raw_points, raw_idx = trimesh.sample.sample_surface(bad, 2048, seed=0)
    assert not _outward_ok(raw_points, bad.face_normals[raw_idx]).all()  # the mesh's own normals: half inward
    points, normals = _object(bad, [cube]).surface_samples(2048, seed=0)
    assert _outward_ok(points, normals).all()


def test_a_mesh_whose_surface_is_its_parts_boundary_keeps_every_sample_and_normal():
    obj = random_object(3, "test")
    points, face_idx = trimesh.sample.sample_surface(obj.mesh, 4096, seed=5)
    normals = obj.mesh.face_normals[face_idx]
    keep, turned = exposed_samples(obj.parts, points, normals)
    assert keep.all()
    assert np.array_equal(turned, normals)


def test_a_mesh_lying_wholly_inside_its_parts_is_sampled_on_the_parts_boundary():
    cube = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    inner = trimesh.creation.box(extents=(SIDE / 2, SIDE / 2, SIDE / 2))
    obj = _object(inner, [cube])  # every point of the mesh lies 2 cm inside the parts, which the simulator collides
    points, normals = obj.surface_samples(512, seed=0)
    assert len(points) == 512
    assert np.allclose(np.max(np.abs(points), axis=1), SIDE / 2, atol=1e-6)
    assert _outward_ok(points, normals).all()


def test_where_the_parts_bulge_past_the_mesh_their_boundary_fills_the_hole():
    cube = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    dented = cube.copy()
    top = dented.vertices[:, 2] > 0
    dented.vertices[top, 2] -= 0.01  # the mesh's top lies 1 cm inside the part, as where a part closes a cavity
    obj = _object(dented, [cube])
    points, normals = obj.surface_samples(4096, seed=0)
    assert len(points) == 4096
    assert np.all(depth_in_parts(obj.parts, points) <= BURIED_DEPTH)  # no sample lies buried
    on_top = points[:, 2] > SIDE / 2 - 1e-6
    assert 0.1 < np.mean(on_top) < 0.25  # the part's top face, a sixth of its area, is sampled
    assert np.allclose(normals[on_top], [0.0, 0.0, 1.0])
    # every point of the part's boundary lies near a sample, as on a uniform draw of 4,096 (spaced ~3 mm): no hole
    # is left (without the fill the top face's centre would lie 4 cm from the nearest sample)
    boundary, _ = trimesh.sample.sample_surface(cube, 2000, seed=1)
    gaps, _ = cKDTree(points).query(boundary)
    assert gaps.max() < 2 * HOLE_RADIUS


def test_the_exposed_boundary_of_overlapping_parts_leaves_out_what_lies_inside_the_other():
    a = trimesh.creation.box(extents=(SIDE, SIDE, SIDE))
    b = a.copy().apply_translation([SIDE / 2, 0.0, 0.0])  # overlapping by half
    points, normals = exposed_boundary([a, b], 4000, seed=0)
    assert np.all(depth_in_parts([a], points[points[:, 0] > SIDE / 2 + 1e-6]) < 1e-9)
    assert np.all(depth_in_parts([a, b], points) <= SHARED_FACE)  # on the union's boundary
    assert np.all(depth_in_parts([a, b], points + 1e-3 * normals) < 0.0)  # normals point out of the union
    # the union's area is 10 of the 12 faces' worth of SIDE^2 squares: a sixth of the draw is inside the other
    assert len(points) == pytest.approx(4000 * 10 / 12, rel=0.05)


def test_a_procedural_object_needs_no_hole_fill():
    obj = random_object(3, "test")
    points, face_idx = trimesh.sample.sample_surface(obj.mesh, 4096, seed=5)
    fill, _ = hole_fill(obj.parts, points, float(obj.mesh.area), 4096, seed=5)
    assert len(fill) == 0


@pytest.mark.parametrize("n, seed", [(0, 0), (-5, 0), (2.5, 0), (True, 0), (64, -1)])
def test_surface_samples_refuse_a_count_or_seed_that_is_not_one(n, seed):
    with pytest.raises(InputError, match="n must|seed must"):
        random_object(3, "test").surface_samples(n, seed=seed)
