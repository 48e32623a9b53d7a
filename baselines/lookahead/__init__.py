"""The lookahead baseline for SteppingStones (Patla & Vickers 2003; Eom et al. 2019 section 7): see
:mod:`.agent` and :mod:`.perception`."""

from .agent import LookaheadAgent, LookaheadParams
from .perception import StoneMemory

__all__ = ["LookaheadAgent", "LookaheadParams", "StoneMemory"]
