"""The Ray rollout backend: the CLI run writes a checkpoint, weights reach the actors, resume works.

Runs on a local Ray instance with 2 CPUs and no dashboard (no network needed). Ray is an optional
dependency; the file is skipped where it is not installed.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace

import numpy as np
import pytest
import torch

from primitives import weights_file
from primitives.networks import HybridActorCritic
from primitives.research.compare_backends import Proportions
from primitives.training import checkpoint as ckpt
from primitives.training.env import EnvConfig
from primitives.training.rollouts import Exploration, LocalWorkers, RayWorkers, worker_seed
from primitives.training.train import TrainConfig, main, train

ray = pytest.importorskip("ray")


@pytest.fixture(autouse=True)
def _quiet_ray(monkeypatch):
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")  # never report anything over the network


@pytest.mark.slow
def test_cli_ray_run_writes_checkpoint_and_policy(tmp_path):
    """`python -m primitives.train push --backend ray --steps 64 --workers 1 --out DIR`, in-process."""
    was_running = ray.is_initialized()
    assert main(["push", "--backend", "ray", "--steps", "64", "--workers", "1", "--learning-starts", "16",
                 "--out", str(tmp_path)]) == 0
    assert ray.is_initialized() == was_running  # the instance it started is shut down again
    saved = ckpt.load(tmp_path / "checkpoint.pt")
    assert saved["state"]["global_step"] == 64  # exactly the budget: surplus transitions are dropped
    assert saved["replay"]["size"] == 64 - saved["state"]["invalid"] > 0
    assert np.isfinite(saved["replay"]["reward"]).all()
    policy = weights_file.load(tmp_path / "policy.pt", kind="policy", skill="push")[0]["model"]
    assert all(torch.equal(saved["model"][k], v) for k, v in policy.items())
    config = json.loads((tmp_path / "config.json").read_text())
    assert config["backend"] == "ray" and config["workers"] == 1 and config["ray_address"] is None


@pytest.fixture(scope="module")
def ray_instance():
    """One local Ray instance shared by the tests below (the trainer then leaves it running)."""
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, object_store_memory=256 * 2**20)
    yield ray
    if started:
        ray.shutdown()


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


@pytest.mark.parametrize("backend", ["ray", "local"])
def test_pushed_weights_reach_the_workers(backend, request):
    """Workers start with a policy that moves along -1 and, after a push, act with one that moves along +1."""
    env_cfg = EnvConfig("push", objects=("cube",), n_points=32)
    explore = Exploration(motion_noise=0.0)  # the motion is the actor's, exactly
    seeds = [worker_seed(0, 0, 0)]
    if backend == "ray":
        request.getfixturevalue("ray_instance")
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


@pytest.mark.slow
def test_ray_run_learns_syncs_and_resumes(tmp_path, ray_instance):
    cfg = TrainConfig(primitive="push", steps=64, workers=1, backend="ray", seed=3, out=str(tmp_path),
                      objects=("cube",), n_points=64, learning_starts=32, replay_size=256, replay_ratio=16.0,
                      weight_sync_updates=2, checkpoint_minutes=60.0)
    first = train(cfg, progress=False)
    assert first["steps"] == 64 and first["updates"] > 2  # it learned, and pushed weights along the way
    resumed = train(replace(cfg, steps=96), resume=True, progress=False)
    saved = ckpt.load(tmp_path / "checkpoint.pt")
    assert resumed["steps"] == saved["state"]["global_step"] == 96
    assert resumed["updates"] > first["updates"]
    assert saved["replay"]["size"] == 96 - saved["state"]["invalid"]


def test_cli_rejects_bad_backend_combinations_and_a_missing_ray(tmp_path, monkeypatch, capsys):
    with pytest.raises(SystemExit):
        main(["push", "--ray-address", "auto", "--out", str(tmp_path)])  # an address without --backend ray
    assert "--backend ray" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["push", "--backend", "ray", "--workers", "0", "--out", str(tmp_path)])
    assert "--workers 1 or more" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "ray", None)  # as if ray were not installed
    with pytest.raises(SystemExit):
        main(["push", "--backend", "ray", "--out", str(tmp_path)])
    assert "pip install" in capsys.readouterr().err
    assert not (tmp_path / "checkpoint.pt").exists()


def test_two_proportion_tests_agree_with_the_chi_square_test():
    from scipy.stats import chi2_contingency

    table = Proportions(successes=(260, 239), trials=(600, 600))
    z, p = table.z_test()
    chi2, p_chi2, _, _ = chi2_contingency([[260, 340], [239, 361]], correction=False)
    assert z > 0 and z**2 == pytest.approx(chi2) and p == pytest.approx(p_chi2)
    assert Proportions((239, 260), (600, 600)).z_test()[0] == pytest.approx(-z)
    assert 0.0 < table.fisher() <= 1.0
    assert Proportions((0, 0), (50, 70)).z_test() == (0.0, 1.0)  # nothing to tell apart
