"""MuJoCo XML assets, installed as ``visuomotor_gym.envs_assets`` (see ``visuomotor_gym/assets.py``)."""
