"""Every kind of bad or unusual mesh either loads correctly or raises MeshError naming the fault.

"Loads correctly" means: normalised (largest half-extent = size, frame at the centre of mass),
positive mass and inertia, resting states whose probabilities sum to 1, and a simulator that builds
and settles the object in its first resting state. Bad files are written into ``tmp_path``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh

import affordplan as ap
from affordplan.errors import MeshError
from affordplan.objects import decompose, repair


def assert_loads_correctly(obj: ap.ObjectModel, size: float = 0.05) -> None:
    assert max(obj.mesh.extents) / 2 == pytest.approx(size, rel=1e-6)
    assert np.all(np.isfinite(obj.mesh.vertices))
    assert obj.mass > 0 and np.all(np.linalg.eigvalsh(obj.inertia) > 0)
    assert len(obj.parts) >= 1 and all(p.is_convex and p.volume > 0 for p in obj.parts)
    states = obj.resting_states
    assert len(states) >= 1 and sum(s.probability for s in states) == pytest.approx(1.0)
    sim = ap.Simulator(obj)
    T = sim.reset(resting_state=0)
    assert np.all(np.isfinite(T))
    assert obj.classify(T) == 0
    assert T[2, 3] == pytest.approx(states[0].height, abs=0.005)


def load_quietly(source, **kwargs) -> tuple[ap.ObjectModel, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        obj = ap.load_object(source, **kwargs)
    return obj, [str(w.message) for w in caught]


def obj_text(vertices, faces) -> str:
    return "".join(f"v {x} {y} {z}\n" for x, y, z in vertices) + "".join(
        f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)


# ---------------------------------------------------------------- files that are not meshes
@pytest.mark.parametrize("suffix", [".obj", ".stl", ".ply", ".glb"])
def test_empty_file(tmp_path, suffix):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    with pytest.raises(MeshError, match="empty"):
        ap.load_object(path)


@pytest.mark.parametrize("suffix", [".obj", ".stl", ".ply", ".glb", ".off"])
def test_random_bytes(tmp_path, suffix):
    path = tmp_path / f"noise{suffix}"
    path.write_bytes(np.random.default_rng(7).bytes(8192))
    with pytest.raises(MeshError, match=r"cannot read mesh|empty or holds no triangles") as info:
        ap.load_object(path)
    assert "Traceback" not in str(info.value) and len(str(info.value).splitlines()) == 1


def test_missing_file(tmp_path):
    with pytest.raises(MeshError, match="no such mesh file"):
        ap.load_object(tmp_path / "nope.stl")


def test_folder_instead_of_a_file(tmp_path):
    folder = tmp_path / "meshes.obj"
    folder.mkdir()
    with pytest.raises(MeshError, match="is a folder"):
        ap.load_object(folder)


def test_unknown_catalogue_name():
    with pytest.raises(MeshError, match=r"unknown object 'teapot': not a catalogue name \(cube, mug"):
        ap.load_object("teapot")


def test_faces_pointing_at_missing_vertices(tmp_path):
    path = tmp_path / "bad_index.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 9\nf 1 2 3\n")
    with pytest.raises(MeshError):
        ap.load_object(path)


# ---------------------------------------------------------------- non-finite vertices
@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
def test_non_finite_vertex_in_an_obj_file(tmp_path, bad):
    """trimesh's own processing would silently drop the vertex and load a box with a corner missing."""
    box = trimesh.creation.box()
    text = obj_text(box.vertices, box.faces).replace("v -0.5 -0.5 -0.5", f"v {bad} -0.5 -0.5", 1)
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(MeshError, match="1 vertices with NaN or infinite coordinates"):
        ap.load_object(path)


def test_non_finite_vertices_in_an_stl_file(tmp_path):
    box = trimesh.creation.box()
    vertices = box.vertices.copy()
    vertices[0, 2] = np.inf
    path = tmp_path / "bad.stl"
    with np.errstate(invalid="ignore"):  # the exporter's face normals of the bad faces
        trimesh.Trimesh(vertices, box.faces, process=False).export(path)
    with pytest.raises(MeshError, match="NaN or infinite"):
        ap.load_object(path)


def test_non_finite_vertices_in_a_trimesh():
    box = trimesh.creation.box()
    vertices = box.vertices.copy()
    vertices[3, 1] = np.nan
    with pytest.raises(MeshError, match="NaN"):
        ap.load_object(trimesh.Trimesh(vertices, box.faces, process=False))


# ---------------------------------------------------------------- flat and zero volume
def test_flat_sheet(tmp_path):
    path = tmp_path / "sheet.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    with pytest.raises(MeshError, match="zero volume: it is flat"):
        ap.load_object(path)


def test_closed_surface_with_zero_volume(tmp_path):
    """Two triangles back to back: watertight, no volume."""
    path = tmp_path / "pillow.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.3 0.3 0\nf 1 2 3\nf 1 3 2\nf 1 2 4\n")
    with pytest.raises(MeshError, match="zero volume") as info:
        ap.load_object(path)
    assert len(str(info.value).splitlines()) == 1  # qhull's pages of diagnostics are cut to one line


@pytest.mark.parametrize("text, why", [
    ("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n", "every face is degenerate"),
    ("v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n", "all its vertices are at one point"),
])
def test_degenerate_faces(tmp_path, text, why):
    path = tmp_path / "degenerate.obj"
    path.write_text(text)
    with pytest.raises(MeshError, match=f"zero volume: {why}"):
        ap.load_object(path)


def test_paper_thin_plate_is_flat():
    """A closed plate 0.1 % as thick as it is long: MuJoCo would reject its inertia or sink it."""
    with pytest.raises(MeshError, match=r"is flat: its thinnest width is 0.1% of its length"):
        ap.load_object(trimesh.creation.cylinder(radius=0.5, height=1e-3, sections=64))


def test_thin_but_simulable_plate_loads():
    obj, _ = load_quietly(trimesh.creation.box((1.0, 1.0, 0.05)))
    assert_loads_correctly(obj)


# ---------------------------------------------------------------- size and scale
@pytest.mark.parametrize("scale", [1e-3, 1e-1, 1e1, 1e3])
def test_scales_from_a_millimetre_to_a_kilometre_load_the_same_object(tmp_path, scale):
    shape = trimesh.creation.cone(radius=0.4, height=1.0, sections=24)
    shape.apply_translation([3.0, -2.0, 1.0])  # off the origin, like a mesh from a CAD assembly
    reference = ap.load_object(shape)
    scaled = shape.copy()
    scaled.apply_scale(scale)
    path = tmp_path / "cone.stl"
    scaled.export(path)
    obj = ap.load_object(path)
    assert_loads_correctly(obj)
    assert obj.mesh.extents == pytest.approx(reference.mesh.extents, rel=1e-6)
    assert obj.mass == pytest.approx(reference.mass, rel=1e-6)
    assert [s.height for s in obj.resting_states] == pytest.approx([s.height for s in reference.resting_states],
                                                                    rel=1e-5)


@pytest.mark.slow
def test_a_million_faces_load_decimated(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=8)  # 1,310,720 faces
    sphere.apply_scale([1.0, 0.7, 0.5])
    path = tmp_path / "ellipsoid.ply"
    sphere.export(path)
    obj, messages = load_quietly(path)
    assert any("1310720 faces; decimated to" in m for m in messages)
    assert len(obj.mesh.faces) <= repair.DECIMATED_FACES
    assert len(obj.hull.faces) <= repair.MAX_HULL_FACES + 10
    assert obj.mesh.extents == pytest.approx([0.1, 0.07, 0.05], rel=1e-3)
    ellipsoid_mass = 400.0 * 4.0 / 3.0 * np.pi * 0.05 * 0.035 * 0.025
    assert obj.mass == pytest.approx(ellipsoid_mass, rel=0.01)  # decimation keeps the shape
    assert_loads_correctly(obj)


# ---------------------------------------------------------------- soups and self-intersections
def test_random_triangle_soup_uses_its_hull_without_coacd(tmp_path, monkeypatch):
    """200 random, disconnected, mutually intersecting triangles: before, CoACD ran for minutes on them."""
    tris = np.random.default_rng(0).uniform(-1.0, 1.0, size=(200, 3, 3))
    path = tmp_path / "soup.obj"
    trimesh.Trimesh(tris.reshape(-1, 3), np.arange(600).reshape(-1, 3), process=False).export(path)

    def no_coacd(*args, **kwargs):
        raise AssertionError("CoACD was started on a triangle soup")

    monkeypatch.setattr(decompose, "_coacd", no_coacd)
    obj, messages = load_quietly(path)
    assert any("triangle soup" in m for m in messages)
    assert len(obj.parts) == 1
    assert obj.mass == pytest.approx(400.0 * obj.parts[0].volume, rel=1e-6)  # the hull is the solid
    assert_loads_correctly(obj)


def test_non_manifold_edge_soup(tmp_path):
    """Four triangles, three of them on one edge."""
    path = tmp_path / "fan.obj"
    path.write_text(obj_text([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0.5, 0.5, 1]],
                             [[0, 1, 2], [0, 1, 3], [0, 1, 4], [1, 2, 5]]))
    obj, messages = load_quietly(path)
    assert any("triangle soup" in m for m in messages)
    assert_loads_correctly(obj)


def test_overlapping_closed_bodies_are_merged(tmp_path):
    """Two closed boxes that overlap by a third: the mass is the union's, not the sum's."""
    a = trimesh.creation.box((2.0, 1.0, 1.0), transform=trimesh.transformations.translation_matrix([1.0, 0, 0]))
    b = trimesh.creation.box((2.0, 1.0, 1.0), transform=trimesh.transformations.translation_matrix([2.0, 0, 0]))
    path = tmp_path / "overlap.obj"
    trimesh.util.concatenate([a, b]).export(path)
    obj, messages = load_quietly(path)
    assert any("overlapping bodies" in m for m in messages)
    scale = 0.05 / 1.5  # longest side 3 -> largest half-extent 5 cm
    assert obj.mass == pytest.approx(400.0 * 3.0 * scale**3, rel=1e-6)  # union volume 3, not 4
    assert obj.mesh.is_watertight and len(obj.mesh.split()) == 1  # no hidden faces inside
    assert len(obj.resting_states) == 6
    assert_loads_correctly(obj)


def test_duplicated_shell_counts_once():
    box = trimesh.creation.box((2.0, 1.0, 1.0))
    twice = trimesh.Trimesh(np.vstack([box.vertices, box.vertices]), np.vstack([box.faces, box.faces + 8]),
                            process=False)
    obj, _ = load_quietly(twice)
    assert obj.mass == pytest.approx(ap.load_object(box).mass, rel=1e-6)
    assert_loads_correctly(obj)


def test_self_intersecting_bodies_at_an_angle(tmp_path):
    a = trimesh.creation.box()
    b = trimesh.creation.box()
    b.apply_transform(trimesh.transformations.rotation_matrix(0.5, [1, 1, 0]))
    b.apply_translation([0.5, 0.5, 0.3])
    union = trimesh.boolean.union([a, b], engine="manifold")
    path = tmp_path / "crossed.stl"
    trimesh.util.concatenate([a, b]).export(path)
    obj, _ = load_quietly(path)
    scale = 0.05 / (0.5 * max(union.extents))
    assert obj.mass == pytest.approx(400.0 * union.volume * scale**3, rel=1e-3)
    assert_loads_correctly(obj)


# ---------------------------------------------------------------- the decomposition cannot hang or crash
def _l_shape() -> trimesh.Trimesh:
    base = trimesh.creation.box((1.0, 0.4, 0.25), transform=trimesh.transformations.translation_matrix([0, 0, 0.125]))
    upright = trimesh.creation.box((0.25, 0.4, 1.0),
                                   transform=trimesh.transformations.translation_matrix([-0.375, 0, 0.5]))
    return trimesh.boolean.union([base, upright], engine="manifold")


def test_decomposition_past_its_time_limit_falls_back_to_the_hull(monkeypatch, tmp_path):
    monkeypatch.setenv("AFFORDPLAN_CACHE", str(tmp_path))
    monkeypatch.setattr(decompose, "COACD_TIMEOUT", 0.05)
    obj, messages = load_quietly(_l_shape())
    assert any("took longer than" in m for m in messages)
    assert len(obj.parts) == 1
    assert not list(decompose.cache_dir().glob("*.npz"))  # a fallback is not cached
    assert_loads_correctly(obj)


def test_a_crash_inside_the_decomposition_does_not_take_the_caller_down(monkeypatch, tmp_path):
    crasher = tmp_path / "crash.py"
    crasher.write_text("import os, signal\nos.kill(os.getpid(), signal.SIGSEGV)\n")
    monkeypatch.setenv("AFFORDPLAN_CACHE", str(tmp_path))
    monkeypatch.setattr(decompose, "_WORKER", crasher)
    obj, messages = load_quietly(_l_shape())
    assert any("CoACD) failed" in m for m in messages)
    assert len(obj.parts) == 1
    assert_loads_correctly(obj)
