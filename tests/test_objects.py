"""Catalogue, random family, user meshes and MeshError."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

import affordplan as ap
from affordplan.errors import InputError, MeshError
from affordplan.objects import decompose
from affordplan.objects.resting import compute_resting_states, yaw_period
from affordplan.objects.shapes import annular_wedges, frustum, union

DATA = Path(__file__).parent / "data"

SEED_OBJECTS = ["cube", "mug", "tape", "planter_1", "planter_2", "pill_bottle", "lunch_box", "bowl"]


def test_catalogue_has_the_eight_objects():
    assert sorted(ap.catalogue()) == sorted(SEED_OBJECTS)


@pytest.mark.parametrize("name", SEED_OBJECTS)
def test_catalogue_objects_are_normalised_solids(name):
    obj = ap.load_object(name)
    assert obj.mesh.is_watertight
    assert max(obj.mesh.extents) / 2 == pytest.approx(0.05)  # largest half-extent = size
    assert np.allclose(obj.mesh.center_mass, 0.0, atol=1e-6)  # frame at the centre of mass
    assert obj.mass > 0 and np.all(np.linalg.eigvalsh(obj.inertia) > 0)
    assert all(p.is_convex for p in obj.parts)
    # The parts cover the object: their union has the object's volume.
    assert union(list(obj.parts)).mesh.volume == pytest.approx(obj.mesh.volume, rel=1e-3)
    probs = [s.probability for s in obj.resting_states]
    assert sum(probs) == pytest.approx(1.0) and probs == sorted(probs, reverse=True)


@pytest.mark.parametrize("name, n", [("cube", 6), ("pill_bottle", 3), ("tape", 3), ("lunch_box", 6),
                                     ("planter_1", 3)])
def test_resting_state_counts(name, n):
    assert len(ap.load_object(name).resting_states) == n


def test_size_scales_the_object():
    small = ap.load_object("cube", size=0.02)
    assert small.mesh.extents == pytest.approx([0.04] * 3)
    assert small.mass == pytest.approx(ap.load_object("cube").mass * (0.4**3))


def test_mug_is_non_convex_with_several_parts(mug):
    assert len(mug.parts) > 1
    assert mug.mesh.volume < 0.8 * mug.hull.volume


def test_mug_handle_changes_how_it_rests(mug):
    """Without its handle the mug's side is a full rolling circle; the handle cuts it short and
    tilts it, so the mug never lies with its handle (the +x side) pointing down."""
    side = next(s for s in mug.resting_states if s.is_rolling_family)
    handle_down = np.array([-1.0, 0.0, 0.0])  # up-vector of a mug lying on its handle
    assert np.max(side.member_ups @ handle_down) < np.cos(np.radians(30))

    r_out, wall = 0.04, 0.006
    body = union([frustum(r_out, r_out, 0.0, 0.008)]
                 + annular_wedges(r_out - wall, r_out, 0.004, r_out - wall, r_out, 0.095))
    body_mesh = body.mesh.copy()
    body_mesh.apply_translation(-body_mesh.center_mass)
    bare = compute_resting_states(body_mesh.convex_hull)
    bare_side = next(s for s in bare if s.is_rolling_family)
    assert np.max(bare_side.member_ups @ handle_down) > np.cos(np.radians(15))


@pytest.mark.parametrize("order", ["reversed", "top_two_swapped"])
def test_resting_states_do_not_hang_on_the_order_stable_poses_come_in(monkeypatch, order):
    """An ellipsoid's facets come in mirror pairs of equal probability; which of a pair a state is posed on
    must not hang on the order trimesh lists them (its sort leaves ties in a CPU-dependent order)."""
    hull = ap.random_object(4008, "test").hull
    reference = compute_resting_states(hull)
    tied = trimesh.poses.compute_stable_poses(hull, center_mass=np.zeros(3))[1]
    assert np.sum(np.isclose(tied, tied.max(), rtol=0, atol=1e-12)) >= 2  # the top facets tie

    stable_poses = trimesh.poses.compute_stable_poses

    def permuted(*args, **kwargs):
        transforms, probs = stable_poses(*args, **kwargs)
        index = np.arange(len(probs))[::-1] if order == "reversed" else np.r_[1, 0, 2:len(probs)]
        return transforms[index], probs[index]

    monkeypatch.setattr(trimesh.poses, "compute_stable_poses", permuted)
    states = compute_resting_states(hull)
    assert len(states) == len(reference)
    for state, ref in zip(states, reference):
        assert state.probability == pytest.approx(ref.probability, abs=1e-12)
        np.testing.assert_allclose(state.rotation, ref.rotation, atol=1e-12)
        np.testing.assert_allclose(state.member_ups, ref.member_ups, atol=1e-12)
        assert state.height == pytest.approx(ref.height, abs=1e-12)


def test_mug_side_state_is_posed_leaning_the_way_the_demo_has_it(mug):
    """The mug's side state ties two mirror-image members (leaning on either side of the handle); the tie rule
    poses it on the one with up-vector y < 0, the pose the demo's start yaw and its README figures assume."""
    side = mug.resting_states[0]
    assert side.is_rolling_family
    assert side.up[1] < -0.8 and np.any(side.member_ups[:, 1] > 0.8)


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


def test_classify_recovers_every_state_at_any_yaw(cube, pill_bottle):
    for obj in (cube, pill_bottle):
        for state in obj.resting_states:
            for yaw in (0.0, 1.0, -2.5):
                assert obj.classify(state.pose((0.5, 0.0), yaw)) == state.index


def test_resting_pose_yaw_round_trips(lunch_box):
    for state in lunch_box.resting_states:
        T = state.pose((0.5, 0.1), 0.7)
        assert state.yaw_of(T[:3, :3]) == pytest.approx(0.7)


# ------------------------------------------------------------ user meshes
HOUSEHOLD = ["pybullet_mug.obj", "robosuite_can.stl", "metaworld_cup.stl"]


@pytest.fixture(scope="module", params=HOUSEHOLD)
def household(request):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        obj = ap.load_object(DATA / "household" / request.param)
    return request.param, obj, caught


@pytest.mark.slow
def test_household_meshes_load_normalised_with_resting_states(household):
    name, obj, caught = household
    assert obj.name == name.rsplit(".", 1)[0]
    assert max(obj.mesh.extents) / 2 == pytest.approx(0.05)
    assert obj.mass > 0
    assert len(obj.parts) >= 1 and all(p.is_convex for p in obj.parts)
    assert 1 <= len(obj.resting_states) <= 8
    # These meshes are open surfaces: the loader says it used the hull for mass properties.
    assert any("convex hull" in str(w.message) for w in caught)


@pytest.mark.slow  # its fixture runs CoACD on three test meshes (75 s on a fresh machine)
def test_household_mesh_settles_in_its_resting_state(household):
    _, obj, _ = household
    sim = ap.Simulator(obj)
    T = sim.reset(resting_state=0)
    assert obj.classify(T) == 0
    assert T[2, 3] == pytest.approx(obj.resting_states[0].height, abs=0.004)


@pytest.mark.slow
def test_non_convex_user_mesh_is_decomposed_and_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("AFFORDPLAN_CACHE", str(tmp_path))
    mesh = trimesh.load(DATA / "household" / "pybullet_mug.obj", force="mesh")
    first = ap.load_object(mesh)
    assert len(first.parts) > 1
    cached = list(decompose.cache_dir().glob("*.npz"))
    assert len(cached) == 1
    second = ap.load_object(mesh)
    assert [len(p.vertices) for p in second.parts] == [len(p.vertices) for p in first.parts]


def test_watertight_user_mesh_keeps_its_own_mass_properties(tmp_path):
    path = tmp_path / "box.stl"
    trimesh.creation.box((2.0, 1.0, 1.0)).export(path)  # any units: normalised
    obj = ap.load_object(path)
    assert obj.mesh.extents == pytest.approx([0.1, 0.05, 0.05])
    assert len(obj.parts) == 1 and len(obj.resting_states) == 6


# ------------------------------------------------------------ broken input
def test_missing_file_raises(tmp_path):
    with pytest.raises(MeshError, match="no such mesh file"):
        ap.load_object(tmp_path / "nope.obj")


def test_unknown_catalogue_name_raises():
    with pytest.raises(MeshError, match="unknown object 'teapot'"):
        ap.load_object("teapot")


def test_empty_file_raises(tmp_path):
    path = tmp_path / "empty.obj"
    path.write_bytes(b"")
    with pytest.raises(MeshError, match="empty"):
        ap.load_object(path)


def test_random_bytes_raise(tmp_path):
    path = tmp_path / "noise.stl"
    path.write_bytes(np.random.default_rng(0).bytes(4096))
    with pytest.raises(MeshError):
        ap.load_object(path)


def test_nan_vertices_raise():
    mesh = trimesh.creation.box()
    vertices = mesh.vertices.copy()
    vertices[3, 1] = np.nan
    with pytest.raises(MeshError, match="NaN"):
        ap.load_object(trimesh.Trimesh(vertices, mesh.faces, process=False))


def test_flat_sheet_raises(tmp_path):
    path = tmp_path / "sheet.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    with pytest.raises(MeshError, match="zero volume"):
        ap.load_object(path)


def test_bad_size_raises():
    with pytest.raises(InputError):
        ap.load_object("cube", size=float("nan"))
    with pytest.raises(InputError):
        ap.load_object("cube", size=-1.0)


def test_yaw_period_is_the_smallest_turn_that_maps_the_state_onto_itself(cube, lunch_box, mug):
    assert [round(math.degrees(cube.yaw_period(i)), 6) for i in range(6)] == [90.0] * 6
    assert [round(math.degrees(lunch_box.yaw_period(i)), 6) for i in range(6)] == [180.0] * 6
    assert [math.degrees(mug.yaw_period(i)) for i in range(3)] == [360.0] * 3  # the handle
    planter = ap.load_object("planter_1")  # 32 facets round: upright either way up, 11.25 deg; lying, none
    assert sorted(round(math.degrees(planter.yaw_period(i)), 6) for i in range(3)) == [11.25, 11.25, 360.0]
    # the turn by the period maps the posed mesh onto itself, half of it does not
    for obj, state in ((lunch_box, 0), (planter, 1)):
        period, up = obj.yaw_period(state), obj.resting_states[state].up
        v = obj.mesh.vertices
        for angle, same in ((period, True), (period / 2, False)):
            turned = Rotation.from_rotvec(up * angle).apply(v)
            gap = np.max(np.min(np.linalg.norm(turned[:, None] - v[None], axis=2), axis=1))
            assert (gap < 1e-4) == same


def test_a_scanned_mesh_has_no_symmetry():
    rng = np.random.default_rng(0)
    box = trimesh.creation.box((0.05, 0.05, 0.05))
    box.vertices += rng.normal(0.0, 1e-3, box.vertices.shape)  # scanner noise: vertices no longer coincide
    assert yaw_period(box.vertices, np.array([0.0, 0.0, 1.0])) == pytest.approx(2 * math.pi)
    assert yaw_period(trimesh.creation.box((0.05, 0.05, 0.05)).vertices, np.array([0.0, 0.0, 1.0])) == \
        pytest.approx(math.pi / 2)


def test_tied_resting_states_are_ordered_by_up_vector_not_by_rounding_noise(cube):
    """A cube's six faces are equally likely: their order must not hang on trimesh's last bits."""
    states = cube.resting_states
    assert len({s.probability for s in states}) == 1  # one probability for the tie
    ups = np.array([s.up for s in states])
    expected = [(0, 0, 1), (0, 1, 0), (1, 0, 0), (-1, 0, 0), (0, -1, 0), (0, 0, -1)]
    assert np.allclose(ups, expected, atol=1e-6)
    assert states[1].index in [t for t in range(6) if abs(states[t].up @ states[0].up) < 0.5]  # a neighbour
