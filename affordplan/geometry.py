"""Rigid-body helpers on 4x4 homogeneous poses.

Conventions: world frame z up, table top at z = 0; poses are ``T_world_object`` (4x4, metres);
rotations go through :class:`scipy.spatial.transform.Rotation`, never hand-written quaternions.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from affordplan.errors import InputError

WORLD_Z = np.array([0.0, 0.0, 1.0])


def make_pose(rotation: np.ndarray | None = None, translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Build a 4x4 pose from a 3x3 rotation (identity by default) and a translation in metres."""
    T = np.eye(4)
    if rotation is not None:
        T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


def rot_z(yaw: float) -> np.ndarray:
    """3x3 rotation about the world z axis by ``yaw`` radians."""
    return Rotation.from_rotvec([0.0, 0.0, yaw]).as_matrix()


def check_pose(T: np.ndarray, name: str = "pose") -> np.ndarray:
    """Return ``T`` as a float 4x4 array, or raise :class:`InputError` if it is malformed."""
    try:
        T = np.asarray(T, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} must be a 4x4 homogeneous matrix of numbers") from None
    if T.shape != (4, 4):
        raise InputError(f"{name} must be a 4x4 homogeneous matrix, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise InputError(f"{name} contains NaN or infinite entries")
    return T


def relative_rotation(T0: np.ndarray, T1: np.ndarray) -> tuple[float, np.ndarray]:
    """Rotation taking pose ``T0`` to ``T1``, expressed in the world frame.

    Returns ``(theta, w)``: the angle in radians (in [0, pi]) of ``R = R1 R0^T`` and its unit axis
    in the world frame. At ``theta == 0`` the axis is undefined and ``w = z`` by convention.
    """
    T0 = check_pose(T0, "T0")
    T1 = check_pose(T1, "T1")
    R = T1[:3, :3] @ T0[:3, :3].T
    rotvec = Rotation.from_matrix(R).as_rotvec()
    theta = float(np.linalg.norm(rotvec))
    if theta < 1e-9:
        return 0.0, WORLD_Z.copy()
    return theta, rotvec / theta


def yaw_of_direction(v: np.ndarray) -> float:
    """Heading (radians) of a world vector projected onto the table plane."""
    return math.atan2(float(v[1]), float(v[0]))


def wrap_angle(a: float) -> float:
    """Wrap an angle in radians to [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def wrap_period(a: float, period: float) -> float:
    """Wrap an angle to ``[-period / 2, period / 2)`` (radians; a ``period`` of ``2 pi`` is :func:`wrap_angle`)."""
    if period >= 2.0 * math.pi - 1e-12:
        return wrap_angle(a)
    return (a + 0.5 * period) % period - 0.5 * period


def transform_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a 4x4 pose to (n, 3) points."""
    return points @ T[:3, :3].T + T[:3, 3]
