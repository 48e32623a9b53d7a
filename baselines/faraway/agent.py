"""The ``faraway`` baseline for ShelfReach: look, then reach along Faraway's path.

The agent sees observations only (the object's position only as the eye's samples). Each 20 ms step:

1. **Perception**: every visual sample of the object (eye frame at sampling time; the eye pose of that
   time is kept for the visual delay) is turned into the seat frame with its covariance from the vision
   model (Eyecatch Eq. 1-3, :func:`visuomotor_gym.vision.foveation.covariance`) and fused in information
   form (the object does not move). Peripheral samples know the direction well and the depth badly; a
   fixated one knows both.
2. **Gaze**: the first saccade goes ``saccade_latency_s`` after the start (~200 ms, REFERENCES.md:
   Prablanc et al. 1979, the saccade within ~250 ms; saccade latency 180-200 ms) to the estimated
   object, or, while the object has not been seen, to the next tower of the known layout (search).
   Then the eye is sent to the estimate every step (the plant turns small errors into pursuit, large
   ones into corrective saccades). The head turns by the part of the gaze angle beyond a 20 deg dead
   zone (Eyecatch Sec. 4.2). Vergence follows the estimate's distance.
3. **Hand**: ``hand_delay_s`` (100 ms, Prablanc et al. 1979: the hand ~100 ms after the saccade) after the
   saccade to the object, the hand starts along :func:`visuomotor_gym.handpath.faraway_path` from where it
   is to the estimated object; the end point follows the estimate as it sharpens (on-line correction,
   re-evaluated every step). The reach lasts ``reach_duration_s`` (0.6 s, so that gaze, which lands
   ~0.05-0.1 s after the saccade onset, leads the hand's arrival by ~0.5-0.6 s: Land, Mennie & Rusted
   1999, gaze reaches an object ~0.56 s before the hand acts on it), longer when the peak speed would
   exceed ``max_peak_speed_m_s``. The fingers close from ``grasp_at_tau`` of the reach on.

**With the depth law** (the eye's ``VisionParams.depth_pedestal_arcmin``, e.g. ``human_periphery()``: depth
precise only near the vergence distance), step 1 changes (``_fuse_depth_law``): the direction is fused from
every sample's lateral part, and the distance is the posterior over a grid of candidate distances in which
each sample's depth counts with the std the law gives at the candidate's distance and the vergence the eye
had when it took the sample; the agent verges on its estimate from the first saccade on, so its foveal
samples soon sit near the vergence distance and fix the depth. With the default vision (no depth law) the
agent is unchanged.

``gaze_blind=True`` is the gaze-blind twin (docs/gaze_gain.md): the same agent with gaze, vergence and
head held (zero actions), reaching to whatever its peripheral samples tell it, when they tell it anything.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, fields, replace

import numpy as np

from visuomotor_gym import handpath
from visuomotor_gym.core.frames import SEAT_ORIGIN
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.envs.actions import NECK_RANGE_DEG, hand_action
from visuomotor_gym.envs.reach import reach_observation
from visuomotor_gym.registration import agent_eye, env_vision
from visuomotor_gym.tasks.reach import SHELF_LAYOUT
from visuomotor_gym.vision import foveation, periphery
from visuomotor_gym.vision.foveation import VisionParams

DEG = math.pi / 180.0
_LAYOUT = ObservationLayout(reach_observation())
_S = _LAYOUT.slices
# Peak of the Beta(1.63, 1.75) speed density (at its mode 0.457): peak speed = this x length / duration.
PRIOR_STD_M = 0.5  # weak prior on the object: the shelves' centre +- 0.5 m (modelling choice)
SAMPLE_DISTANCE_RANGE_M = (0.2, 1.6)  # samples outside are rejected: the shelves are 0.5-1.1 m from the eye (modelling choice)
FAR_SHELF_M = 1.2  # beyond the farthest shelf target (1.1 m from the eye): the depth-law fusion takes every
# sample's lateral std at this distance (modelling choice, see FarawayAgent._fuse_depth_law)
PRIOR_DISTANCE_M = 0.8  # distance assumed for the first sample's noise: the shelves are 0.5-1.1 m from the eye
PATH_REPLAN_M = 0.01  # recompute faraway_path when the end estimate moved more than this; in between the path is
# shifted linearly in relative time onto the new end (cost: ~3 ms a call on a loaded core; modelling choice)
# The depth-law fusion's candidate distances: SAMPLE_DISTANCE_RANGE_M on a 5 mm grid (flat prior: the object is on
# the shelves; 5 mm is a tenth of the 6 cm success radius: modelling choice)
_DEPTH_GRID = np.arange(SAMPLE_DISTANCE_RANGE_M[0], SAMPLE_DISTANCE_RANGE_M[1] + 1e-9, 0.005)
_BETA_PEAK = float(np.max(np.diff(handpath.beta_progress(np.linspace(0.0, 1.0, 2001))) * 2000.0))


@dataclass(frozen=True)
class FarawayParams:
    """Every constant of the baseline, with its source; override by name (``faraway:name=value``)."""

    # Vision assumed by the brain (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    # Timing (REFERENCES.md, Reaching).
    saccade_latency_s: float = 0.2  # first saccade: 180-200 ms latency; Prablanc et al. 1979: within ~250 ms
    hand_delay_s: float = 0.1  # Prablanc et al. 1979: the hand ~100 ms after the saccade
    reach_duration_s: float = 0.6  # gaze leads the hand by ~0.56 s (Land et al. 1999); modelling choice
    max_peak_speed_m_s: float = 1.8  # below the hand controller's 2 m/s cap (Eyecatch 4.3); modelling choice
    grasp_at_tau: float = 0.8  # close the fingers over the last fifth of the reach (modelling choice)
    search_dwell_s: float = 0.3  # look at a tower this long before searching the next (modelling choice)
    head_dead_zone_deg: float = 20.0  # Eyecatch Sec. 4.2 Eq. 17
    # The gaze-blind twin: gaze, vergence and head held.
    gaze_blind: bool = False

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("foveated", "gaze_blind"):
                if not isinstance(v, bool):
                    raise ValueError(f"FarawayParams.{f.name} must be true or false, got {v!r}")
            elif isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"FarawayParams.{f.name} must be a finite number >= 0, got {v!r}")
        if not 0.0 < self.grasp_at_tau <= 1.0:
            raise ValueError(f"FarawayParams.grasp_at_tau must be in (0, 1], got {self.grasp_at_tau!r}")
        if self.reach_duration_s <= 0 or self.max_peak_speed_m_s <= 0:
            raise ValueError("FarawayParams.reach_duration_s and max_peak_speed_m_s must be > 0")


class FarawayAgent:
    """Saccade to the object, then a reach along Faraway's predicted path (SB3 ``predict`` interface)."""

    def __init__(self, params: FarawayParams | None = None, dt: float = 0.02):
        self.params = params or FarawayParams()
        p = self.params
        self.dt = float(dt)
        self.vision = VisionParams(noise_scale=max(p.vision_noise_scale, 1e-6), foveated=p.foveated)
        self.delay_steps = round(p.visual_delay_s / self.dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        # Search points: the towers' centres (the layout is known, as a person knows the shelves in front).
        targets = SHELF_LAYOUT.targets() - SEAT_ORIGIN
        self.search_points = [targets[t * 10 : t * 10 + 10].mean(axis=0) for t in range(3)]
        self.prior_mean = targets.mean(axis=0)
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> FarawayAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency); when the
        env's eye has a peripheral mechanism (``VisionParams.periphery_on``, e.g. ``human_periphery()``), the
        agent models that whole eye (``registration.env_vision_params``), as ``agents.match_vision`` does,
        unless the spec overrides the vision it assumes (``faraway:vision_noise_scale=5``)."""
        base = FarawayParams(**env_vision(env_id))
        unknown = sorted(set(overrides) - {f.name for f in fields(FarawayParams)})
        if unknown:
            raise TypeError(f"unknown faraway parameter(s) {unknown}; known: {[f.name for f in fields(FarawayParams)]}")
        agent = cls(replace(base, **overrides))
        vision = agent_eye(env_id, overrides)
        if vision is not None and vision.periphery_on:
            agent.vision = vision
        return agent

    def reset(self) -> None:
        """Forget the episode (called by the evaluator, and on ``episode_start``)."""
        self.started = False
        # The object estimate (seat frame): a precision-weighted mean started from a weak prior on the
        # shelves' centre (the layout is known), PRIOR_STD_M in every direction.
        self.weight_sum = 1.0 / PRIOR_STD_M**2
        self.point_sum = self.weight_sum * self.prior_mean
        self.samples = 0
        # With the depth law (VisionParams.depth_pedestal_arcmin) the samples are fused with their full
        # modelled covariance instead (``_fuse_depth_law``): information matrix and vector, same prior.
        self.info = np.eye(3) * self.weight_sum
        self.info_vec = self.info @ self.prior_mean
        self.depth_samples: list[tuple[np.ndarray, np.ndarray, float, float, float]] = []
        self._reference = 0  # the kept sample whose line of sight the candidates run along (least lateral std)
        self._reference_std = math.inf
        self._cached: tuple[np.ndarray, float] | None = None
        self.prev_rot: np.ndarray | None = None
        self.prev_eye: np.ndarray | None = None
        self.poses: deque = deque(maxlen=self.delay_steps + 1)
        self.saccade_time: float | None = None  # when the first saccade to the object was commanded
        self.search_index = 1  # the gaze starts on tower 0
        self.search_since = 0.0
        self.reach_start: np.ndarray | None = None
        self.reach_t0 = 0.0
        self.reach_T = self.params.reach_duration_s
        self.home: np.ndarray | None = None
        self._path: np.ndarray | None = None
        self._path_end: np.ndarray | None = None
        self.events: list[tuple[float, str]] = []

    # --- estimate ---------------------------------------------------------------------------
    @property
    def has_estimate(self) -> bool:
        return self.samples > 0

    @property
    def depth_law(self) -> bool:
        """Whether the eye this agent models has the depth law (depth precise only near the vergence
        distance, ``VisionParams.depth_pedestal_arcmin``; set by ``agents.match_vision``)."""
        v = self.vision
        return v.foveated and getattr(v, "depth_pedestal_arcmin", None) is not None

    def estimate(self) -> np.ndarray:
        """Seat-frame estimate of the object centre: the precision-weighted mean of the samples and the prior
        (with the depth law: :meth:`_depth_law_estimate`)."""
        if self.depth_law:
            return self._depth_law_estimate()[0]
        return self.point_sum / self.weight_sum

    def estimate_std(self) -> float:
        """Standard deviation (m) of the estimate along the worst (depth) direction."""
        if self.depth_law:
            return self._depth_law_estimate()[1]
        return float(1.0 / math.sqrt(self.weight_sum))

    def depth_sigma(self, distance, eccentricity, fixation):
        """The modelled depth std (m) of a sample of a point ``distance`` m away at ``eccentricity`` (rad),
        seen with the vergence distance ``fixation`` m: Eyecatch Eq. 2's ``d * depth_std_fraction *
        noise_scale / alpha(theta)`` times the depth law's ``1 + eta / eta_2``, ``eta = I |1/d - 1/d_fix|``
        (:func:`visuomotor_gym.vision.periphery.depth_factor`, vectorised: arrays broadcast)."""
        v = self.vision
        d = np.asarray(distance, dtype=float)
        e2 = v.fovea_e2_deg * DEG
        base = d * v.depth_std_fraction * v.noise_scale * (1.0 + np.asarray(eccentricity, dtype=float) / e2)
        eta = v.interocular_m * np.abs(1.0 / np.maximum(d, 1e-6) - 1.0 / np.asarray(fixation, dtype=float))
        return base * (1.0 + eta / (v.depth_pedestal_arcmin * periphery.ARCMIN))

    def _fuse(self, pos_eye: np.ndarray, rot: np.ndarray, eye: np.ndarray) -> None:
        """Add one sample, weighted by its depth precision (Eyecatch Eq. 2 at its eccentricity).

        Depth noise dominates (5 % of the distance at the fovea vs 1 arcmin laterally), so each sample is
        weighted isotropically by 1 / depth variance: the weighted mean of the sample points is unbiased
        (the eye-to-world map is linear) and, unlike a full-covariance fusion, it does not collapse onto the
        eye where the samples' nearly parallel lines of sight meet. The noise grows with the *true*
        distance, which a sample does not know (a far-peripheral one may put the object at the eye), so it
        is taken at the current estimate's distance (before the first sample: ``PRIOR_DISTANCE_M``)."""
        dist = float(np.linalg.norm(pos_eye))
        if pos_eye[0] <= 0.0 or not SAMPLE_DISTANCE_RANGE_M[0] <= dist <= SAMPLE_DISTANCE_RANGE_M[1]:
            return  # behind the eye or off the shelves' range: a far-peripheral depth error, not the object
        ref = float(np.linalg.norm(self.estimate() - eye)) if self.has_estimate else PRIOR_DISTANCE_M
        v = self.vision
        ecc = foveation.eccentricity(pos_eye)
        depth_std = max(ref, 0.1) * v.depth_std_fraction * v.noise_scale / foveation.acuity(ecc, v)
        w = 1.0 / max(depth_std, 1e-6) ** 2
        self.weight_sum += w
        self.point_sum += w * (eye + rot @ pos_eye)
        self.samples += 1

    def _fuse_depth_law(self, pos_eye: np.ndarray, rot: np.ndarray, eye: np.ndarray, fixation: float,
                        retinal_speed: float) -> None:
        """Add one sample when the eye has the depth law: its direction and its depth apart.

        A sample is the object plus noise along its line of sight (depth) and across it (lateral),
        Eyecatch Eq. 1-3. **Direction**: the lateral part is fused in information form
        (``lat / sigma_lat^2``, the sample's own line of sight; the lateral std, with the eye's position law
        and slip, at ``FAR_SHELF_M``, beyond the farthest shelf: a std taken at an underestimated distance lets two nearly
        parallel lines of sight from a moving eye triangulate the object onto the eye). **Depth**: the
        sample's distance along its line of sight is kept with the eye's position, line of sight,
        eccentricity and vergence distance, for :meth:`_depth_law_estimate`, which weighs it with the
        std the depth law gives *at each candidate distance* (far from the vergence distance depth is
        poor, at it a foveal sample is precise). No range cut: the likelihood handles wide samples."""
        dist = float(np.linalg.norm(pos_eye))
        if dist <= 1e-6:
            return
        u_eye = pos_eye / dist
        # The sample lies on the object's line of sight, on either side of the eye (a wide depth error can
        # put it behind): the half-line is the one toward the current estimate (the prior's centre at first).
        if float((rot @ u_eye) @ (self.estimate() - eye)) < 0.0:
            u_eye = -u_eye
        u = rot @ u_eye
        ecc = math.acos(max(-1.0, min(1.0, float(u_eye[0]))))
        # dt: under the positional disarray (VisionParams.position_disarray) a stream of looks at one place of
        # the retina shares its fixed error, so each look counts for less (foveation.believed_sigmas; no effect
        # without the disarray).
        lateral_std = float(foveation.believed_sigmas(FAR_SHELF_M, ecc, retinal_speed, self.vision, None, self.dt)[1])
        # The line of sight is the eye-to-sample ray, whose angle errs by the lateral error over the sample's
        # distance: a sample that depth noise put near the eye (|s| << d) has no direction to speak of.
        # At the object's distance d <= FAR_SHELF_M the ray is off by d * (d k) / |s| <= lateral_std * FAR / |s|
        # (k: the angular lateral std), so the lateral std grows by FAR_SHELF_M / |s| below FAR_SHELF_M.
        lateral_std *= max(1.0, FAR_SHELF_M / dist)
        w = (np.eye(3) - np.outer(u, u)) / max(lateral_std, 1e-9) ** 2
        point = eye + rot @ pos_eye
        self.info += w
        self.info_vec += w @ point
        self.depth_samples.append((eye.copy(), u, float(u @ (point - eye)), ecc, float(fixation)))
        if lateral_std <= self._reference_std:  # the surest line of sight so far (ties: the latest)
            self._reference, self._reference_std = len(self.depth_samples) - 1, lateral_std
        self.samples += 1
        self._cached = None

    def _depth_law_estimate(self) -> tuple[np.ndarray, float]:
        """(estimate, std) with the depth law: the posterior over candidate points, one per distance.

        The candidates ``c(lam) = c0 + lam g`` are, for each distance ``lam`` along the line of sight ``u0``
        from the eye ``e0`` of the kept sample with the least lateral std (the surest direction; ties: the
        latest. The latest sample's ray, taken before, may be one that depth noise put near the eye, tens
        of degrees off, and then no candidate lies near the object: seed 73 under ``human_periphery()``)
        (``lam`` on ``_DEPTH_GRID``, flat prior: the object is on the shelves), the point that best fits the lateral information at that distance (the minimum of the
        lateral quadratic under a stiff constraint ``u0 . (c - e0) = lam``, which is linear in ``lam``).
        A candidate's log-posterior is the lateral quadratic plus, for each kept sample ``i`` (eye ``e_i``,
        line of sight ``u_i``, measured distance ``s_i``), ``log N(s_i; u_i . (c - e_i), sigma_i(c)^2)``
        with ``sigma_i(c)`` = :meth:`depth_sigma` at the candidate's distance ``|c - e_i|`` and the sample's
        own eccentricity and vergence distance: the exact depth law, so a sample taken far from its
        vergence distance weighs little wherever the object is, and the estimate does not lock onto an
        early wrong depth (which a covariance taken at the estimate, where the agent verges, would do:
        there the pedestal is zero). The estimate is the posterior mean; its std the larger of the
        posterior's and the lateral one."""
        if self._cached is not None:
            return self._cached
        lateral = np.linalg.solve(self.info, self.info_vec)
        if not self.depth_samples:
            self._cached = (lateral, float(math.sqrt(max(np.linalg.eigvalsh(np.linalg.inv(self.info))[-1], 0.0))))
            return self._cached
        e0, u0 = self.depth_samples[self._reference][0], self.depth_samples[self._reference][1]
        kappa = 1e4 * float(np.trace(self.info))
        A = self.info + kappa * np.outer(u0, u0)
        c0 = np.linalg.solve(A, self.info_vec + kappa * u0 * float(u0 @ e0))
        g = np.linalg.solve(A, kappa * u0)
        lam = _DEPTH_GRID
        cand = c0 + lam[:, None] * g  # (K, 3)
        dev = cand - lateral
        loglik = -0.5 * np.einsum("kc,cd,kd->k", dev, self.info, dev)  # the lateral evidence
        E = np.array([d[0] for d in self.depth_samples])  # (N, 3)
        U = np.array([d[1] for d in self.depth_samples])
        S = np.array([d[2] for d in self.depth_samples])
        ecc = np.array([d[3] for d in self.depth_samples])
        fix = np.array([d[4] for d in self.depth_samples])
        rel = cand[None, :, :] - E[:, None, :]  # (N, K, 3)
        pred = np.einsum("nkc,nc->nk", rel, U)
        dist = np.linalg.norm(rel, axis=2)
        sig = self.depth_sigma(dist, ecc[:, None], fix[:, None])
        loglik = loglik + np.sum(-0.5 * ((S[:, None] - pred) / sig) ** 2 - np.log(sig), axis=0)
        w = np.exp(loglik - loglik.max())
        w /= w.sum()
        mean = float(w @ lam)
        std = float(math.sqrt(max(float(w @ (lam - mean) ** 2), 0.0)))
        lat_std = float(math.sqrt(max(np.linalg.eigvalsh(np.linalg.inv(self.info))[0], 0.0)))
        self._cached = (c0 + mean * g, max(std * float(np.linalg.norm(g)), lat_std))
        return self._cached

    # --- policy -------------------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        if obs.shape != (_LAYOUT.size,):
            raise ValueError(f"FarawayAgent expects the flat ShelfReach observation of size {_LAYOUT.size} "
                             f"(hand_action='target'), got shape {obs.shape}")
        return self._act(obs), state

    def _act(self, obs: np.ndarray) -> np.ndarray:
        p = self.params
        t = float(obs[_S["time"]][0])
        rot = obs[_S["eye_rot"]].reshape(3, 3)
        eye = obs[_S["eye_pos"]].copy()  # seat frame
        hand = obs[_S["hand_pos"]].copy()
        if not self.started:
            self.started = True
            self.home = hand.copy()
        # The static object's retinal slip over the last step (rad/s; depth-law fusion), as the retina
        # computes it (``core.eye.Eye.retinal_speed``) with the object at the current estimate.
        turn = 0.0
        if self.prev_rot is not None:
            turn = self._retinal_slip(rot, eye)
        self.prev_rot = rot.copy()
        self.prev_eye = eye.copy()
        self.poses.append((rot.copy(), eye.copy(), float(obs[_S["fixation"]][0]), turn))
        if obs[_S["object_visible"]][0] > 0.5 and len(self.poses) == self.delay_steps + 1:
            r0, e0, f0, w0 = self.poses[0]  # the eye pose (and vergence) when the sample was taken
            if self.depth_law:
                self._fuse_depth_law(obs[_S["object_pos"]].copy(), r0, e0, f0, w0)
            else:
                self._fuse(obs[_S["object_pos"]].copy(), r0, e0)

        # --- gaze ---------------------------------------------------------------------------
        gaze = (0.0, 0.0)
        head = (0.0, 0.0)
        fixation = None
        look_at = None
        if t >= p.saccade_latency_s - 1e-9:
            if self.has_estimate:
                look_at = self.estimate()
                if self.saccade_time is None:
                    self.saccade_time = t
                    self.events.append((t, "saccade"))
            else:
                if t - self.search_since >= p.search_dwell_s and self.search_index < len(self.search_points):
                    self.search_since = t
                    self.search_index += 1
                look_at = self.search_points[min(self.search_index, len(self.search_points)) - 1]
        if look_at is not None and not p.gaze_blind:
            d_eye = rot.T @ (look_at - eye)
            gaze = (math.atan2(d_eye[1], d_eye[0]), math.atan2(d_eye[2], math.hypot(d_eye[0], d_eye[1])))
            d = look_at - eye  # seat frame = world axes
            az, el = math.atan2(d[1], d[0]), math.atan2(d[2], math.hypot(d[0], d[1]))
            head = (self._beyond_dead_zone(az, 0), self._beyond_dead_zone(el, 1))
            fixation = float(np.linalg.norm(d))
        elif p.gaze_blind and self.has_estimate and self.saccade_time is None and t >= p.saccade_latency_s - 1e-9:
            self.saccade_time = t  # the time the looking agent would have looked: the twin's hand starts alike

        # --- hand ---------------------------------------------------------------------------
        target = self.home
        grasp = False
        if self.saccade_time is not None and t >= self.saccade_time + p.hand_delay_s - 1e-9 and self.has_estimate:
            end = self.estimate()
            if self.reach_start is None:
                self.reach_start = hand.copy()
                self.reach_t0 = t
                length = float(np.linalg.norm(end - hand))
                self.reach_T = max(p.reach_duration_s, _BETA_PEAK * length / p.max_peak_speed_m_s)
                self.events.append((t, "reach"))
            tau = min((t + self.dt - self.reach_t0) / self.reach_T, 1.0)  # where the hand should be next step
            if float(np.linalg.norm(end - self.reach_start)) < 1e-3 or tau >= 1.0:
                target = end
            else:
                n = 101
                if self._path_end is None or float(np.linalg.norm(end - self._path_end)) > PATH_REPLAN_M:
                    self._path = handpath.faraway_path(self.reach_start + SEAT_ORIGIN, end + SEAT_ORIGIN, n) - SEAT_ORIGIN
                    self._path_end = end
                path = self._path + np.linspace(0.0, 1.0, n)[:, None] * (end - self._path_end)  # exact end point
                target = np.array([np.interp(tau * (n - 1), np.arange(n), path[:, k]) for k in range(3)])
            grasp = tau >= p.grasp_at_tau
        return hand_action(target + SEAT_ORIGIN, grasp, gaze, head, fixation, self.gaze_range)

    def _retinal_slip(self, rot: np.ndarray, eye: np.ndarray) -> float:
        """Speed (rad/s) of the static object's image on the retina over the last step: the angular
        velocity of its line of sight, from the eye's own translation (the head's turn carries the eye,
        which sits off the neck's axes), minus the gaze's angular velocity, perpendicular to the line of
        sight; the object taken at the current estimate (before the first sample: the prior's centre).
        Counting the gaze's turn alone misses the translation: a head turn with the gaze held in the body
        frame slips a shelf object 0.7 m away by ~50 deg/s (seed 78 under ``human_periphery()``)."""
        r = self.estimate() - eye
        dist2 = max(float(r @ r), 1e-6)
        rel_vel = -(eye - self.prev_eye) / self.dt  # the object's velocity relative to the eye
        los = np.cross(r, rel_vel) / dist2
        gaze = np.cross(self.prev_rot[:, 0], rot[:, 0]) / self.dt
        slip = los - gaze
        slip = slip - (slip @ r) / dist2 * r
        return float(np.linalg.norm(slip))

    def _beyond_dead_zone(self, angle: float, k: int) -> float:
        """Head angle (rad) that leaves at most the dead zone to the eye (Eyecatch Eq. 17), within the neck's range."""
        dz = self.params.head_dead_zone_deg * DEG
        h = 0.0 if abs(angle) <= dz else angle - math.copysign(dz, angle)
        lo, hi = NECK_RANGE_DEG[k]
        return min(max(h, lo * DEG), hi * DEG)
