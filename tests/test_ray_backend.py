"""Training on the Ray rollout backend: the CLI run writes a checkpoint, a run learns, syncs and resumes, bad backend
combinations are refused. (Weights reaching the workers: tests/test_rollouts.py; the backend comparison's statistics:
tests/test_compare_backends.py; the shared Ray instance: tests/conftest.py.)

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
from primitives.training import checkpoint as ckpt
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


