"""Depth cameras: the object's point cloud as fixed depth sensors around the workspace would see it.

The seed (like HACMan) observed the object with calibrated depth cameras and segmented it out. This module does the
same in MuJoCo: each camera casts one ray per pixel (``mujoco.mj_multiRay``) against everything in the scene, so the
table, obstacles and the arm occlude what they hide; hits on the object's geoms are its segmented points. A consumer
depth camera's faults are modelled (:class:`DepthNoise`): range noise that grows with the square of the distance
(1 mm at 0.5 m), pixels that return nothing (dropout) and holes where the surface is seen at a grazing angle. Normals
are *estimated* from the merged cloud (PCA over each point's nearest neighbours, turned towards the camera that saw
it), as a real pipeline must.

Only pixels whose ray can meet the object's bounding sphere are cast (the others cannot see it): the same points as
casting the whole image, at a tenth of the cost.

All positions are world frame, metres; angles radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.spatial import cKDTree

from affordplan.errors import InputError
from affordplan.robot import TABLE_CONTACT_HEIGHT

SENSORS = ("cameras", "surface")


def check_sensor(sensor: str) -> str:
    """``sensor`` if it names one of :data:`SENSORS`; raises :class:`InputError` otherwise."""
    if sensor not in SENSORS:
        raise InputError(f"unknown sensor {sensor!r}; expected one of {SENSORS}")
    return sensor
NORMAL_NEIGHBOURS = 12  # points in each normal's PCA neighbourhood


@dataclass(frozen=True)
class DepthCamera:
    """A pinhole depth camera at ``position`` looking at ``target`` (world, metres), image rows along world up."""

    position: tuple[float, float, float]
    target: tuple[float, float, float]
    fovy: float = math.radians(45.0)  # vertical field of view, radians
    width: int = 200
    height: int = 150

    def ray_directions(self) -> np.ndarray:
        """``(height * width, 3)`` unit ray directions of the pixels, world frame."""
        forward = np.subtract(self.target, self.position, dtype=float)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, [0.0, 0.0, 1.0])
        if np.linalg.norm(right) < 1e-9:  # looking straight down (or up): image up is world +x
            right = np.cross(forward, [1.0, 0.0, 0.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        half_h = math.tan(self.fovy / 2)
        half_w = half_h * self.width / self.height
        u = (np.arange(self.width) + 0.5) / self.width * 2 - 1
        v = (np.arange(self.height) + 0.5) / self.height * 2 - 1
        uu, vv = np.meshgrid(u * half_w, -v * half_h)
        dirs = forward + uu.reshape(-1, 1) * right + vv.reshape(-1, 1) * up
        return dirs / np.linalg.norm(dirs, axis=1, keepdims=True)


@dataclass(frozen=True)
class DepthNoise:
    """Faults of a consumer depth camera (structured light or stereo, e.g. at 0.3-1 m).

    Attributes:
        sigma_at_half_metre: standard deviation of the range error at 0.5 m, metres; it grows with range squared.
        dropout: probability that a pixel returns no depth at all.
        grazing_angle: pixels that see the surface more obliquely than this (angle between the ray and the surface
            normal, radians) return nothing: the holes at object silhouettes.
    """

    sigma_at_half_metre: float = 0.001
    dropout: float = 0.03
    grazing_angle: float = math.radians(78.0)


NO_NOISE = DepthNoise(0.0, 0.0, math.pi / 2)

# Three cameras around the workspace's middle (0.525, 0), 0.6 m out at 120 degree spacing, 0.45 m up, looking at a
# point 3 cm above the table: every side of an object in the open is seen by at least one of them.
_CENTRE = (0.525, 0.0, 0.03)
DEFAULT_CAMERAS = tuple(
    DepthCamera((0.525 + 0.6 * math.cos(a), 0.6 * math.sin(a), 0.45), _CENTRE)
    for a in (0.0, 2 * math.pi / 3, -2 * math.pi / 3)
)


class CameraSensor:
    """The object's segmented, noisy cloud as the cameras see it in one MuJoCo scene.

    Args:
        model: the scene (any MJCF with the object as one body).
        object_body: the object's body id; its geoms are what is segmented out.
        cameras, noise: the rig and its faults.
    """

    def __init__(self, model: mujoco.MjModel, object_body: int, cameras: tuple[DepthCamera, ...] = DEFAULT_CAMERAS,
                 noise: DepthNoise = DepthNoise()):
        if not cameras:
            raise InputError("a camera sensor needs at least one camera")
        self.model = model
        self.cameras = tuple(cameras)
        self.noise = noise
        self._object_body = int(object_body)
        self._object_geoms = np.flatnonzero(model.geom_bodyid == self._object_body)
        self._dirs = [c.ray_directions() for c in self.cameras]
        self._origins = [np.asarray(c.position, dtype=float) for c in self.cameras]
        self._pixel_angle = [c.fovy / c.height for c in self.cameras]

    def scan(self, data: mujoco.MjData, rng: np.random.Generator, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Every object point the cameras return, and the index of the camera that saw each.

        ``radius``: of a sphere about the object's body origin that holds the whole object, metres.
        """
        centre = data.xpos[self._object_body]
        points, seen_by = [], []
        for k, (origin, dirs) in enumerate(zip(self._origins, self._dirs)):
            to_centre = centre - origin
            dist = float(np.linalg.norm(to_centre))
            if dist <= radius:
                continue
            cone = math.asin(min(1.0, radius / dist)) + 2 * self._pixel_angle[k]
            rays = dirs[dirs @ (to_centre / dist) >= math.cos(cone)]
            if len(rays) == 0:
                continue
            geom = np.empty(len(rays), dtype=np.int32)
            depth = np.empty(len(rays))
            normal = np.empty((len(rays), 3))
            mujoco.mj_multiRay(self.model, data, origin, np.ascontiguousarray(rays).reshape(-1), None, 1, -1, geom,
                               depth, normal.reshape(-1), len(rays), dist + radius)
            hit = np.isin(geom, self._object_geoms) & (depth > 0)
            cos_incidence = np.abs(np.einsum("ij,ij->i", normal, rays))
            keep = hit & (cos_incidence >= math.cos(self.noise.grazing_angle))
            keep &= rng.random(len(rays)) >= self.noise.dropout
            r = depth[keep]
            r = r + rng.normal(0.0, 1.0, len(r)) * self.noise.sigma_at_half_metre * (r / 0.5) ** 2
            p = origin + rays[keep] * r[:, None]
            above = p[:, 2] > TABLE_CONTACT_HEIGHT
            points.append(p[above])
            seen_by.append(np.full(int(above.sum()), k))
        if not points:
            return np.zeros((0, 3)), np.zeros(0, dtype=int)
        return np.concatenate(points), np.concatenate(seen_by)

    def cloud(self, data: mujoco.MjData, rng: np.random.Generator, radius: float, n: int
              ) -> tuple[np.ndarray, np.ndarray]:
        """``n`` points drawn from :meth:`scan` (with replacement only when fewer are seen) and their estimated
        outward normals, world frame; ``(0, 3)`` arrays when the object is hidden from every camera."""
        points, seen_by = self.scan(data, rng, radius)
        if len(points) == 0:
            return points, points.copy()
        idx = rng.choice(len(points), size=n, replace=len(points) < n)
        normals = estimate_normals(points, np.asarray(self._origins)[seen_by[idx]], at=idx)
        return points[idx], normals


def surface_cloud(samples_obj: np.ndarray, normals_obj: np.ndarray, T_world_object: np.ndarray,
                  rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The privileged sensor (``sensor="surface"``): ``n`` of an object's even surface samples (object frame) and
    their exact normals, posed at ``T_world_object``; points touching the table are left out (unless all do)."""
    points = np.asarray(samples_obj) @ T_world_object[:3, :3].T + T_world_object[:3, 3]
    normals = np.asarray(normals_obj) @ T_world_object[:3, :3].T
    visible = np.flatnonzero(points[:, 2] > TABLE_CONTACT_HEIGHT)
    if len(visible) == 0:
        visible = np.arange(len(points))
    idx = rng.choice(visible, size=n, replace=len(visible) < n)
    return points[idx], normals[idx]


def estimate_normals(points: np.ndarray, viewpoints: np.ndarray, k: int = NORMAL_NEIGHBOURS,
                     at: np.ndarray | None = None) -> np.ndarray:
    """Unit normals of a cloud by PCA of each point's ``k`` nearest neighbours, each turned towards its viewpoint
    (the camera that saw it: a surface seen from outside faces its camera).

    ``at``: indices of the points whose normals are wanted (default: all); ``viewpoints`` has one row per
    wanted point.
    """
    points = np.asarray(points, dtype=float)
    query = points if at is None else points[np.asarray(at)]
    k = int(min(k, len(points)))
    if k < 3:
        n = np.asarray(viewpoints, dtype=float) - query
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    _, idx = cKDTree(points).query(query, k=k)
    nb = points[idx] - points[idx].mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", nb, nb)
    _, vecs = np.linalg.eigh(cov)
    normals = np.ascontiguousarray(vecs[:, :, 0])
    flip = np.einsum("ij,ij->i", normals, viewpoints - query) < 0
    normals[flip] *= -1
    return normals
