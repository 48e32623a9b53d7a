"""The fajen_warren baseline for ObstacleDodge: Fajen & Warren's (2003) steering dynamics on
the agent's own estimates of the pedestrians, gaze to the highest collision risk (:mod:`.agent`)."""

from .agent import FajenWarrenAgent, FajenWarrenParams, PedestrianFilter

__all__ = ["FajenWarrenAgent", "FajenWarrenParams", "PedestrianFilter"]
