"""The command lines kept at their old names (primitives/train.py, evaluate.py, success.py): ``python -m`` runs the
machinery's main, whose help names the command as it is typed, and a bad argument is a usage error under that name."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHIMS = {
    "primitives.train": "primitives.training.train",
    "primitives.evaluate": "primitives.training.evaluate",
    "primitives.success": "primitives.training.success",
}


@pytest.fixture(scope="module")
def helped() -> dict[str, tuple[int, str, str]]:
    """``python -m SHIM --help`` of every shim, run at once (each pays torch's import): returncode, stdout, stderr."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    procs = {module: subprocess.Popen([sys.executable, "-m", module, "--help"], stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env) for module in SHIMS}
    outputs = {module: proc.communicate(timeout=120) for module, proc in procs.items()}
    return {module: (procs[module].returncode, *outputs[module]) for module in SHIMS}


@pytest.mark.parametrize("module", sorted(SHIMS))
def test_the_shim_runs_the_machinery_s_command_line(module, helped):
    returncode, stdout, stderr = helped[module]
    assert returncode == 0, stderr
    assert stdout.startswith(f"usage: python -m {module} ")  # the prog name is the command as typed


@pytest.mark.parametrize("module", sorted(SHIMS))
def test_the_shim_is_the_machinery_s_main(module, capsys):
    shim, machinery = importlib.import_module(module), importlib.import_module(SHIMS[module])
    assert shim.main is machinery.main
    with pytest.raises(SystemExit) as info:
        shim.main(["--no-such-option"])
    assert info.value.code == 2 and f"python -m {module}: error:" in capsys.readouterr().err
