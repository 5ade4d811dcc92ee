"""affordplan: planning non-prehensile manipulation with learned push, roll and spin primitives.

The public surface::

    import affordplan as ap
    obj = ap.load_object("mug")
    sim = ap.Simulator(obj, obstacles=[ap.Box(center=(0.6, 0.1), size=(0.3, 0.02, 0.1))])
    sim.reset(resting_state=0, xy=(0.5, 0.0))
    points, normals = sim.point_cloud(512)
    outcome = sim.execute(points[0], (1.0, 0.0, 0.0))
"""

from affordplan import errors
from affordplan.objects import ObjectModel, RestingState, catalogue, load_object, random_object
from affordplan.sim import Outcome, Simulator
from affordplan.world import Box, Workspace

__version__ = "0.1.0"

__all__ = [
    "Box",
    "ObjectModel",
    "Outcome",
    "RestingState",
    "Simulator",
    "Workspace",
    "catalogue",
    "errors",
    "load_object",
    "random_object",
]
