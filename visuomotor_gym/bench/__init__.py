"""The evaluator every leaderboard number comes from (see :mod:`visuomotor_gym.bench.trace`)."""
