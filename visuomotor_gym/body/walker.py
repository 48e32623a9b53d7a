"""The walker's scripted gait, by its former module name: a re-export of :mod:`visuomotor_gym.body.gait`.

The gait (footstep plan, leg inverse kinematics, servo setpoints) lives in :mod:`visuomotor_gym.body.gait`;
the obstacle pool in :mod:`visuomotor_gym.tasks.walk_scene` and the trip and misstep classification in
:mod:`visuomotor_gym.tasks.walk_contacts` (task side: what the walker walks among, and what a touch means).
"""

from __future__ import annotations

from visuomotor_gym.body.gait import (
    DEG,
    GAIT_ORDER,
    GAIT_RULES,
    LEFT,
    RIGHT,
    FootPlan,
    GaitParams,
    TurningGait,
    WalkerGait,
)

__all__ = ["DEG", "GAIT_ORDER", "GAIT_RULES", "LEFT", "RIGHT", "FootPlan", "GaitParams", "TurningGait", "WalkerGait"]
