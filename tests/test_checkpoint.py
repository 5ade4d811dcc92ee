"""Training checkpoints (primitives.training.checkpoint): clear errors for damaged files, atomic writes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import torch

from affordplan.errors import WeightsError
from primitives import weights_file
from primitives.training import checkpoint as ckpt


def test_corrupt_checkpoint_gives_a_clear_error(tmp_path):
    path = tmp_path / "checkpoint.pt"
    path.write_bytes(b"not a checkpoint at all")
    with pytest.raises(ckpt.CheckpointError, match="damaged"):
        ckpt.load(path)
    ckpt.save(path, {"model": {"w": torch.ones(3)}})
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])  # truncated
    with pytest.raises(ckpt.CheckpointError):
        ckpt.load(path)
    with pytest.raises(ckpt.CheckpointError, match="no checkpoint"):
        ckpt.load(tmp_path / "missing.pt")



def test_a_checkpoint_round_trips_for_the_skill_its_config_names(tmp_path):
    path = tmp_path / "checkpoint.pt"
    payload = {"model": {"w": torch.arange(4.0)}, "config": {"primitive": "spin"}, "state": {"global_step": 12}}
    ckpt.save(path, payload)
    saved = ckpt.load(path, skill="spin")
    assert torch.equal(saved["model"]["w"], torch.arange(4.0)) and saved["state"]["global_step"] == 12
    assert saved["meta"]["kind"] == "checkpoint" and saved["meta"]["skill"] == "spin"
    assert ckpt.load(path)["meta"]["skill"] == "spin"  # no skill asked: any
    with pytest.raises(ckpt.CheckpointError, match="for the spin skill, not push"):
        ckpt.load(path, skill="push")


def test_what_is_not_a_checkpoint_is_refused_as_a_weights_error(tmp_path):
    assert issubclass(ckpt.CheckpointError, WeightsError)  # one except clause catches every weights problem
    policy = tmp_path / "policy.pt"
    weights_file.save(policy, {"model": {"w": torch.ones(2)}}, weights_file.make_meta("push", "policy"))
    with pytest.raises(ckpt.CheckpointError, match="holds a policy file, not a checkpoint"):
        ckpt.load(policy)
    empty = tmp_path / "empty.pt"
    ckpt.save(empty, {"state": {}}, weights_file.make_meta("push", "checkpoint"))
    with pytest.raises(ckpt.CheckpointError, match="not an affordplan checkpoint"):
        ckpt.load(empty)
    ckpt.save(tmp_path / "again.pt", {"model": {}, "config": {"primitive": "roll"}})
    assert not list(tmp_path.glob("*.tmp"))  # no temporary file left behind


_WRITER = textwrap.dedent("""
    import sys, torch
    from primitives.training import checkpoint as ckpt
    path, i = sys.argv[1], 0
    while True:
        i += 1
        ckpt.save(path, {"model": {"w": torch.full((2_000_000,), float(i))}, "state": {"i": i}})
        print(i, flush=True)
""")


@pytest.mark.slow
def test_checkpoint_writes_are_atomic_under_sigkill(tmp_path):
    """A writer saving 8 MB checkpoints in a loop is killed mid-stream three times: the file on disk
    always loads, whole, as one of the checkpoints it finished."""
    path = tmp_path / "checkpoint.pt"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    for delay in (0.15, 0.35, 0.6):
        proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(path)], stdout=subprocess.PIPE, env=env,
                                text=True)
        assert proc.stdout.readline()  # one checkpoint is complete
        time.sleep(delay)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        finished = [int(line) for line in proc.stdout.read().split()]
        saved = ckpt.load(path)
        i = saved["state"]["i"]
        assert torch.equal(saved["model"]["w"], torch.full((2_000_000,), float(i)))
        last = finished[-1] if finished else 1  # the last save the writer reported finished
        assert i in (last, last + 1)  # that one, or the next if it finished between print and kill
