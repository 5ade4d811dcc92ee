"""The depth-camera sensor: occlusion, segmentation, noise, estimated normals."""

from __future__ import annotations

import math

import numpy as np
import pytest

import affordplan as ap
from affordplan.errors import InputError, PerceptionError
from affordplan.sim.sensor import DEFAULT_CAMERAS, DepthCamera, estimate_normals

WALL = ap.Box(center=(0.57, 0.0), size=(0.01, 0.3, 0.3))  # between the cube's +x face and the camera facing it


def _cloud(obstacles=(), seed=0, n=2048):
    cube = ap.load_object("cube")
    sim = ap.Simulator(cube, obstacles=obstacles, seed=seed)
    sim.reset(0, xy=(0.5, 0.0), yaw=0.0)
    T = sim.object_pose()
    points, normals = sim.point_cloud(n)
    return cube, T, points, normals


def _on_plus_x_face(cube, T, points):
    """Points on the interior of the cube's world +x face (not its edges, which the other faces share)."""
    rel = points - T[:3, 3]  # the cube stands axis-aligned (yaw 0): world axes are its face normals
    half = 0.5 * cube.mesh.extents[0]
    inner = half - 0.012
    return (np.abs(rel[:, 0] - half) < 0.004) & (np.abs(rel[:, 1]) < inner) & (np.abs(rel[:, 2]) < inner)


def test_a_face_hidden_behind_an_obstacle_gets_no_points_while_in_the_open_it_does():
    cube, T, open_points, _ = _cloud()
    _, _, hidden_points, _ = _cloud(obstacles=(WALL,))
    assert _on_plus_x_face(cube, T, open_points).sum() > 100
    assert _on_plus_x_face(cube, T, hidden_points).sum() == 0
    # the rest of the cube is still seen by the other cameras
    assert len(hidden_points) == 2048 and (hidden_points[:, 2] > 0.09).sum() > 100


def test_the_default_cloud_is_not_the_exact_mesh_surface():
    cube, T, points, normals = _cloud()
    p_obj = (points - T[:3, 3]) @ T[:3, :3]
    half = 0.5 * cube.mesh.extents[0]
    off_surface = np.abs(np.max(np.abs(p_obj), axis=1) - half)  # distance to the cube's surface along its face
    assert np.median(off_surface) > 2e-4  # range noise: about a millimetre at these distances
    assert np.max(off_surface) < 0.02  # but segmented: every point belongs to the cube
    n_obj = normals @ T[:3, :3]
    exact = np.abs(n_obj).max(axis=1)
    assert np.median(exact) > 0.95  # estimated normals agree with the faces' ...
    assert np.mean(exact > 1 - 1e-9) < 0.05  # ... but are estimates, not the mesh's exact normals
    # the privileged sensor is the exact surface
    sim = ap.Simulator(cube, seed=0, sensor="surface")
    sim.reset(0, xy=(0.5, 0.0), yaw=0.0)
    exact_points, _ = sim.point_cloud(512)
    q = (exact_points - sim.object_pose()[:3, 3]) @ sim.object_pose()[:3, :3]
    assert np.max(np.abs(np.max(np.abs(q), axis=1) - half)) < 2e-3


def test_estimated_normals_point_outwards_towards_the_cameras():
    cube, T, points, normals = _cloud()
    outward = points - T[:3, 3]
    assert np.mean(np.einsum("ij,ij->i", normals, outward) > 0) > 0.97


def test_the_cloud_is_seeded():
    a = _cloud(seed=3, n=256)[2]
    b = _cloud(seed=3, n=256)[2]
    c = _cloud(seed=4, n=256)[2]
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_an_object_no_camera_sees_raises_perception_error():
    walls = tuple(ap.Box(center=(0.5 + 0.08 * math.cos(a), 0.08 * math.sin(a)), size=(0.02, 0.12, 0.4), yaw=a)
                  for a in np.linspace(0, 2 * np.pi, 12, endpoint=False))
    roof_cube = ap.load_object("cube", size=0.02)
    sim = ap.Simulator(roof_cube, obstacles=walls, seed=0)
    sim.reset(0, xy=(0.5, 0.0), yaw=0.0)
    with pytest.raises(PerceptionError):
        sim.point_cloud(64)


@pytest.mark.parametrize("n", [0, -1, True, 1.5, "8", 10**12])
def test_point_cloud_refuses_bad_counts(n):
    sim = ap.Simulator(ap.load_object("cube"))
    with pytest.raises(InputError):
        sim.point_cloud(n)


def test_unknown_sensor_is_refused():
    with pytest.raises(InputError, match="sensor"):
        ap.Simulator(ap.load_object("cube"), sensor="lidar")


def test_estimate_normals_on_a_noisy_plane():
    rng = np.random.default_rng(0)
    points = np.c_[rng.uniform(-0.05, 0.05, (400, 2)), rng.normal(0, 0.0005, 400)]
    normals = estimate_normals(points, np.tile([0.0, 0.0, 1.0], (400, 1)))
    assert np.median(normals[:, 2]) > 0.98 and np.all(normals[:, 2] > 0)


def test_camera_rays_cover_its_field_of_view():
    cam = DepthCamera((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), fovy=math.radians(40), width=40, height=30)
    dirs = cam.ray_directions()
    assert dirs.shape == (1200, 3) and np.allclose(np.linalg.norm(dirs, axis=1), 1)
    angles = np.degrees(np.arccos(-dirs[:, 2]))
    assert angles.min() < 2  # the middle pixels look along the axis
    vertical = np.degrees(np.arctan2(np.abs(dirs[:, 0]), -dirs[:, 2]))  # image up is world +x here
    assert 19 < vertical.max() < 20  # the top row is half a pixel inside the 20 deg half field of view
    assert len(DEFAULT_CAMERAS) >= 3


def _off_cube_surface(sim, points):
    """Each point's distance to the cube's surface along its face, metres (the cube at ``sim``'s pose)."""
    T = sim.object_pose()
    q = (points - T[:3, 3]) @ T[:3, :3]
    return np.abs(np.max(np.abs(q), axis=1) - 0.5 * sim.obj.mesh.extents[0])


def test_a_simulator_shows_another_sensors_clouds_inside_seeing_and_its_own_after():
    cube = ap.load_object("cube")
    sim = ap.Simulator(cube, seed=0, sensor="surface")
    sim.reset(0, xy=(0.5, 0.0), yaw=0.0)
    with sim.seeing("cameras") as seen:
        assert seen is sim and sim.sensor == "cameras"
        cameras, _ = sim.point_cloud(1024)
    assert sim.sensor == "surface"
    surface, _ = sim.point_cloud(1024)
    assert np.median(_off_cube_surface(sim, cameras)) > 2e-4  # range noise: the cameras' cloud
    assert np.max(_off_cube_surface(sim, surface)) < 2e-3  # the exact surface again
    camera_sim = ap.Simulator(cube, seed=0)
    camera_sim.reset(0, xy=(0.5, 0.0), yaw=0.0)
    with camera_sim.seeing("surface"):
        assert np.max(_off_cube_surface(camera_sim, camera_sim.point_cloud(512)[0])) < 2e-3
    assert camera_sim.sensor == "cameras"
    assert np.median(_off_cube_surface(camera_sim, camera_sim.point_cloud(512)[0])) > 2e-4
    with pytest.raises(InputError, match="unknown sensor"):
        with sim.seeing("lidar"):
            pass
    assert sim.sensor == "surface"
