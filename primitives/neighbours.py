"""A decision's neighbours: the same push with its motion turned a little, or from a contact moved a little.

A primitive's decision is a contact on the object's surface and a motion (world frame). Whether it succeeds can
hang on millimetres and degrees (``python -m primitives.sensitivity``), while the share of its neighbours that
succeed ranks one start's options much better than any success model yet: it is the part of the outcome a model
of the cloud and the decision can hope to predict. Both the sensitivity benchmark and the success models' smoothed
labels (:func:`primitives.success.collect_contrast` with ``neighbours``) execute these variants:

- **motion +-a**: the same contact, the motion turned by ``a`` about the world vertical;
- **contact +-d**: the same motion from a contact ``d`` along the surface's horizontal tangent at the contact (on a
  flat top, where there is none: along world x).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

MOTION_RAD = np.radians(3.0)  # default turn of the motion variants, radians
CONTACT_M = 0.002  # default shift of the contact variants, metres


def turn_about_vertical(v: np.ndarray, angle: float) -> np.ndarray:
    """``v`` (world) turned by ``angle`` (rad) about the world z axis."""
    return Rotation.from_rotvec([0.0, 0.0, angle]).apply(v)


def surface_tangent(normal: np.ndarray) -> np.ndarray:
    """The surface's horizontal unit tangent at a contact with outward ``normal`` (world); world x on a flat top."""
    along = np.cross(normal, [0.0, 0.0, 1.0])
    norm = np.linalg.norm(along)
    return along / norm if norm > 1e-6 else np.array([1.0, 0.0, 0.0])


def neighbour_decisions(contact: np.ndarray, normal: np.ndarray, motion_world: np.ndarray,
                        motion_rad: float = MOTION_RAD,
                        contact_m: float = CONTACT_M) -> list[tuple[np.ndarray, np.ndarray]]:
    """The four neighbours ``(contact, motion)`` (world, metres; motion as the simulator takes it) of a decision, in
    the order motion +a, motion -a, contact +d, contact -d (module docstring)."""
    along = surface_tangent(normal)
    return [(contact, turn_about_vertical(motion_world, motion_rad)),
            (contact, turn_about_vertical(motion_world, -motion_rad)),
            (contact + contact_m * along, motion_world),
            (contact - contact_m * along, motion_world)]
