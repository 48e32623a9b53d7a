"""The ``faraway`` baseline for the reach family: a saccade to the object, then a reach along Faraway,
Reed & Wang's (2007) predicted hand path (see :mod:`.agent`)."""

from .agent import FarawayAgent, FarawayParams

__all__ = ["FarawayAgent", "FarawayParams"]
