"""The seeded random object family that the primitives train on.

Kinds: boxes of varied aspect ratio, cylinders, frustums, capsules, ellipsoids, random convex hulls
and composite L/T shapes. Each object is a :class:`~affordplan.objects.shapes.Shape` in its
construction frame; :func:`affordplan.objects.random_object` normalises it like HACMan (largest
half-extent 5 cm times a uniform 0.8-1.2 factor).

Splits are disjoint by construction: object ``i`` of split ``s`` is drawn from
``numpy.random.default_rng([SPLIT_KEYS[s], i])``, so the held-out ``"test"`` objects are never
among the ``"train"`` ones.
"""

from __future__ import annotations

import numpy as np
import trimesh

from affordplan.objects.shapes import SECTIONS, Shape, box, frustum, hull, union

KINDS = ("box", "cylinder", "frustum", "capsule", "ellipsoid", "convex", "composite")
SPLIT_KEYS = {"train": 11, "test": 29}


def _box(rng: np.random.Generator) -> Shape:
    return union([box(rng.uniform(0.3, 1.0, size=3))])


def _cylinder(rng: np.random.Generator) -> Shape:
    r, h = rng.uniform(0.15, 0.5), rng.uniform(0.3, 1.0)
    return union([frustum(r, r, 0.0, h)])


def _frustum(rng: np.random.Generator) -> Shape:
    r0, h = rng.uniform(0.2, 0.5), rng.uniform(0.3, 1.0)
    r1 = r0 * rng.uniform(0.4, 0.8)
    if rng.random() < 0.5:
        r0, r1 = r1, r0
    return union([frustum(r0, r1, 0.0, h)])


def _capsule(rng: np.random.Generator) -> Shape:
    r, h = rng.uniform(0.15, 0.35), rng.uniform(0.2, 0.8)
    return union([trimesh.creation.capsule(height=h, radius=r, count=[16, SECTIONS])])


def _ellipsoid(rng: np.random.Generator) -> Shape:
    sphere = trimesh.creation.icosphere(subdivisions=2)
    sphere.apply_scale(rng.uniform(0.35, 1.0, size=3))
    return union([sphere])


def _convex(rng: np.random.Generator) -> Shape:
    n = int(rng.integers(8, 20))
    pts = rng.uniform(-1.0, 1.0, size=(n, 3)) * rng.uniform(0.4, 1.0, size=3)
    return union([hull(pts)])


def _composite(rng: np.random.Generator) -> Shape:
    """An L or a T made of two boxes, extruded along y."""
    t = rng.uniform(0.15, 0.35)  # bar thickness
    a, b = rng.uniform(0.5, 1.0), rng.uniform(0.4, 0.9)  # bar lengths
    depth = rng.uniform(0.3, 0.8)
    base = box((a, depth, t), center=(0.0, 0.0, t / 2))
    if rng.random() < 0.5:  # L: upright at one end
        x = -a / 2 + t / 2
    else:  # T: upright in the middle
        x = 0.0
    upright = box((t, depth, b), center=(x, 0.0, t + b / 2 - 0.01))
    return union([base, upright])


_BUILDERS = {
    "box": _box, "cylinder": _cylinder, "frustum": _frustum, "capsule": _capsule,
    "ellipsoid": _ellipsoid, "convex": _convex, "composite": _composite,
}


def random_shape(index: int, split: str = "train", kind: str | None = None) -> tuple[str, Shape, float]:
    """Object ``index`` of ``split``: ``(kind, shape, scale_factor)``.

    ``kind`` forces the kind (the draw stays seeded by ``index``); the scale factor is uniform in
    [0.8, 1.2], to multiply the nominal size.
    """
    if split not in SPLIT_KEYS:
        raise ValueError(f"unknown split {split!r}; expected one of {sorted(SPLIT_KEYS)}")
    rng = np.random.default_rng([SPLIT_KEYS[split], int(index)])
    chosen = KINDS[int(rng.integers(len(KINDS)))] if kind is None else kind
    if chosen not in _BUILDERS:
        raise ValueError(f"unknown kind {chosen!r}; expected one of {KINDS}")
    shape = _BUILDERS[chosen](rng)
    return chosen, shape, float(rng.uniform(0.8, 1.2))

