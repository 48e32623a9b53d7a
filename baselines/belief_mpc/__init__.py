"""Belief-space MPC of Eom, Han, Shin & Noh (TOG 2019), in real time: see :mod:`.agent`."""

from .agent import BeliefMPCAgent, BeliefMPCParams
from .belief import ObservationNoise
from .ilqr import ILQRResult, solve
from .model import GazeBeliefProblem, HandProblem, Limits, PlannerWeights

__all__ = ["BeliefMPCAgent", "BeliefMPCParams", "GazeBeliefProblem", "HandProblem", "ILQRResult", "Limits", "ObservationNoise",
           "PlannerWeights", "solve"]
