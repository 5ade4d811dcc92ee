"""Experiments and release tooling (ceilings, sensitivity, backend comparison, sim-to-sim, shipping, curves,
the kill test), run as ``python -m primitives.research.NAME``. Neither the run-time code nor training imports it."""
