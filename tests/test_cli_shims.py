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


def _run(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", *args], capture_output=True, text=True, cwd=ROOT, env=env,
                          timeout=120)


@pytest.mark.parametrize("module", sorted(SHIMS))
def test_the_shim_runs_the_machinery_s_command_line(module):
    helped = _run(module, "--help")
    assert helped.returncode == 0, helped.stderr
    assert helped.stdout.startswith(f"usage: python -m {module} ")  # the prog name is the command as typed


@pytest.mark.parametrize("module", sorted(SHIMS))
def test_the_shim_is_the_machinery_s_main(module, capsys):
    shim, machinery = importlib.import_module(module), importlib.import_module(SHIMS[module])
    assert shim.main is machinery.main
    with pytest.raises(SystemExit) as info:
        shim.main(["--no-such-option"])
    assert info.value.code == 2 and f"python -m {module}: error:" in capsys.readouterr().err
