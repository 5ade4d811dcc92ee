"""MuJoCo simulation: scene generation, physics guards and the primitive protocol."""

from affordplan.sim.guards import GuardLimits
from affordplan.sim.simulator import Outcome, Protocol, SimState, Simulator

__all__ = ["GuardLimits", "Outcome", "Protocol", "SimState", "Simulator"]
