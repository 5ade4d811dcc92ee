"""affordplan: planning non-prehensile manipulation with learned push, roll and spin primitives.

The public surface::

    import affordplan as ap
    obj = ap.load_object("mug")
    sim = ap.Simulator(obj, obstacles=[ap.Box(center=(0.6, 0.1), size=(0.3, 0.02, 0.1))])
    sim.reset(resting_state=0, xy=(0.5, 0.0))
    points, normals = sim.point_cloud(512)
    outcome = sim.execute(points[0], (1.0, 0.0, 0.0))
"""

import os as _os
import sys as _sys
import typing as _typing
from collections.abc import Iterable as _Iterable
from collections.abc import Mapping as _Mapping
from typing import Any as _Any
from typing import Literal as _Literal

# MuJoCo picks its OpenGL backend once, at import. On a Linux machine without a display, GLFW cannot
# open a context, so default to EGL (headless GPU or Mesa); an explicit MUJOCO_GL always wins.
if _sys.platform.startswith("linux") and not _os.environ.get("DISPLAY") and "mujoco" not in _sys.modules:
    _os.environ.setdefault("MUJOCO_GL", "egl")

from affordplan import errors  # noqa: E402
from affordplan.goal import Goal  # noqa: E402
from affordplan.goal import StartLike as _StartLike  # noqa: E402
from affordplan.objects import ObjectModel, RestingState, catalogue, load_object, random_object  # noqa: E402
from affordplan.sim import Outcome, Simulator  # noqa: E402
from affordplan.world import Box, Workspace  # noqa: E402

if _typing.TYPE_CHECKING:  # the planner package is imported when ap.plan is called, not with affordplan
    from planner.api import Plan, Predictor


def plan(obj: ObjectModel, goal: Goal, *, start: _StartLike = None,
         obstacles: _Iterable[Box | _Mapping[str, _Any]] = (), time_limit: float = 5.0,
         planner: _Literal["affordplan", "greedy"] = "affordplan", seed: int = 0,
         predictor: "Predictor | None" = None, workspace: Workspace = Workspace()) -> "Plan":
    """Plan to bring ``obj`` from ``start`` to ``goal`` around ``obstacles``; returns a ``Plan``.

    ``start``: ``{"resting_state": i, "xy": (x, y), "yaw": a}`` (metres, radians; each key optional) or a 4x4 pose;
    ``obstacles``: :class:`Box` objects, or dicts in the scene-file form ``{"center": [x, y], "size": [sx, sy, sz],
    "yaw": rad}`` (or ``"yaw_deg"``; :meth:`Box.from_dict`);
    ``planner``: ``"affordplan"`` (resting-state graph + OMPL + learned skills) or ``"greedy"`` (the
    reactive baseline); ``time_limit``: seconds. See :mod:`planner.plan`. The planner package is imported here,
    lazily.
    """
    from planner.api import plan as _plan

    return _plan(obj, goal, start=start, obstacles=obstacles, time_limit=time_limit, planner=planner, seed=seed,
                 predictor=predictor, workspace=workspace)


__version__ = "0.24.0.dev0"


def versions() -> dict[str, str]:
    """Versions of affordplan and of the libraries its figures depend on (physics, learning, planning).

    Benchmarks print them: the same weights and seeds give other figures under another MuJoCo release.
    """
    from importlib.metadata import PackageNotFoundError, version

    out = {"affordplan": __version__}
    for name in ("mujoco", "torch", "ompl", "mink", "python-fcl", "numpy"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def versions_text(skip: tuple[str, ...] = ()) -> str:
    """:func:`versions` as one line, ``"affordplan 0.23.0, mujoco 4.0.0, ..."``, less the names in ``skip``."""
    return ", ".join(f"{name} {v}" for name, v in versions().items() if name not in skip)


__all__ = [
    "Box",
    "Goal",
    "ObjectModel",
    "Outcome",
    "RestingState",
    "Simulator",
    "Workspace",
    "catalogue",
    "errors",
    "load_object",
    "plan",
    "random_object",
    "versions",
    "versions_text",
]
