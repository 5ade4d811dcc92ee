"""MuJoCo's interactive viewer on a running simulator, when a display exists.

:func:`open_viewer` opens ``mujoco.viewer.launch_passive`` on the simulator's model and data and
returns a :class:`LiveViewer` whose :meth:`LiveViewer.on_chunk` hook (for
:attr:`affordplan.Simulator.on_chunk`) syncs the window every 20 ms of simulated time, paced to at
most real time. Without a display (neither ``DISPLAY`` nor ``WAYLAND_DISPLAY`` set) it says so and
returns ``None``, so callers carry on headless. On macOS the passive viewer needs ``mjpython``.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable

from affordplan.sim.simulator import CHUNK_STEPS, Simulator


def display_available() -> bool:
    """Whether a window can be opened: an X11 or Wayland display on Linux; assumed elsewhere."""
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


class LiveViewer:
    """A passive MuJoCo viewer following a simulator; close the window or call :meth:`close`."""

    def __init__(self, handle, sim: Simulator, realtime: bool = True):
        self.handle = handle
        self.sim = sim
        self.realtime = realtime
        self._chunk_s = CHUNK_STEPS * sim.model.opt.timestep
        self._t0 = time.perf_counter()
        self._sim_s = 0.0

    def on_chunk(self, sim: Simulator) -> None:
        """Sync the window; sleep so that simulated time runs no faster than the wall clock."""
        if not self.handle.is_running():
            return
        self._sim_s += self._chunk_s
        if self.realtime:
            ahead = self._sim_s - (time.perf_counter() - self._t0)
            if ahead > 0:
                time.sleep(ahead)
        self.handle.sync()

    def wait_closed(self) -> None:
        """Block until the user closes the window."""
        while self.handle.is_running():
            self.handle.sync()
            time.sleep(0.05)

    def close(self) -> None:
        self.handle.close()


def open_viewer(sim: Simulator, echo: Callable[[str], None] = print, realtime: bool = True) -> LiveViewer | None:
    """A :class:`LiveViewer` on ``sim``, or ``None`` (with a message) when no display exists."""
    if not display_available():
        echo("viewer: no display (DISPLAY / WAYLAND_DISPLAY unset): carrying on headless; "
             "the video and pictures are written as usual")
        return None
    try:
        import mujoco.viewer

        handle = mujoco.viewer.launch_passive(sim.model, sim.data, show_left_ui=False, show_right_ui=False)
    except Exception as exc:  # e.g. no GLFW, or macOS without mjpython
        echo(f"viewer: could not open MuJoCo's viewer ({type(exc).__name__}: {exc}); carrying on headless")
        return None
    return LiveViewer(handle, sim, realtime=realtime)


__all__ = ["LiveViewer", "display_available", "open_viewer"]
