"""Convex decomposition of user meshes, cached on disk.

MuJoCo collides every mesh geom as its convex hull, so a non-convex object (a mug, a bowl) needs
convex parts. Nearly convex meshes get their hull; the rest go through CoACD. Results are cached
under ``$AFFORDPLAN_CACHE`` (default ``~/.cache/affordplan``), keyed by a hash of the mesh's
vertices and faces and the decomposition settings, so a mesh is decomposed once per machine.

CoACD runs in a child process (:mod:`.coacd_worker`) with a time limit, ``COACD_TIMEOUT``: on a
pathological mesh it can search for many minutes, and a crash in its C++ code would otherwise take
the caller down. When it fails or runs out of time the mesh's convex hull is its collision shape,
with a warning (nothing is cached, so a later load tries again).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
import warnings
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
COACD_TIMEOUT = 120.0  # seconds a decomposition may take (4-25 s for household meshes on 2 cores)
MIN_PART_VOLUME = 1e-9  # parts smaller than this fraction of the hull's volume are dropped
_CACHE_VERSION = "2"
_WORKER = Path(__file__).with_name("coacd_worker.py")


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


def _coacd(mesh: trimesh.Trimesh, seed: int, timeout: float | None = None) -> list[trimesh.Trimesh]:
    """CoACD's convex parts of ``mesh``, computed in a child process within ``timeout`` seconds
    (default ``COACD_TIMEOUT``); ``[]`` when it fails or runs out of time."""
    timeout = COACD_TIMEOUT if timeout is None else float(timeout)
    settings = dict(threshold=COACD_THRESHOLD, max_convex_hull=MAX_PARTS, seed=int(seed), **COACD_SEARCH)
    with tempfile.TemporaryDirectory(prefix="affordplan-coacd-") as folder:
        source, target = Path(folder) / "mesh.npz", Path(folder) / "parts.npz"
        np.savez(source, vertices=np.asarray(mesh.vertices, dtype=float),
                 faces=np.asarray(mesh.faces, dtype=np.int64))
        try:
            proc = subprocess.run([sys.executable, str(_WORKER), str(source), str(target), json.dumps(settings)],
                                  capture_output=True, text=True, timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            warnings.warn(f"convex decomposition (CoACD) took longer than {timeout:.0f} s and was stopped; the "
                          "mesh's convex hull is its collision shape", stacklevel=3)
            return []
        except OSError:  # no Python executable to start (an embedded interpreter): run it here, unguarded
            return _coacd_here(mesh, settings)
        if proc.returncode != 0 or not target.exists():
            detail = (proc.stderr.strip().splitlines() or [f"exit status {proc.returncode}"])[-1]
            warnings.warn(f"convex decomposition (CoACD) failed ({detail}); the mesh's convex hull is its "
                          "collision shape", stacklevel=3)
            return []
        with np.load(target) as data:
            arrays = [(data[f"v{i}"], data[f"f{i}"]) for i in range(len(data.files) // 2)]
    return [trimesh.Trimesh(v, f).convex_hull for v, f in arrays if len(v) >= 4]


def _coacd_here(mesh: trimesh.Trimesh, settings: dict) -> list[trimesh.Trimesh]:
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)), **settings)
    return [trimesh.Trimesh(v, f).convex_hull for v, f in parts if len(v) >= 4]


def _solid_parts(parts: list[trimesh.Trimesh], hull: trimesh.Trimesh) -> list[trimesh.Trimesh]:
    """Parts with a volume (MuJoCo rejects flat mesh geoms)."""
    return [p for p in parts if p.volume > MIN_PART_VOLUME * hull.volume]


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
                parts = _solid_parts([trimesh.convex.convex_hull(data[k]) for k in sorted(data.files, key=int)], hull)
            if parts:
                return parts
        except Exception:  # a damaged cache entry (or one qhull cannot hull) is recomputed and overwritten
            pass
    parts = _solid_parts(_coacd(mesh, seed), hull)
    if not parts:
        return [hull]
    try:
        _write_cache(path, parts)
    except OSError:  # a read-only or full cache folder: the parts are still good, only not kept
        pass
    return parts


def _write_cache(path: Path, parts: list[trimesh.Trimesh]) -> None:
    """Write atomically (temporary file, then rename), so a killed process leaves no torn entry."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".npz.tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **{str(i): p.vertices for i, p in enumerate(parts)})
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
