"""The one-step environment every primitive trains in (HACMan's, with the skill parameter as its goal).

``reset`` draws an object (from a procedural split, a fixed list, or the seed's seven; a drawn object
serves ``episodes_per_object`` consecutive episodes, since building its simulator costs ~80 ms against
~20 ms for a primitive; the object's model, whose resting states and surface samples are most of that
cost, is kept for later draws, see ``EnvConfig.model_cache``), one of its resting states (by its
probability), a position in the middle of the workspace and a yaw, lets it settle and returns its
point cloud. ``step`` takes a contact point index and a 3-D motion in [-1, 1], executes the primitive
in the finger sim and returns ``-L`` of the objective. With probability ``p_params`` an episode asks
for a parameter (a push direction, a spin angle, a roll target; :mod:`primitives.params`) and the
parameterised objective applies; otherwise the seed's.

The observation is :mod:`primitives.observation`'s.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np

from affordplan.checks import require_probability, require_whole
from affordplan.errors import InputError
from affordplan.objects import housekeep
from affordplan.objects.model import ObjectModel, load_object, random_object
from affordplan.sim.sensor import check_sensor
from affordplan.sim.simulator import Outcome, Simulator
from primitives import params as skill_params
from primitives import rewards
from primitives.observation import (  # noqa: F401 (re-exported for training code)
    OBS_DIM,
    PRIMITIVES,
    SkillObservation,
    observation,
    observe_cloud,
    skill_observation,
)

T = TypeVar("T")
SEED_SEVEN = ("cube", "mug", "tape", "planter_1", "planter_2", "pill_bottle", "lunch_box")


@dataclass(frozen=True)
class EnvConfig:
    """What the environment draws from.

    ``objects``: ``"train"`` or ``"test"`` (the procedural splits, ``n_objects`` of them), ``"seed7"``
    (the seed's seven), ``"housekeep:SPLIT"`` (HACMan's household meshes of a split,
    :func:`affordplan.objects.housekeep.names`), several of these joined by ``+`` (each episode draws a group
    uniformly, then an object in it), or a tuple of catalogue names / mesh paths.
    ``sensor``: how the policy sees the object (:meth:`affordplan.Simulator.point_cloud`).
    ``full_motion``: every stroke runs its commanded motion in full, open-loop as HACMan's protocol has it: a spin by
    an angle does not end where the object has turned that far (:func:`primitives.params.motion_stop`) and a push is
    neither steered against the object's turn nor carried on until the object has travelled far enough
    (:func:`primitives.params.motion_loop`). Spins run so in plans; every file fitted before the spin's stop
    (2026-12-06), the push's steering or its reach (both 2026-12-07) was collected or trained so.
    """

    primitive: str = "push"
    objects: str | tuple[str, ...] = "train"
    n_objects: int = 500
    n_points: int = 256
    xy_range: tuple[tuple[float, float], tuple[float, float]] = ((0.45, 0.6), (-0.1, 0.1))
    sim_cache: int = 48  # simulators kept alive per environment (LRU)
    # Object models kept per environment (LRU; ~0.8 MB each): a simulator rebuilt for an object drawn again
    # reuses its model, so its resting states (~50 ms with trimesh) and surface samples (~17 ms) are computed
    # once. 512 holds the whole training split; what an episode sees does not depend on it.
    model_cache: int = 512
    episodes_per_object: int = 8  # consecutive episodes on one drawn object: amortises its setup
    p_params: float = 0.0  # probability that an episode asks for a parameter (0: the seed's objective)
    sensor: str = "cameras"
    full_motion: bool = False


@dataclass
class StepResult:
    reward: float
    success: bool
    valid: bool
    outcome: Outcome
    params: dict | None = None


def check_env_config(config: EnvConfig) -> None:
    """Raise :class:`InputError` for a configuration the environment cannot run: an unknown primitive, a
    count below its least value (``sim_cache`` 1: the simulator in use must stay open; ``model_cache`` 0: none
    kept), or ``p_params`` outside [0, 1]."""
    if config.primitive not in PRIMITIVES:
        raise InputError(f"unknown primitive {config.primitive!r}; expected one of {PRIMITIVES}")
    least = dict(n_objects=1, n_points=16, sim_cache=1, model_cache=0, episodes_per_object=1)
    for name, low in least.items():
        require_whole(f"EnvConfig.{name}", getattr(config, name), low)
    require_probability("EnvConfig.p_params", config.p_params)
    check_sensor(config.sensor)
    object_groups(config.objects, config.n_objects)


def object_groups(objects: str | tuple[str, ...], n_objects: int) -> list[list]:
    """The object keys an environment draws from, in groups (see :class:`EnvConfig`; an episode draws a group
    uniformly, then a key in it): procedural ``(split, index)`` pairs, or names and paths for :func:`load_object`.

    Raises:
        InputError: a ``housekeep:SPLIT`` naming no split.
    """
    if not isinstance(objects, str):
        return [list(objects)]
    groups = []
    for spec in objects.split("+"):
        if spec in ("train", "test"):
            groups.append([(spec, i) for i in range(n_objects)])
        elif spec == "seed7":
            groups.append(list(SEED_SEVEN))
        elif spec.startswith("housekeep:"):
            groups.append([housekeep.PREFIX + name for name in housekeep.names(spec.split(":", 1)[1])])
        else:  # a catalogue name, housekeep/NAME or a mesh path
            groups.append([spec])
    return groups


def held_out(spec: str) -> bool:
    """Whether one ``+``-part of an ``--objects`` is held out for evaluation: the procedural test split, any of
    HACMan's unseen household splits (``housekeep:unseen``, ``unseen_instance``, ``unseen_class`` and their
    ``_thick`` lists), or one of their meshes named alone (``housekeep/NAME``, or its file's path)."""
    if spec == "test" or spec.startswith("housekeep:unseen"):
        return True
    unseen = set(housekeep.names("unseen"))
    if spec.startswith(housekeep.PREFIX):
        return spec.removeprefix(housekeep.PREFIX) in unseen
    return Path(spec).suffix.lower() == ".obj" and Path(spec).stem in unseen


def check_objects(objects: str | tuple[str, ...], fitting: bool) -> None:
    """Raise :class:`InputError` for an ``--objects`` naming no objects, or, when ``fitting`` (a policy, a model or
    a calibration is fitted on them), naming held-out objects (:func:`held_out`): test objects are never trained,
    tuned or selected on. ``objects`` as :class:`EnvConfig` takes it: a ``+``-joined string, or a tuple of keys
    (names, paths, procedural ``(split, index)`` pairs)."""
    object_groups(objects, 1)
    specs = objects.split("+") if isinstance(objects, str) else [
        key if isinstance(key, str) else str(key[0]) for key in objects]  # a pair names its split
    held = [spec for spec in specs if held_out(spec)]
    if fitting and held:
        raise InputError(f"--objects {objects}: {', '.join(held)} is held out for evaluation; fit on train, "
                         "housekeep:training or housekeep:validation")


def _lru(cache: OrderedDict, key, capacity: int, build: Callable[[], T], evict: Callable[[T], None] | None = None) -> T:
    """``cache[key]``, made by ``build()`` when missing; then the least recently used entries beyond ``capacity``
    are dropped (each passed to ``evict``), so a capacity of 0 keeps nothing."""
    if key in cache:
        cache.move_to_end(key)
        return cache[key]
    value = cache[key] = build()
    while len(cache) > capacity:
        _, old = cache.popitem(last=False)
        if evict is not None:
            evict(old)
    return value


class PrimitiveEnv:
    """One-step environment for ``config.primitive``; seeded, deterministic."""

    def __init__(self, config: EnvConfig, seed: int = 0):
        check_env_config(config)
        self.config = config
        self.rng = np.random.default_rng(seed)
        self._seed = seed
        self._sims: OrderedDict[object, Simulator] = OrderedDict()
        self._models: OrderedDict[object, ObjectModel] = OrderedDict()
        self.sim: Simulator | None = None
        self.seen: SkillObservation | None = None
        self.object_key: object = None
        self._episodes_left = 0

    # ------------------------------------------------------------------ objects
    def _object_groups(self) -> list[list]:
        return object_groups(self.config.objects, self.config.n_objects)

    def _load(self, key) -> ObjectModel:
        """The model of object ``key``, from the model cache when it was built before."""
        return _lru(self._models, key, self.config.model_cache,
                    lambda: random_object(key[1], key[0]) if isinstance(key, tuple) else load_object(key))

    def _simulator(self, key) -> Simulator:
        return _lru(self._sims, key, self.config.sim_cache,
                    lambda: Simulator(self._load(key), seed=int(self.rng.integers(2**31)),
                                                                    sensor=self.config.sensor), evict=Simulator.close)

    # ---------------------------------------------------------------- episode
    def reset(self, object_key=None, resting_state: int | None = None, params="random") -> np.ndarray:
        """Start an episode; returns the observation ``(n_points, 9)``.

        ``params``: ``"random"`` draws one (see ``EnvConfig.p_params``); a dict or ``None`` is used as given.
        """
        if object_key is not None:
            key = object_key
        elif self._episodes_left > 0 and self.object_key is not None:
            key = self.object_key
        else:
            groups = self._object_groups()
            keys = groups[int(self.rng.integers(len(groups)))] if len(groups) > 1 else groups[0]
            key = keys[int(self.rng.integers(len(keys)))]
            self._episodes_left = self.config.episodes_per_object
        self._episodes_left -= 1
        sim = self._simulator(key)
        states = sim.obj.resting_states
        if resting_state is None:
            probs = np.array([s.probability for s in states])
            resting_state = int(self.rng.choice(len(states), p=probs / probs.sum()))
        (x0, x1), (y0, y1) = self.config.xy_range
        sim.reset(resting_state=resting_state, xy=(self.rng.uniform(x0, x1), self.rng.uniform(y0, y1)),
                  yaw=self.rng.uniform(-np.pi, np.pi))
        self.sim, self.object_key = sim, key
        state = sim.obj.classify(sim.object_pose())
        if isinstance(params, str) and params == "random":
            params = skill_params.sample(self.config.primitive, self.rng, sim.obj, state, self.config.p_params)
        self.seen = skill_observation(sim, self.config.primitive, params, self.config.n_points, state)
        return self.seen.obs

    @property
    def points(self) -> np.ndarray:
        """The current episode's world-frame cloud."""
        return self.seen.points

    @property
    def params(self) -> dict | None:
        """The current episode's parameter (``None``: the seed's objective)."""
        return self.seen.params

    def step(self, index: int, motion: np.ndarray) -> StepResult:
        """Execute the primitive at point ``index`` with goal-frame ``motion``; the episode ends here."""
        assert self.sim is not None and self.seen is not None, "call reset() first"
        seen = self.seen
        loop = skill_params.MotionLoop()
        if not self.config.full_motion:
            loop = skill_params.motion_loop(self.config.primitive, self.params, self.sim.object_pose())
        out = self.sim.execute(seen.points[index], seen.motion_to_world(motion), normal=seen.normals[index],
                               **loop.as_kwargs())
        name, obj = self.config.primitive, self.sim.obj
        reward = -rewards.loss(name, out.pose_before, out.pose_after, self.params, obj)
        success = rewards.success(name, out.pose_before, out.pose_after, self.params, obj)
        return StepResult(reward=reward, success=bool(success and out.valid), valid=out.valid, outcome=out,
                          params=self.params)

    def close(self) -> None:
        for sim in self._sims.values():
            sim.close()
        self._sims.clear()
        self._models.clear()
