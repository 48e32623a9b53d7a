"""A trained PPO / RecurrentPPO policy behind the common ``predict`` interface (``ppo:<path>``).

``path`` is the ``model.zip`` a training run saved (or a folder holding it); ``ppo_meta.json`` beside
it gives the algorithm, whether belief features were used, and the observation normalisation
statistics, which this agent applies itself (no pickled VecNormalize).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def resolve(path: str | Path) -> tuple[Path, Path]:
    """(model zip, meta json) for a run folder or a model file."""
    p = Path(path)
    model = p / "model.zip" if p.is_dir() else p
    if not model.is_file():
        raise FileNotFoundError(f"no PPO model at {model} (give a model .zip or a run folder holding model.zip)")
    meta = model.with_name("ppo_meta.json")
    if not meta.is_file():
        meta = model.with_suffix(".meta.json")
    if not meta.is_file():
        raise FileNotFoundError(f"{model} has no ppo_meta.json (or {model.stem}.meta.json) beside it")
    return model, meta


class PPOAgent:
    """Deterministic actions of a trained policy for the flat EyeCatch observation."""

    def __init__(self, path: str | Path, env_id: str | None = None):
        model_path, meta_path = resolve(path)
        self.meta = json.loads(meta_path.read_text())
        if env_id is not None and env_id != self.meta["env_id"]:
            # Allowed (e.g. a policy trained on EyeCatch-v0 evaluated on the ladder), but the belief
            # features must match the env it runs in.
            pass
        self.env_id = env_id or self.meta["env_id"]
        if self.meta["algo"] == "RecurrentPPO":
            from sb3_contrib import RecurrentPPO

            self.model = RecurrentPPO.load(model_path, device="cpu")
        else:
            from stable_baselines3 import PPO

            self.model = PPO.load(model_path, device="cpu")
        self.features = None
        if self.meta.get("belief"):
            from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

            self.features = BeliefFeatures(self.env_id, self.meta.get("hand_action", "absolute"),
                                           float(self.meta.get("intercept_residual_m", 0.15)))
        self.mean = np.asarray(self.meta["obs_mean"]) if "obs_mean" in self.meta else None
        self.std = np.sqrt(np.asarray(self.meta["obs_var"]) + self.meta.get("epsilon", 1e-8)) if self.mean is not None else None
        self.clip = float(self.meta.get("clip_obs", 10.0))
        self.reset()

    def reset(self) -> None:
        self.lstm_state = None
        if self.features is not None:
            self.features.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=np.float32)
        start = episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0])
        if start:
            self.reset()
        if self.features is not None:
            obs = self.features(obs)
        if self.mean is not None:
            obs = np.clip((obs - self.mean) / self.std, -self.clip, self.clip).astype(np.float32)
        if self.meta["algo"] == "RecurrentPPO":
            action, self.lstm_state = self.model.predict(
                obs, state=self.lstm_state, episode_start=np.array([start]), deterministic=True
            )
        else:
            action, _ = self.model.predict(obs, deterministic=True)
        action = np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)  # as SB3 does in training
        if self.features is not None:
            action = self.features.env_action(action)
        return action, state
