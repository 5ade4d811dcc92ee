"""Shared fixtures: objects are loaded once per session; the decomposition cache is private."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
_CACHE = tempfile.mkdtemp(prefix="affordplan-test-cache-")
os.environ["AFFORDPLAN_CACHE"] = _CACHE

import affordplan as ap  # noqa: E402

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="session")
def cube() -> ap.ObjectModel:
    return ap.load_object("cube")


@pytest.fixture(scope="session")
def pill_bottle() -> ap.ObjectModel:
    return ap.load_object("pill_bottle")


@pytest.fixture(scope="session")
def mug() -> ap.ObjectModel:
    return ap.load_object("mug")


@pytest.fixture(scope="session")
def lunch_box() -> ap.ObjectModel:
    return ap.load_object("lunch_box")


@pytest.fixture(scope="module")
def ray_instance():
    """One local Ray instance shared by a module's tests (the trainer then leaves it running); skipped without Ray.
    Ray's usage statistics stay off: nothing is reported over the network."""
    ray = pytest.importorskip("ray")
    quiet = pytest.MonkeyPatch()
    quiet.setenv("RAY_USAGE_STATS_ENABLED", "0")
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, object_store_memory=256 * 2**20)
    try:
        yield ray
    finally:
        if started:
            ray.shutdown()
        quiet.undo()
