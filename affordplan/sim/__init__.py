"""MuJoCo simulation: scene generation, physics guards and the primitive protocol."""

from affordplan.sim.guards import GuardLimits
from affordplan.sim.simulator import Outcome, Protocol, Simulator

__all__ = ["GuardLimits", "Outcome", "Protocol", "Simulator"]
