"""Procedural shapes built as unions of convex parts.

A :class:`Shape` carries its convex parts (what MuJoCo collides) and the watertight union of them
(what mass properties, resting states and point clouds come from), so procedural objects need no
convex decomposition: the decomposition is known by construction. Units are metres; the frame is
the construction frame (normalisation to the centre of mass happens in :mod:`.model`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh

SECTIONS = 32  # facets around a round convex shape: 11.25 deg apart, one rolling family
# Wedges around a hollow wall (mug, tape): each is a convex geom with its own table contacts, so
# fewer is cheaper to simulate; 16 (22.5 deg apart) still merge into one rolling family.
WALL_SECTIONS = 16


@dataclass(frozen=True)
class Shape:
    """A solid as convex parts plus their watertight union."""

    mesh: trimesh.Trimesh
    parts: tuple[trimesh.Trimesh, ...]


def union(parts: list[trimesh.Trimesh]) -> Shape:
    """Shape from convex parts; their union is computed with manifold3d."""
    parts = [p if p.is_convex else p.convex_hull for p in parts]
    mesh = parts[0].copy() if len(parts) == 1 else trimesh.boolean.union(parts, engine="manifold")
    return Shape(mesh=mesh, parts=tuple(parts))


def hull(points: np.ndarray) -> trimesh.Trimesh:
    return trimesh.convex.convex_hull(np.asarray(points, dtype=float))


def box(extents, center=(0.0, 0.0, 0.0)) -> trimesh.Trimesh:
    return trimesh.creation.box(extents=extents, transform=trimesh.transformations.translation_matrix(center))


def frustum(r_bottom: float, r_top: float, z0: float, z1: float, sections: int = SECTIONS) -> trimesh.Trimesh:
    """Solid of revolution between two circles (a cylinder when the radii agree)."""
    a = np.linspace(0.0, 2.0 * math.pi, sections, endpoint=False)
    ring = np.stack([np.cos(a), np.sin(a)], axis=1)
    bottom = np.column_stack([r_bottom * ring, np.full(sections, z0)])
    top = np.column_stack([r_top * ring, np.full(sections, z1)])
    return hull(np.vstack([bottom, top]))


def annular_wedges(
    r_in_0: float, r_out_0: float, z0: float, r_in_1: float, r_out_1: float, z1: float,
    sections: int = SECTIONS, overlap: float = 0.02,
) -> list[trimesh.Trimesh]:
    """Convex wedges tiling a hollow solid of revolution between heights z0 and z1.

    The wall spans radii [r_in_0, r_out_0] at z0 and [r_in_1, r_out_1] at z1. Neighbouring wedges
    overlap by ``overlap`` of a wedge's angle so that their union is one watertight solid.
    """
    wedges = []
    step = 2.0 * math.pi / sections
    for k in range(sections):
        a0, a1 = (k - overlap) * step, (k + 1 + overlap) * step
        pts = []
        for a in (a0, a1):
            c, s = math.cos(a), math.sin(a)
            for r, z in ((r_in_0, z0), (r_out_0, z0), (r_in_1, z1), (r_out_1, z1)):
                pts.append((r * c, r * s, z))
        wedges.append(hull(np.array(pts)))
    return wedges


def tube_segments(path: np.ndarray, radius: float, ring: int = 12) -> list[trimesh.Trimesh]:
    """Convex pieces of a tube of ``radius`` swept along a polyline ``path`` (n, 3)."""
    pieces = []
    for p0, p1 in zip(path[:-1], path[1:]):
        d = p1 - p0
        d = d / np.linalg.norm(d)
        u = np.cross(d, [0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.cross(d, [1.0, 0.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(d, u)
        a = np.linspace(0.0, 2.0 * math.pi, ring, endpoint=False)
        circle = radius * (np.outer(np.cos(a), u) + np.outer(np.sin(a), v))
        pieces.append(hull(np.vstack([p0 + circle, p1 + circle])))
    return pieces


# --- the seed's seven objects and a bowl (construction sizes; load_object normalises them) ---

def cube() -> Shape:
    return union([box((0.1, 0.1, 0.1))])


def mug() -> Shape:
    """Cylindrical cup, open at the top, with a C-shaped handle on its +x side."""
    r_out, wall, height, floor = 0.04, 0.006, 0.095, 0.008
    parts = [frustum(r_out, r_out, 0.0, floor)]
    parts += annular_wedges(r_out - wall, r_out, floor * 0.5, r_out - wall, r_out, height, sections=WALL_SECTIONS)
    # Handle: a half-ring in the xz plane, from the upper to the lower part of the wall.
    centre = np.array([r_out, 0.0, 0.5 * height])
    a = np.linspace(-0.5 * math.pi, 0.5 * math.pi, 7)
    path = centre + np.column_stack([0.028 * np.cos(a), np.zeros_like(a), 0.032 * np.sin(a)])
    path[0, 0] -= 0.006  # root the ends inside the wall
    path[-1, 0] -= 0.006
    parts += tube_segments(path, 0.006)
    return union(parts)


def tape() -> Shape:
    """A wide, short hollow roll (outer diameter 11 cm, core 7.6 cm, width 5 cm)."""
    return union(annular_wedges(0.038, 0.055, 0.0, 0.038, 0.055, 0.05, sections=WALL_SECTIONS))


def planter_1() -> Shape:
    """Wide, short frustum, wider at the top."""
    return union([frustum(0.035, 0.05, 0.0, 0.065)])


def planter_2() -> Shape:
    """Narrower, taller frustum."""
    return union([frustum(0.03, 0.042, 0.0, 0.1)])


def pill_bottle() -> Shape:
    """Narrow cylinder with a slightly wider cap."""
    body = frustum(0.02, 0.02, 0.0, 0.07)
    cap = frustum(0.0225, 0.0225, 0.068, 0.088)
    return union([body, cap])


def lunch_box() -> Shape:
    """A flat box."""
    return union([box((0.2, 0.14, 0.06))])


def bowl() -> Shape:
    """Hemispherical shell on a small flat foot, open at the top."""
    r, wall = 0.06, 0.006
    bands = np.radians([-75.0, -55.0, -35.0, -15.0, 0.0])  # latitude, 0 is the rim
    parts = [frustum(0.022, 0.022, 0.0, 0.006)]
    z_centre = r * math.cos(math.radians(15.0))  # sphere centre height so the foot touches the table
    for lat0, lat1 in zip(bands[:-1], bands[1:]):
        lat1 = min(lat1 + math.radians(2.0), 0.0)  # bands overlap so that their union is watertight
        parts += annular_wedges(
            (r - wall) * math.cos(lat0), r * math.cos(lat0), z_centre + r * math.sin(lat0),
            (r - wall) * math.cos(lat1), r * math.cos(lat1), z_centre + r * math.sin(lat1),
            sections=16,
        )
    return union(parts)


CATALOGUE = {
    "cube": cube,
    "mug": mug,
    "tape": tape,
    "planter_1": planter_1,
    "planter_2": planter_2,
    "pill_bottle": pill_bottle,
    "lunch_box": lunch_box,
    "bowl": bowl,
}
