"""A training run owns its folder: a lock, a resume that matches, a checkpoint on Ctrl-C / SIGTERM, no untrained
policy presented as trained."""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from affordplan.errors import InputError
from primitives.training import checkpoint as ckpt
from primitives.training.train import RunLock, TrainConfig, main, train


def _config(out, steps=40, **kw) -> TrainConfig:
    base = dict(primitive="push", steps=steps, workers=0, seed=0, out=str(out), objects=("cube",), n_points=32,
                replay_size=200, learning_starts=16, replay_ratio=8.0, checkpoint_minutes=60.0, p_params=0.0)
    base.update(kw)
    return TrainConfig(**base)


def test_a_second_run_into_a_held_folder_is_refused(tmp_path):
    lock = RunLock(tmp_path)  # as a running training run holds it
    try:
        with pytest.raises(InputError, match=f"pid {os.getpid()}"):
            train(_config(tmp_path), progress=False)
    finally:
        lock.release()
    assert train(_config(tmp_path), progress=False)["steps"] == 40  # released: the folder is free again


def test_resume_into_a_run_with_other_settings_is_refused_naming_them(tmp_path, capsys):
    train(_config(tmp_path), progress=False)
    with pytest.raises(InputError, match="primitive push there, roll now"):
        train(_config(tmp_path, primitive="roll"), resume=True, progress=False)
    with pytest.raises(InputError, match="--n-points 32 there, 64 now"):
        train(_config(tmp_path, n_points=64), resume=True, progress=False)
    argv = ["roll", "--resume", "--out", str(tmp_path), "--workers", "0", "--steps", "50"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "cannot resume" in err and "Traceback" not in err
    assert ckpt.load(tmp_path / "checkpoint.pt", skill="push")["config"]["primitive"] == "push"  # untouched


def test_resume_into_a_missing_folder_is_refused(tmp_path):
    with pytest.raises(InputError, match="mistyped"):
        train(_config(tmp_path / "typo"), resume=True, progress=False)
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="is a file"):
        train(_config(tmp_path / "file"), progress=False)


def test_a_run_with_no_updates_writes_no_policy_and_says_so(tmp_path, caplog):
    with caplog.at_level(logging.WARNING, logger="primitives.training.train"):
        summary = train(_config(tmp_path, steps=10, learning_starts=1000), progress=False)
    assert summary["trained"] is False and summary["updates"] == 0
    assert not (tmp_path / "policy.pt").exists() and (tmp_path / "checkpoint.pt").exists()
    assert any("no updates were made" in m for m in caplog.messages)


def test_resume_drops_log_rows_written_after_the_checkpoint(tmp_path):
    train(_config(tmp_path, steps=40, log_every_steps=10), progress=False)
    log = tmp_path / "log.csv"
    log.write_text(log.read_text() + "50,1,0.1,0,0,0,0,0,1,1\n60,1,0.1,0,0,0,0,0,1,1\n")  # logged, then killed
    train(_config(tmp_path, steps=60, log_every_steps=10), resume=True, progress=False)
    steps = [int(row.split(",")[0]) for row in log.read_text().splitlines()[1:]]
    assert steps == sorted(set(steps)) and steps[-1] == 60


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stopped_run_saves_its_checkpoint_and_resumes(tmp_path, sig):
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "primitives.training.train", "push", "--objects", "cube", "--workers", "1", "--steps",
           "100000", "--n-points", "32", "--replay-size", "500", "--learning-starts", "16", "--out", str(out)]
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]), PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True,
                            start_new_session=True)
    end = time.time() + 120
    while time.time() < end and not (out / "log.csv").exists():
        time.sleep(0.2)
    time.sleep(8.0)  # well inside the first 5-minute checkpoint interval: only the stop saves
    os.kill(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err[-2000:]
    assert "Traceback" not in err and "checkpoint saved" in err
    saved = ckpt.load(out / "checkpoint.pt", skill="push")
    summary = json.loads((out / "summary.json").read_text())
    assert saved["state"]["global_step"] == summary["steps"] > 0 and summary["interrupted"]
    assert (out / "policy.pt").exists() == (saved["state"]["n_updates"] > 0)
    end = time.time() + 10.0  # multiprocessing's helpers exit once their last user has
    while time.time() < end and _session(proc.pid):
        time.sleep(0.2)
    assert _session(proc.pid) == []  # no orphaned workers


def _session(sid: int) -> list[str]:
    """Command lines of the live processes in session ``sid``."""
    found = []
    for pid in subprocess.run(["pgrep", "-s", str(sid)], capture_output=True, text=True).stdout.split():
        try:
            with open(f"/proc/{pid}/stat") as f:
                if f.read().split()[2] == "Z":
                    continue
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                found.append(f.read().replace(b"\0", b" ").decode(errors="replace")[:120])
        except OSError:
            continue
    return found


def test_resume_keeps_the_spin_a_run_trained_with(tmp_path):
    """A run trained with spins stopping at the angle does not resume with their full motion, and a checkpoint
    written before the stop existed (no ``full_motion`` in its configuration) resumes only with ``--full-motion``."""
    train(_config(tmp_path), progress=False)
    with pytest.raises(InputError, match="--full-motion False there, True now"):
        train(_config(tmp_path, full_motion=True), resume=True, progress=False)
    from primitives.training.train import check_resume

    before = {k: v for k, v in ckpt.load(tmp_path / "checkpoint.pt", skill="push")["config"].items()
              if k != "full_motion"}
    check_resume(before, _config(tmp_path, full_motion=True), tmp_path / "checkpoint.pt")
    with pytest.raises(InputError, match="--full-motion True there, False now"):
        check_resume(before, _config(tmp_path), tmp_path / "checkpoint.pt")
