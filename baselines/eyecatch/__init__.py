"""The Eyecatch heuristic (Yeo et al., SIGGRAPH 2012): see :mod:`.agent` and :mod:`.kalman`."""

from .agent import EyecatchAgent, EyecatchParams
from .kalman import BallKalmanFilter, KalmanParams

__all__ = ["BallKalmanFilter", "EyecatchAgent", "EyecatchParams", "KalmanParams"]
