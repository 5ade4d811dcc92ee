"""Bring a die (the cube) to a given face and pose, past two blocks.

    python examples/die_past_two_blocks.py [--sim arm|finger] [--out DIR]
"""

import math
import sys

import affordplan as ap
from affordplan.app.example import run_example

if __name__ == "__main__":
    die = ap.load_object("cube")
    blocks = [ap.Box(center=(0.57, 0.08), size=(0.06, 0.06, 0.08)),
              ap.Box(center=(0.55, -0.14), size=(0.06, 0.06, 0.08))]
    start = {"resting_state": 0, "xy": (0.42, 0.0), "yaw": 0.0}
    target_face = 2  # the face that should end up down, a neighbour of the start's
    goal = ap.Goal(xy=(0.68, -0.02), yaw=math.radians(30), resting_state=target_face,
                   yaw_symmetric=False)  # the pips tell turns of 90 deg apart
    sys.exit(run_example("die_past_two_blocks", die, goal, start, blocks, __doc__))
