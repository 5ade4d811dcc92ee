"""``affordplan demo``: the mug on the table, three primitives, their outcomes and the seed's losses.

Until the learned skills ship, the demo picks contacts by hand from the point cloud (a push on the
end face, a roll high on the side, a spin at one end), executes them in the MuJoCo finger sim, prints
what each did with the seed's three objectives, and saves a rendered before/after picture.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from affordplan.objects.model import load_object
from affordplan.sim.simulator import Outcome, Simulator
from primitives import rewards


@dataclass(frozen=True)
class ScriptedPrimitive:
    name: str  # push, roll or spin: the objective it aims at
    direction: tuple[float, float]  # unit push direction on the table, world frame
    height: float  # contact height as a fraction of the object's height above the table (0..1)
    offset: float  # lateral offset as a fraction of the half-width across the direction (-1..1)
    stroke: float  # motion magnitude in [0, 1]
    state: int = 0  # resting state to start from


def scripted_action(sim: Simulator, p: ScriptedPrimitive, n_points: int = 2048):
    """Contact, normal and motion for a hand-scripted primitive, from the observed point cloud."""
    points, normals = sim.point_cloud(n_points)
    d = np.array([p.direction[0], p.direction[1], 0.0])
    d /= np.linalg.norm(d)
    lateral = np.cross([0.0, 0.0, 1.0], d)
    centre = sim.object_pose()[:3, 3]
    behind = (points - centre) @ d < 0.0  # on the finger's side of the object ...
    facing = behind & (normals @ -d > 0.5)  # ... and facing it (not the inside of a cup)
    if not facing.any():
        facing = behind
    top = points[:, 2].max()
    half_width = np.abs((points - centre) @ lateral).max()
    want_z = p.height * top
    want_lat = p.offset * half_width
    cost = np.abs(points[:, 2] - want_z) + np.abs((points - centre) @ lateral - want_lat)
    cost[~facing] = np.inf
    i = int(np.argmin(cost))
    return points[i], normals[i], p.stroke * d


def _describe(out: Outcome) -> dict:
    m = rewards.motion(out.pose_before, out.pose_after)
    return dict(
        moved_cm=100 * m.p_xy, turned_deg=m.theta_deg, axis_z=m.wz, valid=out.valid,
        approach_ok=out.approach_ok, steps=out.n_steps,
        **{f"{k}_loss": f(out.pose_before, out.pose_after) for k, f in rewards.LOSSES.items()},
        **{f"{k}_ok": f(out.pose_before, out.pose_after) for k, f in rewards.SUCCESSES.items()},
    )


DEMO_PRIMITIVES = (
    ScriptedPrimitive("push", (1.0, 0.0), height=0.45, offset=0.0, stroke=0.8),
    ScriptedPrimitive("roll", (0.0, 1.0), height=1.0, offset=0.0, stroke=1.0, state=2),  # tip it over
    ScriptedPrimitive("spin", (0.0, 1.0), height=0.45, offset=-0.85, stroke=1.0),
)


def run_demo(out_dir: str | Path = "affordplan-demo", object_name: str = "mug", seed: int = 0,
             render: bool = True, echo=print) -> list[dict]:
    """Run the demo; returns one row per primitive and writes ``demo.png`` to ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    obj = load_object(object_name)
    states = obj.resting_states
    echo(f"{obj}")
    echo("resting states: " + ", ".join(
        f"#{s.index} p={s.probability:.2f}{' (rolls)' if s.is_rolling_family else ''}" for s in states))
    sim = Simulator(obj, seed=seed)
    renderer = _Pictures(sim) if render else None
    frames = []
    rows = []
    for prim in DEMO_PRIMITIVES:
        sim.reset(resting_state=min(prim.state, len(states) - 1), xy=(0.5, 0.0), yaw=0.0)
        before = renderer.take() if renderer else None
        contact, normal, motion = scripted_action(sim, prim)
        out = sim.execute(contact, motion, normal=normal)
        row = dict(primitive=prim.name, **_describe(out))
        rows.append(row)
        after = renderer.take() if renderer else None
        frames.append((prim.name, before, after))
        echo(
            f"{prim.name:5s} contact ({contact[0]:.3f}, {contact[1]:.3f}, {contact[2]:.3f}) m, "
            f"motion ({motion[0]:+.2f}, {motion[1]:+.2f}, {motion[2]:+.2f}) -> moved {row['moved_cm']:.1f} cm, "
            f"turned {row['turned_deg']:.0f} deg (|w.z| {row['axis_z']:.2f}), state "
            f"{obj.classify(out.pose_before)} -> {obj.classify(out.pose_after)}"
        )
        echo(
            "      seed losses  push {push_loss:.3f} {p}  roll {roll_loss:.3f} {r}  spin {spin_loss:.3f} {s}"
            .format(**row, p=_tick(row["push_ok"]), r=_tick(row["roll_ok"]), s=_tick(row["spin_ok"]))
        )
    sim.close()
    if render and all(f[1] is not None for f in frames):
        path = out_dir / "demo.png"
        _save_grid(frames, path)
        echo(f"wrote {path}")
    echo(f"demo finished in {time.perf_counter() - t0:.1f} s")
    return rows


def _tick(ok: bool) -> str:
    return "success" if ok else "fail   "


class _Pictures:
    """Renders frames until the first failure, then stops trying (a failed GL context can abort)."""

    def __init__(self, sim: Simulator):
        self._sim = sim
        self._ok = True

    def take(self):
        if not self._ok:
            return None
        try:
            return self._sim.render(480, 360)
        except Exception as exc:  # no OpenGL here: the demo still runs, without pictures
            self._ok = False
            warnings.warn(f"rendering unavailable ({exc}); on a headless machine set MUJOCO_GL=egl",
                          stacklevel=2)
            return None


def _save_grid(frames, path: Path) -> None:
    from PIL import Image, ImageDraw

    h, w = frames[0][1].shape[:2]
    grid = Image.new("RGB", (2 * w, len(frames) * h), "white")
    draw = ImageDraw.Draw(grid)
    for r, (name, before, after) in enumerate(frames):
        grid.paste(Image.fromarray(before), (0, r * h))
        grid.paste(Image.fromarray(after), (w, r * h))
        draw.text((8, r * h + 8), f"{name}: before", fill=(0, 0, 0))
        draw.text((w + 8, r * h + 8), f"{name}: after", fill=(0, 0, 0))
    grid.save(path)


__all__ = ["ScriptedPrimitive", "run_demo", "scripted_action"]
