"""Push a box through the gap in a wall, to a goal pose behind it.

    python examples/wall_with_gap.py [--sim arm|finger] [--out DIR]
"""

import math
import sys

import affordplan as ap
from affordplan.app.example import run_example

if __name__ == "__main__":
    obj = ap.load_object("lunch_box")
    wall = [ap.Box(center=(0.6, -0.2), size=(0.02, 0.2, 0.1)), ap.Box(center=(0.6, 0.2), size=(0.02, 0.2, 0.1))]
    goal = ap.Goal(xy=(0.69, 0.0), yaw=0.0, resting_state=0)
    start = {"resting_state": 0, "xy": (0.42, 0.12), "yaw": math.radians(40)}
    sys.exit(run_example("wall_with_gap", obj, goal, start, wall, __doc__))
