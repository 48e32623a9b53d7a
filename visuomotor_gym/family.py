"""One task family as one record: what every shared module needs to know about it.

A family (catch, reach, walk, ...) is one env class, its five-rung observability ladder and a few
extra ids, its metrics and its baselines. Its :class:`Family` record is declared once, at the end of
its env module ``visuomotor_gym/envs/<family>.py``, and :mod:`visuomotor_gym.families` lists those
modules: registration, the metrics dispatcher, the bench table and results check, the agent factory,
the leaderboard's policy formats, the golden digests, the plots and videos of ``visuomotor_gym.viz``
and the family pages' generator read the records and hold no family table of their own.

References to code above the env layer (the family's summariser, miss distance, belief-MPC classes,
figure) are ``"module:attribute"`` strings, resolved by :func:`resolve` when first used: an env module
may not import metrics, baselines or viz (``tests/test_architecture.py``: they sit above it and import
it), so a direct reference would be an import cycle. Everything else (vision defaults, numbers, labels) is a
plain value. This module imports nothing of the package at module level, so any layer may import it,
and importing a record builds no MuJoCo model.
"""

from __future__ import annotations

import importlib
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

# The observability ladder (every family has the same five rungs).
POOR_VISION_SCALE = 2.0  # the PoorVision rungs: every vision noise x2, i.e. 20/40 (2 arcmin) acuity, the
# boundary of mild visual impairment (WHO ICD-11: presenting acuity worse than 6/12); swept against x1.5-x10 in
# docs/reproductions/gaze_default.md (x10, 20/200, leaves the slip model nearly blind: no gaze gain left)
VISUAL_DELAY_S = 0.1  # the Delayed rung's latency: ~100 ms of human visual processing (modelling choice)
RUNG_SUFFIXES = ("Oracle", "FullView", "", "Delayed", "PoorVision")  # <prefix><suffix>-v0, in this order

_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")
_PREFIX = re.compile(r"[A-Z][A-Za-z0-9]*\Z")
_REF = re.compile(r"visuomotor_gym(\.[A-Za-z_][A-Za-z0-9_]*)+:[A-Za-z_][A-Za-z0-9_]*\Z")
_ENV_ID = re.compile(r"[A-Za-z][A-Za-z0-9]*-v\d+\Z")
_KEY = re.compile(r"[a-z][a-z0-9_]*\Z")
_DOC_PAGE = re.compile(r"(?!/)(?!.*\.\.)[A-Za-z0-9_./-]+\.md\Z")  # a page under docs/
_DOC_IMAGE = re.compile(r"(?!/)(?!.*\.\.)[A-Za-z0-9_./-]+\.(png|jpg|jpeg|gif|svg)\Z")


@dataclass(frozen=True)
class EnvEntry:
    """One registered id: its entry point, keyword arguments, episode limit, family and a line of text.
    (Not Gymnasium's ``EnvSpec``, which ``gym.spec(id)`` returns once registered.) Built by
    :meth:`Family.env_entries`; ``visuomotor_gym.ENV_SPECS`` holds one per id."""

    id: str
    entry_point: str
    kwargs: dict = field(default_factory=dict)
    max_episode_steps: int = 0
    description: str = ""
    family: str = ""


@dataclass(frozen=True)
class ExtraEnv:
    """A registered id of a family beyond its five rungs: ``id``, the env keyword arguments that make it,
    a line of text, and its episode limit (None: the family's)."""

    id: str
    kwargs: Mapping[str, Any]
    description: str
    max_episode_steps: int | None = None

    def __post_init__(self):
        if not isinstance(self.id, str) or not _ENV_ID.match(self.id):
            raise ValueError(f"ExtraEnv.id must be an id like 'EyeCatchBounce-v0', got {self.id!r}")
        if not isinstance(self.kwargs, Mapping):
            raise TypeError(f"ExtraEnv.kwargs of {self.id} must be a dict, got {type(self.kwargs).__name__}")
        if not isinstance(self.description, str) or not self.description:
            raise ValueError(f"ExtraEnv.description of {self.id} must be a non-empty string")
        _check_steps(self.max_episode_steps, f"ExtraEnv.max_episode_steps of {self.id}", optional=True)


@dataclass(frozen=True)
class BeliefMPC:
    """How the ``belief_mpc`` agent plays a family: ``agent`` and ``params`` classes (``"module:Class"``;
    the agent class has ``for_env(env_id, **overrides)``), ``vision_note`` -- the name under which an
    exported ``belief-mpc-params`` file notes the env's VisionParams (None: the agent takes none; the
    leaderboard check compares re-exported bytes, so committed entries fix this name) -- and
    ``env_vision``: whether :func:`visuomotor_gym.agents.make_agent` wraps it so it models the env's
    vision (False when ``for_env`` already gives it the env's VisionParams)."""

    agent: str
    params: str
    vision_note: str | None = None
    env_vision: bool = False

    def __post_init__(self):
        for name in ("agent", "params"):
            _check_ref(getattr(self, name), f"BeliefMPC.{name}")
        if self.vision_note is not None and not (isinstance(self.vision_note, str) and self.vision_note):
            raise ValueError(f"BeliefMPC.vision_note must be None or a non-empty string, got {self.vision_note!r}")
        if not isinstance(self.env_vision, bool):
            raise TypeError(f"BeliefMPC.env_vision must be a bool, got {self.env_vision!r}")


@dataclass(frozen=True)
class FollowView:
    """A video camera that follows a walker (``vmgym record``'s scene view of a walker family): a free
    camera looking at the pelvis plus ``offset`` (world frame, m) from ``distance`` m away, ``azimuth``
    deg about z (0: looking along +x, the path's direction; 90: along +y) and ``elevation`` deg
    (negative: from above), with a vertical field of view of ``fovy`` deg. With ``follow_heading`` the
    azimuth and offset turn with the pelvis's heading, smoothed by a first-order filter of time
    constant ``heading_tau_s`` s. The camera is not in the MJCF, so the compiled models (and their
    golden digests) do not change. Values are modelling choices, checked by eye on a frame of each
    family; :class:`visuomotor_gym.viz.video.FrameRenderer` renders it."""

    distance: float
    azimuth: float
    elevation: float
    offset: tuple[float, float, float]
    fovy: float = 45.0
    follow_heading: bool = False
    # 1 s (modelling choice) averages out the gait's sway of the pelvis (~2 steps) and still turns
    # with the path within a few steps.
    heading_tau_s: float = 1.0

    def __post_init__(self):
        for name in ("distance", "azimuth", "elevation", "fovy", "heading_tau_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"FollowView.{name} must be a finite number, got {value!r}")
        if self.distance <= 0 or self.heading_tau_s <= 0:
            raise ValueError(f"FollowView.distance and heading_tau_s must be > 0, got {self.distance!r} and "
                             f"{self.heading_tau_s!r}")
        if not 0 < self.fovy < 180:
            raise ValueError(f"FollowView.fovy must be in (0, 180) degrees, got {self.fovy!r}")
        offset = self.offset
        if not (isinstance(offset, tuple) and len(offset) == 3 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in offset)):
            raise ValueError(f"FollowView.offset must be a tuple of 3 finite numbers (x, y, z in m), got {offset!r}")
        if not isinstance(self.follow_heading, bool):
            raise TypeError(f"FollowView.follow_heading must be a bool, got {self.follow_heading!r}")


@dataclass(frozen=True)
class Viz:
    """How ``vmgym plot`` and ``vmgym record`` (:mod:`visuomotor_gym.viz`) show one episode of a family:

    * ``figure`` -- ``"module:function"``, ``function(trace) -> matplotlib Figure``: the episode's
      figure (:func:`visuomotor_gym.viz.plots.episode_figure` dispatches to it);
    * ``contents`` -- what that figure shows, one sentence (``vmgym plot --help`` lists it per family);
    * ``trace_field`` -- a task field of the family's traces that no other family's traces hold
      (``"ball_pos"``): it tells a trace's family when its env id is not a registered one (a synthetic
      or older trace; :func:`visuomotor_gym.viz.plots.trace_family`);
    * ``scene_view`` -- the video's scene view: an MJCF camera name of the scene (``"scene_camera"``)
      or a :class:`FollowView`;
    * ``video_stride`` -- the default frames per control step: a frame after every ``video_stride``-th
      20 ms step (1 for short episodes, where a 40-60 ms saccade then spans 2-3 frames; 2 for 10-20 s
      walker episodes, which would otherwise take twice as long to render and to watch: a modelling
      choice); ``fps = 50 / video_stride`` is real time;
    * ``dpi`` -- the resolution of the written PNG;
    * ``outcome_words`` -- how the figure title and ``vmgym record`` call a success and a failure
      (``("caught", "missed")``);
    * ``failure_field`` -- the trace field that marks a failed episode (``"missed"``); None: an episode
      that ended without success, divergence or the time limit failed.
    """

    figure: str
    contents: str
    trace_field: str
    scene_view: str | FollowView
    video_stride: int = 1
    dpi: int = 100
    outcome_words: tuple[str, str] = ("succeeded", "failed")
    failure_field: str | None = None

    def __post_init__(self):
        _check_ref(self.figure, "Viz.figure")
        for name in ("contents", "trace_field"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value:
                raise ValueError(f"Viz.{name} must be a non-empty string, got {value!r}")
        if not (isinstance(self.scene_view, FollowView) or (isinstance(self.scene_view, str) and self.scene_view)):
            raise TypeError(f"Viz.scene_view must be an MJCF camera name or a FollowView, got {self.scene_view!r}")
        _check_steps(self.video_stride, "Viz.video_stride")
        if isinstance(self.dpi, bool) or not isinstance(self.dpi, int) or not 20 <= self.dpi <= 600:
            raise ValueError(f"Viz.dpi must be an int in [20, 600], got {self.dpi!r}")
        words = self.outcome_words
        if not (isinstance(words, tuple) and len(words) == 2 and all(isinstance(w, str) and w for w in words)):
            raise ValueError(f"Viz.outcome_words must be 2 non-empty strings (success, failure), got {words!r}")
        if self.failure_field is not None and not (isinstance(self.failure_field, str) and self.failure_field):
            raise ValueError(f"Viz.failure_field must be None or a trace field name, got {self.failure_field!r}")


@dataclass(frozen=True)
class Family:
    """Everything a shared module knows about one task family. Fields:

    * ``name`` -- the family's key (``"catch"``): lower case, the ``family`` of each of its
      :class:`EnvEntry`, what ``registration.family_of(id)`` returns;
    * ``prefix`` -- the ladder's id prefix (``"EyeCatch"``): the five rungs are ``<prefix>Oracle-v0``,
      ``<prefix>FullView-v0``, ``<prefix>-v0``, ``<prefix>Delayed-v0``, ``<prefix>PoorVision-v0``;
    * ``entry_point`` -- the env class, ``"module:Class"`` (Gymnasium's entry point string);
    * ``max_episode_steps`` -- the episode limit of every id (an :class:`ExtraEnv` may set its own);
    * ``oracle_sees`` -- what the Oracle rung gives as true state (``"ball"``: "true ball state");
    * ``body`` -- the body the family's agent moves (``"seated"``, ``"walker"``), for readers that group
      families by body (``registration.WALKER_FAMILIES``);
    * ``vision_defaults`` -- the family's default ``VisionParams`` (the env builds its eye from it, and
      ``registration.env_vision_params`` gives it to agents); None: ``VisionParams()``;
    * ``summariser`` -- ``"module:function"``, ``function(traces) -> dict``: every benchmark number of a
      set of episodes (``metrics.summary.summarize`` dispatches to it);
    * ``miss_distance`` -- ``"module:function"``, ``function(trace) -> float``: how far one failed
      episode was from success, in the family's terms (``metrics.summary.episode_miss_distance``);
    * ``outcome_labels`` -- the bench table's labels of (success rate, time to success, miss distance);
    * ``reaction_from_t0`` -- whether the task starts its stimulus at t = 0 (a throw, an object
      appearing), so reaction times from t = 0 mean something and the bench table shows them;
    * ``extra_envs`` -- registered ids beyond the five rungs (:class:`ExtraEnv`), after the rungs;
    * ``agents`` -- the agents of ``visuomotor_gym.agents`` built for this family (an agent no family
      lists plays every family);
    * ``golden_agent`` -- the scripted agent the golden digests run on each of the family's ids (None:
      the family is not pinned yet); ``golden_extra`` -- more ``(agent, env id)`` golden cases;
    * ``belief_mpc`` -- how the ``belief_mpc`` agent plays the family (:class:`BeliefMPC`), None if it
      does not;
    * ``rate_aliases`` -- result keys the family's summary keeps as its own name of ``success_rate``
      (catch: ``"catch_rate"``): the results check (:mod:`visuomotor_gym.bench.results`) holds each
      equal to ``success_rate`` on the family's ids;
    * ``viz`` -- how ``vmgym plot`` and ``vmgym record`` show an episode (:class:`Viz`); None: no
      figure (``vmgym plot`` refuses the family) and videos from the env's own ``render_cameras``
      scene view, every control step;
    * ``doc_links`` -- ``(title, path relative to docs/)`` of the pages the family's generated page
      links to (reproductions, baselines); ``doc_pictures`` -- ``(image path relative to docs/,
      caption)`` candidates, the first that exists is shown (``docs/gen_family_pages.py``).
    """

    name: str
    prefix: str
    entry_point: str
    max_episode_steps: int
    oracle_sees: str
    body: str
    summariser: str
    miss_distance: str
    outcome_labels: tuple[str, str, str]
    reaction_from_t0: bool = False
    vision_defaults: Any = None
    extra_envs: tuple[ExtraEnv, ...] = ()
    agents: tuple[str, ...] = ()
    golden_agent: str | None = None
    golden_extra: tuple[tuple[str, str], ...] = ()
    belief_mpc: BeliefMPC | None = None
    rate_aliases: tuple[str, ...] = ()
    viz: Viz | None = None
    doc_links: tuple[tuple[str, str], ...] = ()
    doc_pictures: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not _NAME.match(self.name):
            raise ValueError(f"Family.name must be a lower-case identifier like 'catch', got {self.name!r}")
        where = f"Family {self.name!r}"
        if not isinstance(self.prefix, str) or not _PREFIX.match(self.prefix):
            raise ValueError(f"{where}: prefix must be a CamelCase id prefix like 'EyeCatch', got {self.prefix!r}")
        _check_ref(self.entry_point, f"{where}: entry_point")
        _check_steps(self.max_episode_steps, f"{where}: max_episode_steps")
        for name in ("oracle_sees", "body"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value:
                raise ValueError(f"{where}: {name} must be a non-empty string, got {value!r}")
        _check_ref(self.summariser, f"{where}: summariser")
        _check_ref(self.miss_distance, f"{where}: miss_distance")
        labels = self.outcome_labels
        if not (isinstance(labels, tuple) and len(labels) == 3 and all(isinstance(s, str) and s for s in labels)):
            raise ValueError(f"{where}: outcome_labels must be 3 non-empty strings (success rate, time to "
                             f"success, miss distance), got {labels!r}")
        if not isinstance(self.reaction_from_t0, bool):
            raise TypeError(f"{where}: reaction_from_t0 must be a bool, got {self.reaction_from_t0!r}")
        if self.vision_defaults is not None:
            from visuomotor_gym.vision.foveation import VisionParams

            if not isinstance(self.vision_defaults, VisionParams):
                raise TypeError(f"{where}: vision_defaults must be a VisionParams or None, got "
                                f"{type(self.vision_defaults).__name__}")
        if not isinstance(self.extra_envs, tuple) or not all(isinstance(e, ExtraEnv) for e in self.extra_envs):
            raise TypeError(f"{where}: extra_envs must be a tuple of ExtraEnv")
        ids = [e.id for e in self.extra_envs] + [f"{self.prefix}{s}-v0" for s in RUNG_SUFFIXES]
        if len(set(ids)) != len(ids):
            raise ValueError(f"{where}: extra_envs repeat an id: {sorted(i for i in ids if ids.count(i) > 1)}")
        for name in ("agents",):
            value = getattr(self, name)
            if not isinstance(value, tuple) or not all(isinstance(a, str) and a for a in value):
                raise TypeError(f"{where}: {name} must be a tuple of agent names, got {value!r}")
        if self.golden_agent is not None and not (isinstance(self.golden_agent, str) and self.golden_agent):
            raise ValueError(f"{where}: golden_agent must be None or an agent name, got {self.golden_agent!r}")
        if not isinstance(self.golden_extra, tuple) or not all(
                isinstance(c, tuple) and len(c) == 2 and c[1] in ids for c in self.golden_extra):
            raise ValueError(f"{where}: golden_extra must be a tuple of (agent, env id of this family) pairs, "
                             f"got {self.golden_extra!r}")
        if self.belief_mpc is not None and not isinstance(self.belief_mpc, BeliefMPC):
            raise TypeError(f"{where}: belief_mpc must be a BeliefMPC or None, got {type(self.belief_mpc).__name__}")
        if not isinstance(self.rate_aliases, tuple) or not all(
                isinstance(k, str) and _KEY.match(k) and k != "success_rate" for k in self.rate_aliases):
            raise ValueError(f"{where}: rate_aliases must be a tuple of result keys other than 'success_rate' "
                             f"(like 'catch_rate'), got {self.rate_aliases!r}")
        if self.viz is not None and not isinstance(self.viz, Viz):
            raise TypeError(f"{where}: viz must be a Viz or None, got {type(self.viz).__name__}")
        for name, kind, pattern in (("doc_links", "(title, page path relative to docs/)", _DOC_PAGE),
                                    ("doc_pictures", "(image path relative to docs/, caption)", _DOC_IMAGE)):
            value = getattr(self, name)
            path_at = 1 if name == "doc_links" else 0
            if not isinstance(value, tuple) or not all(
                    isinstance(p, tuple) and len(p) == 2 and all(isinstance(x, str) and x for x in p)
                    and pattern.match(p[path_at]) for p in value):
                raise ValueError(f"{where}: {name} must be a tuple of {kind} pairs of non-empty strings, "
                                 f"got {value!r}")

    def env_entries(self) -> tuple[EnvEntry, ...]:
        """Every id of the family, in registration order: the five rungs (same physics and scenario
        sampler on each: true state of what ``oracle_sees`` names; noise independent of gaze; foveated;
        +100 ms; every vision noise x2), then :attr:`extra_envs`."""
        extras = tuple(EnvEntry(e.id, self.entry_point, dict(e.kwargs), e.max_episode_steps or self.max_episode_steps,
                                e.description, self.name) for e in self.extra_envs)
        return vision_rungs(self.prefix, self.entry_point, family=self.name,
                            max_episode_steps=self.max_episode_steps, what=self.oracle_sees) + extras

    def summarise(self, traces) -> dict:
        """The family's summary of a set of episodes (:attr:`summariser`)."""
        return resolve(self.summariser)(traces)

    def episode_miss_distance(self, trace) -> float:
        """One episode's miss distance in the family's terms (:attr:`miss_distance`)."""
        return float(resolve(self.miss_distance)(trace))


def vision_rungs(name: str, entry_point: str, *, family: str, max_episode_steps: int, what: str,
                 kwargs: dict | None = None) -> tuple[EnvEntry, ...]:
    """The observability ladder of one family, same physics and scenario sampler on every rung:
    ``<name>Oracle-v0`` (true state of what ``what`` names), ``<name>FullView-v0`` (noise independent
    of gaze), ``<name>-v0`` (foveated), ``<name>Delayed-v0`` (+100 ms) and ``<name>PoorVision-v0``
    (every vision noise x2: 20/40 acuity). ``kwargs`` are shared by every rung."""
    base = dict(kwargs or {})

    def rung(suffix, extra, description):
        return EnvEntry(f"{name}{suffix}-v0", entry_point, {**base, **extra}, max_episode_steps, description, family)

    return (
        rung(RUNG_SUFFIXES[0], {"vision": "oracle"}, f"true {what} state"),
        rung(RUNG_SUFFIXES[1], {"vision": "full_view"}, "noisy, noise independent of gaze"),
        rung(RUNG_SUFFIXES[2], {}, "foveated vision, saccadic blindness"),
        rung(RUNG_SUFFIXES[3], {"visual_delay_s": VISUAL_DELAY_S}, "foveated + 100 ms visual latency"),
        rung(RUNG_SUFFIXES[4], {"vision_noise_scale": POOR_VISION_SCALE},
             f"foveated, all vision noise x{POOR_VISION_SCALE:g} (20/40 acuity)"),
    )


def resolve(ref: str):
    """The object a ``"module:attribute"`` reference names (the one place such strings are imported)."""
    _check_ref(ref, "reference")
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


def _check_ref(value, what: str) -> None:
    if not isinstance(value, str) or not _REF.match(value):
        raise ValueError(f"{what} must be a 'visuomotor_gym.module:attribute' string, got {value!r}")


def _check_steps(value, what: str, optional: bool = False) -> None:
    if optional and value is None:
        return
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{what} must be a positive int{' or None' if optional else ''}, got {value!r}")
