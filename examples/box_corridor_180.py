"""Turn a box by 180 deg in a narrow corridor and bring it to the corridor's far end.

    python examples/box_corridor_180.py [--sim arm|finger] [--out DIR]
"""

import math
import sys

import affordplan as ap
from affordplan.app.example import run_example

if __name__ == "__main__":
    box = ap.load_object("lunch_box")
    corridor = [ap.Box(center=(0.55, -0.14), size=(0.4, 0.02, 0.1)),
                ap.Box(center=(0.55, 0.14), size=(0.4, 0.02, 0.1))]
    start = {"resting_state": 0, "xy": (0.42, 0.0), "yaw": 0.0}
    goal = ap.Goal(xy=(0.66, 0.0), yaw=math.pi, resting_state=0,
                   yaw_symmetric=False)  # a labelled box: its two ends differ
    sys.exit(run_example("box_corridor_180", box, goal, start, corridor, __doc__))
