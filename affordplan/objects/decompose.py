"""Convex decomposition of user meshes, cached on disk.

MuJoCo collides every mesh geom as its convex hull, so a non-convex object (a mug, a bowl) needs
convex parts. Nearly convex meshes get their hull; the rest go through CoACD. Results are cached
under ``$AFFORDPLAN_CACHE`` (default ``~/.cache/affordplan``), keyed by a hash of the mesh's
vertices and faces and the decomposition settings, so a mesh is decomposed once per machine.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import numpy as np
import trimesh

CONVEX_VOLUME_RATIO = 0.95  # volume / hull volume above which the hull is the collision shape
COACD_THRESHOLD = 0.08  # CoACD concavity threshold (fraction of the mesh's size)
MAX_PARTS = 16
# CoACD's search settings, lowered from its defaults: 4-25 s instead of 30-120 s per household
# mesh on 2 cores, at a concavity error still well under the fingertip's radius.
COACD_SEARCH = dict(preprocess_resolution=30, resolution=1000, mcts_nodes=10, mcts_iterations=50,
                    mcts_max_depth=2)
_CACHE_VERSION = "2"


def cache_dir() -> Path:
    """Folder holding cached decompositions (created on demand)."""
    root = os.environ.get("AFFORDPLAN_CACHE") or os.path.join(Path.home(), ".cache", "affordplan")
    return Path(root) / "convex"


def mesh_key(mesh: trimesh.Trimesh) -> str:
    """Content hash of a mesh and the decomposition settings."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).round(9).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    h.update(f"{_CACHE_VERSION}:{COACD_THRESHOLD}:{MAX_PARTS}:{sorted(COACD_SEARCH.items())}".encode())
    return h.hexdigest()[:32]


def _coacd(mesh: trimesh.Trimesh, seed: int) -> list[trimesh.Trimesh]:
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)),
        threshold=COACD_THRESHOLD,
        max_convex_hull=MAX_PARTS,
        seed=seed,
        **COACD_SEARCH,
    )
    return [trimesh.Trimesh(v, f).convex_hull for v, f in parts if len(v) >= 4]


def convex_parts(mesh: trimesh.Trimesh, *, volume: float | None = None, seed: int = 0) -> list[trimesh.Trimesh]:
    """Convex parts covering ``mesh`` (object frame), from the cache when possible.

    ``volume`` is the solid's volume where known (watertight meshes); a mesh within 5 % of its
    hull's volume is treated as convex.
    """
    hull = mesh.convex_hull
    if volume is not None and volume >= CONVEX_VOLUME_RATIO * hull.volume:
        return [hull]
    path = cache_dir() / f"{mesh_key(mesh)}.npz"
    if path.exists():
        try:
            with np.load(path) as data:
                return [trimesh.convex.convex_hull(data[k]) for k in sorted(data.files, key=int)]
        except (OSError, ValueError, KeyError):
            pass  # a damaged cache entry is recomputed and overwritten below
    parts = _coacd(mesh, seed) or [hull]
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".npz.tmp")
    with os.fdopen(fd, "wb") as f:
        np.savez(f, **{str(i): p.vertices for i, p in enumerate(parts)})
    os.replace(tmp, path)
    return parts
