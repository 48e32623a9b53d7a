"""The ``eom_brace`` baseline for PushRecovery: Eom et al.'s (2019, section 7) balancing after a push
(see :mod:`.agent`)."""

from .agent import EomBraceAgent, EomBraceParams

__all__ = ["EomBraceAgent", "EomBraceParams"]
