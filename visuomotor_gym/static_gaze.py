"""The best static twin: any agent with its gaze and head replaced by one constant posture.

``static_gaze:<posture>:<agent spec>`` is ``<agent spec>`` with three action blocks overwritten
(:class:`StaticGaze`); every other block is the base agent's:

* **gaze**: the line of sight is held at a fixed (azimuth, elevation) in the *body frame* (the seat
  frame of a seated body; the pelvis heading of a walker, ``visuomotor_gym.core.frames``). Each step
  the wrapper reads the eye's axes in that frame from the observation (the ``eye_rot`` block: an
  efference copy of the eye pose, proprioception) and compares the line of sight with the posture.
  Beyond :data:`DEAD_BAND_DEG` it requests the whole change (in the current eye frame, scaled by the
  env's gaze action range, as ``Eye.command`` reads it), which the plant makes as a saccade (after a
  turn of the body, after reset); within it the request is 0, which holds gaze fixed in the world
  (the vestibulo-ocular reflex included). The wrapper never reads a visual sample: ``eye_rot`` is
  the only block it reads.
* **head**: a fixed neck (yaw, pitch), mapped to the head action as ``core.head.Head.command`` maps it
  (0 straight ahead, +-1 the joint's range ends, ``neck_range_deg()``).
* **fixation** (vergence): a fixed distance (default :data:`DEFAULT_FIXATION_M`). Without the depth law
  vergence changes no retinal sample; with it (``VisionParams.depth_pedestal_arcmin``) depth is precise only
  near the vergence distance, and the search also picks the distance (its ``fixation`` stage).

``static_gaze:<agent spec>`` (no posture) takes the posture found by :func:`search` for that env id
and agent, from the package's ``data/static_postures.json``.

The posture is searched (``python -m visuomotor_gym.static_gaze search --env ObstacleWalk-v0 --agent
iwao --out <file.json>``): a coarse-to-fine grid over the line of sight across the eye+neck range
and over the neck, each posture played with the common evaluator on design seeds disjoint from the
pinned evaluation seeds (see :func:`search`).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import math
import sys
import time
from dataclasses import asdict, dataclass, replace
from importlib import resources
from pathlib import Path

import numpy as np

from visuomotor_gym.agents import GazeBlind, Policy, has_depth_law, make_agent, parse_agent_spec

DEAD_BAND_DEG = 3.0  # modelling choice: the plant's saccade threshold (OculomotorParams.saccade_threshold_deg,
# 3 deg), so every non-zero request is a saccade and a sub-threshold request never drives pursuit
DEFAULT_FIXATION_M = 2.0  # modelling choice: without the depth law vergence changes no retinal sample
# The vergence distances the search tries when the env's vision has the depth law (a log grid over the
# distances of these scenes: a shelf at arm's length to a pedestrian ahead; modelling choice).
FIXATION_GRID_M = (0.5, 1.0, 2.0, 4.0, 8.0)
POSTURE_KEYS = ("az", "el", "neck_yaw", "neck_pitch", "fix")
POSTURES_FILE = "static_postures.json"
DESIGN_SEED = 100_000  # design seeds 100000-100039: disjoint from the pinned seeds 0-199 and 200-399
COARSE_EPISODES = 16
FINAL_EPISODES = 40


# --- the env's geometry (read once per env id) ---------------------------------------------------
@dataclass(frozen=True)
class EyeGeometry:
    """What the wrapper needs from an env id: its layouts and the eye's and neck's ranges."""

    action_structure: tuple[tuple[str, int], ...]
    eye_rot: slice  # the eye_rot block of the flat observation
    gaze_action_range: float  # rad at a gaze action of +-1
    eye_az_deg: tuple[float, float]
    eye_el_deg: tuple[float, float]
    fixation_m: tuple[float, float]
    neck_yaw_deg: tuple[float, float]
    neck_pitch_deg: tuple[float, float]

    @property
    def los_az_deg(self) -> tuple[float, float]:
        """The line of sight's reachable azimuth (eye + neck, torso upright)."""
        return self.eye_az_deg[0] + self.neck_yaw_deg[0], self.eye_az_deg[1] + self.neck_yaw_deg[1]

    @property
    def los_el_deg(self) -> tuple[float, float]:
        return self.eye_el_deg[0] + self.neck_pitch_deg[0], self.eye_el_deg[1] + self.neck_pitch_deg[1]


@functools.cache
def env_geometry(env_id: str) -> EyeGeometry:
    """The :class:`EyeGeometry` of a registered id (its env built once per process)."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401
    from visuomotor_gym.core.head import neck_range_deg

    env = gym.make(env_id.removeprefix("visuomotor_gym:"))
    try:
        u = env.unwrapped
        p = u.oculomotor_params
        (yaw, pitch) = neck_range_deg()
        return EyeGeometry(
            action_structure=tuple(u.action_structure.items()),
            eye_rot=u.layout.slices["eye_rot"],
            gaze_action_range=float(u.gaze_action_range),
            eye_az_deg=tuple(map(float, p.eye_azimuth_range_deg)),
            eye_el_deg=tuple(map(float, p.eye_elevation_range_deg)),
            fixation_m=tuple(map(float, p.fixation_range_m)),
            neck_yaw_deg=tuple(yaw),
            neck_pitch_deg=tuple(pitch),
        )
    finally:
        env.close()


def vision_has_depth_law(env_id: str) -> bool:
    """Whether the env (with any :func:`registered_kwargs` in effect) perceives depth with the depth law of
    :mod:`visuomotor_gym.vision.periphery` (then vergence decides depth precision). Not cached: the
    registered kwargs may change between calls."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401

    env = gym.make(env_id.removeprefix("visuomotor_gym:"))
    try:
        return has_depth_law(env.unwrapped.vision_params)
    finally:
        env.close()


# --- the posture ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Posture:
    """A constant gaze-and-head posture, degrees in the body frame (x forward, y left, z up).

    ``az``/``el``: the line of sight (positive = left / up); ``neck_yaw``/``neck_pitch``: the neck's
    joint angles (positive = left / up, as the joints of ``envs_assets/common/head_eye.xml``); ``fix``:
    the fixation (vergence) distance, metres.
    """

    az: float
    el: float
    neck_yaw: float = 0.0
    neck_pitch: float = 0.0
    fix: float = DEFAULT_FIXATION_M

    def as_spec(self) -> str:
        return ",".join(f"{k}={_fmt(getattr(self, k))}" for k in POSTURE_KEYS)

    def eye_in_head_deg(self) -> tuple[float, float]:
        """The eye's (azimuth, elevation) in the head for this line of sight and neck (torso upright).

        The head's rotation in the body is Rz(yaw) Ry(-pitch) (Donders: yaw, then pitch; the pitch
        joint's axis is -y)."""
        d = _unit(self.az * _DEG, self.el * _DEG)
        cy, sy = math.cos(self.neck_yaw * _DEG), math.sin(self.neck_yaw * _DEG)
        x, y, z = cy * d[0] + sy * d[1], -sy * d[0] + cy * d[1], d[2]  # Rz(-yaw) d
        cp, sp = math.cos(self.neck_pitch * _DEG), math.sin(self.neck_pitch * _DEG)
        x, z = cp * x + sp * z, -sp * x + cp * z  # Ry(pitch) (the inverse of Ry(-pitch))
        return math.degrees(math.atan2(y, x)), math.degrees(math.atan2(z, math.hypot(x, y)))

    def distance_from_ahead_deg(self) -> float:
        """How far the line of sight is from straight ahead (the tie-break of the search)."""
        d = _unit(self.az * _DEG, self.el * _DEG)
        return math.degrees(math.acos(max(-1.0, min(1.0, d[0]))))


_DEG = math.pi / 180.0


def _unit(az: float, el: float) -> tuple[float, float, float]:
    ce = math.cos(el)
    return ce * math.cos(az), ce * math.sin(az), math.sin(el)


def _fmt(value: float) -> str:
    text = f"{value:g}"
    return text if float(text) == value else repr(float(value))


def check_posture(posture: Posture, geometry: EyeGeometry) -> Posture:
    """``posture`` if the eye and neck can hold it; otherwise a ValueError naming the field and range."""
    for key in POSTURE_KEYS:
        value = getattr(posture, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"static_gaze posture: {key} must be a finite number, got {value!r}")
    g = geometry
    checks = (("az", g.los_az_deg, "the line of sight's azimuth (eye + neck range)"),
              ("el", g.los_el_deg, "the line of sight's elevation (eye + neck range)"),
              ("neck_yaw", g.neck_yaw_deg, "the neck's yaw range"),
              ("neck_pitch", g.neck_pitch_deg, "the neck's pitch range"),
              ("fix", g.fixation_m, "the fixation range (m)"))
    for key, (lo, hi), what in checks:
        value = getattr(posture, key)
        if not lo <= value <= hi:
            raise ValueError(f"static_gaze posture: {key}={value!r} is outside {what} [{lo:g}, {hi:g}]")
    az_h, el_h = posture.eye_in_head_deg()
    tol = 1e-6
    if not (g.eye_az_deg[0] - tol <= az_h <= g.eye_az_deg[1] + tol
            and g.eye_el_deg[0] - tol <= el_h <= g.eye_el_deg[1] + tol):
        raise ValueError(
            f"static_gaze posture: the line of sight az={posture.az:g}, el={posture.el:g} needs the eye at "
            f"azimuth {az_h:.1f}, elevation {el_h:.1f} deg in the head with neck_yaw={posture.neck_yaw:g}, "
            f"neck_pitch={posture.neck_pitch:g}: outside the eye's range (azimuth [{g.eye_az_deg[0]:g}, "
            f"{g.eye_az_deg[1]:g}], elevation [{g.eye_el_deg[0]:g}, {g.eye_el_deg[1]:g}] deg); turn the neck "
            f"toward the line of sight")
    return posture


def posture_from_overrides(overrides: dict) -> Posture:
    """A :class:`Posture` from ``key=value`` overrides (``az`` and ``el`` required)."""
    unknown = sorted(set(overrides) - set(POSTURE_KEYS))
    if unknown:
        raise ValueError(f"static_gaze posture: unknown key(s) {unknown}; allowed: {list(POSTURE_KEYS)}")
    missing = [k for k in ("az", "el") if k not in overrides]
    if missing:
        raise ValueError(f"static_gaze posture: {missing} missing; a posture is "
                         "az=<deg>,el=<deg>[,neck_yaw=<deg>,neck_pitch=<deg>,fix=<m>]")
    for key, value in overrides.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):  # ValueError: a spec's text
            raise ValueError(f"static_gaze posture: {key} must be a number, got {value!r}")
    return Posture(**{k: float(v) for k, v in overrides.items()})


def static_gaze_spec(posture: Posture, base: str) -> str:
    """The agent spec of ``base`` held at ``posture`` (replays without the postures file)."""
    return f"static_gaze:{posture.as_spec()}:{base}"


# --- the searched postures -----------------------------------------------------------------------
def _postures_path() -> Path:
    return Path(str(resources.files("visuomotor_gym.data").joinpath(POSTURES_FILE)))


def load_postures(path: Path | None = None) -> dict:
    """``{env_id: {agent spec: entry}}`` of the committed postures file (entry: the posture's fields,
    its design-seed score and the results file it came from)."""
    path = _postures_path() if path is None else Path(path)
    if not path.exists():
        return {}
    data = json.loads(path.read_text())
    return data.get("postures", {})


def searched_posture(env_id: str, base: str, path: Path | None = None) -> Posture:
    """The posture the search chose for ``base`` on ``env_id``; ValueError when there is none."""
    env_id = env_id.removeprefix("visuomotor_gym:")
    table = load_postures(path)
    entry = table.get(env_id, {}).get(base)
    if entry is None:
        have = sorted(f"{e} / {a}" for e, agents in table.items() for a in agents)
        raise ValueError(
            f"static_gaze: no searched posture for agent {base!r} on {env_id} (searched: {have or 'none'}); "
            f"give one (static_gaze:az=<deg>,el=<deg>,neck_yaw=<deg>,neck_pitch=<deg>:{base}) or run "
            f"`python -m visuomotor_gym.static_gaze search --env {env_id} --agent {base} --out <file> "
            f"--update-postures`")
    return posture_from_overrides({k: entry[k] for k in POSTURE_KEYS})


def resolve_spec(spec: str, env_id: str) -> str:
    """``static_gaze:<agent>`` with the searched posture written out (a spec that replays as it is)."""
    name, overrides = parse_agent_spec(spec)
    if name != "static_gaze":
        raise ValueError(f"resolve_spec takes a static_gaze spec, got {spec!r}")
    posture, base = split_options(overrides)
    if posture is None:
        posture = searched_posture(env_id, base)
    return static_gaze_spec(posture, base)


def split_options(overrides: dict) -> tuple[Posture | None, str]:
    """(posture or None, base spec) of the parsed ``static_gaze`` overrides."""
    own = {k: v for k, v in overrides.items() if k != "base"}
    return (posture_from_overrides(own) if own else None), overrides["base"]


# --- the wrapper ---------------------------------------------------------------------------------
class StaticGaze(GazeBlind):
    """``base`` with its gaze, fixation and head actions replaced by a constant posture (module docstring).

    A :class:`GazeBlind` subclass, so whatever sees through a gaze-blind twin to its base agent
    (``agents.match_vision``, plotting state through ``__getattr__``) sees through this one too.
    """

    HELD_BLOCKS = ("gaze", "fixation", "head")

    def __init__(self, base: Policy, posture: Posture, geometry: EyeGeometry):
        structure = dict(geometry.action_structure)
        super().__init__(base, structure)
        self.posture = check_posture(posture, geometry)
        self.geometry = geometry
        start = 0
        self._blocks = {}
        for name, size in structure.items():
            self._blocks[name] = slice(start, start + size)
            start += size
        self._rot = geometry.eye_rot
        self._desired = np.array(_unit(posture.az * _DEG, posture.el * _DEG))
        self._cos_dead_band = math.cos(DEAD_BAND_DEG * _DEG)
        self._range = geometry.gaze_action_range
        lo, hi = (math.log(x) for x in geometry.fixation_m)
        self._fix_action = float(np.clip(2.0 * (math.log(posture.fix) - lo) / (hi - lo) - 1.0, -1.0, 1.0))
        self._head_action = np.array([_joint_action(posture.neck_yaw, geometry.neck_yaw_deg),
                                      _joint_action(posture.neck_pitch, geometry.neck_pitch_deg)])

    def gaze_request(self, eye_rot) -> tuple[float, float]:
        """The gaze action for an eye whose axes in the body frame are ``eye_rot`` (row-major 3x3):
        the whole change to the posture's line of sight beyond the dead band, else 0 (hold)."""
        r = np.asarray(eye_rot, dtype=float).reshape(3, 3)
        u = r.T @ self._desired  # the desired line of sight in the current eye frame
        if u[0] >= self._cos_dead_band:
            return 0.0, 0.0
        g_az = math.atan2(u[1], u[0]) / self._range
        g_el = math.atan2(u[2], math.hypot(u[0], u[1])) / self._range
        return min(max(g_az, -1.0), 1.0), min(max(g_el, -1.0), 1.0)

    def posture_action(self, eye_rot) -> np.ndarray:
        """(gaze azimuth, gaze elevation, fixation, head yaw, head pitch) for this eye pose."""
        return np.array([*self.gaze_request(eye_rot), self._fix_action, *self._head_action])

    def _eye_rots(self, observation):
        if isinstance(observation, dict):
            return np.asarray(observation["eye_rot"], dtype=float)
        return np.asarray(observation, dtype=float)[..., self._rot]

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        action, state = self.base_action(observation, state, episode_start, deterministic)
        rots = self._eye_rots(observation)
        b = self._blocks
        if rots.ndim == 1:
            rows = [(action, rots)]
        else:  # a batch of observations (a vectorised env): one posture action per row
            rows = list(zip(action.reshape(-1, self.action_dim), rots.reshape(-1, 9)))
        for act, rot in rows:
            pa = self.posture_action(rot)
            act[b["gaze"]] = pa[0:2]
            act[b["fixation"]] = pa[2]
            act[b["head"]] = pa[3:5]
        return action, state


def _joint_action(angle_deg: float, joint_range: tuple[float, float]) -> float:
    """The head action that ``Head.command`` maps to ``angle_deg`` (0 ahead, +-1 the range's ends)."""
    lo, hi = joint_range
    return angle_deg / hi if angle_deg >= 0 else angle_deg / -lo


def make_static_gaze(env_id, action_dim, seed, base=None, **posture_overrides) -> StaticGaze:
    """The ``static_gaze`` agent factory (``agents.register_agent``)."""
    posture = posture_from_overrides(posture_overrides) if posture_overrides else searched_posture(env_id, base)
    geometry = env_geometry(env_id.removeprefix("visuomotor_gym:"))
    return StaticGaze(make_agent(base, env_id, action_dim, seed=seed), posture, geometry)


# --- the search ----------------------------------------------------------------------------------
@contextlib.contextmanager
def registered_kwargs(env_id: str, kwargs: dict | None):
    """Within the block, ``env_id``'s registered kwargs carry ``kwargs`` (e.g. ``vision_params``,
    ``course_distribution``) in this process, so that the env and every agent's ``for_env`` (which reads
    the registered kwargs) agree on them; restored on exit. Empty or None: nothing changes."""
    import gymnasium as gym

    import visuomotor_gym  # noqa: F401  (registers the ids)

    if not kwargs:
        yield
        return
    if not isinstance(kwargs, dict):
        raise TypeError(f"env kwargs must be a dict of constructor arguments, got {type(kwargs).__name__}")
    spec = gym.registry[env_id.removeprefix("visuomotor_gym:")]
    saved = dict(spec.kwargs)
    spec.kwargs.update(kwargs)
    try:
        gym.make(spec.id).close()  # refuse a bad argument here, naming it, before any search
        yield
    finally:
        spec.kwargs.clear()
        spec.kwargs.update(saved)


def neck_along(az: float, el: float, geometry: EyeGeometry) -> tuple[float, float]:
    """The neck pointing along the line of sight, within its range (the coarse grid's neck)."""
    return (min(max(az, geometry.neck_yaw_deg[0]), geometry.neck_yaw_deg[1]),
            min(max(el, geometry.neck_pitch_deg[0]), geometry.neck_pitch_deg[1]))


def _grid(lo: float, hi: float, step: float) -> list[float]:
    """Multiples of ``step`` within [lo, hi]."""
    return [k * step for k in range(math.ceil(lo / step), math.floor(hi / step) + 1)]


def _los_posture(az: float, el: float, geometry: EyeGeometry, fix: float = DEFAULT_FIXATION_M) -> Posture | None:
    """The posture of a line of sight with the neck along it (vergence ``fix`` m), or None if the eye
    cannot hold it."""
    ny, npitch = neck_along(az, el, geometry)
    posture = Posture(float(az), float(el), float(ny), float(npitch), float(fix))
    try:
        return check_posture(posture, geometry)
    except ValueError:
        return None


RACE_MIN_EPISODES = 4  # modelling choice: no posture is dropped on fewer episodes
RACE_Z = 1.96  # the Wilson interval's 95 % upper bound (two-sided z)


def wilson_upper(successes: int, n: int, z: float = RACE_Z) -> float:
    """The Wilson score interval's upper bound of a success rate (Wilson 1927)."""
    if n == 0:
        return 1.0
    p = successes / n
    centre = p + z * z / (2 * n)
    spread = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (centre + spread) / (1 + z * z / n)


class _Scorer:
    """Plays postures on the design seeds with the common evaluator's chunk layout and remembers
    every result seed by seed (a posture played on 16 seeds extends to 40 without replaying).

    A posture stops early once it can no longer reach ``bar`` successes even if every remaining
    episode succeeds (``bar``: the k-th best complete score so far, so the pruning never changes which
    postures make the top k; ties continue, as the tie rule might favour the newcomer)."""

    def __init__(self, env_id: str, agent: str, design_seed: int, log=None):
        from visuomotor_gym.bench.evaluate import make_env

        self.env_id, self.agent, self.design_seed = env_id, agent, design_seed
        self.env = make_env(env_id)
        self.results: dict[Posture, list[bool]] = {}
        self.stage_of: dict[Posture, str] = {}
        self.log = log or (lambda *_: None)
        self.episodes_played = 0

    def play(self, posture: Posture, episodes: int, stage: str, bar: int = 0, race: float = 0.0) -> bool:
        """Play ``posture`` on the first ``episodes`` design seeds unless it cannot reach ``bar``
        successes, or (after :data:`RACE_MIN_EPISODES`) the Wilson upper bound of its success rate
        is below ``race``; returns whether it played them all."""
        from visuomotor_gym.bench.evaluate import episode_chunks, episode_seeds, run_chunk

        have = self.results.setdefault(posture, [])
        self.stage_of.setdefault(posture, stage)
        before = len(have)
        spec = static_gaze_spec(posture, self.agent)
        seeds = episode_seeds(self.design_seed, episodes)
        for chunk in episode_chunks(episodes):  # evaluate()'s chunks for this many episodes
            chunk_seeds = [seeds[i] for i in chunk]
            if chunk_seeds[-1] < self.design_seed + len(have):
                continue  # played already
            if chunk_seeds[0] < self.design_seed + len(have):  # a chunk layout that changed: replay it
                del have[chunk_seeds[0] - self.design_seed:]
            if sum(have) + episodes - len(have) < bar:
                break
            if len(have) >= RACE_MIN_EPISODES and wilson_upper(sum(have), len(have)) < race:
                break
            have.extend(tr.success for tr in run_chunk(spec, self.env_id, chunk_seeds, env=self.env))
            self.episodes_played += len(chunk_seeds)
        complete = len(have) >= episodes
        if len(have) > before or not complete:
            self.log(f"{stage:>9} {posture.as_spec():<55} {sum(have[:episodes]):>3}/{min(len(have), episodes):<3}"
                     + ("" if complete else f" stopped (bar {bar}/{episodes}, race {race:.3f})"))
        return complete

    def complete(self, postures, episodes: int) -> list[Posture]:
        return [p for p in postures if len(self.results.get(p, ())) >= episodes]

    def rank(self, postures, episodes: int) -> list[Posture]:
        """The postures played on ``episodes`` seeds, best first: more successes, then the line of
        sight nearer straight ahead, then the neck nearer straight ahead, then the vergence nearer
        :data:`DEFAULT_FIXATION_M` (the tie rule)."""
        return sorted(self.complete(postures, episodes),
                      key=lambda p: (-sum(self.results[p][:episodes]), p.distance_from_ahead_deg(),
                                     abs(p.neck_yaw) + abs(p.neck_pitch),
                                     abs(math.log(p.fix / DEFAULT_FIXATION_M)), p.az, p.el, p.fix))

    def best_rate(self, episodes: int) -> float:
        """The best complete success rate on ``episodes`` seeds (0 while none is complete)."""
        ranked = self.rank(list(self.results), episodes)
        return sum(self.results[ranked[0]][:episodes]) / episodes if ranked else 0.0

    def bar(self, episodes: int, k: int) -> int:
        """The k-th best complete score on ``episodes`` seeds (0 while fewer than k are complete)."""
        ranked = self.rank(list(self.results), episodes)
        return sum(self.results[ranked[k - 1]][:episodes]) if len(ranked) >= k else 0

    def close(self):
        self.env.close()


def search(env_id: str, agent: str, *, design_seed: int = DESIGN_SEED, coarse_episodes: int = COARSE_EPISODES,
           final_episodes: int = FINAL_EPISODES, coarse_step: float = 20.0, refine_steps=(10.0, 5.0),
           refine_top: int = 3, finalists: int = 5, neck_step: float = 20.0, postures=None,
           command: str | None = None, log=None, env_kwargs: dict | None = None, fixations=None,
           grid_fixation: float | None = None, fixation_top: int = 1) -> dict:
    """Search the best static posture of ``agent`` on ``env_id``; returns the results record.

    Every posture is played with :func:`visuomotor_gym.bench.evaluate.run_chunk` in ``evaluate()``'s
    chunk layout, episode ``i`` on seed ``design_seed + i`` (so ``evaluate(spec, env_id, n,
    design_seed)`` replays it). Stages:

    1. ``coarse``: the line of sight on a ``coarse_step`` grid over the eye+neck range (straight up or
       down once), the neck along it (within its range), on ``coarse_episodes`` seeds, nearest
       straight ahead first;
    2. ``refine<step>`` for each of ``refine_steps``: the 8 neighbours at +-step around the
       ``refine_top`` best so far, neck along, on ``coarse_episodes`` seeds;
    3. ``final``: the ``finalists`` best so far extended to ``final_episodes`` seeds;
    4. ``neck``: at the best final line of sight, the neck at +-``neck_step`` (yaw, pitch, both) around
       the along-the-line-of-sight neck (the postures the eye can hold; none when ``neck_step`` is 0),
       on ``final_episodes`` seeds;
    5. ``fixation``: at the best posture so far, the vergence distance at each of ``fixations`` (metres,
       within the eye's fixation range), on ``final_episodes`` seeds. ``fixations=None`` (default):
       :data:`FIXATION_GRID_M` when the env's vision has the depth law (``depth_pedestal_arcmin``: depth
       precision then depends on the vergence distance, so the static twin's vergence is part of what is
       searched), else none (vergence changes no sample); ``()``: none. With ``fixation_top`` > 1 the
       ``fixation_top`` best postures so far each get this stage (targets near the eye: a posture that
       is poor at the grid's vergence may be the best at another).

    ``grid_fixation`` (m; default :data:`DEFAULT_FIXATION_M`): the vergence of every posture of stages
    1-4 (set it near the family's targets when they lie far from 2 m, e.g. a shelf or a wall at arm's
    length, so that the line of sight is not chosen at a vergence no static eye would keep).

    A posture stops early once it cannot reach the score that selection needs (stages 1-2: the
    ``max(refine_top, finalists)``-th best on ``coarse_episodes`` seeds; 3-4: the best on
    ``final_episodes`` seeds), which never changes the selection (see :class:`_Scorer`), or, in
    stages 1, 2 and 4, once the Wilson 95 % upper bound of its rate (after 4 episodes) is below the
    best complete rate so far (racing: a posture clearly worse than the best is not played out). The chosen
    posture is the best on ``final_episodes`` seeds; ties go to the line of sight nearer straight
    ahead, then the neck nearer straight ahead. ``postures``: an explicit list instead of the grid
    (each on ``final_episodes`` seeds, no early stop; for tests). ``env_kwargs``: constructor
    arguments laid over the registered id's for the whole search (:func:`registered_kwargs`; e.g. the
    human periphery's ``vision_params`` or ``course_distribution="rough"``), recorded in the result.
    """
    with registered_kwargs(env_id, env_kwargs):
        record = _search(env_id, agent, design_seed=design_seed, coarse_episodes=coarse_episodes,
                         final_episodes=final_episodes, coarse_step=coarse_step, refine_steps=refine_steps,
                         refine_top=refine_top, finalists=finalists, neck_step=neck_step, postures=postures,
                         command=command, log=log, fixations=fixations, grid_fixation=grid_fixation,
                         fixation_top=fixation_top)
    if env_kwargs:
        record["env_kwargs"] = dict(env_kwargs)
    return record


def _search(env_id: str, agent: str, *, design_seed: int, coarse_episodes: int, final_episodes: int,
            coarse_step: float, refine_steps, refine_top: int, finalists: int, neck_step: float, postures,
            command: str | None, log, fixations=None, grid_fixation: float | None = None,
            fixation_top: int = 1) -> dict:
    from visuomotor_gym.bench.evaluate import check_env_id
    from visuomotor_gym.bench.provenance import provenance

    env_id = check_env_id(env_id)
    if parse_agent_spec(agent)[0] in ("static_gaze", "gaze_blind", "fixed_gaze"):
        raise ValueError(f"search takes an agent with its own gaze, got {agent!r}")
    if not 1 <= coarse_episodes <= final_episodes:
        raise ValueError(f"need 1 <= coarse_episodes <= final_episodes, got {coarse_episodes}, {final_episodes}")
    if fixation_top < 1:
        raise ValueError(f"fixation_top must be >= 1, got {fixation_top}")
    geometry = env_geometry(env_id)
    gfix = DEFAULT_FIXATION_M if grid_fixation is None else float(grid_fixation)
    if not geometry.fixation_m[0] <= gfix <= geometry.fixation_m[1]:
        raise ValueError(f"grid_fixation must lie in the eye's fixation range {list(geometry.fixation_m)} m, got {gfix}")
    origin = provenance(command)  # the code that runs (taken before, not after, a long search)
    started = time.perf_counter()
    scorer = _Scorer(env_id, agent, design_seed, log=log)
    stages = []
    keep = max(refine_top, finalists)
    try:
        if postures is not None:
            final = [check_posture(p, geometry) for p in postures]
            for p in final:
                scorer.play(p, final_episodes, "explicit")
            stages.append({"name": "explicit", "episodes": final_episodes, "postures": len(final)})
        else:
            coarse = [p for el in _grid(*geometry.los_el_deg, coarse_step) for az in _grid(*geometry.los_az_deg, coarse_step)
                      if (abs(el) < 90.0 or az == 0.0) and (p := _los_posture(az, el, geometry, gfix)) is not None]
            coarse.sort(key=lambda p: (p.distance_from_ahead_deg(), p.az, p.el))
            for p in coarse:
                scorer.play(p, coarse_episodes, "coarse", bar=scorer.bar(coarse_episodes, keep),
                            race=scorer.best_rate(coarse_episodes))
            stages.append({"name": "coarse", "step_deg": coarse_step, "episodes": coarse_episodes,
                           "neck": "along the line of sight, within its range", "postures": len(coarse),
                           "az_deg": [min(p.az for p in coarse), max(p.az for p in coarse)],
                           "el_deg": [min(p.el for p in coarse), max(p.el for p in coarse)],
                           "early_stop_rank": keep})
            for step in refine_steps:
                centres = scorer.rank(list(scorer.results), coarse_episodes)[:refine_top]
                new = []
                for c in centres:
                    for daz in (-step, 0.0, step):
                        for dele in (-step, 0.0, step):
                            p = _los_posture(c.az + daz, c.el + dele, geometry, gfix)
                            if p is not None and p not in scorer.results and p not in new:
                                new.append(p)
                for p in new:
                    scorer.play(p, coarse_episodes, f"refine{step:g}", bar=scorer.bar(coarse_episodes, keep),
                                race=scorer.best_rate(coarse_episodes))
                stages.append({"name": f"refine{step:g}", "step_deg": step, "episodes": coarse_episodes,
                               "around": [c.as_spec() for c in centres], "postures": len(new),
                               "early_stop_rank": keep})
            best_coarse = scorer.rank(list(scorer.results), coarse_episodes)[:finalists]
            for p in best_coarse:
                scorer.play(p, final_episodes, "final", bar=scorer.bar(final_episodes, 1))
            stages.append({"name": "final", "episodes": final_episodes,
                           "postures": [p.as_spec() for p in best_coarse], "early_stop_rank": 1})
            best = scorer.rank(best_coarse, final_episodes)[0]
            ny0, np0 = neck_along(best.az, best.el, geometry)
            offsets = (-neck_step, 0.0, neck_step) if neck_step > 0 else (0.0,)
            necks = []
            for ny in sorted({ny0 + k for k in offsets}):
                for npitch in sorted({np0 + k for k in offsets}):
                    p = Posture(best.az, best.el, float(ny), float(npitch), gfix)
                    try:
                        check_posture(p, geometry)
                    except ValueError:
                        continue
                    if p not in scorer.results:
                        necks.append(p)
            for p in necks:
                scorer.play(p, final_episodes, "neck", bar=scorer.bar(final_episodes, 1),
                            race=scorer.best_rate(final_episodes))
            stages.append({"name": "neck", "step_deg": neck_step, "episodes": final_episodes,
                           "line_of_sight": {"az": best.az, "el": best.el}, "postures": len(necks),
                           "early_stop_rank": 1})
            final = best_coarse + necks
            if fixations is None:
                fixations = FIXATION_GRID_M if vision_has_depth_law(env_id) else ()
            tops = scorer.rank(final, final_episodes)[:fixation_top]
            best = tops[0]
            lo, hi = geometry.fixation_m
            verged = []
            for top in tops:
                verged += [p for p in (replace(top, fix=float(f)) for f in fixations if lo <= f <= hi)
                           if p not in scorer.results and p not in verged]
            for p in verged:
                scorer.play(p, final_episodes, "fixation", bar=scorer.bar(final_episodes, 1),
                            race=scorer.best_rate(final_episodes))
            if fixations:
                stages.append({"name": "fixation", "episodes": final_episodes, "around": best.as_spec(),
                               "around_all": [t.as_spec() for t in tops],
                               "fixations_m": [float(f) for f in fixations], "postures": len(verged),
                               "early_stop_rank": 1})
            final = final + verged
        chosen = scorer.rank(final, final_episodes)[0]
    finally:
        scorer.close()
    wall = time.perf_counter() - started
    k = sum(scorer.results[chosen][:final_episodes])
    return {
        "env_id": env_id,
        "agent": agent,
        "chosen": {**asdict(chosen), "spec": static_gaze_spec(chosen, agent), "successes": k,
                   "episodes": final_episodes, "success": k / final_episodes},
        "design_seeds": {"first": design_seed, "last": design_seed + final_episodes - 1,
                         "coarse_episodes": coarse_episodes, "final_episodes": final_episodes,
                         "note": "episode i resets with design_seed + i (the common evaluator's rule); disjoint "
                                 "from the pinned evaluation seeds 0-199 and 200-399"},
        "stages": stages,
        "rules": {"dead_band_deg": DEAD_BAND_DEG, "fixation_m": DEFAULT_FIXATION_M, "grid_fixation_m": gfix, "fixations_m": list(fixations or ()),
                  "ties": "higher success, then the line of sight nearer straight ahead, then the neck nearer "
                          "straight ahead, then the vergence nearer fixation_m",
                  "early_stop": "a posture stops once successes + remaining episodes < the score of the "
                                "stage's early_stop_rank-th best complete posture (it can no longer be selected), "
                                f"or (coarse, refine and neck stages, after {RACE_MIN_EPISODES} episodes) once the "
                                "Wilson 95 % upper bound of its success rate is below the best complete rate of "
                                "the stage's episode count (racing; stopped postures are not ranked)",
                  "evaluator": "visuomotor_gym.bench.evaluate.run_chunk in evaluate()'s chunk layout: the same "
                               "per-seed outcomes as evaluate(spec, env_id, episodes, design_seed)"},
        "postures": [{**asdict(p), "stage": scorer.stage_of[p], "successes": sum(r), "episodes": len(r)}
                     for p, r in scorer.results.items()],
        "episodes_played": scorer.episodes_played,
        "wall_time_s": round(wall, 1),
        "provenance": origin,
    }


def evaluate_pinned(record: dict, episodes: int = 200, seed: int = 0, workers: int = 1) -> dict:
    """The chosen posture on the pinned seeds (``evaluate``), added to ``record`` as ``pinned``."""
    from visuomotor_gym.bench.evaluate import evaluate

    spec = record["chosen"]["spec"]
    with registered_kwargs(record["env_id"], record.get("env_kwargs")):
        result = evaluate(spec, record["env_id"], episodes, seed, workers=workers if not record.get("env_kwargs") else 1,
                          keep_traces=True)
    k = sum(tr.success for tr in result.traces)
    record["pinned"] = {"spec": spec, "seed": seed, "episodes": episodes, "successes": k,
                        "success": k / episodes, "wall_time_s": round(result.wall_time_s, 1)}
    return record


def update_postures(record: dict, path: Path | None = None, source: str | None = None) -> None:
    """Write the record's chosen posture into the postures file, keeping every other entry."""
    path = _postures_path() if path is None else Path(path)
    data = json.loads(path.read_text()) if path.exists() else {}
    data.setdefault("description", "The searched best static posture per (env id, agent): static_gaze:<agent> "
                    "uses it (python -m visuomotor_gym.static_gaze search ... --update-postures writes it)")
    table = data.setdefault("postures", {})
    c = record["chosen"]
    entry = {k: c[k] for k in POSTURE_KEYS}
    entry.update({"design_successes": c["successes"], "design_episodes": c["episodes"]})
    if "pinned" in record:
        entry.update({"pinned_successes": record["pinned"]["successes"], "pinned_episodes": record["pinned"]["episodes"]})
    if source:
        entry["source"] = source
    table.setdefault(record["env_id"], {})[record["agent"]] = entry
    data["postures"] = {e: dict(sorted(a.items())) for e, a in sorted(table.items())}
    path.write_text(json.dumps(data, indent=2) + "\n")


def _grid_text(stages: list) -> str:
    """The search's stages in a few words (``coarse 20 deg / 16 seeds; refine 10, 5; neck +-20``)."""
    by = {st["name"]: st for st in stages}
    if "explicit" in by:
        return f"{by['explicit']['postures']} explicit postures"
    parts = [(f"coarse {by['coarse']['step_deg']:g} deg ({by['coarse']['postures']} postures) / "
              f"{by['coarse']['episodes']} seeds")]
    refine = [f"{st['step_deg']:g}" for st in stages if st["name"].startswith("refine")]
    if refine:
        parts.append("refine " + ", ".join(refine) + " deg")
    neck = by.get("neck")
    parts.append(f"neck +-{neck['step_deg']:g} deg" if neck and neck["step_deg"] > 0 else "no neck stage")
    return "; ".join(parts)


def parse_json_object(text: str, option: str, what: str) -> dict:
    """A command-line option holding a JSON object (``what``: what its keys are); SystemExit naming
    ``option`` otherwise."""
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SystemExit(f"{option}: not JSON ({exc})") from None
    if not isinstance(value, dict):
        raise SystemExit(f"{option}: must be a JSON object of {what}, got {text!r}")
    return value


def parse_fixations(text: str):
    """``--fixations``: ``"auto"`` -> None (the search decides), ``"none"`` -> (), else positive metres."""
    if text == "auto":
        return None
    if text == "none":
        return ()
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        values = ()
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise SystemExit(f"--fixations: 'auto', 'none' or comma-separated positive distances in metres, got {text!r}")
    return values


def summary_table(folder: Path) -> str:
    """A markdown table of every search results JSON in ``folder`` (env, agent, posture, rates)."""
    rows = ["# Best static twins (`static_gaze:<agent>`)", "",
            ("Each agent with its gaze, fixation and head held at one body-frame posture (line of sight "
             "`az`/`el`, neck `neck_yaw`/`neck_pitch`, degrees, positive = left/up; fixation `fix`, m), the "
             "posture searched on the design seeds (100000-100039) by `python -m visuomotor_gym.static_gaze "
             "search` (its command, grid, stages and every posture's score are in the JSON next to this file), "
             "then played on the 200 pinned seeds (0-199) with the common evaluator. Regenerate this table "
             "with `python -m visuomotor_gym.static_gaze summary docs/reproductions/data/static_gaze --out "
             "docs/reproductions/data/static_gaze/summary.md`."), "",
            ("| env id | agent | posture (deg; fixation m) | design seeds | pinned seeds 0-199 | grid | "
             "episodes played | search wall time |"),
            "|---|---|---|---|---|---|---|---|"]
    for path in sorted(Path(folder).glob("*__*.json")):
        r = json.loads(path.read_text())
        c = r["chosen"]
        pinned = r.get("pinned")
        pinned_text = (f"{pinned['successes']}/{pinned['episodes']} ({100 * pinned['success']:.1f} %)"
                       if pinned else "not run")
        rows.append(f"| {r['env_id']} | `{r['agent']}` | `{Posture(**{k: c[k] for k in POSTURE_KEYS}).as_spec()}` | "
                    f"{c['successes']}/{c['episodes']} ({100 * c['success']:.1f} %) | {pinned_text} | "
                    f"{_grid_text(r['stages'])} | {r.get('episodes_played', '')} | {r['wall_time_s'] / 60:.0f} min |")
    return "\n".join(rows) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m visuomotor_gym.static_gaze",
                                     description="Search an agent's best static gaze-and-head posture.")
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("search", help="grid-search the posture on design seeds and write a results JSON")
    s.add_argument("--env", required=True)
    s.add_argument("--agent", required=True)
    s.add_argument("--out", required=True, help="results JSON to write")
    s.add_argument("--design-seed", type=int, default=DESIGN_SEED)
    s.add_argument("--coarse-episodes", type=int, default=COARSE_EPISODES)
    s.add_argument("--final-episodes", type=int, default=FINAL_EPISODES)
    s.add_argument("--coarse-step", type=float, default=20.0)
    s.add_argument("--refine-steps", type=str, default="10,5", help="comma-separated refinement steps (deg)")
    s.add_argument("--refine-top", type=int, default=3)
    s.add_argument("--finalists", type=int, default=5)
    s.add_argument("--neck-step", type=float, default=20.0)
    s.add_argument("--postures", type=str, default=None,
                   help="explicit postures instead of the grid: 'az,el,neck_yaw,neck_pitch;...'")
    s.add_argument("--pinned", type=int, default=0, metavar="N",
                   help="also evaluate the chosen posture on the pinned seeds 0..N-1 (e.g. 200)")
    s.add_argument("--workers", type=int, default=1, help="worker processes of the pinned evaluation")
    s.add_argument("--update-postures", action="store_true",
                   help="write the chosen posture into the package's static_postures.json")
    s.add_argument("--env-kwargs", type=str, default=None, metavar="JSON",
                   help="constructor arguments laid over the registered id's for the whole search, as a JSON "
                        "object, e.g. '{\"course_distribution\": \"rough\", \"vision_params\": {\"crowding\": true}}'")
    s.add_argument("--fixations", type=str, default="auto", metavar="auto|none|M,M,...",
                   help="vergence distances (m) tried at the best posture: 'auto' (the default) tries "
                        f"{','.join(f'{f:g}' for f in FIXATION_GRID_M)} when the env's vision has the depth law, "
                        "'none' tries none, or a comma-separated list")
    s.add_argument("--grid-fixation", type=float, default=None, metavar="M",
                   help=f"vergence (m) of the grid, refine, final and neck stages (default {DEFAULT_FIXATION_M:g}); "
                        "set it near the targets when they lie at arm's length")
    s.add_argument("--fixation-top", type=int, default=1, metavar="N",
                   help="how many of the best postures get the vergence stage (default 1)")
    s.add_argument("--quiet", action="store_true")
    p = sub.add_parser("pinned", help="add the pinned-seed evaluation to an existing results JSON")
    p.add_argument("results")
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--workers", type=int, default=1)
    p.add_argument("--update-postures", action="store_true")
    t = sub.add_parser("summary", help="write a markdown table of the results JSONs in a folder")
    t.add_argument("folder")
    t.add_argument("--out", default=None, help="markdown file (default: print)")
    args = parser.parse_args(argv)
    if args.command == "summary":
        table = summary_table(Path(args.folder))
        if args.out:
            Path(args.out).write_text(table)
        else:
            print(table, end="")
        return 0
    command = "python -m visuomotor_gym.static_gaze " + " ".join(sys.argv[1:] if argv is None else argv)
    if args.command == "pinned":
        path = Path(args.results)
        record = evaluate_pinned(json.loads(path.read_text()), episodes=args.episodes, workers=args.workers)
        record["pinned"]["command"] = command
        path.write_text(json.dumps(record, indent=2) + "\n")
        print(f"{record['env_id']} {record['agent']}: {record['pinned']['successes']}/{args.episodes} on the pinned seeds")
        if args.update_postures:
            update_postures(record, source=str(path))
        return 0
    postures = None
    if args.postures:
        postures = []
        for item in args.postures.split(";"):
            values = [float(x) for x in item.split(",")]
            if len(values) not in (2, 4):
                raise SystemExit(f"--postures: {item!r} is not az,el[,neck_yaw,neck_pitch]")
            postures.append(Posture(*values))
    log = None if args.quiet else (lambda line: print(line, flush=True))
    env_kwargs = parse_json_object(args.env_kwargs, "--env-kwargs", "constructor arguments") if args.env_kwargs else None
    fixations = parse_fixations(args.fixations)
    record = search(args.env, args.agent, design_seed=args.design_seed, coarse_episodes=args.coarse_episodes,
                    final_episodes=args.final_episodes, coarse_step=args.coarse_step,
                    refine_steps=tuple(float(x) for x in args.refine_steps.split(",") if x),
                    refine_top=args.refine_top, finalists=args.finalists, neck_step=args.neck_step,
                    postures=postures, command=command, log=log, env_kwargs=env_kwargs, fixations=fixations,
                    grid_fixation=args.grid_fixation, fixation_top=args.fixation_top)
    if args.pinned:
        evaluate_pinned(record, episodes=args.pinned, workers=args.workers)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=2) + "\n")
    c = record["chosen"]
    print(f"chosen {c['spec']}: {c['successes']}/{c['episodes']} design seeds"
          + (f"; {record['pinned']['successes']}/{args.pinned} pinned" if args.pinned else "")
          + f" ({record['wall_time_s']} s)")
    if args.update_postures:
        update_postures(record, source=str(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


__all__ = ["DEAD_BAND_DEG", "Posture", "StaticGaze", "check_posture", "env_geometry", "registered_kwargs",
           "resolve_spec", "search",
           "searched_posture", "static_gaze_spec"]
