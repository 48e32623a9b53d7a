"""PPO baselines (stable-baselines3 / sb3-contrib): training in :mod:`.train`, evaluation-time agent
in :mod:`.agent`, the optional Kalman belief features in :mod:`.belief`."""
