"""HACMan's household objects (the Housekeep meshes), shipped as package data.

The 140 meshes HACMan trained and evaluated on, with HACMan's own split (``data/housekeep/split.json``) and their
provenance (``data/housekeep/PROVENANCE.md``: keep it next to any copy). They load by name like the catalogue,
``load_object("housekeep/mug_025_mug_M")``, through the same repair and normalisation as a user's mesh; their convex
decompositions are shipped (``data/housekeep/parts/``, written by ``tools/vendor_housekeep.py``), so nobody waits for
CoACD.

Splits (:func:`names`):

- HACMan's own: ``train``, ``unseen_instance``, ``unseen_class``, ``not_in_split`` and the ``*_thick`` lists (objects
  that are not flat or thin).
- ``validation``: every ``VALIDATION_EVERY``-th name of ``train`` in sorted order, carved out for model selection.
- ``training``: ``train`` without ``validation``, plus ``not_in_split``: what training draws from.
- ``unseen``: ``unseen_instance`` + ``unseen_class``, the test objects (never trained, tuned or selected on);
  ``unseen_thick`` likewise.
"""

from __future__ import annotations

import functools
import json
from importlib import resources
from pathlib import Path

import numpy as np

from affordplan.errors import InputError, MeshError

PREFIX = "housekeep/"
VALIDATION_EVERY = 6  # every 6th training mesh (12 of 72) is held out for model selection
PARTS_SIZE = 0.05  # largest half-extent (metres) at which the shipped convex parts are stored
HACMAN_SPLITS = ("train", "unseen_instance", "unseen_class", "not_in_split", "train_thick", "unseen_instance_thick",
                 "unseen_class_thick")
SPLITS = HACMAN_SPLITS + ("validation", "training", "unseen", "unseen_thick")


def data_dir() -> Path:
    """The folder holding ``meshes/``, ``parts/``, ``split.json`` and ``PROVENANCE.md``."""
    return Path(str(resources.files("affordplan.objects").joinpath("data", "housekeep")))


@functools.cache
def _hacman_split() -> dict[str, tuple[str, ...]]:
    with open(data_dir() / "split.json", encoding="utf-8") as f:
        raw = json.load(f)
    return {key: tuple(sorted(raw[key])) for key in HACMAN_SPLITS}


def names(split: str = "all") -> list[str]:
    """Mesh names (without the ``housekeep/`` prefix) of ``split`` (see the module's docstring), or ``"all"``."""
    split_map = _hacman_split()
    if split == "all":
        return sorted({name for key in ("train", "unseen_instance", "unseen_class", "not_in_split")
                       for name in split_map[key]})
    if split in split_map:
        return list(split_map[split])
    validation = split_map["train"][::VALIDATION_EVERY]
    derived = {
        "validation": validation,
        "training": sorted(set(split_map["train"]) - set(validation)) + list(split_map["not_in_split"]),
        "unseen": split_map["unseen_instance"] + split_map["unseen_class"],
        "unseen_thick": split_map["unseen_instance_thick"] + split_map["unseen_class_thick"],
    }
    if split not in derived:
        raise InputError(f"unknown housekeep split {split!r}; one of: all, {', '.join(SPLITS)}")
    return sorted(derived[split])


def mesh_path(name: str) -> Path:
    """The OBJ file of mesh ``name`` (with or without the ``housekeep/`` prefix)."""
    bare = name.removeprefix(PREFIX)
    if bare not in set(names()):
        raise MeshError(f"unknown household object {name!r}; affordplan.objects.housekeep.names() lists them")
    return data_dir() / "meshes" / f"{bare}.obj"


def shipped_parts(name: str, mesh_vertices: np.ndarray, size: float) -> list[np.ndarray] | None:
    """Vertex arrays (object frame, metres) of the shipped convex parts of ``name`` at largest half-extent ``size``.

    ``mesh_vertices``: the normalised surface's vertices (object frame, at ``size``), checked against the
    fingerprint stored with the parts (vertex count and extents), so parts computed for another repair of the mesh
    are never used. ``None`` when none are shipped or the fingerprint differs (the caller decomposes).
    """
    path = data_dir() / "parts" / f"{name.removeprefix(PREFIX)}.npz"
    if not path.exists():
        return None
    scale = float(size) / PARTS_SIZE
    with np.load(path, allow_pickle=False) as data:
        extents = np.ptp(np.asarray(mesh_vertices, dtype=float), axis=0)
        if int(data["n_vertices"]) != len(mesh_vertices) or not np.allclose(
                extents, scale * data["extents"], rtol=1e-4, atol=1e-7):
            return None
        keys = sorted((k for k in data.files if k.isdigit()), key=int)
        return [scale * np.asarray(data[k], dtype=float) for k in keys]
