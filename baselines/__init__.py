"""Baseline agents for visuomotor_gym (installed as ``visuomotor_gym.baselines``).

Every agent answers ``predict(observation, state=None, episode_start=None, deterministic=True)
-> (action, state)``, the stable-baselines3 ``PolicyPredictor`` protocol.
"""
