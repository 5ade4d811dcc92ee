"""The live viewer (affordplan.app.viewer), headless: whether a display exists, a viewer that cannot open, and
:class:`LiveViewer` syncing a stand-in window once per control chunk, paced to the wall clock."""

from __future__ import annotations

import sys
import time
import types

import numpy as np
import pytest

import affordplan as ap
from affordplan.app.viewer import LiveViewer, display_available, open_viewer
from affordplan.sim.simulator import CHUNK_STEPS


class _Window:
    """Stands in for the handle ``mujoco.viewer.launch_passive`` returns: counts syncs, runs for ``runs`` checks."""

    def __init__(self, runs: int | None = None):
        self.syncs, self.closed, self._runs = 0, False, runs

    def is_running(self) -> bool:
        if self.closed:
            return False
        if self._runs is None:
            return True
        self._runs -= 1
        return self._runs >= 0

    def sync(self) -> None:
        self.syncs += 1

    def close(self) -> None:
        self.closed = True


def _fake_mujoco_viewer(monkeypatch, launch_passive) -> None:
    import mujoco

    module = types.ModuleType("mujoco.viewer")
    module.launch_passive = launch_passive
    monkeypatch.setitem(sys.modules, "mujoco.viewer", module)
    monkeypatch.setattr(mujoco, "viewer", module, raising=False)


def test_viewer_without_a_display_carries_on_headless(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    lines: list[str] = []
    assert open_viewer(object(), echo=lines.append) is None
    assert "no display" in lines[0] and "headless" in lines[0]


def test_a_display_is_an_x11_or_wayland_one_on_linux_and_assumed_elsewhere(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    assert not display_available()
    monkeypatch.setenv("WAYLAND_DISPLAY", "wayland-0")
    assert display_available()
    monkeypatch.delenv("WAYLAND_DISPLAY")
    monkeypatch.setenv("DISPLAY", ":0")
    assert display_available()
    monkeypatch.delenv("DISPLAY")
    monkeypatch.setattr(sys, "platform", "darwin")
    assert display_available()


def test_a_viewer_that_cannot_open_says_why_and_carries_on_headless(monkeypatch):
    def no_glfw(*args, **kwargs):
        raise RuntimeError("GLFW could not be initialised")

    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setenv("DISPLAY", ":99")
    _fake_mujoco_viewer(monkeypatch, no_glfw)
    lines: list[str] = []
    assert open_viewer(types.SimpleNamespace(model=None, data=None), echo=lines.append) is None
    assert len(lines) == 1 and "could not open" in lines[0] and "headless" in lines[0]
    assert "RuntimeError: GLFW could not be initialised" in lines[0]


def test_an_open_viewer_follows_the_simulator_once_per_control_chunk(monkeypatch, cube):
    """Opened on the simulator's own model and data with the side panels hidden; hooked to ``on_chunk``, it syncs
    the window once per control chunk of a primitive (every ``CHUNK_STEPS`` physics steps)."""
    seen = {}

    def launch_passive(model, data, **kwargs):
        seen.update(model=model, data=data, **kwargs)
        return _Window()

    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setenv("DISPLAY", ":99")
    _fake_mujoco_viewer(monkeypatch, launch_passive)
    sim = ap.Simulator(cube)
    T0 = sim.reset(xy=(0.5, 0.0))
    viewer = open_viewer(sim, echo=pytest.fail, realtime=False)
    assert isinstance(viewer, LiveViewer)
    assert seen["model"] is sim.model and seen["data"] is sim.data
    assert seen["show_left_ui"] is False and seen["show_right_ui"] is False
    sim.on_chunk = viewer.on_chunk
    out = sim.execute(T0[:3, 3] - np.array([0.05, 0.0, 0.0]), (1.0, 0.0, 0.0))
    assert out.n_steps > 0 and viewer.handle.syncs * CHUNK_STEPS == out.n_steps
    viewer.close()
    assert viewer.handle.closed
    syncs = viewer.handle.syncs
    viewer.on_chunk(sim)  # a closed window is left alone
    assert viewer.handle.syncs == syncs


def test_realtime_pacing_keeps_simulated_time_behind_the_wall_clock():
    """Ten 20 ms chunks take at least the 0.2 s they simulate when paced, and far less when not."""
    sim = types.SimpleNamespace(model=types.SimpleNamespace(opt=types.SimpleNamespace(timestep=0.002)))
    chunk_s = CHUNK_STEPS * 0.002
    paced = LiveViewer(_Window(), sim, realtime=True)
    t0 = time.perf_counter()
    for _ in range(10):
        paced.on_chunk(sim)
    assert time.perf_counter() - t0 >= 10 * chunk_s - 1e-3
    assert paced.handle.syncs == 10
    free = LiveViewer(_Window(), sim, realtime=False)
    t0 = time.perf_counter()
    for _ in range(10):
        free.on_chunk(sim)
    assert time.perf_counter() - t0 < 5 * chunk_s and free.handle.syncs == 10


def test_wait_closed_returns_when_the_user_closes_the_window():
    sim = types.SimpleNamespace(model=types.SimpleNamespace(opt=types.SimpleNamespace(timestep=0.002)))
    viewer = LiveViewer(_Window(runs=3), sim, realtime=False)
    viewer.wait_closed()  # returns: the window reports itself closed after three checks
    assert viewer.handle.syncs == 3
