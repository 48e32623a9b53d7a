"""Train PPO (or RecurrentPPO, or SAC) on any registered env id with stable-baselines3, top to bottom.

    python -m visuomotor_gym.baselines.ppo.train --env EyeCatchOracle-v0 --timesteps 2000000
    vmgym train ppo --env EyeCatch-v0 --timesteps 3000000 --minutes 55
    vmgym train ppo --env SteppingStones-v0 --recurrent --timesteps 100000
    vmgym train ppo --env EyeCatch-v0 --recipe free_belief --minutes 62 --timesteps 5000000   (free gaze)

Every registered id has hyperparameters in ``hyperparams.yml``: the catch ids default to the project's
recipe (belief features, intercept hand action); every other family plays free gaze (the env's own
actions) with its named training-only shaping term. ``--belief no --hand-action absolute`` gives the
catch ids free gaze too (the RL baseline table, ``table.py``). ``--sac`` trains SB3 SAC (MlpPolicy, one env)
with the file's ``sac`` section for the id merged over its entry (same wrappers and shaping; only the ids
listed there).

Steps: read the hyperparameters for the env id (``hyperparams.yml``, a ``default`` plus per-id
overrides, then command-line overrides), make the vectorised training env (shaped reward, optional
Kalman belief features, observation/reward normalisation), train with TensorBoard logging (SB3
logs ``rollout/success_rate``, the catch rate, from ``info["is_success"]``), an ``EvalCallback`` on
the registered env and periodic checkpoints, then save the model with its normalisation statistics
as JSON (``ppo_meta.json``: no pickles) so ``ppo:<path>`` loads it in the common evaluator.

Every run writes into its own folder: ``config.yml`` (the resolved hyperparameters), ``args.json``,
``command.txt`` (the exact command), ``model.zip``, ``ppo_meta.json``, ``progress.csv``,
TensorBoard events, ``checkpoints/`` and ``eval/``.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import json
import shlex
import sys
import time
from dataclasses import asdict, dataclass, field, fields
from importlib import resources
from pathlib import Path

import numpy as np
import yaml


class TrainArgumentError(ValueError):
    """A refused argument of the training script: one line, raised before anything is written or trained
    (``vmgym train ppo`` prints it and exits with status 2, as ``python -m`` does)."""


# Bounds of the numeric flags (modelling choices: 10**10 transitions is years of CPU time; a week of
# minutes; seeds of 31 bits; 256 training envs).
MAX_TIMESTEPS = 10**10
MAX_MINUTES = 7 * 24 * 60.0
MAX_SEED = 2**31 - 1
MAX_N_ENVS = 256
ALGOS = ("PPO", "RecurrentPPO", "SAC")
# SB3 SAC's own keyword arguments that the hyperparameter file's `sac` section sets (the rest are PPO's).
SAC_KEYS = ("learning_rate", "buffer_size", "learning_starts", "batch_size", "tau", "gamma", "train_freq",
            "gradient_steps", "ent_coef", "target_update_interval", "target_entropy")
CHOICES = {"belief": ("", "yes", "no", "true", "false", "1", "0"), "hand_action": ("", "absolute", "intercept"),
           "gaze_action": ("", "free", "gated", "frozen", "free_belief")}
GAZE_BLOCK = slice(4, 6)  # the policy action's gaze block (retinal azimuth, elevation), for gaze_log_std_init
EYE_HEAD_BLOCK = slice(6, 9)  # its fixation and head blocks, for eye_head_log_std_init


@dataclass
class Args:
    """Command-line arguments (each field is a flag: ``--env``, ``--timesteps`` ...)."""

    env: str = "EyeCatchOracle-v0"
    """registered env id to train on (evaluation uses it unchanged)"""
    timesteps: int = 1_000_000
    """total environment transitions"""
    minutes: float = 0.0
    """stop after this many minutes of training (0: no limit)"""
    seed: int = 0
    """seed of the training envs, the policy and the evaluation"""
    out: str = "runs/ppo"
    """parent folder; the run writes to <out>/<env>/<run_name>"""
    run_name: str = ""
    """folder name of the run (default: algo_seed_timestamp)"""
    recurrent: bool = False
    """RecurrentPPO (LSTM policy, sb3-contrib) instead of PPO"""
    sac: bool = False
    """SB3 SAC (MlpPolicy, off-policy) instead of PPO: the hyperparameter file's `sac` section for the id"""
    belief: str = ""
    """'yes'/'no' overrides the config's belief features"""
    hand_action: str = ""
    """'absolute' (hand target anywhere in the workspace) or 'intercept' (residual around the
    belief's interception point); overrides the config"""
    gaze_action: str = ""
    """'free' (the gaze block is the policy's own) or 'gated' (a look gate: gate > 0 sends the eye to the
    belief's ball, Eyecatch 4.1, plus a small gaze residual; needs hand_action=intercept) or 'free_belief' (the gated
    mode's inputs, the believed ball on the retina, with the env's own free gaze action); overrides the config"""
    recipe: str = ""
    """a named recipe of the hyperparameter file's `recipes` section, applied over the env id's entry
    (e.g. 'free_belief': the free-gaze EyeCatch recipe of docs/baselines/rl.md)"""
    hyperparams: str = ""
    """YAML file of hyperparameters (default: the packaged hyperparams.yml)"""
    set: list = field(default_factory=list)
    """overrides as key=value (YAML values), e.g. --set learning_rate=1e-4 n_envs=4"""
    progress_bar: bool = True
    """show SB3's progress bar"""
    device: str = "cpu"
    """torch device"""


def _field_docs() -> dict[str, str]:
    """The docstring under each ``Args`` field (CleanRL style), for ``--help``."""
    import ast
    import inspect

    tree = ast.parse(inspect.getsource(Args))
    docs, last = {}, None
    for node in tree.body[0].body:
        if isinstance(node, ast.AnnAssign):
            last = node.target.id
        elif isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and last:
            docs[last] = str(node.value.value)
            last = None
    return docs


def parse_args(argv=None) -> Args:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    docs = _field_docs()
    for f in fields(Args):
        flag = "--" + f.name.replace("_", "-")
        doc = docs.get(f.name, "")
        if f.type in ("bool", bool):
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=f.default, help=doc)
        elif f.name == "set":
            parser.add_argument(flag, nargs="*", default=[], help="key=value hyperparameter overrides")
        else:
            cast = {"int": int, "float": float}.get(f.type if isinstance(f.type, str) else f.type.__name__, str)
            parser.add_argument(flag, type=cast, default=f.default, help=doc)
    return Args(**vars(parser.parse_args(argv)))


def check_args(args: Args) -> None:
    """Refuse a bad flag (:class:`TrainArgumentError`, one line) before any work: the env id registered,
    counts inside their bounds, choices among theirs, the hyperparameter file readable, the run folder
    new and its parent writable."""
    import tempfile

    from visuomotor_gym.bench.evaluate import check_env_id

    try:
        check_env_id(args.env)
    except (ValueError, TypeError) as exc:
        raise TrainArgumentError(f"--env: {exc}") from None
    for name, low, high in (("timesteps", 1, MAX_TIMESTEPS), ("seed", 0, MAX_SEED)):
        value = getattr(args, name)
        if not low <= value <= high:
            raise TrainArgumentError(f"--{name} must be in [{low}, {high}], got {value}")
    if not 0.0 <= args.minutes <= MAX_MINUTES:  # NaN fails too
        raise TrainArgumentError(f"--minutes must be in [0, {MAX_MINUTES:g}] (0: no limit), got {args.minutes}")
    for name, allowed in CHOICES.items():
        value = getattr(args, name)
        if (value.lower() if name == "belief" else value) not in allowed:
            raise TrainArgumentError(f"--{name.replace('_', '-')} must be one of {[a for a in allowed if a]}, "
                                     f"got {value!r}")
    if args.hyperparams and not Path(args.hyperparams).is_file():
        raise TrainArgumentError(f"--hyperparams {args.hyperparams} is not a file")
    if "/" in args.run_name or args.run_name in (".", ".."):
        raise TrainArgumentError(f"--run-name must be a folder name, not a path: {args.run_name!r}")
    run_dir = Path(args.out) / args.env / (args.run_name or "x")
    if args.run_name and run_dir.exists():
        raise TrainArgumentError(f"{run_dir} already exists: pick another --run-name (runs are never overwritten)")
    for ancestor in [run_dir.parent, *run_dir.parent.parents]:
        if ancestor.exists():
            if not ancestor.is_dir():
                raise TrainArgumentError(f"--out {args.out}: {ancestor} is a file, not a folder")
            try:  # proven by a folder made and removed there (/proc passes os.access for root)
                with tempfile.TemporaryDirectory(dir=ancestor, prefix=".vmgym-probe-"):
                    pass
            except OSError as exc:
                raise TrainArgumentError(f"--out {args.out}: cannot write in {ancestor} ({exc.strerror or exc})") from None
            break


def _check_config(config: dict) -> None:
    n_envs = config.get("n_envs")
    if isinstance(n_envs, bool) or not isinstance(n_envs, int) or not 1 <= n_envs <= MAX_N_ENVS:
        raise TrainArgumentError(f"n_envs must be an integer in [1, {MAX_N_ENVS}], got {n_envs!r}")
    if config.get("algo") not in ALGOS:
        raise TrainArgumentError(f"algo must be one of {list(ALGOS)}, got {config.get('algo')!r}")
    if config["algo"] == "SAC":
        if config.get("bc_episodes") or config.get("gaze_log_std_init") is not None or \
                config.get("eye_head_log_std_init") is not None:
            raise TrainArgumentError("SAC has no behaviour-cloning warm start and no per-block log std "
                                     "(bc_episodes 0, gaze_log_std_init and eye_head_log_std_init null)")
        if config.get("normalize_reward"):
            raise TrainArgumentError("SAC trains on the raw (shaped) reward: normalize_reward must be false")


def _merge(base: dict, over: dict) -> dict:
    """``base`` with ``over`` merged in, mappings recursively (a recipe's ``reward_weights: {foveation: 0.05}``
    changes that one weight and keeps the others)."""
    out = dict(base)
    for key, value in over.items():
        out[key] = _merge(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    return out


def load_config(args: Args) -> dict:
    """Hyperparameters: ``default``, then the env id's entry, then ``--set`` overrides."""
    if args.hyperparams:
        try:
            table = yaml.safe_load(Path(args.hyperparams).read_text())
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
            raise TrainArgumentError(
                f"--hyperparams {args.hyperparams}: cannot read it ({exc})".replace("\n", " ")
            ) from exc
        if not isinstance(table, dict) or not isinstance(table.get("default"), dict):
            raise TrainArgumentError(f"--hyperparams {args.hyperparams}: a YAML mapping with a 'default' entry expected")
    else:
        table = yaml.safe_load(resources.files("visuomotor_gym.baselines.ppo").joinpath("hyperparams.yml").read_text())
    config = copy.deepcopy(table["default"])
    entry = dict(table.get(args.env) or {})
    replace = set(entry.pop("replace", []) or [])  # keys whose dict replaces the default's (not merged)
    for key, value in entry.items():
        if isinstance(value, dict) and isinstance(config.get(key), dict) and key not in replace:
            config[key] = {**config[key], **value}
        else:
            config[key] = value
    if args.recipe:
        recipes = table.get("recipes") or {}
        if args.recipe not in recipes:
            raise TrainArgumentError(f"--recipe must be one of {sorted(recipes)}, got {args.recipe!r}")
        config = _merge(config, recipes[args.recipe] or {})
    if args.sac:
        if args.recurrent:
            raise TrainArgumentError("--sac and --recurrent exclude each other")
        section = table.get("sac") or {}
        if args.env not in section:
            raise TrainArgumentError(f"--sac: the hyperparameter file's `sac` section has no entry for {args.env} "
                                     f"(it has {sorted(k for k in section if k != 'default')})")
        config = _merge(_merge(config, section.get("default") or {}), section[args.env] or {})
        config["algo"] = "SAC"
    for item in args.set:
        key, eq, value = item.partition("=")
        if not eq or key not in config:
            raise TrainArgumentError(f"--set {item!r}: expected key=value with key in {sorted(config)}")
        parsed = yaml.safe_load(value)
        if isinstance(parsed, str):  # YAML 1.1 reads "1e-4" as a string
            with contextlib.suppress(ValueError):
                parsed = float(parsed)
        config[key] = parsed
    if args.recurrent:
        config["algo"] = "RecurrentPPO"
    if args.belief:
        config["belief"] = args.belief.lower() in ("yes", "true", "1")
    if args.hand_action:
        config["hand_action"] = args.hand_action
    if args.gaze_action:
        config["gaze_action"] = args.gaze_action
    config.setdefault("hand_action", "absolute")
    config.setdefault("intercept_residual_m", 0.15)
    config.setdefault("gaze_action", "free")
    config.setdefault("gaze_residual_deg", 3.0)
    _check_numbers(config)
    config.setdefault("bc_teacher", None)
    teacher = config["bc_teacher"]
    if teacher is not None:  # an agent spec (e.g. lookahead on SteppingStones-v0), fed the env's own observation
        from visuomotor_gym.agents import check_agent_family

        if not isinstance(teacher, str) or not teacher:
            raise TrainArgumentError(f"bc_teacher must be null or an agent spec (e.g. 'lookahead'), got {teacher!r}")
        if config["belief"] or config["gaze_action"] != "free":
            raise TrainArgumentError(f"bc_teacher={teacher!r} needs the env's own observation and action "
                                     f"(belief: false, gaze_action: free)")
        try:
            check_agent_family(teacher, args.env)
        except (ValueError, KeyError) as exc:
            raise TrainArgumentError(f"bc_teacher={teacher!r}: {exc}".replace("\n", " ")) from None
    elif config["bc_episodes"] and config["gaze_action"] != "free_belief":
        raise TrainArgumentError(f"bc_episodes needs gaze_action=free_belief (the LookTeacher's inputs) or a "
                                 f"bc_teacher agent spec, got gaze_action={config['gaze_action']}")
    if config["gaze_action"] not in CHOICES["gaze_action"][1:]:
        raise TrainArgumentError(f"gaze_action must be one of {list(CHOICES['gaze_action'][1:])}, "
                                 f"got {config['gaze_action']!r}")
    if config["gaze_action"] != "free" and config["hand_action"] != "intercept":
        raise TrainArgumentError(f"gaze_action={config['gaze_action']} needs hand_action=intercept (and the belief features)")
    if config["hand_action"] not in ("absolute", "intercept"):
        raise TrainArgumentError(f"hand_action must be 'absolute' or 'intercept', got {config['hand_action']!r}")
    if config["hand_action"] == "intercept" and not config["belief"]:
        raise TrainArgumentError("hand_action=intercept needs the belief features (belief: true): the residual is "
                         "relative to the belief's interception point")
    return config


# The recipes' numeric options: (key, default, (low, high), integer, null allowed, what it is), checked by
# _check_numbers before anything is built.
NUMERIC_OPTIONS = (
    ("bc_episodes", 0, (0, 100_000), True, False, ""),
    ("bc_epochs", 20, (1, 10_000), True, False, ""),
    ("bc_dagger_rounds", 0, (0, 100), True, False, ""),
    ("bc_noise", 0.02, (0.0, 1.0), False, False, ""),
    ("bc_lr", 1e-3, (1e-6, 1.0), False, False, ""),
    ("bc_gaze_weight", 1.0, (0.0, 1000.0), False, False, ""),
    ("gaze_shaping", 0.0, (0, 100), False, False, "reward per rad of the ball off the line of sight"),
    ("vergence_shaping", 0.0, (0, 100), False, False, "reward per unit of |ln(fixation / ball distance)|"),
    ("eye_centre_shaping", 0.0, (0, 100), False, False, "reward per rad of the eye's angle in the head"),
    ("gaze_log_std_init", None, (-10, 2), False, True, "log of the block's initial action std"),
    ("eye_head_log_std_init", None, (-10, 2), False, True, "log of the block's initial action std"),
)


def _check_numbers(config: dict) -> None:
    """Fill in the defaults of :data:`NUMERIC_OPTIONS` and refuse a value of the wrong kind or out of range,
    naming the option."""
    for key, default, (low, high), integer, nullable, what in NUMERIC_OPTIONS:
        config.setdefault(key, default)
        v = config[key]
        if nullable and v is None:
            continue
        if isinstance(v, bool) or not isinstance(v, int if integer else (int, float)) or not low <= v <= high:
            kind = ("null or " if nullable else "") + ("an integer" if integer else "a number")
            note = f" ({what})" if what else ""
            raise TrainArgumentError(f"{key} must be {kind} in [{low}, {high}]{note}, got {v!r}")


class InterceptShaping:
    """Training-only reward shaping: minus ``weight`` x the distance (m) from the hand to the throw's
    arrival point, every step. It uses the true throw (privileged), but only in the reward: the policy
    still sees observations only, and evaluation uses the registered env's own reward."""

    def __new__(cls, env, weight: float):
        import gymnasium as gym

        class _Wrapper(gym.Wrapper):
            def step(self, action):
                obs, reward, terminated, truncated, info = self.env.step(action)
                arrival = self.env.unwrapped.throw.arrival_pos
                term = -weight * float(np.linalg.norm(info["hand_pos"] - arrival))
                info = {**info, "reward_terms": {**info["reward_terms"], "intercept": term}}
                return obs, reward + term, terminated, truncated, info

        return _Wrapper(env)


class LookShaping:
    """Training-only reward shaping, every step, seen or not, privileged like :class:`InterceptShaping` and
    only in the reward: ``gaze``, minus ``gaze_weight`` x the angle (rad) between the line of sight and the
    true ball; ``vergence``, minus ``vergence_weight`` x |ln(fixation distance / true ball distance)|;
    ``eye_centre``, minus ``centre_weight`` x the eye's angle in the head (rad; the head carries the gaze, as
    in Eyecatch 4.2, before the eye reaches its orbital limit, +27.7 deg up).
    Unlike the env's ``foveation`` term (a 5 deg Gaussian, flat and zero for a ball 15 deg away), both pay
    for every degree (every percent of depth) the eye comes nearer, so a small exploration of the gaze and
    fixation blocks is rewarded from the first step."""

    def __new__(cls, env, gaze_weight: float, vergence_weight: float = 0.0, centre_weight: float = 0.0):
        import gymnasium as gym

        from visuomotor_gym.envs.observation import ObservationLayout

        fixation = ObservationLayout().slices["fixation"]
        eye_in_head = ObservationLayout().slices["eye_in_head"]

        class _Wrapper(gym.Wrapper):
            def step(self, action):
                obs, reward, terminated, truncated, info = self.env.step(action)
                to_ball = np.asarray(info["ball_pos"], dtype=float) - np.asarray(info["eye_pos"], dtype=float)
                distance = max(float(np.linalg.norm(to_ball)), 1e-9)
                cos = float(np.dot(info["gaze_dir"], to_ball)) / distance
                terms = {"gaze": -gaze_weight * float(np.arccos(np.clip(cos, -1.0, 1.0)))}
                if vergence_weight:
                    fix = max(float(np.asarray(obs)[fixation][0]), 1e-3)
                    terms["vergence"] = -vergence_weight * abs(float(np.log(fix / distance)))
                if centre_weight:
                    terms["eye_centre"] = -centre_weight * float(np.hypot(*np.asarray(obs)[eye_in_head]))
                info = {**info, "reward_terms": {**info["reward_terms"], **terms}}
                return obs, reward + sum(terms.values()), terminated, truncated, info

        return _Wrapper(env)


def make_env_fn(env_id: str, env_kwargs: dict, belief: bool, seed: int, intercept_shaping: float = 0.0,
                hand_action: str = "absolute", residual_m: float = 0.15, gaze_action: str = "free",
                gaze_residual_deg: float = 3.0, gaze_shaping: float = 0.0, vergence_shaping: float = 0.0,
                eye_centre_shaping: float = 0.0):
    """A thunk for SB3's vec envs: the env, optional shaping and belief features (and the
    belief-relative hand action), a Monitor."""

    def thunk():
        import gymnasium as gym
        from stable_baselines3.common.monitor import Monitor

        import visuomotor_gym  # noqa: F401

        env = gym.make(env_id, **env_kwargs)
        if intercept_shaping:
            env = InterceptShaping(env, intercept_shaping)
        if gaze_shaping or vergence_shaping or eye_centre_shaping:
            env = LookShaping(env, gaze_shaping, vergence_shaping, eye_centre_shaping)
        if belief:
            from visuomotor_gym.baselines.ppo.belief import BeliefObservation

            env = BeliefObservation(env, env_id, hand_action, residual_m, gaze_action, gaze_residual_deg)
        env = Monitor(env, info_keywords=("is_success",))
        env.reset(seed=seed)
        return env

    return thunk


def set_block_log_std(model, block: slice, value) -> None:
    """Set the initial log action std of a block of the policy's action (the gaze block 4-5, or the fixation
    and head block 6-8) to ``value`` (None: leave ``log_std_init`` there). SB3's diagonal Gaussian has one learned ``log_std`` per action value;
    with the 60 deg gaze range, the default std 0.37 explores +-22 deg and the plant saccades nearly every
    step (docs/baselines/ppo.md, "Left open"), so the free-gaze recipe starts the gaze block lower."""
    if value is None:
        return
    import torch

    with torch.no_grad():
        model.policy.log_std[block] = float(value)


def behaviour_clone(model, train_env, env_fn, config: dict, seed: int, log: Path) -> dict:
    """Warm start (training only): play ``bc_episodes`` episodes of the training env with the teacher, the
    scripted :class:`~visuomotor_gym.baselines.ppo.belief.LookTeacher` or, with ``bc_teacher``, that registered
    agent fed the env's own observations in order (its actions plus Gaussian noise of std
    ``bc_noise`` for state coverage; labels are the teacher's clean actions), fold their observations and
    returns into the VecNormalize statistics, then fit the policy's mean action (MSE) and its value
    (discounted normalised shaped return, MSE) for ``bc_epochs`` epochs with Adam (lr ``bc_lr``). PPO then
    trains from there with the env's free action. Returns what it did (kept in the run's ``bc.json``)."""
    import torch
    from stable_baselines3.common.vec_env import VecNormalize
    from visuomotor_gym.baselines.ppo.belief import BeliefObservation, LookTeacher

    rng = np.random.default_rng(seed)
    env = env_fn()
    agent = None
    if config.get("bc_teacher"):  # a registered agent on the env's own flat observation (stateful: it sees
        from visuomotor_gym.agents import make_agent  # every observation of the episode, in order)

        agent = make_agent(config["bc_teacher"], env.unwrapped.spec.id, int(env.action_space.shape[0]), seed=seed)

        def teacher(x):
            return np.asarray(agent.predict(x, deterministic=True)[0], np.float32)
    else:
        inner = env
        while not isinstance(inner, BeliefObservation):
            inner = inner.env
        teacher = LookTeacher(inner.features)
    noise = float(config["bc_noise"])
    gamma = float(config["gamma"])
    policy = model.policy
    rounds = []

    def play(n_episodes: int, first_seed: int, learner: bool):
        """Throws played by the teacher (or, DAgger, by the policy's mean action), each step labelled with
        the teacher's clean action; noise on the played action."""
        xs, ys, rewards, dones, caught = [], [], [], [], 0
        for episode in range(n_episodes):
            x, _ = env.reset(seed=first_seed + episode)
            if agent is not None and hasattr(agent, "reset"):
                agent.reset()
            done = False
            while not done:
                a = teacher(x)
                xs.append(x)
                ys.append(a)
                if learner:
                    obs_n = train_env.normalize_obs(x[None]) if isinstance(train_env, VecNormalize) else x[None]
                    with torch.no_grad():
                        mean = policy.get_distribution(torch.as_tensor(np.asarray(obs_n, np.float32)))
                        a = mean.distribution.mean.numpy()[0]
                played = np.clip(a + noise * rng.standard_normal(a.shape).astype(np.float32), -1.0, 1.0)
                x, r, terminated, truncated, info = env.step(played)
                done = terminated or truncated
                rewards.append(float(r))
                dones.append(done)
            caught += bool(info.get("is_success"))
        rounds.append({"player": "policy" if learner else "teacher", "episodes": n_episodes, "caught": caught,
                       "transitions": len(xs)})
        return xs, ys, rewards, dones

    data = [play(int(config["bc_episodes"]), seed + 1_000_000, False)]
    losses = []
    for k in range(int(config["bc_dagger_rounds"]) + 1):
        if k:  # DAgger (Ross et al. 2011): the states the cloned policy visits, labelled by the teacher
            data.append(play(int(config["bc_episodes"]), seed + 1_000_000 + k * 100_000, True))
        losses += _fit(model, train_env, data, config, seed, gamma, first=(k == 0))
    env.close()
    info = {"episodes": int(config["bc_episodes"]), "dagger_rounds": int(config["bc_dagger_rounds"]),
            "rounds": rounds, "transitions": sum(r["transitions"] for r in rounds),
            "teacher": config.get("bc_teacher") or "LookTeacher",
            "teacher_catches": rounds[0]["caught"], "noise": noise, "epochs": int(config["bc_epochs"]),
            "lr": float(config["bc_lr"]), "policy_mse_per_epoch": [round(v, 6) for v in losses]}
    log.write_text(json.dumps(info, indent=1))
    return info


def _fit(model, train_env, data, config: dict, seed: int, gamma: float, first: bool) -> list:
    """Fit the policy's mean action to the teacher labels and its value to the discounted normalised
    return, on all transitions in ``data``; returns the policy MSE per epoch."""
    import torch
    from stable_baselines3.common.vec_env import VecNormalize

    xs = np.asarray([x for d in data for x in d[0]], np.float32)
    ys = np.asarray([y for d in data for y in d[1]], np.float32)
    rewards = np.asarray([r for d in data for r in d[2]])
    dones = np.asarray([e for d in data for e in d[3]])
    obs = xs
    scaled = rewards
    if isinstance(train_env, VecNormalize):
        if train_env.norm_obs:
            if first:  # the statistics are fixed after the first fit: later rounds refit on the same scale
                train_env.obs_rms.update(xs)
            obs = train_env.normalize_obs(xs)
        if train_env.norm_reward and first:  # VecNormalize's running discounted return, as it would have seen it
            ret, rets = 0.0, []
            for r, d in zip(rewards, dones):
                ret = ret * gamma + r
                rets.append(ret)
                if d:
                    ret = 0.0
            train_env.ret_rms.update(np.asarray(rets))
        if train_env.norm_reward:
            scaled = np.clip(rewards / np.sqrt(train_env.ret_rms.var + train_env.epsilon),
                             -train_env.clip_reward, train_env.clip_reward)
    targets, g = np.zeros(len(scaled)), 0.0
    for i in range(len(scaled) - 1, -1, -1):  # discounted return to the episode's end
        g = scaled[i] + gamma * (0.0 if dones[i] else g)
        targets[i] = g
    policy = model.policy
    opt = torch.optim.Adam(policy.parameters(), lr=float(config["bc_lr"]))
    x_t = torch.as_tensor(np.asarray(obs, np.float32))
    y_t = torch.as_tensor(ys)
    v_t = torch.as_tensor(targets, dtype=torch.float32)
    gen = torch.Generator().manual_seed(seed)
    weight = torch.ones(y_t.shape[1])
    weight[GAZE_BLOCK] = float(config["bc_gaze_weight"])  # the gaze block's share of the imitation loss
    losses = []
    for _ in range(int(config["bc_epochs"])):
        order = torch.randperm(len(x_t), generator=gen)
        total = 0.0
        for start in range(0, len(order), 256):
            idx = order[start : start + 256]
            dist = policy.get_distribution(x_t[idx])
            loss_pi = (weight * (dist.distribution.mean - y_t[idx]) ** 2).mean()
            loss_v = ((policy.predict_values(x_t[idx]).flatten() - v_t[idx]) ** 2).mean()
            loss = loss_pi + 0.5 * loss_v
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss_pi.detach()) * len(idx)
        losses.append(total / len(order))
    return losses


def _ppo_kwargs(config: dict, args: Args) -> dict:
    """PPO's / RecurrentPPO's keyword arguments from the resolved hyperparameters."""
    return {
        "n_steps": int(config["n_steps"]), "batch_size": int(config["batch_size"]),
        "n_epochs": int(config["n_epochs"]),
        "learning_rate": float(config["learning_rate"]), "gamma": float(config["gamma"]),
        "gae_lambda": float(config["gae_lambda"]), "clip_range": float(config["clip_range"]),
        "ent_coef": float(config["ent_coef"]), "vf_coef": float(config["vf_coef"]),
        "max_grad_norm": float(config["max_grad_norm"]), "seed": args.seed, "device": args.device,
        "verbose": 0,
        "policy_kwargs": {"net_arch": list(config["net_arch"]),
                          "log_std_init": float(config["log_std_init"])},
    }


def run_meta(model, train_env, config: dict, args: Args, wall_s: float) -> dict:
    """What ``ppo:<path>`` needs besides the zip: algorithm, inputs, hand action, normalisation."""
    from stable_baselines3.common.vec_env import VecNormalize

    meta = {
        "algo": config["algo"],
        "env_id": args.env,
        "belief": bool(config["belief"]),
        "hand_action": config["hand_action"],
        "intercept_residual_m": float(config["intercept_residual_m"]),
        "timesteps": int(model.num_timesteps),
        "train_wall_s": round(wall_s, 1),
        "seed": args.seed,
    }
    if config.get("gaze_action", "free") != "free":  # old metas have no key: free gaze
        meta["gaze_action"] = config["gaze_action"]
        meta["gaze_residual_deg"] = float(config["gaze_residual_deg"])
    for key in ("gaze_log_std_init", "eye_head_log_std_init"):  # training only: a block's initial action std
        if config.get(key) is not None:
            meta[key] = float(config[key])
    if isinstance(train_env, VecNormalize) and config["normalize_obs"]:
        meta["obs_mean"] = train_env.obs_rms.mean.tolist()
        meta["obs_var"] = train_env.obs_rms.var.tolist()
        meta["clip_obs"] = float(train_env.clip_obs)
        meta["epsilon"] = float(train_env.epsilon)
    return meta


def main(argv=None) -> Path:
    """Train; a refused flag raises :class:`TrainArgumentError` before anything is written."""
    args = parse_args(argv)
    check_args(args)
    config = load_config(args)
    _check_config(config)

    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback, EvalCallback
    from stable_baselines3.common.logger import configure
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    torch.set_num_threads(1)
    run_name = args.run_name or f"{config['algo'].lower()}_s{args.seed}_{time.strftime('%Y%m%d-%H%M%S')}"
    run_dir = Path(args.out) / args.env / run_name
    if run_dir.exists():
        raise SystemExit(f"{run_dir} already exists: pick another --run-name (runs are never overwritten)")
    run_dir.mkdir(parents=True)
    (run_dir / "config.yml").write_text(yaml.safe_dump(config, sort_keys=True))
    (run_dir / "args.json").write_text(json.dumps(asdict(args), indent=2))
    (run_dir / "command.txt").write_text(shlex.join([sys.executable, "-m", "visuomotor_gym.baselines.ppo.train",
                                                     *(argv if argv is not None else sys.argv[1:])]) + "\n")

    # 1. Environments: shaped reward for training, the registered env for evaluation.
    n_envs = int(config["n_envs"])
    hand = {"hand_action": config["hand_action"], "residual_m": float(config["intercept_residual_m"]),
            "gaze_action": config["gaze_action"], "gaze_residual_deg": float(config["gaze_residual_deg"])}
    train_env = DummyVecEnv([make_env_fn(args.env, config["env_kwargs"], config["belief"], args.seed + i,
                                         float(config.get("intercept_shaping", 0.0)), **hand,
                                         gaze_shaping=float(config.get("gaze_shaping", 0.0)),
                                         vergence_shaping=float(config.get("vergence_shaping", 0.0)),
                                         eye_centre_shaping=float(config.get("eye_centre_shaping", 0.0)))
                             for i in range(n_envs)])
    eval_env = DummyVecEnv([make_env_fn(args.env, {}, config["belief"], 10_000 + args.seed, **hand)])
    if config["normalize_obs"] or config["normalize_reward"]:
        train_env = VecNormalize(train_env, norm_obs=config["normalize_obs"], norm_reward=config["normalize_reward"],
                                 gamma=config["gamma"])
        eval_env = VecNormalize(eval_env, norm_obs=config["normalize_obs"], norm_reward=False, training=False)

    # 2. The algorithm.
    common = _ppo_kwargs(config, args) if config["algo"] != "SAC" else {}
    if config["algo"] == "RecurrentPPO":
        from sb3_contrib import RecurrentPPO

        common["policy_kwargs"]["lstm_hidden_size"] = int(config.get("lstm_hidden_size", 256))
        model = RecurrentPPO("MlpLstmPolicy", train_env, **common)
    elif config["algo"] == "PPO":
        model = PPO("MlpPolicy", train_env, **common)
    elif config["algo"] == "SAC":
        from stable_baselines3 import SAC

        sac = {k: config[k] for k in SAC_KEYS if k in config}
        for k in ("learning_rate", "tau", "gamma"):
            sac[k] = float(sac[k])
        for k in ("buffer_size", "learning_starts", "batch_size", "train_freq", "gradient_steps"):
            sac[k] = int(sac[k])
        model = SAC("MlpPolicy", train_env, seed=args.seed, device=args.device, verbose=0,
                    policy_kwargs={"net_arch": list(config["net_arch"])}, **sac)
    else:
        raise SystemExit(f"algo must be one of {list(ALGOS)}, got {config['algo']!r}")
    set_block_log_std(model, GAZE_BLOCK, config.get("gaze_log_std_init"))
    set_block_log_std(model, EYE_HEAD_BLOCK, config.get("eye_head_log_std_init"))
    if int(config.get("bc_episodes", 0)) > 0:
        t0 = time.time()
        bc = behaviour_clone(model, train_env, make_env_fn(args.env, config["env_kwargs"], config["belief"],
                             args.seed, float(config.get("intercept_shaping", 0.0)), **hand,
                             gaze_shaping=float(config.get("gaze_shaping", 0.0)),
                             vergence_shaping=float(config.get("vergence_shaping", 0.0)),
                             eye_centre_shaping=float(config.get("eye_centre_shaping", 0.0))),
                             config, args.seed, run_dir / "bc.json")
        print(f"behaviour cloning: {bc['transitions']} teacher transitions ({bc['teacher_catches']}/{bc['episodes']} "
              f"caught), policy MSE {bc['policy_mse_per_epoch'][0]:.4f} -> {bc['policy_mse_per_epoch'][-1]:.4f}, "
              f"{time.time() - t0:.0f} s", flush=True)
    model.set_logger(configure(str(run_dir), ["csv", "tensorboard"]))

    # 3. Callbacks: evaluation on the registered env (with the training normalisation), checkpoints,
    #    and the wall-clock budget.
    class SyncNormalization(EvalCallback):
        """EvalCallback with the training normalisation, and the wall time of each evaluation
        (``eval/wall_time.json``, one row per evaluation: transitions, seconds since training started
        before it ran, earlier evaluations included, and its own seconds; for learning curves against
        wall time; ``eval/evaluations.npz`` holds the outcomes)."""

        def _init_callback(self) -> None:
            super()._init_callback()
            self.wall = []

        def _on_step(self) -> bool:
            due = self.eval_freq > 0 and self.n_calls % self.eval_freq == 0
            if isinstance(train_env, VecNormalize) and due:
                eval_env.obs_rms = copy.deepcopy(train_env.obs_rms)
            elapsed = time.time() - start  # before the evaluation runs: training time to this point
            keep_going = super()._on_step()
            if due:
                self.wall.append({"timesteps": int(self.num_timesteps), "wall_s": round(elapsed, 2),
                                  "eval_wall_s": round(time.time() - start - elapsed, 2)})
                (run_dir / "eval" / "wall_time.json").write_text(json.dumps(self.wall, indent=1))
            return keep_going

    from stable_baselines3.common.callbacks import BaseCallback

    class SaveBestMeta(BaseCallback):
        """Beside EvalCallback's ``eval/best_model.zip``, the normalisation it was evaluated with
        (``eval/best_model.meta.json``), so ``ppo:<run>/eval/best_model.zip`` loads it. The best is
        chosen on the EvalCallback's own throws (seed 10 000 + seed), never the evaluator's 0-199."""

        def _on_step(self) -> bool:
            meta = run_meta(model, train_env, config, args, time.time() - start)
            meta["selected"] = f"best EvalCallback mean reward {self.parent.best_mean_reward:.3f}"
            (run_dir / "eval" / "best_model.meta.json").write_text(json.dumps(meta, indent=2))
            return True

    callbacks = [
        SyncNormalization(eval_env, n_eval_episodes=int(config["eval_episodes"]),
                          eval_freq=max(1, int(config["eval_freq"]) // n_envs), log_path=str(run_dir / "eval"),
                          best_model_save_path=str(run_dir / "eval"), deterministic=True,
                          callback_on_new_best=SaveBestMeta()),
        CheckpointCallback(save_freq=max(1, int(config["checkpoint_freq"]) // n_envs),
                           save_path=str(run_dir / "checkpoints"), name_prefix="model"),
    ]
    if args.minutes > 0:

        class WallClock(BaseCallback):
            def _on_training_start(self) -> None:
                self.deadline = time.time() + 60.0 * args.minutes

            def _on_step(self) -> bool:
                return time.time() < self.deadline

        callbacks.append(WallClock())

    start = time.time()
    model.learn(total_timesteps=args.timesteps, callback=CallbackList(callbacks), progress_bar=args.progress_bar)
    wall = time.time() - start

    # 4. Save the policy and what evaluation needs to reproduce its inputs, as JSON.
    model.save(run_dir / "model.zip")
    meta = run_meta(model, train_env, config, args, wall)
    (run_dir / "ppo_meta.json").write_text(json.dumps(meta, indent=2))
    print(f"trained {model.num_timesteps} steps in {wall / 60:.1f} min; saved {run_dir / 'model.zip'}")
    return run_dir


if __name__ == "__main__":
    try:
        main()
    except TrainArgumentError as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
