"""Resting states: the distinct ways an object can lie still on the table.

``trimesh.poses.compute_stable_poses`` gives one stable pose per hull facet that the centre of mass
projects into, with its quasi-static probability. Two of them are the same resting state when the
object-frame "up" vectors agree; a round object's side facets (each a few degrees from the next)
form a *rolling family* that is one state too. Both cases are one rule: facets whose up-vectors are
within ``merge_angle`` of each other are linked, and each connected group is a state. With the
default of 25 deg, round shapes modelled with 16 or more facets around (22.5 deg apart) form one
rolling family, so a cylinder has 3 states and a cube 6; faces closer than 25 deg are one state
(no primitive tells them apart: a roll turns the object by >= 60 deg).

Yaw convention: every state has a ``heading`` (an object-frame unit vector perpendicular to the
state's up-vector; a rolling family's roll axis). A pose of the state has yaw ``a`` when that
vector points along ``(cos a, sin a)`` on the table. ``RestingState.rotation`` is the pose at yaw 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import trimesh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from affordplan.errors import InputError
from affordplan.geometry import rot_z, yaw_of_direction

DEFAULT_MERGE_ANGLE = math.radians(25.0)
MIN_PROBABILITY = 0.01  # states rarer than this are dropped; classify maps them to the nearest kept
MAX_SYMMETRY_ORDER = 64  # turns of 2 pi / n about the vertical tried for n = 2..64
SYMMETRY_TOLERANCE = 2e-4  # metres: a turned vertex this close to a vertex coincides with it


@dataclass(frozen=True)
class RestingState:
    """One resting state of an object on the table.

    Attributes:
        index: position in the object's list (sorted by probability, most likely first).
        rotation: 3x3 ``R_world_object`` of the most likely member pose at yaw 0 (of tied mirror-image
            members, the one with the smallest up-vector x, then y, then the largest z).
        height: the centre of mass above the table in that pose, metres.
        probability: quasi-static probability of landing in this state (sums to 1 over states).
        up: object-frame unit vector pointing up in ``rotation``.
        heading: object-frame unit vector that defines yaw (see the module docstring).
        member_ups: (k, 3) object-frame up-vectors of every merged stable pose, in the order of ``rotation``'s
            tie rule (likeliest first).
        roll_axis: object-frame unit axis of a rolling family, else ``None``.
    """

    index: int
    rotation: np.ndarray
    height: float
    probability: float
    up: np.ndarray
    heading: np.ndarray
    member_ups: np.ndarray = field(repr=False)
    roll_axis: np.ndarray | None = None

    @property
    def is_rolling_family(self) -> bool:
        return self.roll_axis is not None

    def yaw_of(self, R_world_object: np.ndarray) -> float:
        """Yaw (radians) of an orientation of this state."""
        return yaw_of_direction(R_world_object @ self.heading)

    def pose(self, xy=(0.0, 0.0), yaw: float = 0.0) -> np.ndarray:
        """4x4 world pose of this state at table position ``xy`` (metres) and ``yaw`` (radians)."""
        T = np.eye(4)
        T[:3, :3] = rot_z(yaw) @ self.rotation
        T[:3, 3] = (xy[0], xy[1], self.height)
        return T


class _UnionFind:
    def __init__(self, n: int):
        self.parent = list(range(n))

    def find(self, i: int) -> int:
        while self.parent[i] != i:
            self.parent[i] = self.parent[self.parent[i]]
            i = self.parent[i]
        return i

    def union(self, i: int, j: int) -> None:
        self.parent[self.find(i)] = self.find(j)


def _heading(up: np.ndarray, roll_axis: np.ndarray | None) -> np.ndarray:
    if roll_axis is not None:
        v = roll_axis - np.dot(roll_axis, up) * up
    else:  # the object axis least aligned with up, made perpendicular to up
        e = np.eye(3)[int(np.argmin(np.abs(up)))]
        v = e - np.dot(e, up) * up
    return v / np.linalg.norm(v)


def _roll_axis(ups: np.ndarray) -> np.ndarray | None:
    """Axis of a rolling family: the normal of the plane (or cone) its up-vectors sweep."""
    if len(ups) < 3:
        return None
    spread = np.degrees(np.arccos(np.clip(ups @ ups.T, -1.0, 1.0))).max()
    if spread < 30.0:  # a face that compute_stable_poses split in near-duplicates, not a family
        return None
    centred = ups - ups.mean(axis=0)
    axis = np.linalg.svd(centred)[2][-1]
    sign = 1.0 if axis[int(np.argmax(np.abs(axis)))] > 0 else -1.0
    return sign * axis / np.linalg.norm(axis)


def _member_order(members: list[int], probs: np.ndarray, ups: np.ndarray) -> list[int]:
    """A state's member poses, likeliest first; the first is the one the state is posed on.

    Mirror-image facets of a symmetric mesh tie (their probabilities agree to the last bits, or all
    but the last); ties go to the smallest object-frame up-vector x, then y, then the largest z
    (rounded to 1e-6). Left to the order of ``compute_stable_poses`` the order hung on how numpy's
    sort orders equal keys, which differs between CPUs, and so did the state's pose at yaw 0 (a few
    degrees of tilt, or a turn about a rolling family's axis: the mug lay leaning on one side of its
    handle or the other) and the order of ``member_ups``. Of the 48 such lexicographic rules this one
    keeps the mug as the demo and its figures have it.
    """
    def key(i: int) -> tuple[float, ...]:
        x, y, z = (round(float(c), 6) for c in ups[i])
        return -round(float(probs[i]), 9), x, y, -z

    return sorted(members, key=key)


def compute_resting_states(
    hull: trimesh.Trimesh, merge_angle: float = DEFAULT_MERGE_ANGLE,
    min_probability: float = MIN_PROBABILITY,
) -> list[RestingState]:
    """Resting states of a solid whose centre of mass is at the origin of ``hull``'s frame.

    ``hull`` is the object's convex hull (the object rests on its hull) in the object frame.
    States whose probability is below ``min_probability`` (a mug balanced on its handle and rim)
    are dropped and the rest renormalised.
    """
    transforms, probs = trimesh.poses.compute_stable_poses(hull, center_mass=np.zeros(3))
    if len(transforms) == 0:
        return []
    ups = np.array([T[:3, :3].T @ np.array([0.0, 0.0, 1.0]) for T in transforms])
    ups /= np.linalg.norm(ups, axis=1, keepdims=True)
    uf = _UnionFind(len(ups))
    cos_merge = math.cos(merge_angle)
    dots = ups @ ups.T
    for i, j in zip(*np.nonzero(np.triu(dots >= cos_merge, k=1))):
        uf.union(int(i), int(j))
    groups: dict[int, list[int]] = {}
    for i in range(len(ups)):
        groups.setdefault(uf.find(i), []).append(i)

    states = []
    for members in groups.values():
        members = _member_order(members, probs, ups)
        best = members[0]
        member_ups = ups[members]
        roll_axis = _roll_axis(member_ups)
        up = ups[best]
        heading = _heading(up, roll_axis)
        R = transforms[best][:3, :3]
        R = rot_z(-yaw_of_direction(R @ heading)) @ R
        height = float(-(hull.vertices @ R.T)[:, 2].min())
        states.append(
            dict(rotation=R, height=height, probability=float(probs[members].sum()), up=up,
                 heading=heading, member_ups=member_ups, roll_axis=roll_axis)
        )
    # Most likely first. Ties (a cube's six faces; a box's opposite faces) are broken by the up-vector, so that
    # the order does not hang on the last bits of trimesh's probabilities (which differ between its releases).
    # Tied states get one probability (the mean of the tie), so that the list stays sorted exactly.
    states.sort(key=lambda s: (-round(s["probability"], 4), *(-np.round(s["up"][::-1], 3))))
    ties: dict[float, list[dict]] = {}
    for s in states:
        ties.setdefault(round(s["probability"], 4), []).append(s)
    for tie in ties.values():
        mean = float(np.mean([s["probability"] for s in tie]))
        for s in tie:
            s["probability"] = mean
    states = [s for s in states if s["probability"] >= min_probability] or states[:1]
    total = sum(s["probability"] for s in states)
    return [
        RestingState(index=i, **{**s, "probability": s["probability"] / total})
        for i, s in enumerate(states)
    ]


def yaw_period(vertices: np.ndarray, up: np.ndarray, max_order: int = MAX_SYMMETRY_ORDER,
               tol: float = SYMMETRY_TOLERANCE) -> float:
    """The smallest turn about ``up`` (object-frame unit vector through the origin) that maps ``vertices`` onto
    themselves: ``2 pi / n`` for the largest ``n <= max_order`` that does, ``2 pi`` when none (radians).

    A resting state whose pose turned by this angle is the same solid in the same place: an upright 32-facet
    cylinder has a period of 11.25 deg, a cube on a face 90 deg, a lying box 180 deg. The test is on the mesh's
    vertices (a turned vertex must land within ``tol`` metres of a vertex), so a scanned mesh, whose vertices
    never land on each other, has no symmetry: the check errs towards asking for the yaw.
    """
    vertices = np.asarray(vertices, dtype=float)
    up = np.asarray(up, dtype=float) / np.linalg.norm(up)
    tree = cKDTree(vertices)
    for n in range(max_order, 1, -1):
        turned = Rotation.from_rotvec(up * (2.0 * math.pi / n)).apply(vertices)
        if tree.query(turned, distance_upper_bound=tol)[0].max() <= tol:
            return 2.0 * math.pi / n
    return 2.0 * math.pi


def classify(states: list[RestingState], R_world_object: np.ndarray) -> int:
    """Index of the state whose member up-vectors come closest to the pose's up-vector."""
    R = np.asarray(R_world_object, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise InputError("classify takes a finite rotation (or 4x4 pose); it has NaN, infinite or misshapen entries")
    up = R.T @ np.array([0.0, 0.0, 1.0])
    best = max(states, key=lambda s: float(np.max(s.member_ups @ up)))
    return best.index


def angle_to_state(state: RestingState, R_world_object: np.ndarray) -> float:
    """Angle (radians) between a pose's up-vector and the nearest up-vector of ``state``."""
    R = np.asarray(R_world_object, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise InputError("classify takes a finite rotation (or 4x4 pose); it has NaN, infinite or misshapen entries")
    up = R.T @ np.array([0.0, 0.0, 1.0])
    return float(np.arccos(np.clip(np.max(state.member_ups @ up), -1.0, 1.0)))
