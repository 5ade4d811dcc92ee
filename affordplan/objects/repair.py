"""Checking and repairing user meshes before they become physical objects.

Everything here works on a mesh that :func:`clean` has put in a *unit frame*: centred on its
bounding box and scaled so that its longest side is 1 (dimensionless). Doing that first makes the
checks independent of the source's units (millimetres, metres, 1e-6 or 1e6 of them) and keeps
trimesh's absolute merge tolerance (1e-8) meaningful. What cannot be made physical raises
:class:`~affordplan.errors.MeshError` naming the fault; what can be repaired is repaired with a
:class:`UserWarning` saying how.

Budgets (so that no input makes loading hang):

- meshes above ``MAX_FACES`` faces are decimated (quadric error, ``fast_simplification``) to
  ``DECIMATED_FACES``; a 1.3M-face mesh then loads in seconds, at a surface error far below the
  fingertip's radius;
- the convex hull the object rests on is simplified to at most ``MAX_HULL_FACES`` faces
  (``trimesh.poses.compute_stable_poses`` costs ~0.15 ms per hull face);
- a *triangle soup* (over ``SOUP_OPEN_EDGES`` of its edges not shared by exactly two faces) is
  not decomposed: its convex hull is its collision shape (CoACD can take minutes on a soup).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import trimesh

from affordplan.errors import MeshError

MAX_FACES = 100_000
DECIMATED_FACES = 40_000
MAX_HULL_FACES = 2_000
SOUP_OPEN_EDGES = 0.3
MIN_THICKNESS = 0.01  # thinnest width of the hull / longest side, below which an object is flat
_MIN_RELATIVE_VOLUME = 1e-4  # hull volume / (longest side)^3 below which a mesh is flat
_OVERLAP = 1e-4  # relative volume lost by a union of bodies above which they overlapped


def first_line(exc: BaseException) -> str:
    """``"Type: first line of the message"``: enough to say what failed (qhull prints pages)."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")


def clean(mesh: trimesh.Trimesh, what: str) -> trimesh.Trimesh:
    """A processed copy of ``mesh`` in the unit frame, degenerate faces removed, decimated if huge.

    Raises:
        MeshError: no vertices or faces, non-finite vertices, malformed faces, all faces degenerate,
            or all vertices at one point.
    """
    try:
        vertices = np.asarray(mesh.vertices, dtype=float)
        faces = np.asarray(mesh.faces)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"{what} has malformed vertex or face arrays ({first_line(exc)})") from exc
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) == 0 or faces.size == 0:
        raise MeshError(f"{what} is empty or holds no triangles ({len(vertices)} vertices, {len(faces)} faces)")
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        raise MeshError(f"{what} has {int(bad.sum())} vertices with NaN or infinite coordinates")
    if (faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer)
            or faces.min() < 0 or faces.max() >= len(vertices)):
        raise MeshError(f"{what} has malformed faces (indices must be triangles of existing vertices)")
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    longest = float(np.max(hi - lo))
    if not longest > 0 or not np.isfinite(longest):
        raise MeshError(f"{what} has zero volume: all its vertices are at one point")
    with np.errstate(over="ignore", invalid="ignore"):
        unit = (vertices - 0.5 * (lo + hi)) / longest
    if not np.all(np.isfinite(unit)):
        raise MeshError(f"{what} spans more than floating point can scale (longest side {longest:g})")
    out = trimesh.Trimesh(unit, faces, process=True)
    out.update_faces(out.nondegenerate_faces())
    out.remove_unreferenced_vertices()
    if len(out.faces) == 0:
        raise MeshError(f"{what} has zero volume: every face is degenerate (no area)")
    if len(out.faces) > MAX_FACES:
        out = decimate(out, DECIMATED_FACES, what)
    return out


def decimate(mesh: trimesh.Trimesh, faces: int, what: str) -> trimesh.Trimesh:
    """``mesh`` simplified to about ``faces`` faces (quadric error decimation), with a warning."""
    try:
        import fast_simplification  # noqa: F401  (trimesh's quadric decimation backend)

        out = mesh.simplify_quadric_decimation(face_count=int(faces))
    except Exception as exc:
        raise MeshError(f"{what} has {len(mesh.faces)} faces (more than {MAX_FACES}) and could not be "
                        f"decimated ({first_line(exc)}); simplify it first") from exc
    out.update_faces(out.nondegenerate_faces())
    out.remove_unreferenced_vertices()
    if len(out.faces) == 0:
        raise MeshError(f"{what}: decimating {len(mesh.faces)} faces left no valid faces")
    warnings.warn(f"{what} had {len(mesh.faces)} faces; decimated to {len(out.faces)}", stacklevel=5)
    return out


def open_edge_fraction(mesh: trimesh.Trimesh) -> float:
    """Share of the mesh's edges not shared by exactly two faces (0 for a closed manifold surface)."""
    _, counts = np.unique(mesh.edges_sorted, axis=0, return_counts=True)
    return float(np.mean(counts != 2)) if len(counts) else 1.0


def is_soup(mesh: trimesh.Trimesh) -> bool:
    """Whether ``mesh`` is a triangle soup rather than a (possibly holed) surface."""
    return open_edge_fraction(mesh) > SOUP_OPEN_EDGES


def thickness(hull: trimesh.Trimesh) -> float:
    """Approximate thinnest width of a convex hull: the least extent along its principal axes and
    (up to 512 of) its face normals; same units as the hull."""
    v = np.asarray(hull.vertices)
    centred = v - v.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    normals = np.asarray(hull.face_normals)
    if len(normals) > 512:
        normals = normals[np.linspace(0, len(normals) - 1, 512).astype(int)]
    directions = np.vstack([axes, normals])
    widths = np.ptp(v @ directions.T, axis=0)
    return float(np.min(widths))


def _hull(mesh: trimesh.Trimesh, what: str) -> trimesh.Trimesh:
    try:
        with np.errstate(invalid="ignore", divide="ignore"):  # flat input: 0/0 inside trimesh
            hull = mesh.convex_hull
            volume = float(hull.volume)
    except Exception as exc:  # qhull fails on flat or collinear input
        raise MeshError(f"{what} has zero volume: it is flat or degenerate ({first_line(exc)})") from exc
    longest = float(np.max(mesh.extents))
    if not longest > 0 or not volume >= _MIN_RELATIVE_VOLUME * longest**3:
        raise MeshError(f"{what} has zero volume: it is flat or degenerate "
                        f"(extents {np.round(mesh.extents / longest, 6).tolist()} of its longest side)")
    thin = thickness(hull) / longest
    if thin < MIN_THICKNESS:
        raise MeshError(f"{what} is flat: its thinnest width is {100 * thin:.2g}% of its length (at least "
                        f"{100 * MIN_THICKNESS:g}% is needed to simulate it)")
    return hull


def _union_of_bodies(mesh: trimesh.Trimesh) -> trimesh.Trimesh | None:
    """The boolean union of a closed mesh's bodies when they overlap, else ``None``."""
    bodies = mesh.split(only_watertight=False)
    if len(bodies) < 2 or not all(b.is_volume for b in bodies):
        return None
    try:
        merged = trimesh.boolean.union(list(bodies), engine="manifold")
    except Exception:  # manifold3d refuses the input: keep the mesh, the checks below still apply
        return None
    if not merged.is_volume or merged.volume >= (1.0 - _OVERLAP) * sum(b.volume for b in bodies):
        return None
    return merged


@dataclass(frozen=True)
class Solid:
    """What :func:`solid` made of a surface.

    Attributes:
        surface: the surface to keep (repaired where it could be).
        volume: the closed mesh standing for the solid: ``surface`` itself, or its convex hull.
        closed: whether ``volume`` is ``surface``.
        soup: the surface is a triangle soup (see :func:`is_soup`); its hull is its collision shape.
    """

    surface: trimesh.Trimesh
    volume: trimesh.Trimesh
    closed: bool
    soup: bool = False


def solid(mesh: trimesh.Trimesh, what: str) -> Solid:
    """The closed volume standing for ``mesh`` (in the unit frame of :func:`clean`).

    Holes are filled when that closes the surface into a volume; closed bodies that overlap are
    merged by a boolean union (their overlap would otherwise count twice in the mass, and the hidden
    faces inside would show up in point clouds). A soup, a surface that stays open, or one whose
    volume exceeds its hull's (it intersects itself) is represented by its hull, with a warning.

    Raises:
        MeshError: the mesh has zero volume or is flat (thinner than ``MIN_THICKNESS``).
    """
    hull = _hull(mesh, what)
    longest = float(np.max(mesh.extents))
    if is_soup(mesh):
        warnings.warn(f"{what} is a triangle soup ({100 * open_edge_fraction(mesh):.0f}% of its edges are open or "
                      "non-manifold); its convex hull stands in for the solid and is its collision shape",
                      stacklevel=4)
        return Solid(mesh, hull, closed=False, soup=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        if not mesh.is_watertight:
            repaired = mesh.copy()
            trimesh.repair.fill_holes(repaired)
            if repaired.is_watertight and repaired.is_volume:
                mesh = repaired
                warnings.warn(f"{what} was not watertight; holes were filled", stacklevel=4)
        reason = "it is not a closed volume"
        if mesh.is_watertight:
            trimesh.repair.fix_normals(mesh)
            merged = _union_of_bodies(mesh) if mesh.body_count > 1 else None
            if merged is not None:
                warnings.warn(f"{what} is made of overlapping bodies; they were merged by a boolean union",
                              stacklevel=4)
                mesh = merged
                hull = _hull(mesh, what)
            if mesh.is_volume and mesh.volume > _MIN_RELATIVE_VOLUME * longest**3:
                if mesh.volume <= hull.volume * (1.0 + 1e-3):
                    return Solid(mesh, mesh, closed=True)
                reason = "it intersects itself (its volume exceeds its convex hull's)"
    warnings.warn(f"{what}: {reason}; its convex hull stands in for the solid (mass, centre of mass, inertia "
                  "and resting states)", stacklevel=4)
    return Solid(mesh, hull, closed=False)


def bounded_hull(mesh: trimesh.Trimesh, max_faces: int = MAX_HULL_FACES) -> trimesh.Trimesh:
    """The convex hull of ``mesh``, simplified to at most about ``max_faces`` faces.

    A hull within the budget is returned as is. A larger one (smooth high-resolution objects) is
    decimated and re-hulled: a slightly smaller convex polytope, its vertices on the true hull's
    surface to within the decimation error.
    """
    hull = mesh.convex_hull
    if len(hull.faces) <= max_faces:
        return hull
    try:
        import fast_simplification  # noqa: F401

        simplified = hull.simplify_quadric_decimation(face_count=int(max_faces)).convex_hull
    except Exception:  # fall back to the hull of an even subset of its vertices
        v = np.asarray(hull.vertices)
        simplified = trimesh.convex.convex_hull(v[np.linspace(0, len(v) - 1, max_faces // 2).astype(int)])
    return simplified if simplified.volume > 0 else hull
