"""The CoACD child process (affordplan.objects.coacd_worker), run by path as affordplan.objects.decompose runs it:
it writes convex parts that cover the mesh, and imports numpy and coacd only."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import trimesh

from affordplan.objects import decompose


def _l_shape() -> trimesh.Trimesh:
    base = trimesh.creation.box((1.0, 0.4, 0.25), transform=trimesh.transformations.translation_matrix([0, 0, 0.125]))
    upright = trimesh.creation.box((0.25, 0.4, 1.0),
                                   transform=trimesh.transformations.translation_matrix([-0.375, 0, 0.5]))
    return trimesh.boolean.union([base, upright], engine="manifold")


_RUN_BY_PATH = """
import json, runpy, sys
sys.argv = json.loads(sys.argv[1])
try:
    runpy.run_path(sys.argv[0], run_name="__main__")
except SystemExit as exc:
    print(json.dumps(dict(code=exc.code, modules=sorted({m.split(".")[0] for m in sys.modules}))))
"""


def test_the_worker_writes_convex_parts_covering_the_mesh_and_imports_numpy_and_coacd_only(tmp_path):
    pytest.importorskip("coacd")
    mesh = _l_shape()  # two boxes: CoACD's parts must cover it, no more
    np.savez(tmp_path / "mesh.npz", vertices=mesh.vertices, faces=mesh.faces)
    settings = dict(threshold=decompose.COACD_THRESHOLD, max_convex_hull=decompose.MAX_PARTS, seed=0,
                    **decompose.COACD_SEARCH)
    argv = [str(decompose._WORKER), str(tmp_path / "mesh.npz"), str(tmp_path / "parts.npz"), json.dumps(settings)]
    proc = subprocess.run([sys.executable, "-c", _RUN_BY_PATH, json.dumps(argv)], capture_output=True, text=True,
                          timeout=120, check=True)
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["code"] == 0
    assert {"numpy", "coacd"} <= set(report["modules"])
    assert not {"affordplan", "trimesh", "scipy", "torch", "mujoco"} & set(report["modules"])  # a light child
    with np.load(tmp_path / "parts.npz") as data:
        n = len(data.files) // 2
        assert sorted(data.files) == sorted([f"v{i}" for i in range(n)] + [f"f{i}" for i in range(n)])
        assert all(data[f"f{i}"].dtype == np.int64 for i in range(n))
        parts = [trimesh.Trimesh(data[f"v{i}"], data[f"f{i}"]).convex_hull for i in range(n)]
    assert n >= 2  # an L is not convex
    assert trimesh.boolean.union(parts, engine="manifold").volume == pytest.approx(mesh.volume, rel=0.02)
    for part in parts:
        assert np.all(part.bounds[0] >= mesh.bounds[0] - 1e-6) and np.all(part.bounds[1] <= mesh.bounds[1] + 1e-6)
