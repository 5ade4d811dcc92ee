"""Where the learner's transitions come from: rollout workers behind one small interface.

A :class:`RolloutSource` runs K workers that each own a :class:`~primitives.training.env.PrimitiveEnv`, act
with exploration (:func:`act`) using the latest weights the learner pushed, and hand back one-step
transitions. Two implementations:

- :class:`LocalWorkers`: K processes on this machine (``multiprocessing``, spawn), one torch thread
  each; transitions come back through a bounded queue.
- :class:`RayWorkers`: K Ray actors (one CPU each) on a local Ray instance or a Ray cluster; each
  actor returns batches of transitions, at most ``max_inflight`` requests per actor are pending, so
  neither the object store nor the learner's memory grows with the run. Weights go out with one
  ``ray.put`` per sync. Ray is imported only here, only when this backend is used.

Both use the same seeding scheme (:func:`worker_seed`) and the same acting loop (:class:`Collector`),
so a worker's environment, exploration and policy-noise streams are the same for both backends.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
import queue
import signal
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import torch

from affordplan.errors import InputError
from primitives.networks import HybridActorCritic, choose_contact
from primitives.training.env import EnvConfig, PrimitiveEnv
from primitives.training.hindsight import relabel
from primitives.training.scripted import scripted_push

# (observation (n_points, 9) float16, contact index, motion (3,) float32 in [-1, 1], reward, success, valid,
#  relabelled: a hindsight copy of the primitive before it, not a primitive of its own)
Transition = tuple[np.ndarray, int, np.ndarray, float, bool, bool, bool]
BACKENDS = ("local", "ray")


@dataclass(frozen=True)
class Exploration:
    """How a training policy explores (HACMan's rule plus motion noise)."""

    temperature: float = 0.1  # softmax temperature over the critic map
    epsilon: float = 0.1  # share of uniformly drawn contacts
    motion_noise: float = 0.2  # std of the Gaussian noise on the chosen motion (motion units, [-1, 1])
    p_scripted: float = 0.0  # push only: share of actions replaced by a scripted push (primitives.training.scripted)
    hindsight: bool = False  # also send each primitive relabelled to other requests (primitives.training.hindsight)


def act(model: HybridActorCritic, obs: np.ndarray, explore: Exploration, rng: np.random.Generator,
        gen: torch.Generator) -> tuple[int, np.ndarray]:
    """Exploring contact index and motion for one observation (greedy acting: evaluate.greedy_action).

    With probability ``explore.p_scripted`` (push only; :func:`primitives.training.train.check_config` says so) the
    action is :func:`primitives.training.scripted.scripted_push` instead; with 0 no extra random number is drawn,
    so runs without it are unchanged.
    """
    if explore.p_scripted > 0.0 and rng.random() < explore.p_scripted:
        return scripted_push(obs, rng)
    actions, q = model.maps(torch.from_numpy(obs)[None])
    idx = int(choose_contact(q, explore.temperature, explore.epsilon, gen, greedy=False)[0])
    motion = actions[0, idx].numpy().astype(np.float64)
    return idx, np.clip(motion + rng.normal(0.0, explore.motion_noise, size=3), -1.0, 1.0)


def worker_seed(seed: int, worker: int, global_step: int) -> int:
    """Seed of worker ``worker`` (0-based) for a run seeded ``seed``, started at ``global_step``.

    Offset by the step count, so a resumed run draws fresh streams instead of replaying old ones.
    """
    return seed * 1000 + 17 * (worker + 1) + global_step


def rss_mb(pid: int | None = None) -> float:
    """Resident memory of a process in MB (Linux /proc; 0 where unavailable)."""
    try:
        with open(f"/proc/{pid or os.getpid()}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return 0.0


class Collector:
    """One worker's acting loop: an environment, its random streams and a copy of the policy.

    Seeded with ``seed``: the environment with ``seed``, the motion noise with ``seed + 1``, the
    contact choice with ``seed + 2``.
    """

    def __init__(self, env_config: EnvConfig, explore: Exploration, seed: int, state_dict: dict):
        torch.set_num_threads(1)
        self.env = PrimitiveEnv(env_config, seed=seed)
        self.explore = explore
        self.rng = np.random.default_rng(seed + 1)
        self.gen = torch.Generator().manual_seed(seed + 2)
        self.model = HybridActorCritic()
        self.model.load_state_dict(state_dict)

    def load_weights(self, state_dict: dict) -> None:
        self.model.load_state_dict(state_dict)

    def step(self) -> list[Transition]:
        """Execute one exploring primitive: its transition, then its hindsight copies (``explore.hindsight``)."""
        obs = self.env.reset()
        seen = self.env.seen
        idx, motion = act(self.model, obs, self.explore, self.rng, self.gen)
        res = self.env.step(idx, motion)
        out = [(obs.astype(np.float16), idx, motion.astype(np.float32), res.reward, res.success, res.valid, False)]
        if self.explore.hindsight:
            for obs_h, motion_h, reward_h, success_h in relabel(self.env.config.primitive, self.env.sim.obj, seen,
                                                                motion, res.outcome, res.success):
                out.append((obs_h.astype(np.float16), idx, motion_h.astype(np.float32), reward_h, success_h,
                            True, True))
        return out

    def collect(self, n: int) -> tuple[list[Transition], float]:
        """The transitions of ``n`` primitives (with their hindsight copies) and this process's memory in MB."""
        return [t for _ in range(n) for t in self.step()], rss_mb()

    def close(self) -> None:
        self.env.close()


class RolloutSource(Protocol):
    """Workers feeding one learner."""

    def push_weights(self, state_dict: dict) -> None:
        """Make every worker act with these weights from its next primitive on (asynchronously)."""

    def poll(self, timeout: float) -> list[Transition]:
        """Every transition available now, waiting up to ``timeout`` seconds for the first one."""

    def worker_rss_mb(self) -> float:
        """Resident memory of all workers together, MB (as last measured)."""

    def close(self) -> None:
        """Stop the workers and release what this source started."""


# ---------------------------------------------------------------------------- local processes
def _local_worker(env_config: EnvConfig, explore: Exploration, seed: int, weights_q: mp.Queue, out_q: mp.Queue,
                  stop) -> None:
    """Process body: collect transitions with the latest weights until ``stop`` is set.

    A learner killed with SIGKILL never sets ``stop``: the worker then notices that its parent is gone
    (checked whenever the queue stays full for a second) and exits instead of blocking for good.
    """
    # The learner owns stopping: Ctrl-C (sent to the whole terminal's process group) and the learner's SIGTERM
    # handler are its own; a worker ignores SIGINT and ends on SIGTERM quietly, when ``close`` terminates it.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    parent = mp.parent_process()
    collector = Collector(env_config, explore, seed, weights_q.get())
    while not stop.is_set():
        try:
            while True:
                collector.load_weights(weights_q.get_nowait())
        except queue.Empty:
            pass
        transitions = collector.step()
        while transitions and not stop.is_set():
            try:
                out_q.put(transitions[0], timeout=1.0)
                transitions.pop(0)
            except queue.Full:
                if parent is not None and not parent.is_alive():
                    collector.close()
                    return
        if parent is not None and not parent.is_alive():
            break
    collector.close()


class LocalWorkers:
    """``len(seeds)`` rollout processes on this machine."""

    def __init__(self, env_config: EnvConfig, explore: Exploration, seeds: list[int], state_dict: dict,
                 queue_size: int = 4096):
        ctx = mp.get_context("spawn")
        self._out, self._stop = ctx.Queue(maxsize=queue_size), ctx.Event()
        state_dict = {k: v.clone() for k, v in state_dict.items()}  # the queues pickle later, in a thread
        self._procs, self._weights_qs = [], []
        for seed in seeds:
            wq = ctx.Queue()
            wq.put(state_dict)
            p = ctx.Process(target=_local_worker, args=(env_config, explore, seed, wq, self._out, self._stop),
                            daemon=True)
            p.start()
            self._procs.append(p)
            self._weights_qs.append(wq)

    def push_weights(self, state_dict: dict) -> None:
        weights = {k: v.clone() for k, v in state_dict.items()}  # the queue pickles later, in a thread
        for wq in self._weights_qs:
            wq.put(weights)

    def poll(self, timeout: float) -> list[Transition]:
        """Transitions the workers have sent (waiting up to ``timeout`` s for the first).

        Raises:
            RuntimeError: nothing came and a worker has died (the learner would otherwise wait for it for good).
        """
        got: list[Transition] = []
        while True:
            try:
                got.append(self._out.get(timeout=timeout if not got else 0))
            except queue.Empty:
                if not got:
                    dead = [(i, p.exitcode) for i, p in enumerate(self._procs) if p.exitcode is not None]
                    if dead:
                        raise RuntimeError(f"rollout worker {dead[0][0]} died (exit code {dead[0][1]}); its error, "
                                           "if any, is above") from None
                return got

    def worker_rss_mb(self) -> float:
        return sum(rss_mb(p.pid) for p in self._procs)

    def close(self) -> None:
        self._stop.set()
        for p in self._procs:
            p.join(timeout=5)
            if p.is_alive():
                p.terminate()


# ---------------------------------------------------------------------------- Ray actors
def import_ray():
    """The ``ray`` module, or an ImportError that says how to install it."""
    try:
        import ray
    except ImportError as exc:
        raise ImportError("the Ray backend needs Ray: pip install 'affordplan[ray]' (or pip install 'ray>=2.9')") \
            from exc
    return ray


def connect_ray(address: str | None = None, num_cpus: int = 2) -> bool:
    """Make sure this process is connected to Ray; ``True`` if this call did it (and should shut it down).

    ``address=None`` starts a local instance with ``num_cpus`` CPUs, no dashboard and a 256 MiB
    object store (it only ever holds a few copies of the weights); ``"auto"`` joins the cluster
    this node belongs to; ``"ray://HOST:10001"`` connects through Ray Client. A process already
    connected keeps its connection.
    """
    ray = import_ray()
    if ray.is_initialized():
        return False
    if address is None:
        ray.init(num_cpus=num_cpus, include_dashboard=False, logging_level=logging.WARNING,
                 object_store_memory=256 * 2**20)
    else:
        ray.init(address=address, logging_level=logging.WARNING)
    return True


class RayWorkers:
    """``len(seeds)`` Ray actors, each owning a :class:`Collector`.

    ``address``: see :func:`connect_ray` (``None``: a local instance with ``max(2, K + 1)`` CPUs).
    If this process is already connected to Ray, that connection is used and left open; otherwise
    Ray is shut down (or disconnected from the cluster) on :meth:`close`.

    Each actor has at most ``max_inflight`` pending requests of ``batch`` transitions; the learner
    takes the finished ones and sends a new request to the same actor, so memory stays bounded.
    """

    def __init__(self, env_config: EnvConfig, explore: Exploration, seeds: list[int], state_dict: dict,
                 address: str | None = None, batch: int = 8, max_inflight: int = 2):
        if batch < 1 or max_inflight < 1:
            raise InputError(f"batch and max_inflight must be >= 1, got {batch} and {max_inflight}")
        ray = import_ray()
        self._ray = ray
        self._owns_ray = connect_ray(address, num_cpus=max(2, len(seeds) + 1))
        self._batch = batch
        self._actors: list = []
        self._rss = [0.0] * len(seeds)
        self._pending: dict = {}  # ObjectRef of a collect request -> index of its actor
        try:
            actor_class = ray.remote(num_cpus=1)(Collector)
            weights = ray.put(state_dict)
            for seed in seeds:  # SPREAD: on a cluster, actors go to different nodes where they can
                self._actors.append(actor_class.options(scheduling_strategy="SPREAD").remote(
                    env_config, explore, seed, weights))
            for i in range(len(self._actors)):
                for _ in range(max_inflight):
                    self._request(i)
        except BaseException:
            self.close()
            raise

    def _request(self, i: int) -> None:
        self._pending[self._actors[i].collect.remote(self._batch)] = i

    def push_weights(self, state_dict: dict) -> None:
        weights = self._ray.put(state_dict)  # once per sync; freed when the actors have loaded it
        for actor in self._actors:  # an actor runs its calls in order: after its pending requests
            actor.load_weights.remote(weights)

    def poll(self, timeout: float) -> list[Transition]:
        ray = self._ray
        refs = list(self._pending)
        ready, _ = ray.wait(refs, num_returns=1, timeout=timeout)
        if not ready:
            return []
        ready, _ = ray.wait(refs, num_returns=len(refs), timeout=0)
        got: list[Transition] = []
        for ref, (transitions, rss) in zip(ready, ray.get(ready)):
            i = self._pending.pop(ref)
            self._rss[i] = rss
            got.extend(transitions)
            self._request(i)
        return got

    def worker_rss_mb(self) -> float:
        return float(sum(self._rss))

    def close(self) -> None:
        self._pending.clear()
        for actor in self._actors:
            self._ray.kill(actor)
        self._actors = []
        if self._owns_ray and self._ray.is_initialized():
            self._ray.shutdown()
        self._owns_ray = False


def make_source(backend: str, workers: int, env_config: EnvConfig, explore: Exploration, seed: int,
                global_step: int, state_dict: dict, ray_address: str | None = None) -> RolloutSource:
    """``workers`` rollout workers of ``backend`` (``"local"`` or ``"ray"``), seeded by :func:`worker_seed`."""
    if backend not in BACKENDS:
        raise InputError(f"unknown rollout backend {backend!r}; expected one of {BACKENDS}")
    if workers < 1:
        raise InputError(f"a rollout source needs at least one worker, got {workers}")
    if ray_address is not None and backend != "ray":
        raise InputError("a Ray address only applies to the ray backend (--backend ray)")
    seeds = [worker_seed(seed, w, global_step) for w in range(workers)]
    if backend == "ray":
        return RayWorkers(env_config, explore, seeds, state_dict, address=ray_address)
    return LocalWorkers(env_config, explore, seeds, state_dict)
