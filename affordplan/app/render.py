"""Pictures of an object in its resting states (``affordplan render OBJECT``).

Each state is placed at the workspace centre at yaw 0, settled in the MuJoCo finger scene (the
fingertip parked under the table, out of view), and rendered offscreen from a free camera looking
at the object from the front-right, ``distance`` object sizes away. Tiles are laid out in a grid and
labelled with the state's index, probability and up-vector (object frame).
"""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import numpy as np

from affordplan.checks import is_whole
from affordplan.errors import InputError
from affordplan.objects.model import ObjectModel
from affordplan.sim.simulator import Simulator
from affordplan.world import Workspace


def render_states(obj: ObjectModel, states: list[int] | None = None, width: int = 320, height: int = 240,
                  seed: int = 0, distance: float = 5.5) -> list[tuple[int, np.ndarray]]:
    """``(state index, RGB image (height, width, 3))`` for each of ``states`` (all by default).

    ``distance``: camera distance in multiples of the object's size (its largest half-extent).
    Headless Linux needs ``MUJOCO_GL=egl`` (set by ``import affordplan`` when no display exists).
    """
    n = len(obj.resting_states)
    states = list(range(n)) if states is None else list(states)
    for s in states:
        if not is_whole(s) or not 0 <= s < n:
            raise InputError(f"{obj.name} has {n} resting states (0..{n - 1}), got state {s!r}")
    sim = Simulator(obj, seed=seed)
    m = sim.model
    if not (16 <= width <= m.vis.global_.offwidth and 16 <= height <= m.vis.global_.offheight):
        raise InputError(f"image size must be within 16x16..{m.vis.global_.offwidth}x{m.vis.global_.offheight} "
                         f"pixels, got {width}x{height}")
    radius = float(np.max(np.linalg.norm(obj.hull.vertices, axis=1)))
    renderer = mujoco.Renderer(m, height=height, width=width)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.azimuth, camera.elevation = 135.0, -25.0  # from the front-right (+x, -y), looking down
    camera.distance = distance * radius
    images = []
    try:
        for s in states:
            T = sim.reset(resting_state=int(s), xy=Workspace().center, yaw=0.0)
            camera.lookat[:] = (T[0, 3], T[1, 3], 0.5 * T[2, 3])
            renderer.update_scene(sim.data, camera=camera)
            images.append((int(s), renderer.render().copy()))
    finally:
        renderer.close()
        sim.close()
    return images


def state_label(obj: ObjectModel, index: int) -> str:
    """``"state 1  p=0.15  up (+0.00, +0.00, +1.00)"``, with ``(rolls)`` for a rolling family."""
    s = obj.resting_states[index]
    up = ", ".join(f"{v:+.2f}" for v in s.up)
    return f"state {index}  p={s.probability:.2f}  up ({up}){'  (rolls)' if s.is_rolling_family else ''}"


def save_states_picture(obj: ObjectModel, images: list[tuple[int, np.ndarray]], path: str | os.PathLike,
                        columns: int = 3) -> Path:
    """Lay ``images`` (from :func:`render_states`) out in a labelled grid and save it as ``path``."""
    from PIL import Image, ImageDraw

    if not images:
        raise InputError("no images to save")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    h, w = images[0][1].shape[:2]
    cols = max(1, min(columns, len(images)))
    rows = (len(images) + cols - 1) // cols
    grid = Image.new("RGB", (cols * w, rows * h), "white")
    draw = ImageDraw.Draw(grid)
    for k, (index, image) in enumerate(images):
        x, y = (k % cols) * w, (k // cols) * h
        grid.paste(Image.fromarray(image), (x, y))
        draw.rectangle((x, y, x + w - 1, y + 16), fill=(255, 255, 255))
        draw.text((x + 4, y + 3), f"{obj.name}  {state_label(obj, index)}", fill=(0, 0, 0))
    grid.save(path)
    return path


__all__ = ["render_states", "save_states_picture", "state_label"]
