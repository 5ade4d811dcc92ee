"""The one-step environment as a Gymnasium environment, for training a primitive with any RL library.

:class:`PrimitiveGymEnv` wraps :class:`~primitives.training.env.PrimitiveEnv` (the environment the project's own
trainer uses) in the :class:`gymnasium.Env` API. Importing this module registers three ids::

    import gymnasium as gym
    import primitives.training.gym_env  # noqa: F401  (registers affordplan/Push-v0, Roll-v0, Spin-v0)

    env = gym.make("affordplan/Push-v0", sensor="surface", n_points=64)

or, without the explicit import, ``gym.make("primitives.training.gym_env:affordplan/Push-v0")`` (Gymnasium
imports the module named before the colon). Gymnasium 1.x has no entry-point plugin mechanism (0.26-0.29's
``gymnasium.envs`` entry-point group and ``load_plugin_envs`` were removed in 1.0), so a bare
``gym.make("affordplan/Push-v0")`` needs one of the two forms above first. Keyword arguments to ``gym.make`` go to
:class:`PrimitiveGymEnv`.

Episodes are one step long (HACMan's contextual bandit): ``reset`` draws an object, a resting state, a pose and,
with probability ``p_params``, a parameter (a push direction, a spin angle, a roll target;
:mod:`primitives.params`), and returns the object's point cloud; ``step`` executes one primitive and always
returns ``terminated=True``, ``truncated=False``.

Observation: ``Box(-inf, inf, (n_points, OBS_DIM), float32)``, :mod:`primitives.observation`'s per-point features
``(x - cx, y - cy, z, nx, ny, nz, fx, fy, fz)``: position relative to the cloud's centroid on the table plane
and height above the table (metres), the outward unit normal, and the goal flow (metres; zero for the seed's
objective), all in the episode's goal frame (the world frame for the seed's objective). The rows are the cloud's
points in the sensor's (random) order. The space is left unbounded: positions and flows scale with the object
(up to 1 m half-extent for a mesh loaded with its own size) and the depth cameras add noise, so any finite bound
would be a guess an observation could break; ``check_env`` only warns about infinite bounds.

Action: a flat ``Box(-1, 1, (4,), float32)``. Component 0 picks the contact point: ``a0`` in [-1, 1] maps to the
row ``min(floor((a0 + 1) / 2 * n_points), n_points - 1)`` of the observation (equal bins, -1 the first row,
+1 the last). Components 1-3 are the motion in the goal frame, unitless in [-1, 1]: each of the primitive's 3
control steps moves the fingertip by ``motion * 3 cm`` (:meth:`affordplan.Simulator.execute`; after the turn
into the world frame each world axis is clipped to [-1, 1] again). Values outside [-1, 1] are clipped; a
wrong shape or a non-finite value raises :class:`~affordplan.errors.InputError`.

Why a flat ``Box`` rather than ``Tuple(Discrete(n_points), Box(-1, 1, (3,)))`` or a ``Dict``: the hybrid action is
what the project's own trainer learns (a per-point critic picks the row, an actor the motion;
:mod:`primitives.training.train`), but the common libraries do not take hybrid action spaces: Stable-Baselines3
accepts no ``Tuple``/``Dict`` action space, CleanRL's and most of RLlib's continuous-control algorithms expect one
``Box``, and SAC/TD3/PPO all run unchanged on a symmetric, normalised ``Box`` (which ``check_env`` also
recommends). The cost: the point order is random, so a policy must learn which row a value of ``a0`` names;
architectures that score every point (as HACMan does) fit the problem better than a flat MLP.

Reward: ``-L``, the primitive's objective (:mod:`primitives.rewards`; the parameterised one when the episode asks
for a parameter). The observation ``step`` returns is all zeros: the episode has ended and nothing
bootstraps from it, and sensing the object again would draw from the simulator's random stream and shift every
later episode. Where the object went is in ``info["pose_after"]``.

``info`` from ``reset``: ``params`` (the episode's parameter, ``None`` for the seed's objective) and ``object``
(the drawn object's key: ``(split, index)`` for a procedural object, else a catalogue name or mesh path). From
``step``: ``success`` and ``valid`` (bools; a primitive the physics guards rejected is invalid and never a
success), ``params``, ``contact_index`` (the row ``a0`` picked), ``invalid_reason`` (the guard that fired, or
``None``), ``pose_before`` and ``pose_after`` (the object's 4x4 world poses, metres, before the approach and after
settling).

Seeding follows Gymnasium: ``reset(seed=s)`` seeds ``self.np_random`` (``super().reset(seed=s)``) and builds a new
inner :class:`PrimitiveEnv` seeded with a number drawn from it, so the same ``s`` gives the same episodes (and
``reset()`` without a seed continues the stream). The first ``reset`` without a seed seeds from the OS's entropy.
"""

from __future__ import annotations

import copy
import math
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from affordplan.checks import as_vector
from affordplan.errors import InputError
from primitives.training.env import OBS_DIM, EnvConfig, PrimitiveEnv, check_env_config

__all__ = ["ENV_IDS", "PrimitiveGymEnv", "register_envs"]

ENV_IDS: dict[str, str] = {
    "push": "affordplan/Push-v0",
    "roll": "affordplan/Roll-v0",
    "spin": "affordplan/Spin-v0",
}
ACTION_DIM = 4  # contact selector + 3-D motion
RESET_OPTIONS = ("object", "resting_state", "params")


class PrimitiveGymEnv(gym.Env[np.ndarray, np.ndarray]):
    """One-step Gymnasium environment of one primitive; see the module docstring for the spaces, reward and info.

    Args:
        primitive: ``"push"``, ``"roll"`` or ``"spin"``.
        objects: what ``reset`` draws from (:class:`~primitives.training.env.EnvConfig`): ``"train"`` / ``"test"``
            (the procedural splits), ``"seed7"``, ``"housekeep:SPLIT"``, groups joined by ``+``, or a tuple of
            catalogue names / mesh paths.
        n_points: points per cloud (rows of the observation), at least 16.
        p_params: probability in [0, 1] that an episode asks for a parameter (0: the seed's objective only).
        sensor: ``"cameras"`` (simulated depth cameras, as deployed) or ``"surface"`` (an even sample of the true
            surface; faster, for ablations and tests).
        render_mode: ``None`` or ``"rgb_array"`` (:meth:`render` returns the overview camera's
            ``(480, 640, 3)`` uint8 image; headless, set ``MUJOCO_GL=egl``).

    Raises:
        InputError: an unknown primitive, sensor or render mode, or a setting out of range.
    """

    # One frame per reset or step; render_fps only paces video writers (gymnasium.wrappers.RecordVideo).
    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, primitive: str = "push", *, objects: str | tuple[str, ...] = "train", n_points: int = 256,
                 p_params: float = 0.0, sensor: str = "cameras", render_mode: str | None = None) -> None:
        self.config = EnvConfig(primitive=primitive, objects=objects, n_points=n_points, p_params=p_params,
                                sensor=sensor)
        check_env_config(self.config)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise InputError(f"unknown render_mode {render_mode!r}; expected None or one of "
                             f"{self.metadata['render_modes']}")
        self.render_mode = render_mode
        self.n_points = int(n_points)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(self.n_points, OBS_DIM), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(ACTION_DIM,), dtype=np.float32)
        self._inner: PrimitiveEnv | None = None
        self._stepped = True  # no episode in progress until reset

    @property
    def inner(self) -> PrimitiveEnv | None:
        """The wrapped :class:`PrimitiveEnv` (``None`` before the first ``reset``); replaced at every seeded reset."""
        return self._inner

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode; returns the observation ``(n_points, OBS_DIM)`` float32 and ``info``.

        Args:
            seed: seeds ``np_random`` and, from it, a fresh inner environment (its simulators are rebuilt).
            options: optional keys ``"object"`` (an object key, as ``info["object"]`` gives one, or a catalogue
                name), ``"resting_state"`` (an index into the object's resting states) and ``"params"`` (a
                parameter dict, or ``None`` for the seed's objective; drawn by ``p_params`` when absent).

        Raises:
            InputError: an unknown option, or an option the object cannot take.
        """
        super().reset(seed=seed)
        options = {} if options is None else dict(options)
        unknown = set(options) - set(RESET_OPTIONS)
        if unknown:
            raise InputError(f"unknown reset options {sorted(unknown)}; expected some of {RESET_OPTIONS}")
        if seed is not None or self._inner is None:
            if self._inner is not None:
                self._inner.close()
            self._inner = PrimitiveEnv(self.config, seed=int(self.np_random.integers(2**31)))
        obs = self._inner.reset(object_key=options.get("object"), resting_state=options.get("resting_state"),
                                params=options.get("params", "random"))
        self._stepped = False
        info = {"params": copy.deepcopy(self._inner.params), "object": self._inner.object_key}
        return np.array(obs, dtype=np.float32, copy=True), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        """Execute one primitive; the episode ends here (``terminated=True``). See the module docstring for the
        action's layout.

        Raises:
            gymnasium.error.ResetNeeded: no episode in progress (before ``reset``, or after this episode's step).
            InputError: ``action`` is not 4 finite numbers of shape ``(4,)``.
        """
        if self._inner is None or self._stepped:
            raise gym.error.ResetNeeded("call reset() before step(): every episode is one step")
        if np.ndim(action) != 1:
            raise InputError(f"action must have shape ({ACTION_DIM},), got shape {np.shape(action)}")
        a = np.clip(as_vector("action", action, ACTION_DIM), -1.0, 1.0)
        index = contact_index(float(a[0]), self.n_points)
        result = self._inner.step(index, a[1:])
        self._stepped = True
        out = result.outcome
        info = {
            "success": bool(result.success),
            "valid": bool(result.valid),
            "params": copy.deepcopy(result.params),
            "contact_index": index,
            "invalid_reason": out.invalid_reason,
            "pose_before": np.array(out.pose_before, dtype=float, copy=True),
            "pose_after": np.array(out.pose_after, dtype=float, copy=True),
        }
        obs = np.zeros((self.n_points, OBS_DIM), dtype=np.float32)
        return obs, float(result.reward), True, False, info

    def render(self) -> np.ndarray | None:
        """With ``render_mode="rgb_array"``: the scene from the overview camera, ``(480, 640, 3)`` uint8 (the object
        where the last ``reset`` or ``step`` left it); ``None`` otherwise.

        Raises:
            gymnasium.error.ResetNeeded: before the first ``reset``.
        """
        if self.render_mode is None:
            return None
        if self._inner is None or self._inner.sim is None:
            raise gym.error.ResetNeeded("call reset() before render()")
        return self._inner.sim.render()

    def close(self) -> None:
        """Free the simulators; safe to call more than once."""
        if self._inner is not None:
            self._inner.close()
            self._inner = None
        self._stepped = True


def contact_index(a0: float, n_points: int) -> int:
    """The observation row that action component ``a0`` (in [-1, 1], clipped) picks: ``n_points`` equal bins."""
    a0 = min(max(a0, -1.0), 1.0)
    return min(int(math.floor((a0 + 1.0) / 2.0 * n_points)), n_points - 1)


def register_envs() -> None:
    """Register ``affordplan/Push-v0``, ``Roll-v0`` and ``Spin-v0`` with Gymnasium; ids already registered are left
    alone, so importing (or reloading) this module again neither warns nor raises."""
    for primitive, env_id in ENV_IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point="primitives.training.gym_env:PrimitiveGymEnv",
                         kwargs={"primitive": primitive})


register_envs()
