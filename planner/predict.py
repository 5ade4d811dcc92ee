"""What the planner expects of a skill: its ideal effect on the pose, and its predicted success.

The planner reasons about poses it has not reached yet, so it cannot ask a simulator for a point
cloud there. It draws the cloud the simulator would see from the object model posed at the expected
pose (the same surface sample, points touching the table left out; :meth:`affordplan.Simulator.point_cloud`)
and asks the skill's success model. The *ideal effect* of a skill is the rigid motion its parameter
names (:func:`primitives.params.goal_transform`), followed, for a roll, by settling into the target
state at the same place on the table.
"""

from __future__ import annotations

import os

import numpy as np

from affordplan.errors import InputError
from affordplan.geometry import transform_points
from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import TABLE_CONTACT_HEIGHT
from primitives import params as skill_params
from primitives.env import observe_cloud
from primitives.skills import Skill, load_skills

N_POINTS = 256
SKILLS = ("push", "spin", "roll")


def settle_to_state(obj: ObjectModel, T_world_object: np.ndarray, state: int) -> np.ndarray:
    """The resting pose of ``state`` nearest to a (tipped) pose: same xy, the state's height, nearest yaw."""
    s = obj.resting_states[state]
    yaw = s.yaw_of(T_world_object[:3, :3])
    return s.pose(T_world_object[:2, 3], yaw)


def expected_pose(obj: ObjectModel, skill: str, params: dict, T_world_object: np.ndarray) -> np.ndarray:
    """The pose after ``skill`` with ``params`` does exactly what it is asked."""
    T = skill_params.goal_transform(skill, params, T_world_object, obj) @ T_world_object
    if skill == "roll":
        return settle_to_state(obj, T, params["target"])
    return T


def state_pose(obj: ObjectModel, state: int, x: float, y: float, yaw: float) -> np.ndarray:
    return obj.resting_states[state].pose((x, y), yaw)


class Predictor:
    """The three skills and their success models, queried on synthesised clouds.

    Args:
        obj: the object.
        skills: ``{"push": Skill, ...}``; by default the shipped skills, or with ``weights_dir`` the skills of that
            folder (:func:`primitives.skills.load_skills`: a candidate set; a skill without files there shipped).
        seed: seeds the choice of cloud points (queries are deterministic for a given seed).
        weights_dir: see ``skills``; not combined with it.

    Raises:
        InputError: both ``skills`` and ``weights_dir``, or an unusable ``weights_dir``.
    """

    def __init__(self, obj: ObjectModel, skills: dict[str, Skill] | None = None, seed: int = 0,
                 weights_dir: str | os.PathLike | None = None):
        if skills is not None and weights_dir is not None:
            raise InputError("give skills or weights_dir, not both")
        self.obj = obj
        self.skills = skills or load_skills(weights_dir)
        self._samples, self._normals = obj.surface_samples()
        self._seed = seed
        self.queries = 0

    def observation(self, skill: str, params: dict | None, T_world_object: np.ndarray) -> np.ndarray:
        """The observation the skill's policy would get at ``T_world_object`` (a settled pose)."""
        points = transform_points(T_world_object, self._samples)
        normals = self._normals @ T_world_object[:3, :3].T
        visible = np.flatnonzero(points[:, 2] > TABLE_CONTACT_HEIGHT)
        rng = np.random.default_rng(self._seed)
        idx = rng.choice(visible, size=N_POINTS, replace=len(visible) < N_POINTS)
        return observe_cloud(self.obj, skill, params, points[idx], normals[idx], T_world_object).obs

    def p_success(self, skill: str, params: dict | None, T_world_object: np.ndarray) -> float:
        """Predicted P(success) of ``skill`` with ``params`` at a settled pose."""
        return float(self.p_success_many([(skill, params, T_world_object)])[0])

    def p_success_many(self, queries: list[tuple[str, dict | None, np.ndarray]]) -> np.ndarray:
        """Batched :meth:`p_success` (one network pass per skill)."""
        out = np.zeros(len(queries))
        for skill in SKILLS:
            for parameterised in (True, False):
                idx = [i for i, q in enumerate(queries) if q[0] == skill and (q[1] is not None) == parameterised]
                if idx:
                    obs = np.stack([self.observation(*queries[i]) for i in idx])
                    out[idx] = self.skills[skill].success_probability_obs(obs, parameterised)
        self.queries += len(queries)
        return out

