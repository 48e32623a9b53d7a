"""A trained PPO / RecurrentPPO policy behind the common ``predict`` interface (``ppo:<path>``).

``path`` is the ``model.zip`` a training run saved (or a folder holding it), with ``ppo_meta.json``
beside it, or a *packed* policy (:func:`pack_policy`: one ``.zip`` with ``ppo_meta.json`` inside and
a fresh optimizer, about a third of the size; the leaderboard keeps these). The meta gives the
algorithm, the belief features and hand action used in training, and the observation normalisation
statistics, which this agent applies itself (no pickled VecNormalize).
"""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np

META_NAME = "ppo_meta.json"


def resolve(path: str | Path) -> tuple[Path, Path | None]:
    """(model zip, meta json) for a run folder or a model file; meta None when packed in the zip."""
    p = Path(path)
    model = p / "model.zip" if p.is_dir() else p
    if not model.is_file():
        raise FileNotFoundError(f"no PPO model at {model} (give a model .zip or a run folder holding model.zip)")
    meta = model.with_name(META_NAME)
    if not meta.is_file():
        meta = model.with_suffix(".meta.json")
    if not meta.is_file():
        if _packed_meta(model.read_bytes()) is not None:
            return model, None
        raise FileNotFoundError(f"{model} has no {META_NAME} (or {model.stem}.meta.json) beside it or inside it")
    return model, meta


def _packed_meta(data: bytes) -> dict | None:
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            if META_NAME not in zf.namelist():
                return None
            return json.loads(zf.read(META_NAME).decode("utf-8"))
    except zipfile.BadZipFile:
        return None


def _algo_class(algo: str):
    if algo == "RecurrentPPO":
        from sb3_contrib import RecurrentPPO

        return RecurrentPPO
    if algo == "PPO":
        from stable_baselines3 import PPO

        return PPO
    raise ValueError(f"unknown algo {algo!r} in {META_NAME} (PPO or RecurrentPPO)")


def pack_policy(path: str | Path) -> bytes:
    """One self-contained policy file for a trained run: the SB3 zip with a fresh (empty) optimizer
    state, which inference never uses, and ``ppo_meta.json`` inside; loadable as ``ppo:<file>``."""
    model_path, meta_path = resolve(path)
    if meta_path is None:
        return model_path.read_bytes()  # already packed
    meta = json.loads(meta_path.read_text())
    model = _algo_class(meta["algo"]).load(model_path, device="cpu")
    policy = model.policy
    policy.optimizer = policy.optimizer_class(policy.parameters(), lr=float(model.lr_schedule(1.0)),
                                              **policy.optimizer_kwargs)
    buf = io.BytesIO()
    model.save(buf)
    with zipfile.ZipFile(buf, "a", compression=zipfile.ZIP_DEFLATED) as zf:
        info = zipfile.ZipInfo(META_NAME, date_time=(1980, 1, 1, 0, 0, 0))
        zf.writestr(info, json.dumps(meta, indent=2, sort_keys=True))
    return buf.getvalue()


class PPOAgent:
    """Deterministic actions of a trained policy for the flat EyeCatch observation."""

    def __init__(self, path: str | Path, env_id: str | None = None):
        model_path, meta_path = resolve(path)
        data = model_path.read_bytes()
        meta = json.loads(meta_path.read_text()) if meta_path is not None else _packed_meta(data)
        self._setup(data, meta, env_id)

    @classmethod
    def from_bytes(cls, data: bytes, env_id: str | None = None) -> PPOAgent:
        """The agent of a packed policy file (:func:`pack_policy`)."""
        meta = _packed_meta(data)
        if meta is None:
            raise ValueError(f"not a packed PPO policy: a zip holding {META_NAME} (see pack_policy)")
        agent = cls.__new__(cls)
        agent._setup(data, meta, env_id)
        return agent

    def _setup(self, data: bytes, meta: dict, env_id: str | None) -> None:
        self.meta = meta
        # Evaluating on another env id than the training one is allowed (e.g. a policy trained on
        # EyeCatch-v0 on the ladder); the belief features then follow the env it runs in.
        self.env_id = env_id or self.meta["env_id"]
        self.model = _algo_class(self.meta["algo"]).load(io.BytesIO(data), device="cpu")
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
