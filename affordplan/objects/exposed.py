"""Which points of a mesh's surface a pusher can touch: those the object's convex parts expose.

The simulator collides an object as the union of its convex parts (:attr:`ObjectModel.parts`), and the cameras see
that union. A raw household mesh often has more surface than that: faces inside the body (a label's inner shell,
a can's inner wall, overlapping shells) and faces wound the wrong way (their normals point into the body). A
privileged sample of such a mesh gives a policy contacts that no fingertip can reach, and normals along which the
fingertip's centre lands inside the object: the approach then shoves the object before it arrives. Of 8,192
uniform samples of each ``housekeep:validation`` mesh, 1-63 % lay more than 2 mm inside its parts.

:func:`exposed_samples` keeps the samples the parts expose and turns each normal to point out of them. Where the
parts bulge past the mesh or close a cavity it leaves open, :func:`hole_fill` samples the parts' own boundary
(:func:`exposed_boundary`) in the holes the kept samples leave. On a mesh whose surface is its parts' boundary (the
procedural family, the catalogue) every sample and every normal is kept and nothing is added.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import trimesh
from scipy.spatial import cKDTree

BURIED_DEPTH = 0.002  # metres inside the parts' union past which a surface sample is dropped (contact softness)
NORMAL_PROBE = 0.003  # metres out along each side of a normal at which the parts' depth decides its orientation
CHUNK = 2048  # points per block of the point-by-face distances (a part of a household mesh has up to ~2,000 faces)
HOLE_RADIUS = 0.004  # metres: the parts' boundary farther than this from every kept mesh sample is a hole to fill
HOLE_SPACINGS = 3.0  # ... or farther than this many mean sample spacings, where the samples are sparse
SHARED_FACE = 1e-5  # metres inside another part past which a point of one part's boundary is not exposed

__all__ = ["BURIED_DEPTH", "CHUNK", "HOLE_RADIUS", "HOLE_SPACINGS", "NORMAL_PROBE", "SHARED_FACE",
           "depth_in_parts", "exposed_boundary", "exposed_samples", "hole_fill"]


def depth_in_parts(parts: Sequence[trimesh.Trimesh], points: np.ndarray) -> np.ndarray:
    """How deep each of ``points`` (N, 3; the parts' frame, metres) lies inside the union of the convex ``parts``:
    the largest over the parts of the point's smallest distance inside a face plane. Positive inside, zero on the
    boundary, negative outside (then at most the distance to the nearest part in size)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    depth = np.full(len(points), -np.inf)
    for part in parts:
        hull = part.convex_hull  # the parts are convex; their hull gives outward-wound faces
        normals = hull.face_normals
        offsets = np.einsum("ij,ij->i", hull.triangles[:, 0], normals)
        for lo in range(0, len(points), CHUNK):  # blocks: the whole points-by-faces array can take hundreds of MB
            block = slice(lo, lo + CHUNK)
            depth[block] = np.maximum(depth[block], np.min(offsets[None, :] - points[block] @ normals.T, axis=1))
    return depth


def exposed_samples(parts: Sequence[trimesh.Trimesh], points: np.ndarray,
                    normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(keep, normals)`` for surface samples ``points`` with unit ``normals`` (N, 3 each; the parts' frame): a mask
    of the samples no deeper than :data:`BURIED_DEPTH` inside the parts, and the normals, each reversed where it
    points into the parts: ``NORMAL_PROBE`` out along it lies inside them, deeper by more than ``NORMAL_PROBE``
    than as far in (on a flat face it would be ``NORMAL_PROBE`` in against as far out, twice that). Where the
    parts only approximate the mesh (a thin wall's pieces bulging past it), a normal is left as it is; so are the
    dropped samples' normals (only the kept ones are probed). Without parts every sample is kept as it is."""
    points = np.asarray(points, dtype=float)
    normals = np.array(normals, dtype=float)
    if not parts or len(points) == 0:
        return np.ones(len(points), dtype=bool), normals
    keep = depth_in_parts(parts, points) <= BURIED_DEPTH
    kept = np.flatnonzero(keep)
    outward = depth_in_parts(parts, points[kept] + NORMAL_PROBE * normals[kept])
    inward = depth_in_parts(parts, points[kept] - NORMAL_PROBE * normals[kept])
    normals[kept[(outward > 0.0) & (outward - inward > NORMAL_PROBE)]] *= -1.0
    return keep, normals


def exposed_boundary(parts: Sequence[trimesh.Trimesh], n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """About ``n`` uniform samples of the boundary of the union of the convex ``parts`` (the parts' frame, metres)
    and their outward unit normals: ``n`` samples spread over the parts by area, those inside another part (deeper
    than ``SHARED_FACE``) left out. This is the surface the simulator collides and the cameras see."""
    points, normals, part = _parts_draw(parts, n, seed)
    keep = _outside_the_others(parts, points, part)
    return points[keep], normals[keep]


def hole_fill(parts: Sequence[trimesh.Trimesh], points: np.ndarray, area: float, n: int,
              seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Samples of the parts' exposed boundary (:func:`exposed_boundary`) where ``points`` (the kept samples of a
    mesh of ``area`` square metres, drawn ``n`` to it; the parts' frame) leave a hole, and their outward normals.

    Where the parts bulge past a raw mesh, or close a cavity the mesh leaves open (a cup whose parts fill it), the
    mesh's samples there lie buried and are dropped; the simulator still collides that surface and the cameras see
    it. The boundary is drawn at the mesh samples' density, and a point of it counts as a hole farther than
    ``HOLE_RADIUS`` (or ``HOLE_SPACINGS`` mean sample spacings, where these are sparse) from every kept sample:
    wider than the gaps a uniform draw leaves. On a mesh whose surface is its parts' boundary nothing is added."""
    parts = list(parts)
    if not parts or n < 1 or area <= 0.0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    density = n / area  # samples per square metre
    boundary, normals, part = _parts_draw(parts, int(np.ceil(density * sum(p.area for p in parts))), seed)
    if len(points):
        radius = max(HOLE_RADIUS, HOLE_SPACINGS / np.sqrt(density))
        far, _ = cKDTree(np.asarray(points, dtype=float)).query(boundary, distance_upper_bound=radius)
        hole = ~np.isfinite(far)  # the cheap test first: most of the boundary lies by a mesh sample
        boundary, normals, part = boundary[hole], normals[hole], part[hole]
    keep = _outside_the_others(parts, boundary, part)
    return boundary[keep], normals[keep]


def _parts_draw(parts: Sequence[trimesh.Trimesh], n: int,
                seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` uniform samples of the parts' surfaces together (spread by area), their outward normals and the index
    of the part each lies on."""
    parts = list(parts)
    if not parts or n < 1:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=int)
    areas = np.array([part.area for part in parts])
    counts = np.random.default_rng(seed).multinomial(n, areas / areas.sum())
    points, normals, index = [], [], []
    for i, (part, count) in enumerate(zip(parts, counts)):
        if count == 0:
            continue
        hull = part.convex_hull  # outward-wound faces, as depth_in_parts takes them
        sample, face_idx = trimesh.sample.sample_surface(hull, int(count), seed=seed + i)
        points.append(sample)
        normals.append(hull.face_normals[face_idx])
        index.append(np.full(len(sample), i))
    return np.vstack(points), np.vstack(normals), np.concatenate(index)


def _outside_the_others(parts: Sequence[trimesh.Trimesh], points: np.ndarray, part: np.ndarray) -> np.ndarray:
    """Whether each of ``points``, on part ``part[k]``'s boundary, lies outside every other part (within
    ``SHARED_FACE``)."""
    parts = list(parts)
    keep = np.ones(len(points), dtype=bool)
    for i in np.unique(part):
        on = np.flatnonzero(part == i)
        others = parts[:i] + parts[i + 1:]
        if others:
            keep[on] = depth_in_parts(others, points[on]) <= SHARED_FACE
    return keep
