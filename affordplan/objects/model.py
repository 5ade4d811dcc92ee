"""Object models: a mesh in its centre-of-mass frame, its convex parts, mass and resting states.

``load_object`` accepts a catalogue name, a mesh file (OBJ, STL, PLY, GLB, anything trimesh reads)
or a ``trimesh.Trimesh``, and normalises it like HACMan: the object frame sits at the centre of mass
(axes kept from the source), and the mesh is scaled so that its largest half-extent (half the
longest side of its axis-aligned bounding box in the source frame) equals ``size`` metres.

Real meshes are often not watertight. Such a mesh is repaired by hole filling when that makes it a
closed volume, and closed bodies that overlap are merged by a boolean union; otherwise its convex
hull stands in for the solid (mass, centre of mass, inertia and resting states), and a warning says
so. Huge meshes are decimated. What cannot be made physical (empty, unreadable, NaN or infinite
vertices, flat, zero volume) raises :class:`~affordplan.errors.MeshError` naming the fault; see
:mod:`affordplan.objects.repair`.
"""

from __future__ import annotations

import functools
import os
import warnings
from pathlib import Path

import numpy as np
import trimesh

from affordplan.checks import as_finite, as_seed, as_whole
from affordplan.errors import InputError, MeshError
from affordplan.objects import decompose, family, housekeep, repair
from affordplan.objects.exposed import exposed_samples, hole_fill
from affordplan.objects.resting import RestingState, angle_to_state, classify, compute_resting_states, yaw_period
from affordplan.objects.shapes import CATALOGUE, Shape

DEFAULT_SIZE = 0.05  # largest half-extent, metres
DEFAULT_DENSITY = 400.0  # kg/m^3: household objects are partly hollow
MAX_SURFACE_SAMPLES = 1_000_000  # most points surface_samples draws (the simulator's clouds ask for 8,192)
TOP_UP_DRAWS = 20  # uniform draws surface_samples tops its count up with before it falls back to the raw mesh
MESH_SUFFIXES = (".obj", ".stl", ".ply", ".glb", ".gltf", ".off", ".dae", ".3mf")


class ObjectModel:
    """A rigid object ready for simulation and planning.

    Attributes:
        name: catalogue name, file stem or ``"mesh"``.
        mesh: the surface, object frame (origin at the centre of mass), metres.
        parts: convex pieces whose union is the collision shape, object frame.
        mass: kilograms.
        inertia: 3x3 inertia tensor about the centre of mass, object frame, kg m^2.
        hull: convex hull of ``mesh`` (what the object rests on), simplified to at most
            ``repair.MAX_HULL_FACES`` faces.
    """

    def __init__(
        self, name: str, mesh: trimesh.Trimesh, parts: list[trimesh.Trimesh], mass: float,
        inertia: np.ndarray,
    ):
        self.name = name
        self.mesh = mesh
        self.parts = tuple(parts)
        self.mass = float(mass)
        self.inertia = np.asarray(inertia, dtype=float)
        self.hull = repair.bounded_hull(mesh)
        self._samples: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
        self._yaw_periods: dict[int, float] = {}

    def __repr__(self) -> str:
        return (f"ObjectModel({self.name!r}, extents={np.round(self.mesh.extents, 3).tolist()} m, "
                f"mass={self.mass:.3f} kg, parts={len(self.parts)})")

    @functools.cached_property
    def resting_states(self) -> list[RestingState]:
        """Resting states sorted by probability, most likely first."""
        states = compute_resting_states(self.hull)
        if not states:
            raise MeshError(f"{self.name}: no stable resting pose found")
        return states

    def classify(self, pose: np.ndarray) -> int:
        """Resting state of a settled 4x4 world pose, up to yaw."""
        return classify(self.resting_states, np.asarray(pose)[:3, :3])

    def planar_pose(self, pose: np.ndarray) -> tuple[int, float, float, float]:
        """``(resting state, x, y, yaw)`` of a settled 4x4 world pose (metres, radians)."""
        state = self.classify(pose)
        yaw = self.resting_states[state].yaw_of(np.asarray(pose)[:3, :3])
        return state, float(pose[0, 3]), float(pose[1, 3]), float(yaw)

    def yaw_period(self, state: int) -> float:
        """Radians: turning a pose of resting ``state`` by this about the vertical gives the same solid in the
        same place (``2 pi``: no symmetry); yaws in the state are equal modulo it (:func:`resting.yaw_period`)."""
        if state not in self._yaw_periods:
            self._yaw_periods[state] = yaw_period(self.mesh.vertices, self.resting_states[state].up)
        return self._yaw_periods[state]

    def tilt_from_state(self, pose: np.ndarray, state: int) -> float:
        """Angle (radians) between a pose's up-vector and the nearest one of ``state``."""
        return angle_to_state(self.resting_states[state], np.asarray(pose)[:3, :3])

    def surface_samples(self, n: int = 8192, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """``n`` points spread over the surface the convex parts expose, and their outward unit normals, object frame.

        The points are drawn on ``mesh``; those buried in the parts (a raw mesh's inner faces) are left out,
        normals wound into the parts are reversed, and where the parts bulge past the mesh or close a cavity it
        leaves open, the parts' own boundary fills the hole (:mod:`affordplan.objects.exposed`): every point is one
        the simulated pusher can touch from where its normal points, and no surface it collides goes unsampled.
        Read-only arrays, computed once per ``(n, seed)`` and kept on the model.

        Raises:
            InputError: ``n`` not a whole number from 1 to ``MAX_SURFACE_SAMPLES``, or ``seed`` not a seed.
        """
        key = (as_whole("n", n, 1, MAX_SURFACE_SAMPLES), as_seed("seed", seed))
        if key not in self._samples:
            # trimesh.sample.sample_surface_even's own steps (3n uniform samples, those closer than its radius
            # dropped), without the warning it logs when fewer than n are left: those are topped up below
            points, normals = self._exposed_draw(3 * n, seed)
            exposed = max(len(points), 1) / (3 * n)  # exposed area over the mesh area (> 1 with holes filled)
            points, keep = trimesh.points.remove_close(points, np.sqrt(exposed * self.mesh.area / (3 * n)))
            points, normals = points[:n], normals[keep][:n]
            for k in range(TOP_UP_DRAWS):  # fewer than n far enough apart: top up uniformly
                missing = n - len(points)
                if missing <= 0:
                    break
                extra, extra_normals = self._exposed_draw(min(int(np.ceil(missing / exposed)), 3 * n), seed + k)
                points = np.vstack([points, extra[:missing]])
                normals = np.vstack([normals, extra_normals[:missing]])
            if len(points) < n:  # the draws kept coming up short (next to nothing exposed): the mesh's own samples
                points, face_idx = trimesh.sample.sample_surface(self.mesh, n, seed=seed)
                normals = np.array(self.mesh.face_normals[face_idx])
            points.setflags(write=False)
            normals.setflags(write=False)
            self._samples[key] = (points, normals)
        return self._samples[key]

    def _exposed_draw(self, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Those of ``n`` uniform samples of ``mesh`` that the parts expose, with their outward normals, and samples
        of the parts' boundary where those leave holes (:func:`~affordplan.objects.exposed.hole_fill`; at the same
        density, so the draw may hold more than ``n`` where the parts' surface is larger), shuffled in."""
        points, face_idx = trimesh.sample.sample_surface(self.mesh, n, seed=seed)
        keep, normals = exposed_samples(self.parts, points, self.mesh.face_normals[face_idx])
        points, normals = points[keep], normals[keep]
        fill, fill_normals = hole_fill(self.parts, points, float(self.mesh.area), n, seed)
        if len(fill) == 0:  # a mesh whose surface is its parts' boundary: its own samples, as drawn
            return points, normals
        order = np.random.default_rng(seed).permutation(len(points) + len(fill))
        return np.vstack([points, fill])[order], np.vstack([normals, fill_normals])[order]


def catalogue() -> list[str]:
    """Names of the built-in objects: the seed paper's seven plus a bowl."""
    return list(CATALOGUE)


def _finish(name: str, mesh: trimesh.Trimesh, solid: trimesh.Trimesh, parts, size: float, density: float):
    """Move to the centre-of-mass frame, scale, and compute mass properties."""
    scale = size / (0.5 * float(np.max(mesh.extents)))
    T = np.eye(4)
    T[:3, :3] *= scale
    T[:3, 3] = -scale * solid.center_mass
    mesh = mesh.copy().apply_transform(T)
    solid = solid.copy().apply_transform(T)
    parts = [p.copy().apply_transform(T) for p in parts]
    mass = density * solid.volume
    inertia = density * solid.moment_inertia
    return ObjectModel(name, mesh, parts, mass, inertia)


def _from_shape(name: str, shape: Shape, size: float, density: float) -> ObjectModel:
    return _finish(name, shape.mesh, shape.mesh, shape.parts, size, density)


def _read_mesh(path: Path) -> trimesh.Trimesh:
    if not path.exists():
        raise MeshError(f"no such mesh file: {path}")
    if path.is_dir():
        raise MeshError(f"{path} is a folder, not a mesh file")
    if path.stat().st_size == 0:
        raise MeshError(f"mesh file is empty: {path}")
    try:
        # process=False: trimesh's processing would silently drop NaN / infinite vertices;
        # repair.clean checks and processes the raw arrays.
        scene = trimesh.load(str(path), process=False)
        geometries = len(scene.geometry) if isinstance(scene, trimesh.Scene) else 1
        if geometries > 1:
            warnings.warn(f"{path.name} holds {geometries} meshes; they are merged into one rigid object",
                          stacklevel=4)
        loaded = scene.to_mesh() if isinstance(scene, trimesh.Scene) else scene
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise MeshError(f"cannot read mesh {path}: {repair.first_line(exc)}") from exc
    if not isinstance(loaded, trimesh.Trimesh):
        raise MeshError(f"{path} holds no triangle mesh (got {type(loaded).__name__})")
    return loaded


def _from_mesh(name: str, mesh: trimesh.Trimesh, size: float | None, density: float, what: str,
               shipped: str | None = None) -> ObjectModel:
    """``shipped``: a household object's name, whose convex parts are shipped (:mod:`.housekeep`). ``size`` None:
    the source's own largest half-extent (its units taken as metres)."""
    cleaned = repair.clean(mesh, what)  # raises for non-finite or empty input before the size is read
    if size is None:
        size = 0.5 * float(np.max(np.ptp(np.asarray(mesh.vertices, dtype=float), axis=0)))
        try:
            _check_size(size, density)
        except InputError as exc:
            raise InputError(f"{what} keeps its own size (size=None), but {exc}; give size= in metres, or convert "
                             "the mesh to metres") from None
    made = repair.solid(cleaned, what)
    # Decompose in a normalised frame so cache keys do not depend on the source's units.
    probe = _finish(name, made.surface, made.volume, [], size, density)
    vertices = housekeep.shipped_parts(shipped, probe.mesh.vertices, size) if shipped else None
    if vertices:
        parts = [trimesh.convex.convex_hull(v) for v in vertices]
    elif made.soup:  # CoACD can take minutes on a soup, for nothing: its hull is its shape
        parts = [probe.mesh.convex_hull]
    else:
        parts = decompose.convex_parts(probe.mesh, volume=probe.mass / density if made.closed else None)
    return ObjectModel(name, probe.mesh, parts, probe.mass, probe.inertia)


SIZE_RANGE = (0.005, 1.0)  # metres: the largest half-extent MuJoCo and the fingertip can handle
DENSITY_RANGE = (1.0, 50_000.0)  # kg/m^3: foam to tungsten


def _check_size(size: float, density: float) -> None:
    as_finite("size (metres)", size, *SIZE_RANGE)
    as_finite("density (kg/m^3)", density, *DENSITY_RANGE)


def load_object(source, *, size: float | None = DEFAULT_SIZE, density: float = DEFAULT_DENSITY) -> ObjectModel:
    """Load an object and normalise it.

    Args:
        source: a catalogue name (see :func:`catalogue`), ``"housekeep/NAME"`` (HACMan's household meshes,
            :func:`affordplan.objects.housekeep.names`), a mesh file path, or a ``trimesh.Trimesh``.
        size: the largest half-extent after normalisation, metres (HACMan scales objects this way); ``None`` keeps
            the source's own size, its units taken as metres.
        density: kg/m^3, for the mass and inertia.

    Warns:
        UserWarning: the object is far from what the skills trained on (its size, its aspect, its thinnest width),
            naming what is unusual (:func:`unusual`).

    Raises:
        MeshError: the source is unknown, missing, unreadable, empty, non-finite, flat or has zero
            volume; the message names which (see :mod:`affordplan.objects.repair`).
        InputError: ``size`` (given, or the source's own) or ``density`` out of range.
    """
    _check_size(DEFAULT_SIZE if size is None else size, density)
    obj = _load(source, size, density)
    note = unusual(obj)
    if note:
        warnings.warn(f"{obj.name}: {note}; the skills trained on objects of 8-12 cm whose sides differ by at most "
                      "a factor of 6, and may fail or misjudge their odds on this one", stacklevel=2)
    return obj


# What the skills trained on: the procedural family's largest half-extents (0.05 m x 0.8-1.2), with margins.
TRAINED_HALF_EXTENT = (0.035, 0.075)  # metres
TRAINED_ASPECT = 6.0  # longest / shortest side
TRAINED_THINNEST = 0.012  # metres


def unusual(obj: ObjectModel) -> str:
    """What puts ``obj`` far outside what the skills trained on ("" when nothing does)."""
    extents = np.sort(np.asarray(obj.mesh.extents))
    half = 0.5 * extents[-1]
    notes = []
    if not TRAINED_HALF_EXTENT[0] <= half <= TRAINED_HALF_EXTENT[1]:
        notes.append(f"its largest half-extent is {100 * half:.1f} cm")
    if extents[-1] > TRAINED_ASPECT * extents[0]:
        notes.append(f"its longest side is {extents[-1] / extents[0]:.0f} times its shortest")
    if extents[0] < TRAINED_THINNEST:
        notes.append(f"it is {1000 * extents[0]:.0f} mm thin")
    return ", ".join(notes)


def _load(source, size: float | None, density: float) -> ObjectModel:
    if isinstance(source, trimesh.Trimesh):
        return _from_mesh("mesh", source, size, density, "mesh")
    if isinstance(source, trimesh.Scene):
        try:
            mesh = source.to_mesh()
        except Exception as exc:
            raise MeshError(f"the scene holds no usable triangle mesh ({repair.first_line(exc)})") from exc
        return _from_mesh("mesh", mesh, size, density, "scene")
    if isinstance(source, (str, os.PathLike)):
        text = os.fspath(source)
        if not str(text).strip():
            raise MeshError(f"empty object name; give a catalogue name ({', '.join(CATALOGUE)}), "
                            "housekeep/NAME or a mesh file path")
        if text in CATALOGUE:
            shape = CATALOGUE[text]()
            return _from_shape(text, shape, 0.5 * float(np.max(shape.mesh.extents)) if size is None else size,
                               density)
        if text.startswith(housekeep.PREFIX):
            path = housekeep.mesh_path(text)
            with warnings.catch_warnings():  # their repairs are known and documented (PROVENANCE.md), not news
                warnings.simplefilter("ignore", UserWarning)
                return _from_mesh(text, _read_mesh(path), size, density, f"mesh {text}", shipped=text)
        path = Path(text)
        if path.exists() or path.suffix.lower() in MESH_SUFFIXES:
            return _from_mesh(path.stem, _read_mesh(path), size, density, f"mesh {path.name}")
        raise MeshError(f"unknown object {text!r}: not a catalogue name ({', '.join(CATALOGUE)}) "
                        "and not a mesh file")
    raise MeshError(f"cannot load an object from {type(source).__name__}")


def random_object(
    index: int, split: str = "train", *, kind: str | None = None, size: float = DEFAULT_SIZE,
    density: float = DEFAULT_DENSITY,
) -> ObjectModel:
    """Object ``index`` of the procedural family's ``split`` ("train" or "test").

    Its largest half-extent is ``size`` times a uniform 0.8-1.2 factor drawn with the object.
    """
    _check_size(size, density)
    chosen, shape, factor = family.random_shape(index, split, kind)
    return _from_shape(f"{split}_{index}_{chosen}", shape, size * factor, density)
