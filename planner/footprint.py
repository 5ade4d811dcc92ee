"""2-D footprints of objects on the table: convex polygons in the table plane.

A footprint is an ``(k, 2)`` float array of polygon vertices, counter-clockwise, in metres. In the
*object-centred* frame its origin is the object's centre of mass projected on the table and its axes
are the world axes of the resting state's pose at yaw 0 (``RestingState.pose(xy=(0, 0), yaw=0)``).
:func:`place` moves it into the world frame for a pose ``(x, y, yaw)`` on the table, with the same
yaw convention as :meth:`affordplan.RestingState.pose` (a rotation about the world z axis).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from affordplan.checks import is_whole
from affordplan.errors import InputError
from affordplan.objects.model import ObjectModel

DISC_POINTS = 16  # vertices of the polygon standing for the disc in :func:`inflate`


def as_polygon(polygon: np.ndarray, name: str = "polygon") -> np.ndarray:
    arr = np.asarray(polygon, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3:
        raise InputError(f"{name} must be an (k, 2) array with k >= 3, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} contains NaN or infinite coordinates")
    return arr


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Convex hull of (n, 2) points as an (k, 2) counter-clockwise polygon, same units.

    Raises:
        InputError: fewer than 3 points, non-finite points, or points with no area (collinear).
    """
    points = as_polygon(points, "points")
    try:
        hull = ConvexHull(points)
    except QhullError as exc:
        raise InputError(f"points span no area (collinear or coincident): {exc}") from exc
    return points[hull.vertices].copy()  # qhull lists 2-D hull vertices counter-clockwise


def footprint(obj: ObjectModel, state: int) -> np.ndarray:
    """The object's shadow on the table in resting state ``state``, object-centred.

    The convex hull of the object's hull vertices posed by ``obj.resting_states[state].pose()``
    (xy = (0, 0), yaw = 0) and projected on the table plane.

    Args:
        obj: the object.
        state: index into ``obj.resting_states``.

    Returns:
        (k, 2) counter-clockwise polygon, metres; the centre of mass projects to the origin.

    Raises:
        InputError: ``state`` is not an index of ``obj.resting_states``.
    """
    states = obj.resting_states
    if not is_whole(state) or not 0 <= state < len(states):
        raise InputError(f"state must be an int in [0, {len(states)}), got {state!r}")
    R_world_object = states[int(state)].rotation
    p_world = np.asarray(obj.hull.vertices, dtype=float) @ R_world_object.T
    return convex_hull_2d(p_world[:, :2])


def inflate(polygon: np.ndarray, radius: float, n_disc: int = DISC_POINTS) -> np.ndarray:
    """Minkowski sum of a convex polygon with a disc of ``radius`` metres.

    The disc is replaced by the regular ``n_disc``-gon *circumscribing* it (vertices at
    ``radius / cos(pi / n_disc)``), so the result contains the exact inflated region and exceeds it by
    at most ``radius * (1 / cos(pi / n_disc) - 1)`` (2 % of ``radius`` for 16 points).

    Args:
        polygon: (k, 2) convex polygon, metres, any frame.
        radius: clearance, metres, >= 0 (0 returns the polygon's convex hull).
        n_disc: vertices of the polygon standing for the disc, >= 3.

    Returns:
        (m, 2) counter-clockwise convex polygon in the frame of ``polygon``.
    """
    polygon = as_polygon(polygon)
    if not (isinstance(radius, (int, float, np.floating)) and math.isfinite(radius) and radius >= 0):
        raise InputError(f"radius must be a finite number >= 0, got {radius!r}")
    if not isinstance(n_disc, (int, np.integer)) or n_disc < 3:
        raise InputError(f"n_disc must be an int >= 3, got {n_disc!r}")
    if radius == 0:
        return convex_hull_2d(polygon)
    angles = (np.arange(n_disc) + 0.5) * (2.0 * math.pi / n_disc)
    disc = (radius / math.cos(math.pi / n_disc)) * np.column_stack([np.cos(angles), np.sin(angles)])
    summed = (polygon[:, None, :] + disc[None, :, :]).reshape(-1, 2)
    return convex_hull_2d(summed)


def place(polygon: np.ndarray, x: float, y: float, yaw: float) -> np.ndarray:
    """An object-centred polygon moved to table pose ``(x, y, yaw)``.

    Args:
        polygon: (k, 2) polygon in the object-centred frame, metres.
        x, y: position of the object-centred origin on the table, world frame, metres.
        yaw: rotation about the world z axis, radians.

    Returns:
        (k, 2) polygon in the world frame, metres (orientation preserved).
    """
    polygon = as_polygon(polygon)
    pose = np.array([x, y, yaw], dtype=float)
    if not np.all(np.isfinite(pose)):
        raise InputError(f"pose (x, y, yaw) must be finite, got {(x, y, yaw)!r}")
    c, s = math.cos(pose[2]), math.sin(pose[2])
    R_world_object = np.array([[c, -s], [s, c]])
    return polygon @ R_world_object.T + pose[:2]


def area(polygon: np.ndarray) -> float:
    """Signed area (shoelace) of a polygon, square metres: positive when counter-clockwise."""
    polygon = as_polygon(polygon)
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
