"""Convex decomposition (affordplan.objects.decompose): convex meshes keep their hull, parts are cached under
``$AFFORDPLAN_CACHE`` by a key of the mesh and the settings, a damaged entry is recomputed, a failure is not kept."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

import affordplan as ap
from affordplan.objects import decompose

DATA = Path(__file__).parent / "data"


def _box(extents, center) -> trimesh.Trimesh:
    return trimesh.creation.box(extents, transform=trimesh.transformations.translation_matrix(center))


def _l_parts() -> list[trimesh.Trimesh]:
    """The two convex boxes of an L (no overlap)."""
    return [_box((0.75, 0.4, 0.25), (0.125, 0.0, 0.125)), _box((0.25, 0.4, 1.0), (-0.375, 0.0, 0.5))]


def _l_shape() -> trimesh.Trimesh:
    return trimesh.boolean.union(_l_parts(), engine="manifold")


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("AFFORDPLAN_CACHE", str(tmp_path))
    return decompose.cache_dir()


def _no_coacd(*args, **kwargs):
    raise AssertionError("CoACD ran")


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


def test_the_cache_lives_under_affordplan_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("AFFORDPLAN_CACHE", str(tmp_path / "here"))
    assert decompose.cache_dir() == tmp_path / "here" / "convex"
    monkeypatch.delenv("AFFORDPLAN_CACHE")
    assert decompose.cache_dir() == Path.home() / ".cache" / "affordplan" / "convex"


def test_a_nearly_convex_mesh_is_its_own_hull_without_running_coacd(cache, monkeypatch):
    monkeypatch.setattr(decompose, "_coacd", _no_coacd)
    box = _box((0.1, 0.05, 0.02), (0.0, 0.0, 0.0))
    (part,) = decompose.convex_parts(box, volume=box.volume)
    assert part.volume == pytest.approx(box.volume)
    assert not cache.exists() or not list(cache.glob("*.npz"))  # nothing to cache


def test_decomposed_parts_are_cached_and_read_back_without_running_coacd_again(cache, monkeypatch):
    mesh = _l_shape()
    assert mesh.volume < decompose.CONVEX_VOLUME_RATIO * mesh.convex_hull.volume  # not nearly convex
    calls = []
    monkeypatch.setattr(decompose, "_coacd", lambda m, seed, timeout=None: calls.append(seed) or _l_parts())
    first = decompose.convex_parts(mesh, volume=mesh.volume, seed=3)
    assert calls == [3] and len(first) == 2
    assert [p.name for p in cache.glob("*.npz")] == [f"{decompose.mesh_key(mesh)}.npz"]
    assert not list(cache.glob("*.tmp"))  # written atomically: no temporary file left
    monkeypatch.setattr(decompose, "_coacd", _no_coacd)
    second = decompose.convex_parts(mesh, volume=mesh.volume)
    assert [p.volume for p in second] == pytest.approx([p.volume for p in first])
    assert sum(p.volume for p in second) == pytest.approx(mesh.volume)


def test_a_damaged_cache_entry_is_recomputed_and_overwritten(cache, monkeypatch):
    mesh = _l_shape()
    cache.mkdir(parents=True)
    entry = cache / f"{decompose.mesh_key(mesh)}.npz"
    entry.write_bytes(b"not an npz file")
    monkeypatch.setattr(decompose, "_coacd", lambda m, seed, timeout=None: _l_parts())
    assert len(decompose.convex_parts(mesh, volume=mesh.volume)) == 2
    with np.load(entry) as data:  # rewritten whole
        assert sorted(data.files) == ["0", "1"]


def test_a_failed_decomposition_falls_back_to_the_hull_and_is_not_cached(cache, monkeypatch):
    mesh = _l_shape()
    monkeypatch.setattr(decompose, "_coacd", lambda m, seed, timeout=None: [])
    (part,) = decompose.convex_parts(mesh, volume=mesh.volume)
    assert part.volume == pytest.approx(mesh.convex_hull.volume)
    assert not cache.exists() or not list(cache.glob("*.npz"))  # a later load tries again


def test_parts_without_volume_are_dropped(cache, monkeypatch):
    mesh = _l_shape()
    sliver = trimesh.Trimesh([[0, 0, 0], [1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-6]], [[0, 1, 2], [0, 1, 3],
                                                                                     [0, 2, 3], [1, 2, 3]])
    monkeypatch.setattr(decompose, "_coacd", lambda m, seed, timeout=None: _l_parts() + [sliver.convex_hull])
    assert len(decompose.convex_parts(mesh, volume=mesh.volume)) == 2


def test_the_cache_key_is_the_mesh_and_the_settings(monkeypatch):
    mesh = _l_shape()
    key = decompose.mesh_key(mesh)
    assert len(key) == 32 and decompose.mesh_key(mesh.copy()) == key
    moved = mesh.copy()
    moved.apply_translation([0.001, 0.0, 0.0])
    assert decompose.mesh_key(moved) != key
    monkeypatch.setattr(decompose, "COACD_THRESHOLD", decompose.COACD_THRESHOLD / 2)
    assert decompose.mesh_key(mesh) != key  # other settings: decomposed again
