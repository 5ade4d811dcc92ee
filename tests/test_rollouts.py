"""Rollout workers (primitives.training.rollouts): pushed weights reach local and Ray workers, worker seeds, exploring
actions, a collector's transitions, and the sources it refuses to make."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from affordplan.errors import InputError
from primitives.networks import HybridActorCritic
from primitives.training.env import EnvConfig
from primitives.training.rollouts import (
    Collector,
    Exploration,
    LocalWorkers,
    RayWorkers,
    act,
    make_source,
    worker_seed,
)


def _saturated_policy(sign: float) -> dict:
    """Weights whose actor map is ``sign * tanh(8) ~ sign`` for every point and every cloud."""
    torch.manual_seed(0)
    model = HybridActorCritic()
    last = model.actor[-1]
    with torch.no_grad():
        last.weight.zero_()
        last.bias.fill_(8.0 * sign)
    return model.state_dict()


def _poll(source, n: int) -> list:
    got = []
    for _ in range(200):
        got += source.poll(timeout=1.0)
        if len(got) >= n:
            return got
    raise AssertionError(f"only {len(got)} of {n} transitions arrived")


@pytest.mark.parametrize("backend", [pytest.param("ray", marks=pytest.mark.slow), "local"])  # Ray starts in ~5 s
def test_pushed_weights_reach_the_workers(backend, request):
    """Workers start with a policy that moves along -1 and, after a push, act with one that moves along +1."""
    env_cfg = EnvConfig("push", objects=("cube",), n_points=32)
    explore = Exploration(motion_noise=0.0)  # the motion is the actor's, exactly
    seeds = [worker_seed(0, 0, 0)]
    ray = request.getfixturevalue("ray_instance") if backend == "ray" else None  # skips the ray case without Ray
    source = (RayWorkers(env_cfg, explore, seeds, _saturated_policy(-1.0), batch=4, max_inflight=2)
              if backend == "ray" else LocalWorkers(env_cfg, explore, seeds, _saturated_policy(-1.0)))
    try:
        before = _poll(source, 4)
        assert all(np.all(t[2] < -0.99) for t in before)
        assert all(t[0].shape == (32, 9) and t[0].dtype == np.float16 for t in before)
        source.push_weights(_saturated_policy(+1.0))
        after = []
        for _ in range(10):  # what was requested before the push still comes back with the old weights
            after += _poll(source, 1)
            if np.all(after[-1][2] > 0.99):
                break
        assert np.all(after[-1][2] > 0.99), "the pushed weights never reached the worker"
        assert source.worker_rss_mb() > 0.0
    finally:
        source.close()
    if backend == "ray":
        assert ray.is_initialized()  # a source that did not start Ray leaves it running


def test_worker_seeds_differ_by_worker_and_by_the_step_a_run_resumes_at():
    seeds = {worker_seed(3, w, step) for w in range(8) for step in (0, 5000)}
    assert len(seeds) == 16  # no two workers, fresh or resumed, draw the same stream
    assert worker_seed(3, 0, 0) != worker_seed(4, 0, 0)
    assert worker_seed(3, 1, 0) == worker_seed(3, 1, 0)


def test_exploring_actions_take_the_actor_s_motion_plus_clipped_noise():
    torch.manual_seed(0)
    model = HybridActorCritic().eval()
    obs = np.random.default_rng(0).normal(0, 0.03, size=(64, 9)).astype(np.float32)
    actions, q = model.maps(torch.from_numpy(obs)[None])
    exact = Exploration(temperature=1e-6, epsilon=0.0, motion_noise=0.0)
    idx, motion = act(model, obs, exact, np.random.default_rng(1), torch.Generator().manual_seed(1))
    assert idx == int(q[0].argmax()) and np.allclose(motion, actions[0, idx].numpy())  # greedy, no noise
    noisy = Exploration(temperature=0.1, epsilon=1.0, motion_noise=5.0)  # uniform contacts, huge noise
    picks = [act(model, obs, noisy, np.random.default_rng(s), torch.Generator().manual_seed(s)) for s in range(40)]
    assert len({i for i, _ in picks}) > 20  # contacts drawn all over the cloud
    motions = np.array([m for _, m in picks])
    assert np.all(np.abs(motions) <= 1.0) and np.mean(np.abs(motions) == 1.0) > 0.5  # clipped to the unit box
    again = act(model, obs, noisy, np.random.default_rng(7), torch.Generator().manual_seed(7))
    assert again[0] == picks[7][0] and np.array_equal(again[1], picks[7][1])  # seeded


def test_a_collector_s_transitions_are_seeded_and_in_the_replay_s_format():
    torch.manual_seed(0)
    state = HybridActorCritic().state_dict()
    cfg = EnvConfig("push", objects=("cube",), n_points=32)
    runs = []
    for _ in range(2):
        collector = Collector(cfg, Exploration(), seed=11, state_dict=state)
        transitions, rss = collector.collect(2)
        collector.close()
        runs.append(transitions)
    assert rss > 0.0 and len(runs[0]) == 2
    for obs, idx, motion, reward, success, valid, relabelled in runs[0]:
        assert obs.shape == (32, 9) and obs.dtype == np.float16 and 0 <= idx < 32
        assert motion.dtype == np.float32 and np.all(np.abs(motion) <= 1.0)
        assert np.isfinite(reward) and not relabelled
        assert valid or not success  # an invalid primitive never counts as a success
    for a, b in zip(*runs):
        assert np.array_equal(a[0], b[0]) and a[1] == b[1] and np.array_equal(a[2], b[2]) and a[3] == b[3]


@pytest.mark.parametrize("backend, workers, address, words", [
    ("mpi", 1, None, "unknown rollout backend 'mpi'"),
    ("local", 0, None, "at least one worker"),
    ("local", 1, "auto", "only applies to the ray backend"),
])
def test_a_source_that_cannot_run_is_refused_before_any_worker_starts(backend, workers, address, words):
    with pytest.raises(InputError, match=words):
        make_source(backend, workers, EnvConfig("push", objects=("cube",), n_points=32), Exploration(), 0, 0,
                    HybridActorCritic().state_dict(), ray_address=address)
