"""Which points of a mesh's surface a pusher can touch: those the object's convex parts expose.

The simulator collides an object as the union of its convex parts (:attr:`ObjectModel.parts`), and the cameras see
that union. A raw household mesh often has more surface than that: faces inside the body (a label's inner shell,
a can's inner wall, overlapping shells) and faces wound the wrong way (their normals point into the body). A
privileged sample of such a mesh gives a policy contacts that no fingertip can reach, and normals along which the
fingertip's centre lands inside the object: the approach then shoves the object before it arrives. Of 8,192
uniform samples of each ``housekeep:validation`` mesh, 1-63 % lay more than 2 mm inside its parts.

:func:`exposed_samples` keeps the samples the parts expose and turns each normal to point out of them. On a mesh
whose surface is its parts' boundary (the procedural family, the catalogue) it keeps every sample and every normal.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import trimesh

BURIED_DEPTH = 0.002  # metres inside the parts' union past which a surface sample is dropped (contact softness)
NORMAL_PROBE = 0.003  # metres out along each side of a normal at which the parts' depth decides its orientation
CHUNK = 2048  # points per block of the point-by-face distances (a part of a household mesh has up to ~2,000 faces)

__all__ = ["BURIED_DEPTH", "CHUNK", "NORMAL_PROBE", "depth_in_parts", "exposed_samples"]


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
