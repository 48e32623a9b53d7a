"""Package data: ``static_postures.json``, the searched best static posture per (env id, agent)
(:mod:`visuomotor_gym.static_gaze`)."""
