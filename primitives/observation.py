"""What a skill's policy sees: a world-frame point cloud as per-point features in the parameter's goal frame.

Observation, per point (``(n_points, 9)`` float32): ``(x - cx, y - cy, z, nx, ny, nz, fx, fy, fz)``:
position relative to the cloud's centroid on the table plane (the policy is translation invariant in
the plane; height above the table matters), the outward normal, and the goal flow ``T_param p - p``
the parameter asks for (zero for the seed's objective), all expressed in the parameter's goal frame
(:func:`primitives.params.goal_frame`: the asked push direction is +x, the asked spin is
counter-clockwise, the roll tips towards -x; the world frame for the seed's objective). Metres. The
policy's motion is in the same frame; :meth:`SkillObservation.motion_to_world` maps it back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import Simulator
from primitives import params as skill_params
from primitives.params import SKILLS

PRIMITIVES = SKILLS  # the skills, in the one order primitives.params gives them
OBS_DIM = 9


@dataclass(frozen=True)
class SkillObservation:
    """What a skill sees before acting: the world cloud, the policy's input and the goal frame."""

    points: np.ndarray  # (n, 3) world frame, metres
    normals: np.ndarray  # (n, 3) world frame, outward unit normals
    obs: np.ndarray  # (n, OBS_DIM) float32, the policy's input (goal frame)
    params: dict | None  # checked parameters
    A_frame_world: np.ndarray  # (3, 3) world vectors -> goal frame
    acted_as: dict | None = None  # the stand-in request the policy is shown for params None (primitives.frames)

    def motion_to_world(self, motion: np.ndarray) -> np.ndarray:
        """A goal-frame motion in [-1, 1]^3 as a world-frame one, clipped to [-1, 1]^3 per world axis as
        :meth:`affordplan.Simulator.execute` clips it (a frame turned about the vertical can stretch an axis to
        sqrt(2)): what the simulator will execute."""
        return np.clip(self.A_frame_world.T @ np.asarray(motion, dtype=float), -1.0, 1.0)



def observation(points: np.ndarray, normals: np.ndarray, flow: np.ndarray | None = None,
                A_frame_world: np.ndarray | None = None) -> np.ndarray:
    """Per-point features of a world-frame cloud and its goal flow (see the module docstring).

    ``A_frame_world`` (3x3, keeps the vertical; identity by default) maps world vectors into the goal frame.
    """
    obs = np.zeros((len(points), OBS_DIM), dtype=np.float32)
    rel = np.array(points, dtype=float)
    rel[:, :2] -= rel[:, :2].mean(axis=0)
    A = np.eye(3) if A_frame_world is None else np.asarray(A_frame_world)
    obs[:, :3] = rel @ A.T
    obs[:, 3:6] = normals @ A.T
    if flow is not None:
        obs[:, 6:9] = flow @ A.T
    return obs


def observe_cloud(obj: ObjectModel, skill: str, params: dict | None, points: np.ndarray, normals: np.ndarray,
                  T_world_object: np.ndarray) -> SkillObservation:
    """The :class:`SkillObservation` of a world cloud of ``obj`` at ``T_world_object`` (params already checked)."""
    flow = skill_params.goal_flow(skill, params, points, T_world_object, obj)
    A = skill_params.goal_frame(skill, params, T_world_object, obj)
    return SkillObservation(points, normals, observation(points, normals, flow, A), params, A)


def skill_observation(sim: Simulator, skill: str, params: dict | None, n_points: int,
                      state: int | None = None) -> SkillObservation:
    """What a skill about to act in ``sim`` sees (raises :class:`InputError` for bad params)."""
    pose = sim.object_pose()
    if state is None:
        state = sim.obj.classify(pose)
    params = skill_params.check(skill, params, sim.obj, state)
    points, normals = sim.point_cloud(n_points)
    return observe_cloud(sim.obj, skill, params, points, normals, pose)
