"""The video recorder (issue 46): frames at the requested rate of simulated time, one rendering context per
recording, drawn in the background without changing what they show. Behaviour only, no timings."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import affordplan as ap
from affordplan.app import video
from affordplan.app.video import FrameRecorder, chain_hooks
from affordplan.errors import InputError
from affordplan.sim.simulator import CHUNK_STEPS

W, H = 96, 72


def _push(sim: ap.Simulator):
    """One finger push of the 10 cm cube along +x (2 s of simulated time; it moves the cube about 9 cm)."""
    T0 = sim.object_pose()
    return sim.execute(T0[:3, 3] - np.array([0.05, 0.0, 0.0]), (1.0, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))


def _record(cube, frame_interval=0.1, **kwargs) -> tuple[ap.Simulator, FrameRecorder, float]:
    """Film one push: (simulator, recorder, simulated seconds); the recorder is unhooked, not closed."""
    sim = ap.Simulator(cube, seed=0)
    rec = FrameRecorder(sim, W, H, camera="overview", frame_interval=frame_interval, **kwargs)
    steps0 = sim.physics_steps
    sim.on_chunk = rec.on_chunk
    _push(sim)
    sim.on_chunk = None
    return sim, rec, (sim.physics_steps - steps0) * sim.model.opt.timestep


@pytest.fixture
def counted(monkeypatch):
    """How many OpenGL and MuJoCo rendering contexts are made (patched into the ``mujoco`` module)."""
    made = {"gl": 0, "mjr": 0}
    gl_cls, mjr_cls = mujoco.GLContext, mujoco.MjrContext

    def gl(*args, **kwargs):
        made["gl"] += 1
        return gl_cls(*args, **kwargs)

    def mjr(*args, **kwargs):
        made["mjr"] += 1
        return mjr_cls(*args, **kwargs)

    monkeypatch.setattr(mujoco, "GLContext", gl)
    monkeypatch.setattr(mujoco, "MjrContext", mjr)
    return made


def test_frames_come_at_the_requested_rate_of_simulated_time(cube):
    for interval in (0.1, 0.25):
        sim, rec, seconds = _record(cube, frame_interval=interval)
        try:
            frames = rec.frames
            assert abs(len(frames) - seconds / interval) <= 1, (interval, seconds, len(frames))
        finally:
            rec.close()
            sim.close()


def test_a_frame_is_an_rgb_image_that_shows_something(cube):
    sim, rec, _ = _record(cube)
    try:
        frames = rec.frames
        assert frames
        for f in frames:
            assert isinstance(f, np.ndarray) and f.shape == (H, W, 3) and f.dtype == np.uint8
        assert len(np.unique(frames[0].reshape(-1, 3), axis=0)) > 10  # not one colour
        moved = np.abs(frames[0].astype(int) - frames[-1].astype(int)).max(axis=2)
        assert (moved > 32).mean() > 0.001  # the cube was pushed: the last frame is not the first
    finally:
        rec.close()
        sim.close()


def test_one_rendering_context_per_recording(cube, counted):
    sim = ap.Simulator(cube, seed=0)
    rec = FrameRecorder(sim, W, H, camera="overview", frame_interval=0.1)
    sim.on_chunk = rec.on_chunk
    assert rec.capture() is not None
    _push(sim)
    assert rec.capture() is not None
    _push(sim)
    sim.on_chunk = None
    assert len(rec.frames) > 20
    rec.close()
    assert counted == {"gl": 1, "mjr": 1}
    assert len(rec.frames) > 20  # closing keeps the frames
    sim.close()


def test_background_frames_equal_those_drawn_at_once(cube):
    """Each frame shows the state when it was taken, whether it is drawn in the background or before the
    simulation goes on (physics is deterministic: both runs simulate the same)."""
    sims, recs = [], []
    for background in (True, False):
        sim, rec, _ = _record(cube, frame_interval=0.2, background=background)
        sims.append(sim)
        recs.append(rec)
    try:
        a, b = recs[0].frames, recs[1].frames
        assert len(a) == len(b) > 5
        assert all(np.array_equal(x, y) for x, y in zip(a, b))
    finally:
        for rec, sim in zip(recs, sims):
            rec.close()
            sim.close()


def test_a_frame_looks_as_mujocos_renderer_draws_it(cube, monkeypatch):
    """At quality "full" the recorder's own context (sized to the frame, drawn on another thread) draws what
    ``mujoco.Renderer`` draws: the same pixels with the scene's shadow map, and nearly so with the smaller one it
    uses by default."""
    sim = ap.Simulator(cube, seed=0)
    renderer = mujoco.Renderer(sim.model, H, W)
    try:
        renderer.update_scene(sim.data, camera="overview")
        reference = renderer.render().copy()
        monkeypatch.setattr(video, "SHADOW_MAP_PER_PIXEL", 10_000)
        rec = FrameRecorder(sim, W, H, camera="overview", quality="full")
        assert np.array_equal(rec.capture(), reference)
        rec.close()
        monkeypatch.undo()
        rec = FrameRecorder(sim, W, H, camera="overview", quality="full")
        diff = np.abs(rec.capture().astype(int) - reference).max(axis=2)
        rec.close()
        assert (diff > 16).mean() < 0.01
    finally:
        renderer.close()
        sim.close()


def test_frames_while_recording_hold_those_drawn_and_afterwards_all(cube):
    sim = ap.Simulator(cube, seed=0)
    rec = FrameRecorder(sim, W, H, camera="overview", frame_interval=0.1)
    other = []
    sim.on_chunk = chain_hooks(rec.on_chunk, lambda s: other.append(1))
    assert rec.recording
    _push(sim)
    drawn = len(rec.frames)  # does not wait for the frames still being drawn
    taken = rec._chunks // rec.every
    sim.on_chunk = None
    assert not rec.recording
    assert drawn <= taken == len(rec.frames) and len(other) == rec._chunks
    rec.close()
    sim.close()


def test_the_frame_budget_is_kept(cube):
    sim, rec, _ = _record(cube, frame_interval=0.02, max_frames=7)
    try:
        assert len(rec.frames) == 7 and rec.capture() is None
    finally:
        rec.close()
        sim.close()


def test_no_rendering_warns_once_and_the_simulation_carries_on(cube, monkeypatch):
    def no_gl(*args, **kwargs):
        raise RuntimeError("no OpenGL here")

    monkeypatch.setattr(mujoco, "MjrContext", no_gl)
    sim = ap.Simulator(cube, seed=0)
    rec = FrameRecorder(sim, W, H, camera="overview", frame_interval=0.1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert rec.capture() is None
        sim.on_chunk = rec.on_chunk
        out = _push(sim)
        sim.on_chunk = None
        assert rec.capture() is None
    assert out.n_steps > 0
    assert rec.frames == [] and "no OpenGL here" in rec.failed
    assert sum("rendering unavailable" in str(w.message) for w in caught) == 1
    rec.close()
    sim.close()


def test_frame_interval_counts_whole_chunks(cube):
    sim = ap.Simulator(cube, seed=0)
    chunk = CHUNK_STEPS * sim.model.opt.timestep
    assert FrameRecorder(sim, W, H, camera="overview", frame_interval=0.25).every == round(0.25 / chunk)
    assert FrameRecorder(sim, W, H, camera="overview", frame_interval=0.001).every == 1
    with pytest.raises(InputError, match="unknown camera"):
        FrameRecorder(sim, W, H, camera="nowhere")
    sim.close()


def _orange(frame: np.ndarray) -> np.ndarray:
    """The pixels of the orange cube (the table is grey)."""
    rgb = frame.astype(int)
    return rgb[..., 0] - rgb[..., 2] > 60


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / max(1, (a | b).sum()))


def test_qualities_draw_the_same_scene(cube):
    """standard (the default) and fast draw the picture full draws, without shadows and gloss (fast: without
    multisampling, so its edges differ from standard's)."""
    sim = ap.Simulator(cube, seed=0)
    recorders = {q: FrameRecorder(sim, W, H, camera="overview", quality=q) for q in ("full", "standard", "fast")}
    assert FrameRecorder(sim, W, H, camera="overview").quality == "standard"
    try:
        frames = {q: r.capture() for q, r in recorders.items()}
        for q in ("standard", "fast"):
            assert frames[q].shape == (H, W, 3) and frames[q].dtype == np.uint8
            assert not np.array_equal(frames[q], frames["full"])
            assert _iou(_orange(frames[q]), _orange(frames["full"])) > 0.9  # the cube where full draws it
        diff = np.abs(frames["fast"].astype(int) - frames["standard"].astype(int)).max(axis=-1)
        assert 0 < (diff > 0).mean() < 0.2  # only edges change when multisampling goes
    finally:
        for r in recorders.values():
            r.close()
        sim.close()
    with pytest.raises(InputError, match="quality"):
        FrameRecorder(sim, W, H, camera="overview", quality="best")


def test_take_queues_a_frame_in_its_turn_and_returns_it_later(cube):
    sim, rec, _ = _record(cube, frame_interval=0.1)
    try:
        before = len(rec.frames)
        pending = rec.take()
        assert callable(pending)
        frame = pending()
        assert frame.shape == (H, W, 3) and frame.dtype == np.uint8
        assert len(rec.frames) == before + 1 and np.array_equal(rec.frames[-1], frame)  # its place, in order
    finally:
        rec.close()
        sim.close()
