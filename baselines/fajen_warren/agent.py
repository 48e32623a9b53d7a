"""The ``fajen_warren`` agent for ObstacleDodge: Fajen & Warren's steering dynamics on its own estimates of
the pedestrians, and gaze to the pedestrian with the highest collision risk.

**Perception** (:class:`PedestrianFilter`): one constant-velocity Kalman filter per pedestrian slot in the
path frame (x along the path from the start, y left). A visual sample (position and velocity in the eye
frame) is placed in the path frame with the agent's proprioception (eye pose in the pelvis frame, the
odometry block) and weighted by the vision model's own covariance (Eyecatch Eq. 1-3: depth 5 % and
lateral 1 arcmin of the distance at the fovea, growing with eccentricity; velocity likewise), evaluated
at the perceived point. Unmodelled accelerations (a veer) enter as white acceleration noise of
``accel_std`` (modelling choice).

**Steering** (Fajen & Warren 2003, JEP:HPP 29:343, the "steering dynamics" model; the same equations in
Fajen, Warren, Temizer & Kaelbling 2003, IJCV 54:13): the direction of travel phi obeys

    phi'' = -b phi' - k_g (phi - psi_g) (exp(-c1 d_g) + c2)
            + sum_o k_o (phi - psi_o) exp(-c3 |phi - psi_o|) exp(-c4 d_o)

with the goal at angle psi_g and distance d_g and each obstacle at psi_o, d_o; the gains are the
paper's fits (b = 3.25 /s, k_g = 7.50 /s^2, c1 = 0.40 /m, c2 = 0.40, k_o = 198 /s^2, c3 = 6.5 /rad,
c4 = 0.8 /m). **Not verified against the paper's own text**: we could not read either paper here. The
same seven values are what secondary sources quote for the published fit (a public steering-model
visualisation's ``default_params`` b=3.25, k_g=7.5, c_1=0.4, c_2=0.4, k_o=198, c_3=6.5, c_4=0.8; notes on
Fajen & Warren 2003 quoting them with the fits' 0.980 / 0.975 of the path variance); see
docs/reproductions/dodge.md. The model is for stationary
obstacles at constant speed; for a moving pedestrian the obstacle term acts on where the pedestrian
will be at the moment of closest approach (so the walker steers away from the meeting point, behind a
crossing pedestrian), and only for pedestrians whose predicted closest distance is below
``avoid_distance_m`` = 1 m (Olivier et al. 2012, Gait & Posture 36:399: walkers adapt only below a
minimal predicted distance of ~1 m). Both adaptations are modelling choices.

**Course and speed** (:meth:`FajenWarrenAgent._evade`; modelling choice beside the constant-speed model):
the steering dynamics' phi at the nominal 1.3 m/s is the default command. Each step the agent predicts,
for phi and for courses 18, 9 and 0 deg either side of the path, each at the speeds 0.5-1.9 m/s (the
body's range), the closest distance to every known pedestrian (the walker keeps the velocity of its last
command, which the step under way was latched from, for the ~0.7 s a footstep command needs to show,
measured on the gait; pedestrians keep their estimated velocity, and one whose velocity changed in the
last second may also take up its old velocity again: a veer ends, ``veer_return_s``), capped at
``speed_margin_m`` = 2.5 m, less ``speed_cost`` per m/s and ``course_cost`` per rad of change; the
best pair is commanded. The margin is on the agent's *estimates*: with a pedestrian's velocity seen
only now and then and noisily, 2.5 m did best in the sweep of docs/reproductions/dodge.md (1.2 m: 79 %,
2.0 m: 84-88 %, 2.5 m: 86-93 %, 3.0 m: 89-90 % on seeds 200-399), though Olivier et al.'s walkers,
who see well, adapt only below ~1 m of predicted distance. While no candidate clears the margin, the change is counted from the previous
command, so a dodge under way is held rather than undone once no change can show in time. (Humans
adapt both speed and course to a crossing pedestrian: Olivier et al. 2012.)

**Gaze** (:meth:`FajenWarrenAgent._choose`): the agent fixates the pedestrian with the highest collision
risk, where risk is the staleness of its estimate (time since it was last seen) plus ``vel_std_weight`` = 3 s per m/s
of its velocity estimate's standard deviation (a pedestrian glimpsed once in the periphery is looked at
again before its velocity is trusted), weighted up for a pedestrian whose predicted closest distance is
below 1 m soon (Olivier et al. 2012), and down for one that has passed; a fixation is held at least ``min_dwell_s`` = 0.1 s counted from the end of the
saccade that brought it (modelling choice; shorter than a typical human fixation, 0.2-0.3 s). Pedestrians not yet seen are searched for: the agent looks alternately
``search_azimuth_deg`` = 45 deg to either side (where pedestrians 4-6 m to the side appear), each side
an urgency that grows with the time since it was last scanned.

**Groups** (only when the env's ``crowd_distribution`` has groups; :func:`group_prior`, the agent's prior
about the crowd like the known number of pedestrians): while pedestrians remain unseen, each known one
with no known neighbour is assumed to have companions abreast at the env's mean spacing, which the
evasion avoids (``companion_m``); fixations last at least ``GROUP_MIN_DWELL_S`` = 0.2 s (the short end
of human fixations, 200-400 ms: Tatler & Land 2016), counted from the saccade that brought the gaze
(``dwell_saccade_s``: catch-up saccades on a near pedestrian no longer restart it); the search for the
next group is more urgent (``GROUP_SEARCH_WEIGHT``), since half the pedestrians appear at once and a
near group holds the gaze. Re-fixating each member follows from the risk rule: each member has its own
slot and filter. See docs/reproductions/data/terrain/dodge_groups.md.

**The human periphery** (only when the agent's eye -- every constant of the env's, from ``for_env`` --
has the mechanisms of ``vision.periphery``; v0's agent otherwise; modelling choices, measured in
docs/reproductions/data/terrain/dodge_groups.md): with the human field (100 deg to either side) no search
(a pedestrian appearing at the side is seen wherever the eye looks ahead) but a look along the path
(``path_urgency``) when no pedestrian needs one more; pedestrians beyond ``gaze_bearing_limit_deg`` of
the heading (passing beside or behind) are not looked at, and one becomes a gaze target ``notice_s``
after its first sight; a pedestrian first seen starts from a zero-mean velocity prior
(``velocity_prior_std``, walking speeds) instead of one far-peripheral velocity sample; with crowding, a
sample that may be pooled with another pedestrian's is fused with the spread of its crowding zone
(``baselines.crowding``, as iwao and lookahead); the gaze risk also counts the position estimate's std
(``pos_std_weight``): depth far in the periphery is poor. Two perception guards (on by default since
fajen_warren-v6; None turns each off): a sample perceived at or behind the eye (``min_depth_m``) is skipped, and
an estimate faster than anyone walks (``max_speed_m_s``) is cut to that speed with the velocity prior's variance,
so that one wild depth sample right after a saccade (the vergence still far from the pedestrian) does not become
a confident, wrong course that the filter then keeps.

``gaze_blind=True`` holds gaze and head (gaze action 0: gaze stays level at the goal; head straight):
the gaze-blind twin (docs/gaze_gain.md), the same filter and steering.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.crowding import crowd_std, crowded

from visuomotor_gym.body.dodge_body import DodgeBody
from visuomotor_gym.envs.dodge import DODGE_LAYOUT
from visuomotor_gym.oculomotor.plant import OculomotorParams
from visuomotor_gym.registration import agent_eye, env_vision
from visuomotor_gym.tasks.obstacle_dodge import K_SLOTS, NOMINAL_SPEED
from visuomotor_gym.vision.foveation import DEG, VisionParams, _los_rows, believed_sigmas

_S = DODGE_LAYOUT.slices
_FIXATION = _S["fixation"].start  # the eye's vergence distance (m): proprioception
# The plant's fixation range, onto which the fixation action is log-mapped (core.eye.Eye.command).
_LOG_FIX = tuple(math.log(x) for x in OculomotorParams().fixation_range_m)
MIN_STD = 1e-3  # floor of the measurement std (the oracle rung is noiseless)
# With groups, half the pedestrians come at once and a near group holds the gaze: the search urgency per
# second is raised so that the next group is found in time (modelling choice; 0.6, 1.2 and 2.0 tried on
# seeds 0-19, docs/reproductions/data/terrain/dodge_groups.md).
GROUP_SEARCH_WEIGHT = 2.0
GROUP_MIN_DWELL_S = 0.2  # s: the short end of human fixations, 200-400 ms (Tatler & Land 2016)


@dataclass(frozen=True)
class FajenWarrenParams:
    # Vision assumed by the agent (set from the env id by ``for_env``).
    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    control_dt: float = 0.02
    # Fajen & Warren 2003 (see the module docstring).
    b: float = 3.25
    k_g: float = 7.50
    c1: float = 0.40
    c2: float = 0.40
    k_o: float = 198.0
    c3: float = 6.5
    c4: float = 0.8
    avoid_distance_m: float = 1.0  # Olivier et al. 2012
    horizon_s: float = 6.0  # closest approaches further ahead are ignored (modelling choice)
    heading_limit_deg: float = 25.0  # what the gait's +-0.3 m lateral step gives at 0.65 m steps
    speed: float = NOMINAL_SPEED
    # Speed (modelling choice beside the heading-only model; see the module docstring): candidate speeds,
    # the footstep latency assumed before a new speed shows (~0.5-1 s: the step after next), and the
    # preference for the nominal speed (m of predicted distance per m/s of change).
    speeds: tuple = (0.5, 0.7, 0.9, 1.1, 1.3, 1.5, 1.7, 1.9)  # the body's range (dodge_body.SPEED_RANGE_M_S)
    speed_latency_s: float = 0.7
    # The velocity of the latency phase: the last command's (True; the step under way was latched from it),
    # else the mean pelvis velocity over ``velocity_window_s`` (one step; 0: the pelvis's now). Modelling
    # choices; the command's velocity did better (seeds 200-399: 185/200 against 180/200).
    latency_at_command: bool = True
    velocity_window_s: float = 0.5
    speed_cost: float = 0.15
    # closest distances beyond this are all equally safe (modelling choice; sweep: docs/reproductions/dodge.md)
    speed_margin_m: float = 2.5
    evade_courses_deg: tuple = (-18.0, -9.0, 0.0, 9.0, 18.0)  # candidate courses off the path (gait's limit ~18 deg)
    course_cost: float = 0.3  # m of predicted distance per rad away from the steering dynamics' phi
    lateral_speed_m_s: float = 0.36  # the gait's widest sideways progress (tests/test_obstacle_dodge.py)
    # "A veer ends" hypotheses (modelling choice on Jovancevic, Sullivan & Hayhoe's veers of ~1 s): when a
    # pedestrian's estimated velocity differs by more than ``veer_detect_m_s`` from its velocity
    # ``veer_memory_s`` ago (and not from its velocity twice that long ago: a change already undone), the
    # evasion also predicts it keeping its new velocity for each of ``veer_return_s`` and then taking up
    # the old one again, and keeps the closest of all those predictions. () switches it off.
    veer_return_s: tuple = (0.3, 0.6, 1.0)
    veer_detect_m_s: float = 0.5
    veer_memory_s: float = 1.0
    # Perception and gaze (modelling choices, see the module docstring).
    accel_std: float = 1.0  # m/s^2, white acceleration noise of the constant-velocity model
    min_dwell_s: float = 0.1
    # s of staleness per m/s of the velocity estimate's std (modelling choice; sweep: docs/reproductions/dodge.md)
    vel_std_weight: float = 3.0
    search_azimuth_deg: float = 45.0
    search_distance_m: float = 6.0
    search_weight: float = 0.25  # a side's search urgency per second since it was last scanned
    head_share: float = 0.5  # the head takes this share of a gaze shift's azimuth
    gaze_blind: bool = False
    # Groups (set by ``for_env`` when the env's crowd_distribution has groups; the defaults are v0's agent):
    # ``companion_m`` > 0: while pedestrians remain unseen, each known pedestrian with no known neighbour
    # within ``1.5 * companion_m`` is assumed to have companions abreast, ``companion_m`` to its left and
    # right at its velocity (the evasion avoids them; the gaze looks at them to find out): the env's mean
    # group spacing (Moussaid et al. 2010's pedestrians walk side by side). ``search_azimuths_deg``: the
    # search looks at these azimuths in turn on each side (v0: ``search_azimuth_deg`` only); groups
    # appear at the onset close to the walker's side, beyond 45 deg (modelling choice).
    companion_m: float = 0.0
    # Only a saccade within this long of choosing the target is the one that brought it (later ones,
    # catch-up saccades on a near pedestrian, no longer restart the dwell, which would hold the gaze on it
    # for good); None: every saccade restarts it (v0). Modelling choice: a saccade lasts well under 0.1 s
    # at the amplitudes here (main sequence), plus the ~0.2 s saccade latency.
    dwell_saccade_s: float | None = None
    search_azimuths_deg: tuple = ()
    # Search for pedestrians not seen yet: None = unless the vision has the human field (see ``_search``)
    search: bool | None = None
    # With the human periphery (``VisionParams.periphery_on``; modelling choices): the velocity prior of a
    # pedestrian first seen (zero mean, this std in m/s; adults walk at 1.27-1.46 m/s, Bohannon 1997), and,
    # without the search, the urgency of a look along the path ``search_distance_m`` ahead when no
    # pedestrian still ahead or approaching needs a look more (pedestrians that have passed are not looked at)
    velocity_prior_std: float = 1.5
    # Two perception guards (since ObstacleDodge-v0's fourth entry of this agent; None: off, the earlier agent).
    # ``max_speed_m_s``: walking speeds (the agent's prior): an estimate faster than this is wrong (a depth
    # sample far off taken as motion); its velocity is cut to this speed and its velocity variance raised back
    # to the prior's (velocity_prior_std), so that the next samples correct it. Adults' fastest walking is about
    # 2.5 m/s (Bohannon 1997, maximum gait speeds 1.75-2.53 m/s); the crowds walk at 1.0-1.5 m/s.
    max_speed_m_s: float | None = 2.5
    # ``min_depth_m``: a sample perceived at or nearer than this along the line of sight (m; at or behind the
    # eye) carries no usable depth and is skipped: right after a saccade onto a far pedestrian, the vergence
    # still far from it, the one eye's depth samples spread over tens of metres either side (the depth law's
    # disparity pedestal). A pedestrian that near is a collision already (contact at 0.55 m). Modelling choice;
    # measured in docs/reproductions/data/terrain/dodge_groups.md ("Two perception guards").
    min_depth_m: float | None = 0.5
    path_urgency: float = 0.2
    # ... and pedestrians further than this from the heading are passing beside or behind: not looked at
    gaze_bearing_limit_deg: float = 75.0
    # ... and a pedestrian becomes a gaze target only this long after it was first seen (modelling choice:
    # with the saccade latency, the dwell on the present target and the saccade the first fixation then begins ~0.6 s after the
    # appearance, as in Jovancevic, Sullivan & Hayhoe: 548-740 ms)
    notice_s: float = 0.15
    # ... and the risk counts the position estimate's std too, this many s per m (modelling choice)
    pos_std_weight: float = 1.0
    # Depth hypotheses along the line of sight (ObstacleDodge-v0's fourth agent; () = before it): a pedestrian
    # seen only in the periphery is placed well in direction and poorly in depth (the human periphery's depth
    # law: a few metres of std at 40-100 deg off a far fixation), so its mean can lie metres behind a
    # pedestrian about to cut across the walker's path. While the estimate's std along the line of sight
    # exceeds ``los_std_min_m``, the agent also considers the pedestrian at the mean's distance plus each of
    # these multiples of that std (nearer ones first; never nearer than ``los_min_distance_m``), with the
    # lateral velocity its bearing rate then implies: the threat test, the evasion and the choice of fixation
    # take the most dangerous one, so the eye goes to a near, badly placed pedestrian and the fovea settles
    # its distance. Humans treat an unresolved peripheral object as a possible obstacle and fixate it before
    # they pass it (Jovancevic, Sullivan & Hayhoe 2006: fixations on pedestrians on a collision course);
    # the multiples and thresholds are modelling choices (sweep: docs/reproductions/data/terrain/dodge_groups.md).
    los_hypotheses_std: tuple = ()
    los_hypotheses_evade: bool = True  # False: the hypotheses choose the fixation only (not the steering, evasion)
    los_std_min_m: float = 0.3
    los_min_distance_m: float = 0.5


def group_prior(env_id: str) -> dict:
    """The group parameters of :class:`FajenWarrenParams` for the registered env (empty without groups):
    the agent's prior about the crowd, like the number of pedestrians (``K_SLOTS``)."""
    import gymnasium as gym

    from visuomotor_gym.core import args
    from visuomotor_gym.tasks.obstacle_dodge import CrowdDistribution, crowd_preset

    kw = gym.spec(env_id).kwargs or {}
    dist = args.coerce(CrowdDistribution, crowd_preset(kw.get("crowd_distribution")), "crowd_distribution")
    if not dist.groups:
        return {}
    return {"companion_m": 0.5 * (dist.group_spacing_m[0] + dist.group_spacing_m[1]),
            "search_azimuths_deg": (45.0,), "search_weight": GROUP_SEARCH_WEIGHT,
            "min_dwell_s": GROUP_MIN_DWELL_S, "dwell_saccade_s": 0.3}


class PedestrianFilter:
    """Constant-velocity Kalman filter of one pedestrian (path frame: x, y, vx, vy)."""

    def __init__(self) -> None:
        self.x = np.zeros(4)
        self.P = np.eye(4) * 1e6
        self.t = -1.0  # time of the last update (-1: never seen)
        self.t_seen = -math.inf
        self.t_first = -math.inf  # time of the first sight
        self.history: list[tuple[float, float, float]] = []  # (t, vx, vy) of the estimate, per control step

    def velocity_at(self, t: float):
        """The estimated velocity at time ``t`` (the oldest kept when ``t`` is earlier), or None."""
        for ti, vx, vy in reversed(self.history):
            if ti <= t + 1e-9:
                return vx, vy
        return (self.history[0][1], self.history[0][2]) if self.history else None

    @property
    def known(self) -> bool:
        return self.t >= 0.0

    def limit_speed(self, vmax: float, velocity_std: float) -> None:
        """An estimate faster than ``vmax`` (m/s) is cut to that speed, and its velocity made as uncertain as
        the prior (std ``velocity_std`` per axis, uncorrelated with the position), so the next samples set it."""
        speed = math.hypot(self.x[2], self.x[3])
        if speed <= vmax:
            return
        self.x[2:] *= vmax / speed
        self.P[2:, :] = 0.0
        self.P[:, 2:] = 0.0
        self.P[2:, 2:] = np.eye(2) * velocity_std ** 2

    def predict_to(self, t: float, q: float) -> None:
        if not self.known or t <= self.t:
            return
        dt = t - self.t
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        G = np.array([[0.5 * dt * dt, 0.0], [0.0, 0.5 * dt * dt], [dt, 0.0], [0.0, dt]])
        self.x = F @ self.x
        self.P = F @ self.P @ F.T + (q * q) * (G @ G.T)
        self.t = t

    def update(self, t: float, z: np.ndarray, R: np.ndarray, q: float, velocity_prior_std: float | None = None) -> None:
        if not self.known and velocity_prior_std is not None:
            # first sight: the position as seen, the velocity fused with a prior of walking speeds (zero
            # mean, ``velocity_prior_std``) so that one far-peripheral look (velocity stds of several m/s)
            # does not send the estimate away at tens of m/s
            prior = np.eye(2) * velocity_prior_std ** 2
            K = prior @ np.linalg.inv(prior + R[2:, 2:])
            self.x = np.concatenate([z[:2], K @ z[2:]])
            self.P = np.zeros((4, 4))
            self.P[:2, :2] = R[:2, :2]
            self.P[2:, 2:] = (np.eye(2) - K) @ prior
            self.t = t
        elif not self.known:
            self.x, self.P, self.t = z.copy(), R.copy(), t
        if self.t_first == -math.inf:
            self.t_first = t
        else:
            self.predict_to(t, q)
            S = self.P + R
            K = self.P @ np.linalg.inv(S)
            self.x = self.x + K @ (z - self.x)
            self.P = (np.eye(4) - K) @ self.P
        self.t_seen = t



def look_action(eye, point, yaw: float, rot, gaze_range: float, head_share: float, verge: bool = False) -> list:
    """Gaze, fixation and head actions that turn the eye from the ``eye`` position (path frame) to
    ``point``: the direction in the pelvis frame (heading ``yaw``), then in the eye frame (``rot``: the
    eye_rot block, row-major), as a gaze change in units of ``gaze_range``; the head yaws
    ``head_share`` of the direction's azimuth (neck yaw range +-80 deg). ``verge``: also ask for
    vergence at the point's distance (the log map of ``core.eye.Eye.command`` onto the plant's
    fixation range; for the depth law of ``VisionParams.depth_pedestal_arcmin``), else the fixation
    action 0 (v0)."""
    ex, ey, ez = eye
    tx, ty, tz = point
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy, dz = tx - ex, ty - ey, tz - ez
    wx, wy = c * dx + s * dy, -s * dx + c * dy  # pelvis frame
    n = math.sqrt(wx * wx + wy * wy + dz * dz) or 1.0
    wx, wy, wz = wx / n, wy / n, dz / n
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = rot[0:3], rot[3:6], rot[6:9]
    e0 = a00 * wx + a10 * wy + a20 * wz  # R^T w: in the eye frame
    e1 = a01 * wx + a11 * wy + a21 * wz
    e2 = a02 * wx + a12 * wy + a22 * wz
    d_az = math.atan2(e1, e0)
    d_el = math.atan2(e2, math.hypot(e0, e1))
    r = gaze_range
    head_yaw = head_share * math.atan2(wy, wx)
    fix = 0.0
    if verge:
        lo, hi = _LOG_FIX
        fix = min(max(2.0 * (math.log(min(max(n, 0.3), 20.0)) - lo) / (hi - lo) - 1.0, -1.0), 1.0)
    return [min(max(d_az / r, -1.0), 1.0), min(max(d_el / r, -1.0), 1.0), fix,
            min(max(head_yaw / (80.0 * DEG), -1.0), 1.0), 0.0]

class FajenWarrenAgent:
    """See the module docstring. ``predict(obs) -> (action, state)`` on flat ObstacleDodge observations."""

    def __init__(self, params: FajenWarrenParams | None = None) -> None:
        p = params or FajenWarrenParams()
        if not isinstance(p.los_hypotheses_std, tuple):
            raise ValueError(f"los_hypotheses_std must be a tuple of std multiples (in a spec: "
                             f"los_hypotheses_std=-1.5;-0.75, or -1; for one), got {p.los_hypotheses_std!r}")
        for name in ("max_speed_m_s", "min_depth_m"):
            v = getattr(p, name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                                  or v <= 0.0):
                raise ValueError(f"{name} must be a positive number of {'m/s' if 'speed' in name else 'm'} or None "
                                 f"(none in a spec: the guard off), got {v!r}")
        self.params = p
        self.vision = VisionParams(noise_scale=p.vision_noise_scale, foveated=p.foveated)
        self.delay_steps = round(p.visual_delay_s / p.control_dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        self.reset()

    @property
    def _search(self) -> bool:
        """Whether pedestrians not seen yet are searched for: not with the human field of view
        (``VisionParams.field_shape="human"``: 100 deg to either side), in which a pedestrian appearing
        4-6 m to the side of the path is seen wherever the eye looks ahead (modelling choice: the search
        saccades, 90 deg from side to side, only blinded the eye)."""
        return self.params.search if self.params.search is not None else \
            getattr(self.vision, "field_shape", "cone") != "human"

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> FajenWarrenAgent:
        base = FajenWarrenParams(**env_vision(env_id), **group_prior(env_id))
        known = {f.name for f in fields(FajenWarrenParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown fajen_warren parameter(s) {unknown}; known: {sorted(known)}")
        agent = cls(replace(base, **overrides))
        vision = agent_eye(env_id, overrides)
        if vision is not None:
            # every constant of the env's eye (the human periphery under groups + human_periphery()), as
            # agents.match_vision gives it: the agent models the eye it sees with
            agent.vision = vision
        return agent

    def reset(self) -> None:
        self.filters = [PedestrianFilter() for _ in range(K_SLOTS)]
        self.odo_hist: list[tuple[float, float, float]] = []  # (t, x, y) over the last velocity_window_s
        self.phi = 0.0
        self.phi_dot = 0.0
        self.command = None  # the last (course, speed) commanded by _evade
        self.started = False
        self.poses: list = []
        self.target = None  # ("ped", k) or ("search", side)
        self.target_since = -math.inf
        self.target_chosen = -math.inf  # when the present target was chosen
        self.scanned = {1: -math.inf, -1: -math.inf}
        self.search_turn = {1: -1, -1: -1}  # which of search_azimuths_deg each side looks at
        self.log: list[tuple] = []  # (time, target, phi) per step
        self._in_saccade = False
        self._odo = (0.0, 0.0, 0.0)

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if obs.shape != (DODGE_LAYOUT.size,):
            raise ValueError(f"FajenWarrenAgent expects the flat ObstacleDodge observation of size "
                             f"{DODGE_LAYOUT.size}, got shape {obs.shape}")
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        self.started = True
        return self._act(obs), state

    # ------------------------------------------------------------------------------------------
    def _act(self, obs: np.ndarray) -> np.ndarray:
        p = self.params
        ol = obs.tolist()
        t = ol[_S["time"].start]
        e0, r0, o0, pz = _S["eye_pos"].start, _S["eye_rot"].start, _S["odometry"].start, _S["pelvis"].start
        odo = ol[o0:o0 + 3]
        self.odo_hist.append((t, odo[0], odo[1]))
        while self.odo_hist[-1][0] - self.odo_hist[0][0] > self.params.velocity_window_s + 1e-6:
            self.odo_hist.pop(0)
        pose = (ol[e0:e0 + 3], ol[r0:r0 + 9], odo, ol[pz], t)
        self._in_saccade = ol[_S["saccade"].start] > 0.5
        self.poses.append(pose)
        if len(self.poses) > self.delay_steps + 1:
            self.poses.pop(0)
        seen_pose = self.poses[0] if len(self.poses) > self.delay_steps else pose
        self._perceive(ol, seen_pose)
        for f in self.filters:
            f.predict_to(t, p.accel_std)
            if f.known and p.veer_return_s:
                f.history.append((t, float(f.x[2]), float(f.x[3])))
                if f.history[0][0] < t - 2.0 * p.veer_memory_s - 0.1:
                    f.history.pop(0)
        g0 = _S["to_goal"].start
        c, s = math.cos(odo[2]), math.sin(odo[2])
        goal = (odo[0] + c * ol[g0] - s * ol[g0 + 1], odo[1] + s * ol[g0] + c * ol[g0 + 1])
        self._odo = (odo[0], odo[1], odo[2])
        threats = self._threats(odo)
        self._steer(odo, goal, threats if p.los_hypotheses_evade else self._threats(odo, hypotheses=False))
        v0 = _S["pelvis"].start
        course, speed = self._evade(odo, (ol[v0 + 1], ol[v0 + 2]))
        action = np.zeros(7, dtype=np.float32)
        action[0:2] = DodgeBody.action_from_locomotion(course - odo[2], speed)
        if not p.gaze_blind:
            action[2:7] = self._look(pose, threats, t)
        return action

    def _perceive(self, ol: list, pose) -> None:
        eye_pos, rot, odo, _, t = pose
        c, s = math.cos(odo[2]), math.sin(odo[2])
        seen = [k for k in range(K_SLOTS) if ol[_S[f"pedestrian_{k}"].start] > 0.0]
        # With crowding in the vision model, a sample that may be pooled with another pedestrian's (a
        # neighbour within the critical spacing, on the perceived lines of sight) is fused with the spread
        # of its crowding zone, as iwao and lookahead do (baselines.crowding; modelling choice)
        pooled = {seen[n] for n in crowded([ol[_S[f"pedestrian_{k}"].start + 1:_S[f"pedestrian_{k}"].start + 4]
                                            for k in seen], seen, self.vision)} if self.vision.crowding else set()
        for k in seen:
            b = _S[f"pedestrian_{k}"].start
            pe, ve = ol[b + 1:b + 4], ol[b + 4:b + 7]
            d = math.sqrt(pe[0] ** 2 + pe[1] ** 2 + pe[2] ** 2)
            if d <= 0.0 or (self.params.min_depth_m is not None and pe[0] <= self.params.min_depth_m):
                continue
            ecc = math.acos(max(-1.0, min(1.0, pe[0] / d)))
            lateral_speed = math.sqrt(max(ve[0] ** 2 + ve[1] ** 2 + ve[2] ** 2 - (sum(a * b for a, b in zip(pe, ve)) / d) ** 2, 0.0))
            # Every std is proportional to the *true* distance: under the depth law depth noise can put a
            # sample far nearer than the pedestrian, and its lateral stds taken at the sample's own distance
            # would then be far too small; the larger of the sample's and the estimate's distance is used
            # (as eyecatch's noise point does; modelling choice, only with the periphery).
            d_noise = d
            f = self.filters[k]
            if self.vision.periphery_on and f.known:
                ex_w = odo[0] + c * eye_pos[0] - s * eye_pos[1]
                ey_w = odo[1] + s * eye_pos[0] + c * eye_pos[1]
                d_noise = max(d, math.hypot(f.x[0] - ex_w, f.x[1] - ey_w))
            # vergence: the depth law; control_dt: the positional disarray sized for a stream of looks
            sig = believed_sigmas(d_noise, ecc, lateral_speed / d, self.vision, ol[_FIXATION], self.params.control_dt)
            if k in pooled:
                zone = crowd_std(d, ecc, self.vision)
                sig = (max(sig[0], zone), max(sig[1], zone), max(sig[2], zone)) + tuple(sig[3:])
            los = np.array(_los_rows(pe[0] / d, pe[1] / d, pe[2] / d))
            Re = np.array(rot).reshape(3, 3)  # eye axes in the pelvis frame
            Rw = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ Re @ los  # line-of-sight axes, path frame
            cov_p = Rw @ np.diag(np.maximum(sig[:3], MIN_STD) ** 2) @ Rw.T
            cov_v = Rw @ np.diag(np.maximum(sig[3:], MIN_STD) ** 2) @ Rw.T
            pw = np.array(rot).reshape(3, 3) @ np.array(pe) + np.array(eye_pos)
            vw = np.array(rot).reshape(3, 3) @ np.array(ve)
            z = np.array([odo[0] + c * pw[0] - s * pw[1], odo[1] + s * pw[0] + c * pw[1],
                          c * vw[0] - s * vw[1], s * vw[0] + c * vw[1]])
            R = np.zeros((4, 4))
            R[:2, :2] = cov_p[:2, :2]
            R[2:, 2:] = cov_v[:2, :2]
            self.filters[k].update(t, z, R, self.params.accel_std,
                                   self.params.velocity_prior_std if self.vision.periphery_on else None)
            if self.params.max_speed_m_s is not None:
                self.filters[k].limit_speed(self.params.max_speed_m_s, self.params.velocity_prior_std)

    def _threats(self, odo, hypotheses: bool = True) -> list[tuple]:
        """Per known pedestrian: (slot, closest-approach time, predicted closest distance, its position
        then, whether it is still ahead or approaching); of its most dangerous depth hypothesis unless
        ``hypotheses`` is False (the mean only)."""
        p = self.params
        wx, wy = odo[0], odo[1]
        wvx, wvy = p.speed * math.cos(self.phi), p.speed * math.sin(self.phi)
        out = []
        for k, f in enumerate(self.filters):
            if not f.known:
                continue
            worst = None
            for x, y, vx, vy in (self._hypotheses(f, wx, wy, wvx, wvy) if hypotheses else [tuple(f.x.tolist())]):
                rx, ry, ux, uy = x - wx, y - wy, vx - wvx, vy - wvy
                w2 = ux * ux + uy * uy
                tca = min(max(-(rx * ux + ry * uy) / w2, 0.0), p.horizon_s) if w2 > 1e-9 else 0.0
                dmin = math.hypot(rx + ux * tca, ry + uy * tca)
                relevant = tca > 0.0 or rx > -0.5
                if worst is None or (relevant, -dmin) > (worst[4], -worst[2]):
                    worst = (k, tca, dmin, (x + vx * tca, y + vy * tca), relevant)
            out.append(worst)
        return out

    def _hypotheses(self, f: PedestrianFilter, wx: float, wy: float, wvx: float, wvy: float) -> list:
        """The states (x, y, vx, vy) the agent considers for the pedestrian of ``f``: its mean first, then
        (``los_hypotheses_std``, while the std along the line of sight from the walker exceeds
        ``los_std_min_m``) the mean moved along that line by each multiple of the std, its velocity across
        the line rescaled so that the bearing rate relative to the walker (moving at ``wvx, wvy``) stays
        the estimated one."""
        p = self.params
        x, y, vx, vy = f.x.tolist()
        out = [(x, y, vx, vy)]
        if not p.los_hypotheses_std:
            return out
        rx, ry = x - wx, y - wy
        r = math.hypot(rx, ry)
        if r < 1e-6:
            return out
        ux, uy = rx / r, ry / r
        sd = math.sqrt(max(ux * ux * f.P[0, 0] + 2.0 * ux * uy * f.P[0, 1] + uy * uy * f.P[1, 1], 0.0))
        if sd <= p.los_std_min_m:
            return out
        nx, ny = -uy, ux
        v_along = vx * ux + vy * uy
        rel_across = (vx - wvx) * nx + (vy - wvy) * ny
        w_across = wvx * nx + wvy * ny
        for n in p.los_hypotheses_std:
            r2 = max(r + n * sd, p.los_min_distance_m)
            across = w_across + rel_across * r2 / r
            out.append((wx + ux * r2, wy + uy * r2, v_along * ux + across * nx, v_along * uy + across * ny))
        return out

    def _steer(self, odo, goal, threats) -> None:
        p = self.params
        wx, wy = odo[0], odo[1]
        psi_g = math.atan2(goal[1] - wy, goal[0] - wx)
        d_g = math.hypot(goal[0] - wx, goal[1] - wy)
        acc = -p.b * self.phi_dot - p.k_g * (self.phi - psi_g) * (math.exp(-p.c1 * d_g) + p.c2)
        for _, tca, dmin, (ox, oy), relevant in threats:
            if not relevant or dmin >= p.avoid_distance_m or tca <= 0.0:
                continue
            psi_o = math.atan2(oy - wy, ox - wx)
            d_o = math.hypot(ox - wx, oy - wy)
            diff = self.phi - psi_o
            acc += p.k_o * diff * math.exp(-p.c3 * abs(diff)) * math.exp(-p.c4 * d_o)
        dt = p.control_dt
        self.phi_dot += acc * dt
        self.phi += self.phi_dot * dt
        lim = p.heading_limit_deg * DEG
        if abs(self.phi - odo[2]) > lim:  # the gait's limit: the heading cannot go further
            self.phi = odo[2] + math.copysign(lim, self.phi - odo[2])
            self.phi_dot = 0.0

    def _evade(self, odo, vel_local) -> tuple[float, float]:
        """The course and speed to command: among the candidate courses (the steering dynamics' phi and
        ``evade_courses_deg`` off the path) and ``speeds``, the pair whose predicted closest distance to
        every known pedestrian is largest (capped at ``speed_margin_m``), less ``speed_cost`` per m/s away
        from the nominal speed and ``course_cost`` per rad away from phi. The walker is predicted to keep
        its present velocity for ``speed_latency_s`` (a footstep is latched at mid-stance), then to walk
        at the candidate speed along the candidate course, its sideways speed capped at
        ``lateral_speed_m_s`` (the gait's widest steps); pedestrians keep their estimated velocity. With
        no pedestrian predicted within the margin, phi at the nominal speed wins (zero cost): the
        steering dynamics alone."""
        p = self.params
        known = [f for f in self.filters if f.known]
        if not known:
            self.command = None
            return self.phi, p.speed
        c, s = math.cos(odo[2]), math.sin(odo[2])
        v_now = np.array([c * vel_local[0] - s * vel_local[1], s * vel_local[0] + c * vel_local[1]])
        # The pelvis speed swings with the stride (0.2-2 m/s within a step when the speed changes): the
        # mean over the last ``velocity_window_s`` (from odometry) stands for the velocity of the latency
        # phase once that much odometry is kept (modelling choice)
        if p.velocity_window_s > 0.0 and len(self.odo_hist) > 1 and \
                self.odo_hist[-1][0] - self.odo_hist[0][0] >= p.velocity_window_s - 1e-6:
            (t0, x0, y0), (t1, x1, y1) = self.odo_hist[0], self.odo_hist[-1]
            v_now = np.array([(x1 - x0) / (t1 - t0), (y1 - y0) / (t1 - t0)])
        if p.latency_at_command and self.command is not None:
            # the step under way was latched from the last command (modelling choice)
            lc, ls = self.command
            lvx = ls * math.cos(lc - odo[2])
            lvy = min(max(ls * math.sin(lc - odo[2]), -p.lateral_speed_m_s), p.lateral_speed_m_s)
            v_now = np.array([c * lvx - s * lvy, s * lvx + c * lvy])
        tau = np.arange(0.0, p.horizon_s, 0.1)
        lat = np.minimum(tau, p.speed_latency_s)
        rest = np.maximum(tau - p.speed_latency_s, 0.0)
        base = np.array(odo[:2])[None, :] + lat[:, None] * v_now[None, :]  # (T, 2)
        courses = np.array([self.phi] + [odo[2] + a * DEG for a in p.evade_courses_deg])
        speeds = np.array(p.speeds)
        cc, ss = np.meshgrid(courses, speeds, indexing="ij")  # (C, S)
        cc, ss = cc.ravel(), ss.ravel()
        # velocity along each candidate course, the sideways part (path frame) capped by the gait
        vx, vy = ss * np.cos(cc - odo[2]), ss * np.sin(cc - odo[2])
        vy = np.clip(vy, -p.lateral_speed_m_s, p.lateral_speed_m_s)
        vel = np.stack([c * vx - s * vy, s * vx + c * vy], axis=-1)  # (M, 2)
        walker = base[None, :, :] + rest[None, :, None] * vel[:, None, :]  # (M, T, 2)
        ped = self._predicted_tracks(known, tau)  # (N', T, 2)
        dist = np.linalg.norm(walker[:, None, :, :] - ped[None, :, :, :], axis=-1)  # (M, N, T)
        closest = np.minimum(dist.min(axis=2).min(axis=1), p.speed_margin_m)
        # Costs from the nominal course and speed; while no candidate clears the margin (a threat), from
        # the previous command instead, so that a dodge under way is kept rather than undone when no
        # change can show before the closest approach any more (modelling choice).
        threat = bool(closest.max() < p.speed_margin_m)
        ref_c, ref_s = (self.command if threat and self.command is not None else (self.phi, p.speed))
        dphi = np.abs((cc - ref_c + math.pi) % (2.0 * math.pi) - math.pi)
        score = closest - p.speed_cost * np.abs(ss - ref_s) - p.course_cost * dphi
        best = int(np.argmax(score))
        self.command = (float(cc[best]), float(ss[best]))
        return self.command

    def _predicted_tracks(self, known, tau: np.ndarray) -> np.ndarray:
        """The pedestrians' predicted positions at ``tau`` (N', T, 2): each at its estimated velocity, and
        for one whose velocity changed lately (a veer?) also the ``veer_return_s`` hypotheses."""
        p = self.params
        peds = [f.x for f in known]
        if p.los_hypotheses_std and p.los_hypotheses_evade:  # the depth hypotheses of the pedestrians placed poorly along the line of sight
            wx, wy = self._odo[0], self._odo[1]
            wvx, wvy = p.speed * math.cos(self.phi), p.speed * math.sin(self.phi)
            for f in known:
                peds += [np.array(h) for h in self._hypotheses(f, wx, wy, wvx, wvy)[1:]]
        peds = np.array(peds + [c for c, _ in self._companions()]).reshape(-1, 4)  # (N, 4)
        tracks = [peds[:, None, :2] + tau[None, :, None] * peds[:, None, 2:]]
        if p.veer_return_s and self.poses:
            t = self.poses[-1][4]
            for f in known:
                old = f.velocity_at(t - p.veer_memory_s)
                older = f.velocity_at(t - 2.0 * p.veer_memory_s)
                if old is None:
                    continue
                v = f.x[2:]
                if math.hypot(v[0] - old[0], v[1] - old[1]) <= p.veer_detect_m_s:
                    continue
                if older is not None and f.history[0][0] <= t - 2.0 * p.veer_memory_s + 0.05 \
                        and math.hypot(v[0] - older[0], v[1] - older[1]) <= p.veer_detect_m_s:
                    continue
                for r in p.veer_return_s:
                    a, b = np.minimum(tau, r), np.maximum(tau - r, 0.0)
                    tracks.append((f.x[:2][None, :] + a[:, None] * v[None, :] + b[:, None] * np.array(old)[None, :])[None])
        return np.concatenate(tracks, axis=0)

    def _companions(self) -> list:
        """Assumed companions (``companion_m``): (state x, y, vx, vy; the slot it walks beside) for each
        known pedestrian with no known neighbour within ``1.5 * companion_m``, while any is unseen."""
        d = self.params.companion_m
        known = [(k, f) for k, f in enumerate(self.filters) if f.known]
        if d <= 0.0 or len(known) == len(self.filters):
            return []
        out = []
        for k, f in known:
            x, y, vx, vy = f.x.tolist()
            if any(j != k and math.hypot(g.x[0] - x, g.x[1] - y) < 1.5 * d for j, g in known):
                continue
            v = math.hypot(vx, vy)
            if v < 1e-6:
                continue
            lx, ly = -vy / v, vx / v
            out += [(np.array([x + sgn * d * lx, y + sgn * d * ly, vx, vy]), k) for sgn in (1.0, -1.0)]
        return out

    # --- gaze ---------------------------------------------------------------------------------
    def _choose(self, threats, t: float):
        p = self.params
        if self.target is not None and t - self.target_since < p.min_dwell_s:
            return self.target
        best, best_u = None, -math.inf
        if not self._search:
            best, best_u = ("path", 0), p.path_urgency
        for k, tca, dmin, _, relevant in threats:
            f = self.filters[k]
            if not self._search and (not relevant or not self._ahead(f) or t - f.t_first < p.notice_s):
                continue
            age = min(t - f.t_seen, 3.0)
            w = 1.0 if relevant else 0.1
            urgency = self._threat_urgency(tca, dmin, relevant)
            if urgency:
                w *= 3.0 * urgency
            vel_std = math.sqrt(max(0.5 * (f.P[2, 2] + f.P[3, 3]), 0.0))
            u = age + 0.05 + p.vel_std_weight * vel_std
            if self.vision.periphery_on:  # the position too: depth from far in the periphery is poor
                u += p.pos_std_weight * math.sqrt(max(0.5 * (f.P[0, 0] + f.P[1, 1]), 0.0))
            u *= w
            if u > best_u:
                best, best_u = ("ped", k), u
        unseen = sum(not f.known for f in self.filters)
        if unseen and self._search:
            for side in (1, -1):
                u = p.search_weight * min(t - self.scanned[side], 3.0)
                if u > best_u:
                    best, best_u = ("search", side), u
        if best != self.target:
            self.target, self.target_since = best, t
            self.target_chosen = t
            if best is not None and best[0] == "search":
                self.scanned[best[1]] = t
                self.search_turn[best[1]] += 1
        return self.target

    def _threat_urgency(self, tca: float, dmin: float, relevant: bool) -> float:
        """How urgent a pedestrian on a near collision course is: ``1 + 2 / (1 + t_ca)`` (growing as the
        closest approach, ``tca`` s away, nears) when it is relevant and its predicted closest distance
        ``dmin`` is within ``avoid_distance_m`` + 0.5 m; 0 otherwise (modelling choice)."""
        if relevant and dmin < self.params.avoid_distance_m + 0.5:
            return 1.0 + 2.0 / (1.0 + tca)
        return 0.0

    def _ahead(self, f: PedestrianFilter) -> bool:
        """Whether the estimate of ``f`` lies within ``gaze_bearing_limit_deg`` of the walker's heading."""
        x, y, yaw = self._odo
        bearing = math.atan2(f.x[1] - y, f.x[0] - x) - yaw
        return abs((bearing + math.pi) % (2.0 * math.pi) - math.pi) <= self.params.gaze_bearing_limit_deg * DEG

    def _look(self, pose, threats, t: float) -> list:
        p = self.params
        eye_pos, rot, odo, pelvis_z, _ = pose
        if self._in_saccade and (p.dwell_saccade_s is None or t - self.target_chosen <= p.dwell_saccade_s):
            self.target_since = t  # a fixation's dwell counts from the end of the saccade that brought it
        target = self._choose(threats, t)
        if target is None:
            return [0.0] * 5
        ex, ey = odo[0] + eye_pos[0], odo[1] + eye_pos[1]
        ez = pelvis_z + eye_pos[2]
        if target[0] == "ped":
            x, y = self.filters[target[1]].x[:2].tolist()
            tx, ty, tz = x, y, 1.5
        elif target[0] == "path":
            c, s = math.cos(odo[2]), math.sin(odo[2])
            tx, ty, tz = ex + p.search_distance_m * c, ey + p.search_distance_m * s, ez
        else:
            side = target[1]
            self.scanned[side] = t
            azs = p.search_azimuths_deg or (p.search_azimuth_deg,)
            az = side * azs[self.search_turn[side] % len(azs)] * DEG
            tx, ty, tz = ex + p.search_distance_m * math.cos(az), ey + p.search_distance_m * math.sin(az), ez
        self.log.append((t, target, self.phi))
        return look_action((ex, ey, ez), (tx, ty, tz), odo[2], rot, self.gaze_range, p.head_share,
                           verge=self.vision.depth_pedestal_arcmin is not None)
