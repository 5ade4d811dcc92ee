"""A decision's neighbours: the same push with its motion turned a little, or from a contact moved a little.

A primitive's decision is a contact on the object's surface and a motion (world frame). Whether it succeeds can
hang on millimetres and degrees (``python -m primitives.research.sensitivity``), while the share of its neighbours that
succeed ranks one start's options much better than any success model yet: it is the part of the outcome a model
of the cloud and the decision can hope to predict. Both the sensitivity benchmark and the success models' smoothed
labels (:func:`primitives.training.success.collect_contrast` with ``neighbours``) execute these variants
(:func:`neighbour_outcomes`):

- **motion +-a**: the same contact, the motion turned by ``a`` about the world vertical;
- **contact +-d**: the same motion from a contact ``d`` along the surface's horizontal tangent at the contact (on a
  flat top, where there is none: along world x).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from primitives import rewards

if TYPE_CHECKING:
    from affordplan.sim import Simulator

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


def judged_execution(sim: Simulator, skill: str, params: dict | None, contact: np.ndarray, motion_world: np.ndarray,
                     normal: np.ndarray) -> bool:
    """Execute ``skill``'s decision in ``sim`` from where it stands and judge it as the skill does: by ``params``'s
    criterion, a guarded (invalid) execution failing."""
    out = sim.execute(contact, motion_world, normal=normal)
    return bool(out.valid and rewards.success(skill, out.pose_before, out.pose_after, params, sim.obj))


def neighbour_outcomes(sim: Simulator, start, skill: str, params: dict | None, contact: np.ndarray,
                       normal: np.ndarray, motion_world: np.ndarray, motion_rad: float = MOTION_RAD,
                       contact_m: float = CONTACT_M) -> list[bool]:
    """The outcomes of a decision's four neighbours (:func:`neighbour_decisions`, in that order), each executed from
    the simulator state ``start`` (:meth:`Simulator.snapshot`) with the decision's ``normal`` and judged by
    :func:`judged_execution`. ``sim`` is left where the last one ended."""
    outcomes = []
    for point, motion in neighbour_decisions(contact, normal, motion_world, motion_rad, contact_m):
        sim.restore(start)
        outcomes.append(judged_execution(sim, skill, params, point, motion, normal))
    return outcomes
