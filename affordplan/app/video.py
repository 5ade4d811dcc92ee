"""Offscreen video of a simulator while it runs, written as MP4 (imageio-ffmpeg) or GIF (Pillow).

:class:`FrameRecorder` hooks :attr:`affordplan.Simulator.on_chunk` (called every 20 ms of simulated
time) and takes one frame every ``frame_interval`` seconds of simulated time with MuJoCo's
offscreen renderer (headless: ``MUJOCO_GL=egl``). :func:`write_video` encodes the frames.

What a frame costs: taking it is a snapshot of the scene (``mjv_updateScene``, microseconds) on the
simulating thread; drawing it (``mjr_render`` and reading the pixels back, 50-150 ms a frame with
Mesa's software rasteriser) happens on one background thread with one OpenGL context per recording,
while the simulation and the planner go on (MuJoCo releases the GIL while it draws). The context's
offscreen buffer is the frame's size rather than the scene's 1280x960 (MuJoCo clears and resolves all of it
every frame). What it draws is the ``quality`` (:data:`QUALITIES`): ``"standard"`` (the default) is multisampled,
without the table's reflection and without shadows, about 12 ms a 480x360 frame with Mesa's software rasteriser;
``"full"`` draws the scene as MuJoCo does (shadows and reflection, about 40 ms: the shadow pass is most of it);
``"fast"`` also drops multisampling (about 5 ms, jagged edges). ``python -m affordplan.app.video --bench`` times the
demo's execution with and without video.

Cameras: the scene's fixed ones (``overview``, ``wide``, ``top``, see :mod:`affordplan.sim.scene`) or
the free views in :data:`FREE_CAMERAS` (``arm``: the whole arm and the workspace in front of it).
"""

from __future__ import annotations

import copy
import os
import queue
import threading
import warnings
import weakref
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
SHADOW_MAP_PER_PIXEL = 2  # shadow-map texels per pixel of the frame's longer side (the scene's map when smaller)
PENDING_FRAMES = 16  # frames taken but not drawn yet, at most: the simulation waits beyond that
QUALITIES = ("standard", "full", "fast")
PLANE_GRID = 0.1  # metres: the coarsest grid a plane is drawn with below quality "full"


def camera_names(sim: Simulator) -> list[str]:
    """The cameras :class:`FrameRecorder` accepts for ``sim``: the scene's and :data:`FREE_CAMERAS`."""
    return [sim.model.camera(i).name for i in range(sim.model.ncam)] + list(FREE_CAMERAS)


def _camera(sim: Simulator, name: str) -> mujoco.MjvCamera:
    """The ``mujoco.MjvCamera`` for a scene camera's name or a free camera of :data:`FREE_CAMERAS`."""
    cam = mujoco.MjvCamera()
    if name in FREE_CAMERAS:
        spec = FREE_CAMERAS[name]
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = spec["lookat"]
        cam.distance, cam.azimuth, cam.elevation = spec["distance"], spec["azimuth"], spec["elevation"]
        return cam
    cam_id = mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_CAMERA, name) if isinstance(name, str) else -1
    if cam_id < 0:
        raise InputError(f"unknown camera {name!r}; expected one of {camera_names(sim)}")
    cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
    cam.fixedcamid = cam_id
    return cam


_DROPPED = object()  # a frame slot whose frame will never be drawn (rendering failed)


class _Drawer:
    """The background thread of a :class:`FrameRecorder`: draws scene snapshots, in order, into frame slots.

    It owns the OpenGL context (made current on its own thread, created at its first frame, freed when it stops)
    and holds no reference to the recorder, so a recorder dropped without ``close()`` still stops it.
    """

    def __init__(self, model: mujoco.MjModel, width: int, height: int, quality: str):
        self.model, self.width, self.height, self.quality = model, width, height, quality
        self.cv = threading.Condition()
        self.slots: list = []  # per frame taken: None while pending, an image, or _DROPPED
        self.failed: str | None = None
        self.jobs: queue.PriorityQueue = queue.PriorityQueue()
        self.free: queue.SimpleQueue = queue.SimpleQueue()
        self.n_scenes = 0
        self.thread = threading.Thread(target=self._run, name="affordplan-video", daemon=True)
        self.thread.start()

    # ---------------------------------------------------------------- simulating thread
    def scene(self) -> mujoco.MjvScene:
        """A scene to snapshot into: a free one, a new one while fewer than PENDING_FRAMES exist, else the next
        one the thread frees."""
        try:
            return self.free.get_nowait()
        except queue.Empty:
            pass
        while self.n_scenes >= PENDING_FRAMES:
            try:
                return self.free.get(timeout=0.5)
            except queue.Empty:
                if not self.thread.is_alive():  # it will free none: submit() drops what it is given
                    break
        self.n_scenes += 1
        m = self.model
        return mujoco.MjvScene(m, maxgeom=1000 + 2 * (m.ngeom + m.nsite + m.ntendon))

    def submit(self, scene: mujoco.MjvScene, urgent: bool) -> int:
        with self.cv:
            index = len(self.slots)
            alive = self.thread.is_alive()
            self.slots.append(None if alive else _DROPPED)
        if alive:
            self.jobs.put((0 if urgent else 1, index, scene))
        return index

    def wait(self, index: int | None = None) -> None:
        """Until frame ``index`` (every frame taken, by default) is drawn or dropped."""
        with self.cv:
            last = len(self.slots) - 1 if index is None else index
            self.cv.wait_for(lambda: all(s is not None for s in self.slots[: last + 1]))

    def stop(self) -> None:
        """Draw what is pending, free the context, end the thread (without waiting for it)."""
        self.jobs.put((2, 0, None))

    # ---------------------------------------------------------------- drawing thread
    def _run(self) -> None:
        gl = con = None
        try:
            while True:
                _, index, scene = self.jobs.get()
                if scene is None:
                    return
                frame = _DROPPED
                if self.failed is None:
                    try:
                        if con is None:
                            gl, con = self._open()
                        frame = self._draw(con, scene)
                    except Exception as exc:  # no OpenGL here: the simulation carries on without video
                        self.failed = f"{type(exc).__name__}: {exc}"
                self.free.put(scene)
                with self.cv:
                    self.slots[index] = frame
                    self.cv.notify_all()
        except BaseException as exc:  # never leave the simulating thread waiting on a dead thread
            self.failed = self.failed or f"{type(exc).__name__}: {exc}"
            raise
        finally:
            with self.cv:
                if self.failed is not None:
                    self.slots[:] = [_DROPPED if s is None else s for s in self.slots]
                self.cv.notify_all()
            if con is not None:
                con.free()
            if gl is not None:
                gl.free()

    def _open(self):
        """(GL context or None, MjrContext) sized to the frame, made current on this thread."""
        model = copy.copy(self.model)  # MjrContext reads the buffer sizes from the model: the simulator's stays as is
        model.vis.global_.offwidth, model.vis.global_.offheight = self.width, self.height
        vq = model.vis.quality
        vq.shadowsize = min(int(vq.shadowsize), SHADOW_MAP_PER_PIXEL * max(self.width, self.height))
        if self.quality != "full":
            # MuJoCo lights per vertex: a plane is drawn as a grid of its third size; a 10 cm grid changes no pixel
            # of the demo by more than 7/255 and halves the table's vertices
            planes = model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
            model.geom_size[planes, 2] = np.maximum(model.geom_size[planes, 2], PLANE_GRID)
        if self.quality == "fast":
            vq.offsamples = 0  # no multisampling
        gl_cls = getattr(mujoco, "GLContext", None)
        gl = gl_cls(self.width, self.height) if gl_cls is not None else None
        if gl is not None:
            gl.make_current()
        con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150.value)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, con)
        self.flipped = gl is not None  # EGL, OSMesa and GLFW give the rows bottom-up
        return gl, con

    def _draw(self, con: mujoco.MjrContext, scene: mujoco.MjvScene) -> np.ndarray:
        if self.quality != "full":
            scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
            scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
        rect = mujoco.MjrRect(0, 0, self.width, self.height)
        mujoco.mjr_render(rect, scene, con)
        rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        mujoco.mjr_readPixels(rgb, None, rect, con)
        return np.ascontiguousarray(rgb[::-1]) if self.flipped else rgb


class FrameRecorder:
    """Renders frames of ``sim`` while it simulates.

    Args:
        sim: the simulator to film.
        width, height: frame size, pixels.
        camera: a scene camera (``"overview"``, ``"wide"``, ``"top"``) or a free one (``"arm"``).
        frame_interval: simulated seconds between frames (rounded to whole 20 ms chunks).
        max_frames: stop recording after this many frames (bounds time and memory: 600 frames of
            480x360 take 311 MB).
        background: draw the frames on a background thread while the simulation goes on (the default);
            ``False`` draws each frame before :meth:`on_chunk` returns.
        quality: ``"standard"``: multisampled, without shadows and without the table's reflection (the table
            looks matte), about a third of ``"full"``'s drawing time with Mesa's software rasteriser, so that
            recording costs little beside the simulation. ``"full"``: the scene as MuJoCo draws it (with shadows
            and the reflection; the shadow map at most :data:`SHADOW_MAP_PER_PIXEL` texels per pixel of the longer
            side, which changes no visible detail). ``"fast"``: as ``"standard"`` without multisampling (jagged
            edges), about half its time again.

    The frames taken by :meth:`on_chunk` are drawn in the background, at most :data:`PENDING_FRAMES` behind.
    :attr:`frames` holds them in order: while the simulator's ``on_chunk`` still calls this recorder
    (:attr:`recording`) it holds the frames drawn so far; afterwards reading it first waits for the rest
    (as :meth:`flush` and :meth:`close` do). :meth:`capture` returns its frame drawn.

    Rendering failures (no OpenGL context) are reported once as a warning; recording then stops and
    the simulation carries on.
    """

    def __init__(self, sim: Simulator, width: int = 480, height: int = 360, camera: str = "arm",
                 frame_interval: float = 0.5, max_frames: int = 600, background: bool = True,
                 quality: str = "standard"):
        vis = sim.model.vis.global_
        if not (isinstance(width, int) and isinstance(height, int) and 16 <= width <= vis.offwidth
                and 16 <= height <= vis.offheight):
            raise InputError(f"frame size must be within 16x16..{vis.offwidth}x{vis.offheight} pixels, "
                             f"got {width}x{height}")
        if not frame_interval > 0:
            raise InputError(f"frame_interval must be positive seconds, got {frame_interval!r}")
        if quality not in QUALITIES:
            raise InputError(f"quality must be one of {QUALITIES}, got {quality!r}")
        self.sim = sim
        self.quality = quality
        self.width, self.height, self.camera = width, height, camera
        self._camera = _camera(sim, camera)
        self._option = mujoco.MjvOption()
        chunk_s = CHUNK_STEPS * sim.model.opt.timestep
        self.every = max(1, round(frame_interval / chunk_s))  # chunks between frames
        self.max_frames = int(max_frames)
        self.background = bool(background)
        self._drawers: list[_Drawer] = []  # the live one last; closed ones keep their frames
        self._warned = False
        self._chunks = 0

    # ---------------------------------------------------------------- frames
    @property
    def recording(self) -> bool:
        """Whether ``sim.on_chunk`` calls this recorder (directly or through :func:`chain_hooks`)."""
        hook = self.sim.on_chunk
        if hook is None:
            return False
        mine = self.on_chunk
        return hook == mine or any(h == mine for h in getattr(hook, "hooks", ()))

    @property
    def frames(self) -> list[np.ndarray]:
        """The frames (RGB uint8, ``(height, width, 3)``) in the order taken; see the class notes on waiting."""
        if not self.recording:
            self.flush()
        out: list[np.ndarray] = []
        for drawer in self._drawers:
            with drawer.cv:
                for s in drawer.slots:
                    if s is None:
                        return out
                    if s is not _DROPPED:
                        out.append(s)
        return out

    @property
    def failed(self) -> str | None:
        """Why rendering failed (``"ExceptionType: message"``), or ``None``."""
        return next((d.failed for d in self._drawers if d.failed is not None), None)

    def _taken(self) -> int:
        return sum(sum(s is not _DROPPED for s in d.slots) for d in self._drawers)

    def _report(self) -> None:
        if self.failed is not None and not self._warned:
            self._warned = True
            warnings.warn(f"rendering unavailable ({self.failed}); on a headless Linux machine set MUJOCO_GL=egl",
                          stacklevel=4)

    # ---------------------------------------------------------------- taking frames
    def _take(self, urgent: bool) -> tuple[_Drawer, int] | None:
        """Snapshot the scene now and queue it for drawing; ``None`` when rendering failed or the budget is spent."""
        self._report()
        if self.failed is not None or self._taken() >= self.max_frames:
            return None
        if not self._drawers or not self._drawers[-1].thread.is_alive():
            drawer = _Drawer(self.sim.model, self.width, self.height, self.quality)
            self._drawers.append(drawer)
            weakref.finalize(self, drawer.stop)
        drawer = self._drawers[-1]
        scene = drawer.scene()
        mujoco.mjv_updateScene(self.sim.model, self.sim.data, self._option, None, self._camera,
                               mujoco.mjtCatBit.mjCAT_ALL.value, scene)
        return drawer, drawer.submit(scene, urgent)

    def capture(self) -> np.ndarray | None:
        """Take one frame now and return it drawn; ``None`` when rendering is unavailable or the budget is spent.

        It is drawn ahead of the frames still pending (it keeps its place in :attr:`frames`)."""
        pending = self._take(urgent=True)
        return None if pending is None else self._result(*pending)

    def take(self) -> Callable[[], np.ndarray | None] | None:
        """Take one frame now without waiting for it to be drawn (it is drawn in its turn, as the frames
        :meth:`on_chunk` takes are): returns a function that waits for it and returns it (``None`` when rendering
        failed), or ``None`` when rendering is unavailable or the budget is spent. The demo takes its key frames
        this way, so that the simulation never waits for the drawing."""
        pending = self._take(urgent=False)
        if pending is None:
            return None
        drawer, index = pending
        return lambda: self._result(drawer, index)

    def _result(self, drawer: _Drawer, index: int) -> np.ndarray | None:
        drawer.wait(index)
        frame = drawer.slots[index]
        if frame is _DROPPED:
            self._report()
            return None
        return frame

    def on_chunk(self, sim: Simulator) -> None:
        """The :attr:`Simulator.on_chunk` hook: a frame every ``self.every`` chunks."""
        self._chunks += 1
        if self._chunks % self.every == 0:
            taken = self._take(urgent=False)
            if taken is not None and not self.background:
                taken[0].wait(taken[1])
                self._report()

    def flush(self) -> None:
        """Wait until every frame taken is drawn (or dropped, when rendering failed)."""
        for drawer in self._drawers:
            drawer.wait()
        self._report()

    def close(self) -> None:
        """Draw the pending frames, then free the rendering context (the frames are kept)."""
        self.flush()
        for drawer in self._drawers:
            drawer.stop()
            drawer.thread.join()


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

    call_all.hooks = tuple(live)  # type: ignore[attr-defined]  # FrameRecorder.recording looks here
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


# ------------------------------------------------------------------------------- benchmark
def bench(repeats: int = 5, max_primitives: int = 30, sim: str = "arm", seed: int = 0, time_limit: float = 5.0,
          width: int = 480, height: int = 360, frame_interval: float = 0.5, fps: float = 10.0,
          quality: str = "standard", echo: Callable[[str], None] = print) -> dict:
    """Time the demo scene's execution without and with video: ``repeats`` rounds of one run each way (the order
    alternating), same seed, so that both runs of a round see the same load on the machine.

    Each run plans afresh, untimed (the same plan every time: same seed; a fresh planner, as ``affordplan demo`` has,
    since a planner caches what it predicts), then executes the plan, timed, recording as the demo does (a frame
    every ``frame_interval`` simulated seconds and one after every primitive, :meth:`FrameRecorder.take`) and waiting
    for the last frame drawn;
    the video is then written, timed apart.

    Returns ``{"without": [s, ...], "with": [s, ...], "encode": [s, ...], "ratio": median with / median without,
    "paired": median over rounds of with / without}`` (execution seconds per run; ``encode``: writing each video).
    """
    import statistics
    import tempfile
    import time

    import affordplan as ap
    from affordplan.app.scene_file import demo_scene
    from primitives.skills import skills_sensor

    scene = demo_scene()
    obj = scene.load_object()
    camera = "arm" if sim == "arm" else "overview"
    echo(f"the demo scene ({scene.name}), seed {seed}, {sim} sim, at most {max_primitives} primitives; "
         f"video {width}x{height}, a frame every {frame_interval:g} s, quality {quality}")

    def run(video: bool) -> tuple[float, float, int, int]:
        plan = ap.plan(obj, scene.goal, start=scene.start, obstacles=scene.obstacles, time_limit=time_limit,
                       seed=seed)
        simulator = Simulator(obj, obstacles=scene.obstacles, pusher=sim, seed=seed,
                              sensor=skills_sensor(plan.planner.predictor.skills))
        simulator.set_object_pose(plan.start_pose)
        recorder = FrameRecorder(simulator, width, height, camera, frame_interval, quality=quality) if video else None
        if recorder is not None:
            simulator.on_chunk = recorder.on_chunk
            recorder.capture()
        t0 = time.perf_counter()
        # a frame after every primitive (a push of several strides is one), as the demo's strip takes them
        execution = plan.execute(sim=simulator, max_primitives=max_primitives, seed=seed,
                                 on_primitive=None if recorder is None else lambda entry: recorder.take())
        simulator.on_chunk = None
        frames = recorder.frames if recorder is not None else []  # waits for the frames still being drawn
        t_exec = time.perf_counter() - t0
        t_encode = 0.0
        if frames:
            with tempfile.TemporaryDirectory() as tmp:
                t1 = time.perf_counter()
                write_video(frames + [frames[-1]] * max(1, round(fps)), Path(tmp) / "video.mp4", fps=fps)
                t_encode = time.perf_counter() - t1
        if recorder is not None:
            recorder.close()
        simulator.close()
        return t_exec, t_encode, execution.n_primitives, len(frames)

    times: dict = {"without": [], "with": [], "encode": []}
    for r in range(repeats):
        for video in ((False, True) if r % 2 == 0 else (True, False)):
            t_exec, t_encode, n, n_frames = run(video)
            times["with" if video else "without"].append(t_exec)
            if video:
                times["encode"].append(t_encode)
            echo(f"round {r + 1} {'with' if video else 'without'} video: execution {t_exec:.1f} s, {n} primitives"
                 + (f", {n_frames} frames (writing them: {t_encode:.1f} s)" if video else ""))
    without, with_ = statistics.median(times["without"]), statistics.median(times["with"])
    times["ratio"] = with_ / without
    times["paired"] = statistics.median(w / o for w, o in zip(times["with"], times["without"]))
    echo(f"median execution: {without:.1f} s without video, {with_:.1f} s with video: ratio {times['ratio']:.2f} "
         f"(median of the rounds' ratios {times['paired']:.2f}); writing the video: "
         f"{statistics.median(times['encode']):.1f} s more")
    return times


def main(argv: list[str] | None = None) -> int:
    """``python -m affordplan.app.video --bench``: :func:`bench` from the command line."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m affordplan.app.video",
                                     description="Time the demo's execution with and without video (interleaved "
                                                 "rounds, medians).")
    parser.add_argument("--bench", action="store_true", required=True, help="run the benchmark")
    parser.add_argument("--repeats", type=int, default=5, help="rounds, one run each way (default: %(default)s)")
    parser.add_argument("--max-primitives", type=int, default=30, help="(default: %(default)s)")
    parser.add_argument("--sim", choices=["arm", "finger"], default="arm", help="(default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0, help="(default: %(default)s)")
    parser.add_argument("--width", type=int, default=480, help="(default: %(default)s)")
    parser.add_argument("--height", type=int, default=360, help="(default: %(default)s)")
    parser.add_argument("--frame-interval", type=float, default=0.5, help="(default: %(default)s)")
    parser.add_argument("--quality", choices=QUALITIES, default="standard", help="(default: %(default)s)")
    args = parser.parse_args(argv)
    if args.repeats < 1 or args.max_primitives < 1:
        parser.error("--repeats and --max-primitives must be at least 1")
    bench(repeats=args.repeats, max_primitives=args.max_primitives, sim=args.sim, seed=args.seed, width=args.width,
          height=args.height, frame_interval=args.frame_interval, quality=args.quality)
    return 0


__all__ = ["FREE_CAMERAS", "QUALITIES", "FrameRecorder", "bench", "camera_names", "chain_hooks", "save_strip",
           "write_video"]


if __name__ == "__main__":
    raise SystemExit(main())
