"""``VisuomotorEnv``: the Gymnasium skeleton every family shares.

A concrete env (a family) declares its own constructor arguments, checks them, and forwards the
shared ones (``**shared``) to :meth:`VisuomotorEnv.__init__`, which checks those, runs the build order
and calls the family's :meth:`VisuomotorEnv._build` for its parts (the base classes a body and a task
subclass are in :mod:`visuomotor_gym.core.parts`):

* ``body`` - a body from :mod:`visuomotor_gym.body` (its action blocks, servo commands,
  proprioception, its frame);
* ``eye`` (:class:`~visuomotor_gym.core.eye.Eye`), ``head`` (:class:`~visuomotor_gym.core.head.Head`)
  and ``retina`` (:class:`~visuomotor_gym.core.retina.Retina`) - the same for every body;
* ``task`` - a module of :mod:`visuomotor_gym.tasks` (scene state, visual targets, observation
  blocks, per-substep checks, evaluation, info).

The skeleton owns the rest: action checks, the reset/step order, the physics loop with its
divergence monitor, observation assembly from the declared blocks (the task's percepts, eye, head,
body, the task's own state), info, rendering and pickling. The action is the body's blocks, then
``gaze`` (2), ``fixation`` (1) and ``head`` (2).
"""

from __future__ import annotations

import inspect
import math
import os
import warnings
from dataclasses import asdict
from typing import Any, ClassVar

import gymnasium as gym
import mujoco
import numpy as np

from visuomotor_gym import _native
from visuomotor_gym.assets import asset_path
from visuomotor_gym.core import args
from visuomotor_gym.core.eye import EYE_ACTION_STRUCTURE, EYE_BLOCKS, Eye
from visuomotor_gym.core.head import HEAD_ACTION_STRUCTURE, HEAD_BLOCKS, Head
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.core.parts import Body, Task
from visuomotor_gym.core.retina import VISION_MODES, Retina
from visuomotor_gym.oculomotor.plant import DEG, OculomotorParams
from visuomotor_gym.vision.foveation import VisionParams

OBS_MODES = ("flat", "dict")
MAX_VISION_NOISE_SCALE = 1000.0  # modelling choice: far beyond blindness (x10 is Eyecatch's poor vision)
MAX_VISUAL_DELAY_S = 2.0  # modelling choice: 20x the human visual latency (~100 ms)
_BAD_STATE_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                       mujoco.mjtWarning.mjWARN_BADQACC)

# The meanings of the arguments every family shares (their defaults: VisuomotorEnv.__init__'s
# signature): the generated Arguments tables' rows. A family's ``argument_meanings`` may replace one
# with a family-specific text (what ``vision="oracle"`` sees, its cameras).
SHARED_ARGUMENT_MEANINGS: dict[str, str] = {
    "render_mode": '``"rgb_array"`` or ``"human"``',
    "vision": ('``"foveated"``, ``"full_view"`` (foveal noise everywhere, no field-of-view limit, no saccadic '
               'blindness) or ``"oracle"`` (true state)'),
    "vision_noise_scale": ("multiplies every vision standard deviation (2: the PoorVision rung, 20/40 acuity; "
                           "10: the Eyecatch paper's poor vision)"),
    "vision_params": ("``VisionParams`` or a dict of its fields (acuity, retinal-slip knee, Weber fraction, depth "
                      "noise, field of view)"),
    "visual_delay_s": "visual latency, a multiple of the control period",
    "obs_mode": '``"flat"`` or ``"dict"``',
    "reward_weights": "dict overriding term weights",
    "oculomotor_params": "``OculomotorParams`` or dict (saccade and pursuit limits, eye ranges, head speed)",
    "control_dt": "control period (s); a whole multiple of the 2 ms physics step",
    "gaze_action_range_deg": "gaze change at action +-1",
    "render_camera": "which camera(s) ``render()`` shows",
    "width": "size of each rendered camera image",
    "record_plant": "keep the 500 Hz gaze trace (``env.unwrapped.plant.trace()``)",
}


def _doc_default(value) -> str:
    """A default as the Arguments tables write it (a Python literal; strings in double quotes)."""
    return f'``"{value}"``' if isinstance(value, str) else repr(value)


class VisuomotorEnv(gym.Env):
    """The shared skeleton (see the module docstring). Not registered itself."""

    # Replaced per instance (render_fps from the step length, _load_physics), never mutated in place.
    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 50}  # noqa: RUF012
    # Camera sets of ``render_camera``; a family may override (names from its scene).
    render_cameras: ClassVar[dict[str, tuple[str, ...]]] = {}
    eye_camera: str = ""

    # --- construction -------------------------------------------------------------------------
    # What a family declares (class attributes; see ``envs/*.py``):
    scene: str = ""  # the MJCF file in ``envs_assets/`` (a property where it depends on an argument)
    vision_defaults: VisionParams | None = None  # the family's default VisionParams (None: VisionParams())
    reward_terms: tuple[str, ...] = ()  # the names ``reward_weights`` may set
    default_reward_weights: dict[str, float] = {}  # noqa: RUF012  (read only; see _default_reward_weights)
    # Meanings of the family's own arguments for the generated Arguments table, and family-specific
    # meanings of shared ones (these replace the rows of SHARED_ARGUMENT_MEANINGS).
    argument_meanings: dict[str, str] = {}  # noqa: RUF012

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        vision: str = "foveated",
        vision_noise_scale: float = 1.0,
        vision_params: VisionParams | dict | None = None,
        visual_delay_s: float = 0.0,
        obs_mode: str = "flat",
        reward_weights: dict[str, float] | None = None,
        oculomotor_params: OculomotorParams | dict | None = None,
        control_dt: float = 0.02,
        gaze_action_range_deg: float = 60.0,
        render_camera: str = "both",
        width: int = 480,
        height: int = 360,
        record_plant: bool = False,
        **unknown: Any,
    ):
        """The arguments every family shares (their meanings: :data:`SHARED_ARGUMENT_MEANINGS`), checked
        once, and the build order in one place. A family's ``__init__`` checks and keeps its own
        arguments, then calls ``super().__init__(render_mode, **shared)``; this then rejects unknown
        names, checks the shared ones, resolves the reward weights (:meth:`_default_reward_weights`,
        ``reward_terms``), compiles ``scene`` and fixes the control period, sets the visual delay,
        calls the family's :meth:`_build` for its body and task, and assembles the eye, head, retina,
        spaces and observation layout."""
        self._reject_unknown(unknown)
        control_dt, visual_delay_s = self._check_eye_arguments(
            render_mode=render_mode, vision=vision, vision_noise_scale=vision_noise_scale,
            vision_params=vision_params, visual_delay_s=visual_delay_s, oculomotor_params=oculomotor_params,
            gaze_action_range_deg=gaze_action_range_deg, control_dt=control_dt, obs_mode=obs_mode,
            render_camera=render_camera, record_plant=record_plant, vision_defaults=self.vision_defaults,
        )
        self.reward_weights = self._reward_weights(self._default_reward_weights(), reward_weights,
                                                   self.reward_terms)
        self._load_physics(self.scene, control_dt)
        self._set_visual_delay(visual_delay_s)
        body, task = self._build()
        self._assemble_eye(body=body, task=task, obs_mode=obs_mode, width=width, height=height)

    def _build(self) -> tuple[Body, Task]:
        """The family's body and task, built on ``self.model`` once the shared and the family's own
        arguments are checked (``self.dt``, ``self.visual_delay_s``, ``self.reward_weights``,
        ``self.oculomotor_params`` ... are set). Called once, by :meth:`__init__`."""
        raise NotImplementedError(f"{type(self).__name__} must define _build() -> (body, task)")

    def _default_reward_weights(self) -> dict[str, float]:
        """The reward weights before ``reward_weights`` (called after the family's own arguments are
        checked, so a reward mode may choose them). Default: ``default_reward_weights``."""
        return self.default_reward_weights

    def __init_subclass__(cls, **kwargs):
        """A family's signature as a user sees it (``inspect.signature``, ``help()``): its own
        arguments, then its parent's (the shared ones, and those of an intermediate class such as
        the walker families'), all forwarded through ``**shared``; and its ``ARGUMENTS_TABLE``
        docstring placeholder replaced by the table generated from that signature."""
        super().__init_subclass__(**kwargs)
        init = cls.__dict__.get("__init__")
        if init is None:
            return
        own = [p for p in inspect.signature(init).parameters.values() if p.kind is not inspect.Parameter.VAR_KEYWORD]
        taken = {p.name for p in own}
        parent = inspect.signature(super(cls, cls).__init__).parameters.values()
        merged = own + [p for p in parent if p.name not in taken and p.kind is not inspect.Parameter.VAR_KEYWORD]
        keyword = [p for p in merged if p.kind is inspect.Parameter.KEYWORD_ONLY]
        init.__signature__ = inspect.Signature([p for p in merged if p not in keyword] + keyword)
        if cls.__doc__ and "ARGUMENTS_TABLE" in cls.__doc__:
            cls.__doc__ = cls.__doc__.replace("ARGUMENTS_TABLE", "\n    ".join(cls.arguments_table().splitlines()))

    @classmethod
    def arguments_table(cls) -> str:
        """The Arguments table (markdown) of the constructor's signature: one row per argument, in
        signature order (``width`` and ``height`` share one), with its default and meaning (the
        family's ``argument_meanings``, else :data:`SHARED_ARGUMENT_MEANINGS`)."""
        params = [p for n, p in inspect.signature(cls.__init__).parameters.items()
                  if n != "self" and p.kind is not inspect.Parameter.VAR_KEYWORD]
        meanings = dict(SHARED_ARGUMENT_MEANINGS)
        for klass in reversed(cls.__mro__):  # a subclass's meanings over its parents'
            meanings.update(klass.__dict__.get("argument_meanings", {}))
        if meanings["reward_weights"] == SHARED_ARGUMENT_MEANINGS["reward_weights"] and cls.reward_terms:
            terms = ", ".join(f"``{t}``" for t in cls.reward_terms)
            meanings["reward_weights"] = f"dict overriding term weights ({terms})"
        rows = ["| argument | default | meaning |", "|---|---|---|"]
        names = [p.name for p in params]
        for p in params:
            if p.name == "height" and "width" in names:
                continue
            if p.name not in meanings:
                raise TypeError(f"{cls.__name__}: argument {p.name!r} has no meaning in argument_meanings")
            if p.name == "width" and "height" in names:
                h = next(q for q in params if q.name == "height")
                rows.append(f"| ``width``, ``height`` | {_doc_default(p.default)}, {_doc_default(h.default)} "
                            f"| {meanings['width']} |")
                continue
            rows.append(f"| ``{p.name}`` | {_doc_default(p.default)} | {meanings[p.name]} |")
        return "\n".join(rows)

    def _check_eye_arguments(
        self,
        *,
        render_mode,
        vision,
        vision_noise_scale,
        vision_params,
        visual_delay_s,
        oculomotor_params,
        gaze_action_range_deg,
        control_dt,
        obs_mode,
        render_camera,
        record_plant,
        vision_defaults: VisionParams | None = None,
    ) -> tuple[float, float]:
        """Check and keep the arguments every family shares (the eye, the retina, rendering); returns
        the checked ``(control_dt, visual_delay_s)`` for :meth:`_load_physics` and :meth:`_assemble_eye`.

        ``vision_defaults``: the family's default ``VisionParams`` (a dict of ``vision_params`` fields
        overrides those); ``vision_noise_scale`` multiplies every standard deviation; ``full_view``
        drops foveation.
        """
        if render_mode is not None:
            args.choice(render_mode, self.metadata["render_modes"], "render_mode")
        self.render_mode = render_mode
        self.vision = args.choice(vision, VISION_MODES, "vision")
        args.choice(obs_mode, OBS_MODES, "obs_mode")
        self.render_camera = args.choice(render_camera, tuple(self.render_cameras), "render_camera")
        scale = args.real(vision_noise_scale, "vision_noise_scale", low=0.0, high=MAX_VISION_NOISE_SCALE)
        base = vision_defaults if vision_defaults is not None else VisionParams()
        if isinstance(vision_params, dict):  # fields over the family's defaults (unknown fields refused)
            vision_params = args.coerce(VisionParams, {**asdict(base), **vision_params}, "vision_params")
        elif vision_params is None:
            vision_params = base
        self.vision_params = args.coerce(VisionParams, vision_params, "vision_params").scaled(scale)
        if self.vision == "full_view":
            self.vision_params = VisionParams(**{**asdict(self.vision_params), "foveated": False})
        self.oculomotor_params = args.coerce(OculomotorParams, oculomotor_params, "oculomotor_params")
        self.gaze_action_range = args.real(gaze_action_range_deg, "gaze_action_range_deg", low=0.0, high=180.0,
                                           low_open=True) * DEG
        self.record_plant = args.flag(record_plant, "record_plant")
        control_dt = args.real(control_dt, "control_dt", low=0.0, high=1.0, low_open=True)
        visual_delay_s = args.real(visual_delay_s, "visual_delay_s", low=0.0, high=MAX_VISUAL_DELAY_S)
        return control_dt, visual_delay_s

    @staticmethod
    def _reward_weights(defaults: dict, reward_weights, terms) -> dict:
        """``defaults`` with ``reward_weights`` (term -> finite weight) applied; unknown terms refused."""
        weights = dict(defaults)
        if reward_weights is not None and not isinstance(reward_weights, dict):
            raise TypeError(f"reward_weights must be a dict of term -> weight, got {type(reward_weights).__name__}")
        for name, value in (reward_weights or {}).items():
            if name not in terms:
                raise ValueError(f"reward_weights: unknown term {name!r}; known terms: {list(terms)}")
            weights[name] = args.real(value, f"reward_weights[{name!r}]")
        return weights

    def _set_visual_delay(self, visual_delay_s: float) -> None:
        """The visual latency in control steps (after :meth:`_load_physics` fixed the period)."""
        self.visual_delay_s = float(visual_delay_s)
        self.delay_steps = args.whole_multiple(visual_delay_s, self.dt, "visual_delay_s")

    def _assemble_eye(self, *, body, task, obs_mode: str, width: int, height: int) -> None:
        """:meth:`_assemble` with the eye, head and retina every family shares, from the checked arguments."""
        self._assemble(
            body=body,
            eye=Eye(self.model, self.oculomotor_params, self.gaze_action_range, record=self.record_plant),
            head=Head(self.model, self.oculomotor_params),
            retina=Retina(self.vision, self.vision_params, self.delay_steps, self.dt),
            task=task,
            obs_mode=obs_mode,
            width=width,
            height=height,
        )

    def _load_physics(self, scene: str, control_dt: float) -> None:
        """Compile ``scene`` (a file in ``envs_assets/``) and fix the control period."""
        self.model = mujoco.MjModel.from_xml_path(str(asset_path(scene)))
        self.data = mujoco.MjData(self.model)
        physics_dt = float(self.model.opt.timestep)
        self.n_substeps = args.whole_multiple(control_dt, physics_dt, "control_dt", minimum=1)
        self.dt = self.n_substeps * physics_dt
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.dt))}
        self._bad_warnings = [int(w) for w in _BAD_STATE_WARNINGS]

    def _assemble(self, *, body, eye, head, retina, task, obs_mode: str, width: int, height: int) -> None:
        """Attach the parts, build the spaces and the observation layout."""
        self.body, self.eye, self.head, self.retina, self.task = body, eye, head, retina, task
        self.plant = eye.plant
        self.frame = body.frame
        self.obs_mode = args.choice(obs_mode, OBS_MODES, "obs_mode")
        self.action_structure = {**body.action_structure, **EYE_ACTION_STRUCTURE, **HEAD_ACTION_STRUCTURE}
        self._n_body_act = body.n_action
        self.action_space = gym.spaces.Box(-1.0, 1.0, shape=(sum(self.action_structure.values()),), dtype=np.float32)
        self._n_action = self.action_space.shape[0]
        self.layout = ObservationLayout(
            tuple(task.leading_blocks) + EYE_BLOCKS + HEAD_BLOCKS + tuple(body.observation_blocks)
            + tuple(task.trailing_blocks)
        )
        self.observation_structure = self.layout.structure
        # Where each part's observe call must leave the value list (checked by _observe).
        n_lead = sum(b.size for b in task.leading_blocks)
        n_head = n_lead + sum(b.size for b in EYE_BLOCKS + HEAD_BLOCKS)
        n_body = n_head + sum(b.size for b in body.observation_blocks)
        self._observe_ends = (n_lead, n_head, n_body, self.layout.size)
        self.observation_space = self.layout.flat_space() if obs_mode == "flat" else self.layout.dict_space()
        self.width = args.integer(width, "width", low=1, high=8192)
        self.height = args.integer(height, "height", low=1, high=8192)
        self._renderers: dict[str, mujoco.Renderer] = {}
        self._viewer = None
        self._warned_human = False
        self._needs_reset = True  # step() before the first reset() is an error
        self._native = _native.enabled()  # compiled action check and observation array (_kernels.c)
        self._warned_after_end = False
        self._reset_parts()

    @classmethod
    def _argument_names(cls) -> list[str]:
        params = inspect.signature(cls.__init__).parameters
        return [n for n, p in params.items() if n != "self" and p.kind is not inspect.Parameter.VAR_KEYWORD]

    def _reject_unknown(self, unknown: dict) -> None:
        if unknown:
            raise TypeError(
                f"{type(self).__name__} got unknown argument(s) {sorted(unknown)}; "
                f"allowed: {sorted(self._argument_names())}"
            )

    # --- Gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if options:
            raise ValueError(f"reset options are not supported; got {sorted(options)}")
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        self._reset_parts()
        self.body.reset_pose(d)
        self.head.reset(d)
        d.ctrl[:] = 0.0
        self.task.reset_episode(d, self.np_random)
        self.retina.draw_field(self.np_random)  # after the scenario: draws only with positional disarray
        mujoco.mj_forward(m, d)
        # Live views of MuJoCo's bad-state warning counters (reading one costs ~0.1 us).
        self._warning_stats = [d.warning[i] for i in self._bad_warnings]
        self._warning_total = sum(w.number for w in self._warning_stats)
        self._half_timestep = 0.5 * float(m.opt.timestep)

        point, offset = self.task.initial_gaze()
        gaze, distance = self.eye.look_at(d, point, offset)
        self.eye.reset(d, gaze, self.task.initial_fixation(distance))
        self.body.start(d)
        obs = self._observe(saccading=False)
        self._last_obs = obs.copy()
        self._needs_reset = False
        self._ended = False
        self._warned_after_end = False
        info = self._info(diverged=False, terms={})
        info.update(self.task.reset_info())
        return self._format(obs), info

    def step(self, action):
        if self._needs_reset:
            raise RuntimeError(f"{type(self).__name__}.step() called before reset(); call env.reset(seed=...) first")
        if self._ended and not self._warned_after_end:
            gym.logger.warn(
                "step() called after the episode ended (terminated=True); call reset(). "
                "The simulation goes on, but its outcome is no longer scored."
            )
            self._warned_after_end = True
        a, al = self._check_action(action)  # al: the same values in a list (cheaper to read than slices)
        m, d = self.model, self.data
        dt = self.dt
        nb = self._n_body_act
        plant_step = self.eye.command(al[nb], al[nb + 1], al[nb + 2], dt, self.n_substeps, self.np_random)
        self.head.command(d, al[nb + 3], al[nb + 4], dt)
        self.body.command(d, a, al, dt)
        self.task.before_physics(d)

        fired, diverged = self._simulate()
        if diverged:
            self._ended = True
            info = self._info(diverged=True, terms={})
            return self._format(self._last_obs.copy()), 0.0, True, False, info
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        fired = fired or self.task.check_substep(d)  # the event (a catch) on the final kinematics
        self.eye.apply(d)
        obs = self._observe(saccading=plant_step.saccading)
        self._last_obs = obs.copy()  # the fallback after divergence; the caller may edit ``obs``
        self.eye.end_step()

        reward, terms, terminated, task_info = self.task.evaluate(d, fired, a, self.eye)
        info = self._generic_info(diverged=False, terms=terms)
        info.update(task_info)
        info["saccade_onset"] = plant_step.saccade_started
        self._ended = self._ended or terminated
        if self.render_mode == "human":
            self.render()
        return self._format(obs), reward, terminated, False, info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' or 'human'")
            return None
        mujoco.mj_kinematics(self.model, self.data)  # the eye joints were written after the last step
        if self.render_mode == "human":
            return self._render_human()
        frames = [self._render_camera(c) for c in self.render_cameras[self.render_camera]]
        return frames[0] if len(frames) == 1 else np.concatenate(frames, axis=1)

    def close(self):
        for r in self._renderers.values():
            r.close()
        self._renderers = {}
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderers"] = {}
        state["_viewer"] = None
        state.pop("_warning_stats", None)  # views into self.data: rebuilt on load
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._native = state.get("_native", False) and _native.enabled()  # unpickled without the extension
        if "_warning_total" in state:
            self._warning_stats = [self.data.warning[i] for i in self._bad_warnings]

    # --- pieces of a step ---------------------------------------------------------------------
    def _reset_parts(self) -> None:
        self.task.reset_state()
        self.eye.reset_state()
        self.retina.reset()

    def _check_action(self, action) -> tuple[np.ndarray, list]:
        """The action as float64, clipped to [-1, 1], and the same values as a list; errors say why not."""
        if self._native:  # compiled: a float32/64 array of the right shape, finite, in [-1, 1]; else None
            checked = _native.kernels.check_action(action, self._n_action)
            if checked is not None:
                return checked
        if type(action) is np.ndarray and action.shape == self.action_space.shape and action.dtype.kind == "f":
            a = action.astype(np.float64)  # the common case: a float array of the right shape
        else:
            try:
                a = np.asarray(action)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"action must be a numeric array of shape {self.action_space.shape}; got {action!r}") from exc
            if a.dtype.kind not in "biuf":
                raise ValueError(
                    f"action must be a real numeric array of shape {self.action_space.shape}; got dtype {a.dtype}"
                )
            a = a.astype(np.float64)
            if a.shape != self.action_space.shape:
                raise ValueError(
                    f"action must have shape {self.action_space.shape} (blocks {self.action_structure}), got shape {a.shape}"
                )
        values = a.tolist()
        if not math.isfinite(sum(values)) and not all(map(math.isfinite, values)):  # NaN or inf somewhere
            bad = np.flatnonzero(~np.isfinite(a)).tolist()
            raise ValueError(f"action contains NaN or inf at index {bad}: {values}; actions must be finite in [-1, 1]")
        if min(values) < -1.0 or max(values) > 1.0:
            a = np.clip(a, -1.0, 1.0)
            values = a.tolist()
        return a, values

    def _simulate(self) -> tuple[bool, bool]:
        """Run the physics substeps; return (the task's substep check fired, diverged)."""
        m, d = self.model, self.data
        fired = False
        t_expected = d.time + self.dt
        task = self.task
        if not task.needs_substep_checks(d):
            mujoco.mj_step(m, d, self.n_substeps)  # nstep (positional: cheaper to pass)
        else:  # the task's event (a catch) may happen within this step: check every substep
            for _ in range(self.n_substeps):
                mujoco.mj_step(m, d)
                if not fired and task.check_substep(d):
                    fired = True
        # MuJoCo checks qpos/qvel/qacc every substep (NaN, inf or > 1e10), counts a warning and resets
        # the data (time back to 0) when one is bad: either sign is our divergence signal.
        total = self._warning_stats[0].number + self._warning_stats[1].number + self._warning_stats[2].number
        return fired, total != self._warning_total or abs(d.time - t_expected) > self._half_timestep

    def _observe(self, saccading: bool) -> np.ndarray:
        d = self.data
        # A moving body frame (a walker's pelvis) and the task's own per-step bookkeeping (which
        # obstacles fill the observation's slots) are brought up to date before any block is written.
        self.frame.update(d)
        self.task.before_observe(d)
        samples = self.retina.sample(d, self.task.targets, self.eye, saccading, self.np_random)
        values: list = []
        n_lead, n_head, n_body, n_obs = self._observe_ends
        self.task.observe_leading(values, samples)
        if len(values) != n_lead:
            self._observe_count_error("task", "observe_leading", values, 0, n_lead)
        self.eye.observe(values, self.frame)
        self.head.observe(values, d)
        if len(values) != n_head:
            self._observe_count_error("eye/head", "observe", values, n_lead, n_head)
        self.body.observe(values, d)
        if len(values) != n_body:
            self._observe_count_error("body", "observe", values, n_head, n_body)
        self.task.observe_trailing(values, samples, d)
        if len(values) != n_obs:
            self._observe_count_error("task", "observe_trailing", values, n_body, n_obs)
        if self._native:  # compiled np.array(values, dtype=np.float32) (floats and ints only, else None)
            obs = _native.kernels.float32_array(values)
            if obs is not None:
                return obs
        return np.array(values, dtype=np.float32)

    def _observe_count_error(self, part: str, hook: str, values: list, start: int, stop: int) -> None:
        """Raise: a part's observe call appended other than its blocks' sizes (names the block)."""
        owner = {"task": self.task, "body": self.body}.get(part)
        who = f"{type(owner).__name__}.{hook}" if owner is not None else f"{part} {hook}"
        blocks, offset, short = [], 0, None
        for b in self.layout.blocks:
            if start <= offset < stop:
                blocks.append(f"{b.name} ({b.size})")
                if short is None and offset + b.size > len(values):
                    short = b.name
            offset += b.size
        n = len(values) - start
        where = (f"block {short!r} is not filled" if short is not None
                 else f"{n - (stop - start)} value(s) past block {blocks[-1].split()[0]!r}" if blocks
                 else "it declares no blocks")
        raise RuntimeError(f"{who} appended {n} observation values, its blocks hold {stop - start} "
                           f"[{', '.join(blocks)}]: {where}")

    def _format(self, obs: np.ndarray):
        if self.obs_mode == "flat":
            return obs
        return self.layout.to_dict(obs)

    def _generic_info(self, *, diverged: bool, terms: dict) -> dict:
        d = self.data
        plant = self.plant
        info = {
            "is_success": bool(self.task.success),
            "physics_diverged": diverged,
            "reward_terms": terms,
            "in_saccade": plant.saccade is not None,
            "saccade_onset": False,
            "time": float(d.time),
            "gaze_dir": plant.gaze.copy(),
            "eye_pos": _native.kernels.vector3(self.eye.pos_list) if self._native else np.array(self.eye.pos_list),
        }
        info.update(self.head.info(d))
        info.update(self.body.info(d))
        return info

    def _info(self, *, diverged: bool, terms: dict) -> dict:
        """Reset or divergence information (nothing happened this step). The true state in here is for
        scoring only: never feed it to a policy."""
        info = self._generic_info(diverged=diverged, terms=terms)
        info.update(self.task.info(self.data, diverged=diverged))
        return info

    # --- what the evaluator records (bench/trace.py) -----------------------------------------
    def trace_fields(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """The body's and task's per-step ``info`` keys the evaluator records: (float arrays, flags)."""
        return (tuple(self.body.trace_step_fields) + tuple(self.task.trace_step_fields),
                tuple(self.task.trace_flag_fields))

    def trace_episode_fields(self) -> dict:
        """The task's per-episode values, right after ``reset`` (scoring only)."""
        return self.task.trace_episode_fields()

    def trace_final_fields(self, info: dict) -> dict:
        """The task's outcome fields from the last step's ``info``."""
        return self.task.trace_final_fields(info)

    # --- rendering ----------------------------------------------------------------------------
    def _render_camera(self, camera: str) -> np.ndarray:
        renderer = self._renderers.get(camera)
        if renderer is None:
            renderer = mujoco.Renderer(self.model, self.height, self.width)
            self._renderers[camera] = renderer
        renderer.update_scene(self.data, camera=camera)
        if camera != self.eye_camera:
            self.eye.draw(renderer.scene)
        return renderer.render().copy()

    def _render_human(self):
        headless = not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
        if headless or os.environ.get("MUJOCO_GL", "glfw") in ("egl", "osmesa"):
            if not self._warned_human:
                warnings.warn(
                    "render_mode='human' needs a display and MUJOCO_GL=glfw; nothing is shown. "
                    "Use render_mode='rgb_array' headless.",
                    stacklevel=2,
                )
                self._warned_human = True
            return None
        if self._viewer is None:
            import mujoco.viewer

            self._viewer = mujoco.viewer.launch_passive(self.model, self.data)
        self._viewer.sync()
        return None

