"""Task modules: what an episode is about (scene, visual targets, observation blocks, episode
initialisation, per-substep checks, evaluation: done, success, named reward terms; info and trace
fields). Tasks build on :mod:`visuomotor_gym.core` and a body from :mod:`visuomotor_gym.body`."""
