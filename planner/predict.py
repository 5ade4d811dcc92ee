"""What the planner expects of a skill: its ideal effect on the pose, and its predicted success.

The planner reasons about poses it has not reached yet, so it cannot ask a simulator for a point
cloud there. It draws the cloud the skills' sensor (:func:`primitives.skills.skills_sensor`, the one their weights
were trained on) would return with the object at the expected pose, through the simulator's own sensor model
(:mod:`affordplan.sim.sensor`): for ``"cameras"`` the same depth cameras cast their rays into a scene of the table,
the obstacles and the object posed there; for ``"surface"`` the same surface sample. It then asks the skill's success
model. The *ideal effect* of a skill is the rigid motion its parameter
names (:func:`primitives.params.goal_transform`), followed, for a roll, by settling into the target
state at the same place on the table.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import mujoco
import numpy as np

from affordplan.errors import InputError
from affordplan.objects.model import ObjectModel
from affordplan.sim.scene import OBJECT_BODY, build_mjcf, set_free_pose
from affordplan.sim.sensor import CameraSensor, surface_cloud
from affordplan.world import Box
from primitives import params as skill_params
from primitives.observation import observe_cloud
from primitives.outcome_model import OutcomeModel
from primitives.params import SKILLS
from primitives.skills import Skill, load_skills, skills_sensor

N_POINTS = 256


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
        obstacles: boxes that occlude the cameras' view of predicted poses.

    Raises:
        InputError: both ``skills`` and ``weights_dir``, or an unusable ``weights_dir``.
    """

    def __init__(self, obj: ObjectModel, skills: dict[str, Skill] | None = None, seed: int = 0,
                 weights_dir: str | os.PathLike | None = None, obstacles: tuple[Box, ...] = ()):
        if skills is not None and weights_dir is not None:
            raise InputError("give skills or weights_dir, not both")
        self.obj = obj
        self.skills = skills or load_skills(weights_dir)
        self.sensor = skills_sensor(self.skills)
        # What the shipped skills' calls achieve (primitives.outcome_model), for the plans' odds; None for skills
        # given here or loaded from a weights folder, which the shipped outcome models do not describe
        self.outcomes: dict[str, OutcomeModel] | None = None
        if skills is None and weights_dir is None:
            self.outcomes = {name: OutcomeModel.load(name) for name in SKILLS}
        self.obstacles = tuple(obstacles)
        self._samples, self._normals = obj.surface_samples()
        self._seed = seed
        self._cameras: tuple[mujoco.MjData, CameraSensor, int] | None = None
        self._radius = float(np.max(np.linalg.norm(obj.hull.vertices, axis=1)))  # bounds the object, metres
        self.queries = 0

    def _camera_scene(self) -> tuple[mujoco.MjData, CameraSensor, int]:
        """The scene the cameras look into (table, obstacles, the object; the finger parked out of view), built on
        first use."""
        if self._cameras is None:
            model = mujoco.MjModel.from_xml_string(build_mjcf(self.obj, self.obstacles, "finger"))
            body = model.body(OBJECT_BODY).id
            self._cameras = (mujoco.MjData(model), CameraSensor(model, body),
                             int(model.jnt_qposadr[model.body_jntadr[body]]))
        return self._cameras

    def cloud(self, T_world_object: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``N_POINTS`` points and normals (world) that the skills' sensor returns with the object at a settled
        pose; the surface sample where no camera would see it."""
        rng = np.random.default_rng(self._seed)
        if self.sensor == "cameras":
            data, camera, adr = self._camera_scene()
            set_free_pose(data, adr, T_world_object)
            mujoco.mj_kinematics(camera.model, data)
            points, normals = camera.cloud(data, rng, self._radius, N_POINTS)
            if len(points):
                return points, normals
        return surface_cloud(self._samples, self._normals, T_world_object, rng, N_POINTS)

    def observation(self, skill: str, params: dict | None, T_world_object: np.ndarray) -> np.ndarray:
        """The observation the skill's policy would get at ``T_world_object`` (a settled pose)."""
        points, normals = self.cloud(T_world_object)
        return observe_cloud(self.obj, skill, params, points, normals, T_world_object).obs

    def p_success(self, skill: str, params: dict | None, T_world_object: np.ndarray) -> float:
        """Predicted P(success) of ``skill`` with ``params`` at a settled pose."""
        return float(self.p_success_many([(skill, params, T_world_object)])[0])

    def p_success_many(self, queries: list[tuple[str, dict | None, np.ndarray]]) -> np.ndarray:
        """Batched :meth:`p_success` (one network pass per skill)."""
        out = self._ask(queries, lambda skill, obs, parameterised: skill.success_probability_obs(obs, parameterised,
                                                                                          sensor=self.sensor))
        self.queries += len(queries)
        return out

    def spread_many(self, queries: list[tuple[str, dict | None, np.ndarray]]) -> np.ndarray:
        """The success models' member disagreement on each of :meth:`p_success_many`'s queries
        (:meth:`primitives.skills.Skill.success_spread_obs`): how uncertain each rating is."""
        return self._ask(queries, lambda skill, obs, parameterised: skill.success_spread_obs(obs, parameterised,
                                                                                      sensor=self.sensor))

    def _ask(self, queries: list[tuple[str, dict | None, np.ndarray]],
             answer: Callable[[Skill, np.ndarray, bool], np.ndarray]) -> np.ndarray:
        """``answer(skill, observations, parameterised)`` for the queries, batched per skill and parameterisation."""
        out = np.zeros(len(queries))
        for skill in SKILLS:
            for parameterised in (True, False):
                idx = [i for i, q in enumerate(queries) if q[0] == skill and (q[1] is not None) == parameterised]
                if idx:
                    obs = np.stack([self.observation(*queries[i]) for i in idx])
                    out[idx] = answer(self.skills[skill], obs, parameterised)
        return out

