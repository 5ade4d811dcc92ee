"""Offscreen video of a simulator while it runs, written as MP4 (imageio-ffmpeg) or GIF (Pillow).

:class:`FrameRecorder` hooks :attr:`affordplan.Simulator.on_chunk` (called every 20 ms of simulated
time) and renders one frame every ``frame_interval`` seconds of simulated time with MuJoCo's
offscreen renderer (headless: ``MUJOCO_GL=egl``). :func:`write_video` encodes the frames.

Cameras: the scene's fixed ones (``overview``, ``wide``, ``top``, see :mod:`affordplan.sim.scene`) or
the free views in :data:`FREE_CAMERAS` (``arm``: the whole arm and the workspace in front of it).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from affordplan.errors import InputError
from affordplan.sim.simulator import CHUNK_STEPS, Simulator

# Free cameras: lookat (world, metres), distance (metres), azimuth and elevation (degrees, MuJoCo's convention).
FREE_CAMERAS: dict[str, dict] = {
    "arm": dict(lookat=(0.45, 0.0, 0.18), distance=1.2, azimuth=140.0, elevation=-32.0),
}


def camera_names(sim: Simulator) -> list[str]:
    """The cameras :class:`FrameRecorder` accepts for ``sim``: the scene's and :data:`FREE_CAMERAS`."""
    return [sim.model.camera(i).name for i in range(sim.model.ncam)] + list(FREE_CAMERAS)


def _camera(sim: Simulator, name: str):
    """What ``mujoco.Renderer.update_scene`` takes as ``camera``: a scene camera's name or an MjvCamera."""
    if name in FREE_CAMERAS:
        spec = FREE_CAMERAS[name]
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = spec["lookat"]
        cam.distance, cam.azimuth, cam.elevation = spec["distance"], spec["azimuth"], spec["elevation"]
        return cam
    if mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, name) < 0:
        raise InputError(f"unknown camera {name!r}; expected one of {camera_names(sim)}")
    return name


class FrameRecorder:
    """Renders frames of ``sim`` while it simulates.

    Args:
        sim: the simulator to film.
        width, height: frame size, pixels.
        camera: a scene camera (``"overview"``, ``"wide"``, ``"top"``) or a free one (``"arm"``).
        frame_interval: simulated seconds between frames (rounded to whole 20 ms chunks).
        max_frames: stop recording after this many frames (bounds time and memory: 600 frames of
            480x360 take 311 MB).

    Rendering failures (no OpenGL context) are reported once as a warning; recording then stops and
    the simulation carries on.
    """

    def __init__(self, sim: Simulator, width: int = 480, height: int = 360, camera: str = "arm",
                 frame_interval: float = 0.25, max_frames: int = 600):
        vis = sim.model.vis.global_
        if not (isinstance(width, int) and isinstance(height, int) and 16 <= width <= vis.offwidth
                and 16 <= height <= vis.offheight):
            raise InputError(f"frame size must be within 16x16..{vis.offwidth}x{vis.offheight} pixels, "
                             f"got {width}x{height}")
        if not frame_interval > 0:
            raise InputError(f"frame_interval must be positive seconds, got {frame_interval!r}")
        self.sim = sim
        self.width, self.height, self.camera = width, height, camera
        self._camera = _camera(sim, camera)
        self._renderer: mujoco.Renderer | None = None
        chunk_s = CHUNK_STEPS * sim.model.opt.timestep
        self.every = max(1, round(frame_interval / chunk_s))  # chunks between frames
        self.max_frames = int(max_frames)
        self.frames: list[np.ndarray] = []
        self.failed: str | None = None
        self._chunks = 0

    def capture(self) -> np.ndarray | None:
        """Render and keep one frame now; ``None`` when rendering is unavailable or the budget is spent."""
        if self.failed is not None or len(self.frames) >= self.max_frames:
            return None
        try:
            if self._renderer is None:
                self._renderer = mujoco.Renderer(self.sim.model, height=self.height, width=self.width)
            self._renderer.update_scene(self.sim.data, camera=self._camera)
            frame = self._renderer.render().copy()
        except Exception as exc:  # no OpenGL here: carry on without video
            self.failed = f"{type(exc).__name__}: {exc}"
            warnings.warn(f"rendering unavailable ({self.failed}); on a headless Linux machine set MUJOCO_GL=egl",
                          stacklevel=2)
            return None
        self.frames.append(frame)
        return frame

    def close(self) -> None:
        """Free the rendering context (the frames are kept)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def on_chunk(self, sim: Simulator) -> None:
        """The :attr:`Simulator.on_chunk` hook: a frame every ``self.every`` chunks."""
        self._chunks += 1
        if self._chunks % self.every == 0:
            self.capture()


def chain_hooks(*hooks: Callable[[Simulator], None] | None) -> Callable[[Simulator], None] | None:
    """One ``on_chunk`` hook calling each of ``hooks`` (``None`` entries skipped) in order."""
    live = [h for h in hooks if h is not None]
    if not live:
        return None
    if len(live) == 1:
        return live[0]

    def call_all(sim: Simulator) -> None:
        for h in live:
            h(sim)

    return call_all


def save_strip(frames: list[tuple[str, np.ndarray]], path: str | os.PathLike, n: int = 6) -> Path:
    """A strip of ``n`` labelled frames (evenly spaced over ``frames``, first and last included) as one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not frames:
        raise InputError("no frames to save")
    path = Path(path)
    idx = np.unique(np.linspace(0, len(frames) - 1, min(n, len(frames))).round().astype(int))
    fig, axes = plt.subplots(1, len(idx), figsize=(3 * len(idx), 2.4), squeeze=False)
    for ax, i in zip(axes[0], idx):
        label, image = frames[i]
        ax.imshow(image)
        ax.set_title(label, fontsize=8)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def write_video(frames: list[np.ndarray], path: str | os.PathLike, fps: float = 10.0) -> Path:
    """Encode ``frames`` (RGB uint8, equal sizes) to ``path``; returns the path written.

    A ``.mp4`` path is written with imageio and its bundled ffmpeg; when those are unavailable the
    video is written as a GIF next to it (same stem) with Pillow. A ``.gif`` path is always a GIF.
    """
    if not frames:
        raise InputError("no frames to write")
    if not fps > 0:
        raise InputError(f"fps must be positive, got {fps!r}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".mp4":
        try:
            _write_mp4(frames, path, fps)
            return path
        except (ImportError, RuntimeError, OSError) as exc:
            warnings.warn(f"MP4 unavailable ({type(exc).__name__}: {exc}); writing a GIF instead "
                          "(pip install imageio imageio-ffmpeg for MP4)", stacklevel=2)
            path = path.with_suffix(".gif")
    elif path.suffix.lower() != ".gif":
        raise InputError(f"video path must end in .mp4 or .gif, got {str(path)!r}")
    _write_gif(frames, path, fps)
    return path


def _write_mp4(frames: list[np.ndarray], path: Path, fps: float) -> None:
    import imageio.v2 as imageio

    # libx264 wants even sizes; macro_block_size=1 keeps the frame size as rendered.
    h, w = frames[0].shape[:2]
    even = [f[: h - h % 2, : w - w % 2] for f in frames] if (h % 2 or w % 2) else frames
    with imageio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=7,
                            pixelformat="yuv420p", macro_block_size=1) as writer:
        for f in even:
            writer.append_data(np.ascontiguousarray(f))


def _write_gif(frames: list[np.ndarray], path: Path, fps: float) -> None:
    from PIL import Image

    images = [Image.fromarray(np.asarray(f, dtype=np.uint8)) for f in frames]
    images[0].save(path, save_all=True, append_images=images[1:], duration=max(20, int(1000 / fps)), loop=0,
                   optimize=False)


__all__ = ["FREE_CAMERAS", "FrameRecorder", "camera_names", "chain_hooks", "save_strip", "write_video"]
