"""Trained primitives as parameterised skills a planner or a user can call on a simulator.

    from primitives import load_skill
    push = load_skill("push")                                   # shipped weights
    push.success_probability(sim, {"direction": 0.0})           # learned P(success), no physics run
    outcome = push.execute(sim, {"direction": 0.0})             # Outcome with .success
    contact, motion = push.act(sim, {"direction": 0.0})         # what the policy would do
    push.execute(sim, PushParams(direction=0.0))                # the same request, typed

Parameters (:mod:`primitives.params`): push ``{"direction": rad}`` (world heading), spin
``{"angle": rad}`` (signed, 15-45 deg), roll ``{"target": state index}`` (one roll away), or the same as
:class:`~primitives.params.PushParams`, :class:`~primitives.params.SpinParams`,
:class:`~primitives.params.RollParams`; ``None`` is the seed's objective. ``Outcome.success`` applies the matching
criterion (:func:`primitives.rewards.success`).
The policy acts greedily, so ``act`` and ``execute`` are deterministic for a given cloud.

**Frame search** (:mod:`primitives.frames`): with a :class:`~primitives.frames.FrameSearch`, the skill looks at
the cloud in the goal frames its request leaves free and acts in the one its success model rates likeliest;
``success_probability`` is that rating, calibrated for the choice. The shipped skills use the search shipped
beside their weights (``weights/{name}_frames.json``) where there is one; without, they act in the goal frame, as
trained.

**Ratings per sensor**: a success model, and the calibration of a frame search built on it, are fitted to clouds of
one sensor; depth-camera clouds and the privileged surface sample differ (partial views, estimated normals), and
ratings fitted to one misrank the options of the other. The ratings shipped beside a policy are for the sensor it
was trained on (:attr:`Skill.sensor`); a folder ``weights/{sensor}/`` may hold the same skill's ratings fitted to
another sensor's clouds (``{name}_success.pt``, ``{name}_frames.json``, ``{name}_success_searched.pt``: the same
policy, fitted together). A skill called on a simulator then rates and picks its options with the ratings of that
simulator's sensor (:meth:`Skill.ratings`), and a planner predicting clouds of a sensor asks for that sensor's.

**A policy per sensor**: a folder ``weights/{sensor}/`` may also hold a policy of its own (``{name}.pt``), chosen
for that sensor's clouds, with its ratings beside it (``{name}_success.pt`` at least; any of ``{name}_frames.json``,
``{name}_success_searched.pt``, all fitted to that policy). A skill called on a simulator of that sensor then acts,
rates and picks with that policy and its ratings (:meth:`Skill.ratings`): one skill, the best policy for each sensor.

**Searched success model**: rating a request through the frame search runs the policy once per free frame (12
for a spin by an angle: ~22 ms on one core). Where one is shipped (``weights/{name}_success_searched.pt``,
``python -m primitives.success train NAME --frames shipped``), ``success_probability`` asks it instead: a success
model trained on the frame-searched skill's own outcomes that rates it from the goal frame alone (one policy
decision and the net, ~2 ms). The skill still *acts* through the frame search.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import torch

from affordplan.errors import InputError, ReachabilityError
from affordplan.sim.sensor import SENSORS
from affordplan.sim.simulator import Outcome, Simulator
from primitives import rewards
from primitives.frames import FrameSearch, reframe_obs, shipped_frame_search  # noqa: F401 (re-exported)
from primitives.networks import HybridActorCritic
from primitives.observation import SkillObservation, skill_observation
from primitives.params import SKILLS, ParamsLike, SkillName, as_params, motion_loop
from primitives.policy import greedy_action, load_policy
from primitives.success_model import SuccessModel, load_success_net
from primitives.weights_file import SHIPPED_DIR as WEIGHTS_DIR
from primitives.weights_file import rated_for, rating_name, rating_path, sensor_policy

MAX_REACH_RETRIES = 8  # next-best contacts tried after the arm could not reach the policy's choice
UNREACHABLE_RADIUS = 0.02  # metres: points this close to an unreachable contact are masked out with it


class Skill:
    """A trained primitive acting greedily on a simulator's point cloud, with its success model.

    ``success_weights``, ``frame_search`` and ``searched_weights`` are the ratings for clouds of the sensor the
    policy was trained on (:attr:`sensor`); ``ratings_by_sensor`` maps another sensor's name to a :class:`Skill`
    of the same name that acts on that sensor's clouds: the same policy with ratings fitted to them, or a policy
    chosen for them with its own ratings (:meth:`ratings`).
    """

    def __init__(self, name: SkillName, model: HybridActorCritic, n_points: int = 256,
                 success_weights: str | os.PathLike | None = None, frame_search: FrameSearch | None = None,
                 searched_weights: str | os.PathLike | None = None,
                 ratings_by_sensor: dict[str, Skill] | None = None):
        self.name: SkillName = name
        self.model = model
        # The clouds the policy was trained on (its weights' metadata): what a simulator should show it.
        self.sensor: str = getattr(model, "sensor", "cameras")
        self.n_points = n_points
        self._success_weights = success_weights
        self._success: SuccessModel | None = None
        self.frame_search = frame_search
        self._searched_weights = searched_weights
        self._searched: SuccessModel | None = None
        self._by_sensor = dict(ratings_by_sensor or {})
        for sensor, other in self._by_sensor.items():
            if other.name != name or other._by_sensor:
                raise InputError(f"the {sensor} skill of {name} must be a {name} skill without sensors of its own")

    def ratings(self, sensor: str | None) -> Skill:
        """The skill that acts on and rates clouds of ``sensor``: this one, or the one given for that sensor where
        there is one (the same policy with ratings fitted to those clouds, or a policy chosen for them with its own
        ratings). ``None``: this one."""
        return self._by_sensor.get(sensor, self) if sensor is not None else self

    @property
    def rated_sensors(self) -> tuple[str, ...]:
        """The sensors this skill has ratings fitted for: its policy's own first."""
        return (self.sensor, *sorted(self._by_sensor))

    def frames(self, params: ParamsLike) -> np.ndarray:
        """The goal frames this skill tries for (checked) ``params``: ``(m, 3, 3)``, the identity first."""
        frames = FrameSearch() if self.frame_search is None else self.frame_search
        return frames.frames(self.name, as_params(self.name, params))

    def _observe_rated(self, sim: Simulator, params: ParamsLike = None) -> tuple[SkillObservation, float | None]:
        """:meth:`observe` and, where frames were searched, the calibrated rating of the chosen one (with the
        ratings of ``sim``'s sensor)."""
        rated = self.ratings(getattr(sim, "sensor", None))
        if rated is not self:
            return rated._observe_rated(sim, params)
        seen = skill_observation(sim, self.name, as_params(self.name, params), self.n_points)
        if self.frame_search is None or not self.frame_search.searches(self.name, seen.params):
            return seen, None
        seen, p = self.frame_search.select(self.name, seen, self.success_model.predict, sim,
                                          decide=self.success_model.rate_and_decide)
        return seen, float(self.frame_search.calibrate(p, seen.params is not None))

    def observe(self, sim: Simulator, params: ParamsLike = None) -> SkillObservation:
        """Cloud, the policy's observation, the checked params and the goal frame (raises InputError).

        With a frame search, the goal frame is the free frame the success model rates likeliest (for the seed's
        objective, of the stand-in requests' as well: ``acted_as``; :mod:`primitives.frames`).
        """
        return self._observe_rated(sim, params)[0]

    def _decide(self, seen: SkillObservation,
                allowed: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The greedy contact (world), its normal and the world-frame motion, among ``allowed`` points."""
        idx, motion, _ = greedy_action(self.model, seen.obs, allowed)
        return seen.points[idx], seen.normals[idx], seen.motion_to_world(motion)

    def act(self, sim: Simulator, params: ParamsLike = None) -> tuple[np.ndarray, np.ndarray]:
        """The contact point (world, metres) and world-frame motion in [-1, 1]^3 the policy picks (the policy for
        ``sim``'s sensor: :meth:`ratings`)."""
        rated = self.ratings(getattr(sim, "sensor", None))
        if rated is not self:
            return rated.act(sim, params)
        contact, _, motion = self._decide(self.observe(sim, params))
        return contact, motion

    def execute(self, sim: Simulator, params: ParamsLike = None, stop_at_angle: bool = True,
                steer: bool = True) -> Outcome:
        """Act and execute; ``Outcome.success``: the criterion for ``params`` was met (and the sample valid).

        With the arm, a contact it cannot reach (:class:`ReachabilityError`, raised before any physics) or
        whose pre-contact point it cannot come down to (:meth:`Simulator.approach_clear`: a wall or a
        handle above it) is masked out together with the points within ``UNREACHABLE_RADIUS`` of it, and the
        policy's next best contact is tried, up to ``MAX_REACH_RETRIES`` times; the last try is executed as
        it is (a blocked descent then fails without touching anything, an unreachable contact raises).
        Without this, a planner asking for the same push again meets the same contact every time.
        A spin by an angle ends its motion once the object has turned that far (:func:`primitives.params.motion_stop`);
        ``stop_at_angle=False`` runs its full motion, as plans execute spins (on the 200 validation plan tasks the
        stopping spin cost plans 9.29 -> 10.26 primitives over the tasks both reached, 153 -> 150 reached).
        A push bends its fingertip's path against the object's turn while it runs and goes on until the object has
        travelled far enough (:func:`primitives.params.motion_loop`); ``steer=False`` pushes straight along the
        policy's motion, open-loop as HACMan's protocol has it (as plans push).
        The policy and ratings are those for ``sim``'s sensor (:meth:`ratings`).
        """
        rated = self.ratings(getattr(sim, "sensor", None))
        if rated is not self:
            return rated.execute(sim, params, stop_at_angle, steer)
        seen = self.observe(sim, params)
        T_world_object = sim.object_pose()
        loop = motion_loop(self.name, seen.params, T_world_object, stop_at_angle=stop_at_angle, steer=steer)
        allowed = np.ones(len(seen.points), dtype=bool)
        retries = 0
        while True:
            contact, normal, motion = self._decide(seen, allowed)
            last_try = retries >= MAX_REACH_RETRIES
            try:
                if last_try or sim.approach_clear(contact, normal):
                    out = sim.execute(contact, motion, normal=normal, **loop.as_kwargs())
                    break
            except ReachabilityError:
                if last_try:
                    raise
            allowed &= np.linalg.norm(seen.points - contact, axis=1) > UNREACHABLE_RADIUS
            retries += 1
            if not allowed.any():
                raise ReachabilityError(f"{self.name}: no contact the arm can reach and come down to")
        out.success = bool(out.valid and rewards.success(self.name, out.pose_before, out.pose_after,
                                                         seen.params, sim.obj))
        return out

    @property
    def success_model(self) -> SuccessModel:
        if self._success is None:
            self._success = SuccessModel(self.model, load_success_net(self.name, self._success_weights))
        return self._success

    @property
    def searched_model(self) -> SuccessModel | None:
        """The searched success model (rates the frame-searched skill from the goal frame), or ``None``: the
        skill acts in the goal frame, none was given, or its search reports its own rating
        (:attr:`primitives.frames.FrameSearch.reports_rating`)."""
        if self.frame_search is None or self.frame_search.reports_rating:
            return None
        return self._obs_rater()

    def _obs_rater(self) -> SuccessModel | None:
        """What rates an observation alone (:meth:`success_probability_obs`): the searched success model where one was
        given, also where the search reports its ranker's score from a simulator
        (:attr:`primitives.frames.FrameSearch.reports_ranking`: that needs the simulator, whose object and resting
        state its stand-in requests need); ``None`` where there is none or the search reports its own rating."""
        search = self.frame_search
        if search is None or self._searched_weights is None or (search.reports_rating and not search.reports_ranking):
            return None
        if self._searched is None:
            self._searched = SuccessModel(self.model, load_success_net(self.name, self._searched_weights))
        return self._searched

    def success_probability(self, sim: Simulator, params: ParamsLike = None) -> float:
        """Predicted probability that ``execute(sim, params)`` succeeds now (no physics is run), rated with the
        ratings of ``sim``'s sensor."""
        rated = self.ratings(getattr(sim, "sensor", None))
        if rated is not self:
            return rated.success_probability(sim, params)
        if self.searched_model is not None:
            seen = skill_observation(sim, self.name, as_params(self.name, params), self.n_points)
            return float(self.searched_model.predict(seen.obs))
        seen, p = self._observe_rated(sim, params)
        return float(self.success_model.predict(seen.obs)) if p is None else p

    def success_probability_obs(self, obs: np.ndarray, parameterised: bool = True,
                                sensor: str | None = None) -> np.ndarray:
        """Predicted P(success) for observations ``(N, 9)`` or ``(B, N, 9)`` built in the goal frame
        (:func:`primitives.training.env.observe_cloud`), all with a parameter or all without; with a frame search, the
        searched success model's answer, or without one the calibrated rating of the best free frame (for the
        seed's objective a lower bound where the search has stand-ins: rating those needs the object and its
        resting state, which an observation does not carry; :meth:`success_probability` rates them). Where the search
        reports its ranker's score (spin with camera clouds), an observation is still rated by the searched model.
        ``sensor``: the sensor whose clouds the observations were built from (default: the policy's)."""
        rated = self.ratings(sensor)
        if rated is not self:
            return rated.success_probability_obs(obs, parameterised)
        rater = self._obs_rater()
        if rater is not None:
            return rater.predict(obs)
        frames = self.frames({} if parameterised else None)
        if len(frames) == 1:
            return self.success_model.predict(obs)
        obs = np.asarray(obs, dtype=np.float32)
        p = self.success_model.predict(reframe_obs(obs, frames).reshape(-1, *obs.shape[-2:]))
        return self.frame_search.calibrate(p.reshape(*obs.shape[:-2], len(frames)).max(axis=-1), parameterised)


    def success_spread_obs(self, obs: np.ndarray, parameterised: bool = True,
                           sensor: str | None = None) -> np.ndarray:
        """How much the success model's members disagree on the ratings :meth:`success_probability_obs` gives
        (:meth:`primitives.success_model.SuccessModel.spread`): the searched success model's where the skill has
        one, else the goal-frame model's on the goal frame. A planner can read it as the rating's uncertainty."""
        rated = self.ratings(sensor)
        if rated is not self:
            return rated.success_spread_obs(obs, parameterised)
        model = self._obs_rater() or self.success_model
        return model.spread(obs)


def load_skill(name: SkillName, weights: str | os.PathLike | None = None,
               success_weights: str | os.PathLike | None = None,
               frame_search: FrameSearch | bool = True, searched: bool = True,
               weights_dir: str | os.PathLike | None = None) -> Skill:
    """The ``push``, ``roll`` or ``spin`` skill, from the shipped weights or given files.

    ``frame_search`` (:mod:`primitives.frames`): ``True``, the one shipped beside the weights where there is one
    and both the policy and the success model are the shipped ones (its calibration is theirs), else none;
    ``False``, act in the goal frame, as trained; or a :class:`~primitives.frames.FrameSearch`.
    ``searched``: with the shipped weights and frame search (``frame_search=True``), rate requests with the
    searched success model shipped beside them (``weights/{name}_success_searched.pt``) where there is one;
    ``False``: rate them through the frame search.
    ``weights_dir``: a folder laid out like the package's ``weights/`` (``{name}.pt`` and ``{name}_success.pt``,
    optionally ``{name}_frames.json`` and ``{name}_success_searched.pt``, all fitted together), whose files then
    stand in for the shipped ones, e.g. a candidate set under ``weights/candidates/``. A folder without
    ``{name}.pt`` leaves that skill on the shipped files. Not combined with ``weights`` or ``success_weights``.
    With the shipped files or a ``weights_dir``, a subfolder named after a sensor (``cameras/``) that holds any of
    ``{name}_success.pt``, ``{name}_frames.json``, ``{name}_success_searched.pt`` refitted to that sensor's clouds
    gives the skill ratings for them (:meth:`Skill.ratings`): those files, and the policy's own for the others
    (:func:`primitives.weights_file.rating_path`). A subfolder that holds ``{name}.pt`` gives the skill a policy for
    that sensor's clouds, with the ratings in that folder alone (its ``{name}_success.pt`` is required).
    """
    if name not in SKILLS:
        raise InputError(f"unknown skill {name!r}; expected one of {SKILLS}")
    if weights_dir is not None and (weights is not None or success_weights is not None):
        raise InputError("give weights_dir, or weights and success_weights, not both")
    shipped = frame_search is True and weights is None and success_weights is None
    directory = WEIGHTS_DIR
    if weights_dir is not None:
        folder = Path(weights_dir)
        if not folder.is_dir():
            raise InputError(f"weights_dir {str(folder)!r} is not a folder")
        if (folder / f"{name}.pt").exists():  # the folder's files, used together as the shipped ones are
            weights, success_weights = folder / f"{name}.pt", folder / f"{name}_success.pt"
            _require_success_beside(weights, success_weights)
            directory = folder
    torch.set_num_threads(max(1, min(torch.get_num_threads(), 2)))
    if frame_search is True:
        frame_search = shipped_frame_search(name, directory) if shipped else None
    elif frame_search is False:
        frame_search = None
    elif not isinstance(frame_search, FrameSearch):
        raise InputError(f"frame_search must be True, False or a FrameSearch, got {frame_search!r}")
    policy = load_policy(weights, name)
    by_sensor = {}
    if shipped:  # ratings of the same policy refitted to other sensors' clouds, in {directory}/{sensor}/
        for sensor in SENSORS:
            own = policy.sensor  # known here: the rules below need not read it from the policy's file again
            if rated_for(name, sensor, directory, trained_on=own):  # the others: the policy's own (rating_path)
                searched_path = rating_path(name, "searched", sensor, directory, trained_on=own)
                success_path = rating_path(name, "success", sensor, directory, trained_on=own)
                acting = policy
                if (own_policy := sensor_policy(name, sensor, directory)) is not None:
                    _require_success_beside(own_policy, success_path)
                    acting = load_policy(own_policy, name)
                by_sensor[sensor] = Skill(
                    name, acting, success_weights=success_path,
                    frame_search=shipped_frame_search(name, directory, sensor, trained_on=own),
                    searched_weights=searched_path if searched and searched_path.exists() else None)
    return Skill(name, policy, success_weights=success_weights, frame_search=frame_search,
                 searched_weights=_searched_beside(name, directory, searched and shipped),
                 ratings_by_sensor=by_sensor)


def _require_success_beside(policy: Path, success: Path) -> None:
    """Refuse a policy file whose success model (fitted to it, in the same folder) is missing."""
    if not success.exists():
        raise InputError(f"{policy} has no success model beside it ({success.name}, fitted to that policy)")


def _searched_beside(name: SkillName, folder: Path, wanted: bool) -> Path | None:
    """``{folder}/{name}_success_searched.pt`` (trained on the skill's frame-searched outcomes) where it is
    ``wanted`` and exists, else ``None``."""
    path = folder / rating_name(name, "searched")
    return path if wanted and path.exists() else None


def load_skills(weights_dir: str | os.PathLike | None = None) -> dict[SkillName, Skill]:
    """All three skills, ``{"push": Skill, "roll": ..., "spin": ...}``: the shipped ones, or with ``weights_dir`` each
    skill whose ``{name}.pt`` is in that folder from the folder's files (:func:`load_skill`), the others shipped.

    Raises:
        InputError: ``weights_dir`` is not a folder, or a policy in it has no success model beside it.
    """
    return {name: load_skill(name, weights_dir=weights_dir) for name in SKILLS}


def skills_sensor(skills: dict[str, Skill]) -> str:
    """The sensor a simulator should give ``skills`` (:attr:`Skill.sensor`): the one they were all trained on;
    ``"cameras"`` (the default sensor) when they disagree."""
    sensors = {getattr(skill, "sensor", "cameras") for skill in skills.values()}  # duck-typed skills: the default
    return sensors.pop() if len(sensors) == 1 else "cameras"
