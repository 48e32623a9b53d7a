"""The iwao baseline for ObstacleWalk (Iwao et al.): see :mod:`.agent`, :mod:`.gaze`,
:mod:`.perception` and :mod:`.planner`."""

from .agent import IwaoAgent, IwaoParams
from .gaze import IwaoGazeParams
from .planner import FootstepPlanner, PlannerParams

__all__ = ["FootstepPlanner", "IwaoAgent", "IwaoGazeParams", "IwaoParams", "PlannerParams"]
