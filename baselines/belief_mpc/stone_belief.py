"""Eom's belief MDP for static footholds, and the receding-horizon choice of where to look (SteppingStones).

**Belief per stone** (Eom et al. 2019 section 4.3, Appendix A). A stone is a static object, so its
process model is Eom Eq. 2 with the velocity known to be zero: ``F = I`` on the position,
``y = 0``, ``Q = q I`` (``q`` the process noise per control step, Eom's alpha). The eye observes the
position (Eom Eq. 1, ``H = I``) with an isotropic noise ``R = r I`` whose ``r`` depends on where the
eye looks (below). The compact covariance of Eom section 4.3, ``sigma = (sp, sv, spv)``, then keeps
``sv = spv = 0`` and Eom Eq. 4 (Appendix A with ``h = 0``) is the scalar Kalman step::

    a = sp + q,     sp' = a r / (a + r)   (seen),     sp' = a   (not seen: prediction only)

(:func:`static_sigma_step`; it is :func:`.belief.covariance_step` with ``h = 0`` and ``sv = spv = 0``,
tested). In information form ``1 / sp' = 1 / a + 1 / r``, so ``n`` samples in one planning node add
``n / r``. The *mean* of the real update is the lookahead agent's plane fusion of every percept
(:class:`baselines.lookahead.perception.StoneMemory`: Eom Eq. 3 with the real ``z`` for a static object,
weighted with the env's anisotropic covariance), as the catch agent keeps the Eyecatch filter's mean
beside Eom's compact covariance (:mod:`.tracker`).

**Observation noise r: the environment's foveated model, on the stones' plane.** A stone's percept is
its top's centre; the agent follows its direction down to the stones' plane (lookahead's
``StoneMemory``), so what matters is the *lateral* noise of the env (Eyecatch Eq. 1-3,
:func:`visuomotor_gym.vision.foveation._sigmas`): ``s = d s_q max(1, slip / knee) / alpha(theta)``
(``s_q`` = 1 arcmin x noise scale, ``alpha = E2 / (E2 + theta)``, knee 2.5 deg/s). On the plane it is
``s`` across the line of sight and ``s / sin(depression)`` along it; Eom's isotropic ``R = r I`` keeps
the mean of the two variances, ``r = s^2 (1 + 1 / sin^2(dep)) / 2``, plus ``belief.ObservationNoise``'s
1 mm^2 floor. ``theta`` is smoothed (``sqrt(theta^2 + eps^2)``, eps = 0.2 deg, as ``belief.py``);
nothing is seen beyond the field of view (20 deg in the walk family) -- ``r = inf``. ``slip`` is the
image speed on the retina, that of the stone's direction minus that of the fixated stone's (the eye
pursues the fixated stone while the body walks).

**The gaze plan** (Eom section 6: minimise the cost over a receding window). The planner's control is
*which stone the line of sight rests on* in each node of the window (``h`` = 0.1 s, ``N`` nodes):
piecewise-constant fixation schedules with up to two switches, the switches at least the plant's
200 ms saccade refractory period apart (Young & Stark 1963), every such schedule evaluated in one
vectorised rollout (exhaustive search; the catch agent's initial-guess search made exhaustive, because
the cost is far from convex in gaze -- the fovea is 2 deg wide, the stones 10-20 deg apart -- and a
gaze between two stones sees both at an eccentricity whose noise is >100 times the fovea's). A switch
costs the saccade's duration of blindness (the plant's main sequence, ``0.021 + 0.0022 A`` s, with
saccadic suppression) in its node. The cost is Eom's (section 6, with their section 7 stepping-stone
task term)::

    J = sum_k sum_j w_uct sp_j(k)^2  +  sum_j w_tsk E|p_foot_j - p_j|^2 at the foothold's commitment

``E|p_foot - p|^2 = |p_foot - mu|^2 + 2 sp`` (2-D, isotropic); the footstep is put on the belief mean
(``p_foot = mu`` up to the lateral nudges of the footstep planner), so the gaze-dependent part of the
task term is ``2 w_tsk sp_j`` at the moment foothold ``j`` is committed -- in our gait the footstep is
read at the previous mid-stance and cannot change afterwards, so the foothold's uncertainty *at the
landing* is the one at that read. ``w_uct`` = 1 and ``w_tsk`` = 10: Eom section 7 (their stepping-stone
``w_tsk``). The uncertainty term runs over the tracked stones (at most 4, Eom section 7: "at most four
objects can be tracked", the observation's 4 slots) that are still to be committed; a stone whose
foothold is committed changes no decision and leaves the cost.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from visuomotor_gym.vision.foveation import ARCMIN, DEG, VisionParams

from .field import field_limit, position_e2_rad

FLOOR_M2 = 1e-6  # belief.ObservationNoise.floor_m2: 1 mm std (as the Eyecatch filter's measurement floor)


def static_sigma_step(sp, r, q: float):
    """Eom Eq. 4 for a static object (``F = I``, ``H = I``, ``R = r I``, ``Q = q I``): ``sp'``.

    ``r = inf``: nothing seen (prediction only). Broadcasts."""
    a = np.asarray(sp, dtype=float) + q
    info = 1.0 / np.asarray(r, dtype=float)  # 0 for inf
    return a / (1.0 + a * info)


def plane_variance(distance, eccentricity, slip, depression_sin, vision: VisionParams, eps_rad: float = 0.2 * DEG,
                   limit=None):
    """Isotropic ``r`` (m^2) of one sample of a point on the stones' plane (module docstring); broadcasts.

    ``distance`` (m), ``eccentricity`` (rad), ``slip`` (rad/s), ``depression_sin`` the sine of the
    line of sight's depression. ``inf`` beyond the field of view (foveated vision only): the
    eccentricity ``limit`` (rad, broadcast; ``field.field_limit``), by default the cone's
    ``field_of_view_deg``. The lateral std grows with the position law's E2 when the env's vision has
    one (``field.position_e2_rad``), else the acuity law's."""
    d = np.asarray(distance, dtype=float)
    th = np.asarray(eccentricity, dtype=float)
    sq = vision.noise_scale * vision.retinal_position_std_arcmin * ARCMIN
    if vision.foveated:
        knee = vision.position_slip_knee_deg_s * DEG
        slip_f = np.maximum(1.0, np.abs(slip) / knee) if math.isfinite(knee) else 1.0
        amp = 1.0 + np.sqrt(th * th + eps_rad * eps_rad) / position_e2_rad(vision)
    else:
        slip_f, amp = 1.0, 1.0
    s = d * sq * slip_f * amp
    dep = np.maximum(np.asarray(depression_sin, dtype=float), 0.02)  # lookahead's MIN_DEPRESSION
    r = 0.5 * s * s * (1.0 + 1.0 / (dep * dep)) + FLOOR_M2
    if vision.foveated and getattr(vision, "crowding", False):
        # With crowding every sample beyond the crowding-free fovea may be pooled with a flanker the
        # observation does not report: its std is at least half the critical spacing at its distance
        # (baselines.crowding.crowd_std; the lookahead agent's distrust_periphery), on the plane as above.
        c = 0.5 * vision.crowding_bouma * th * d
        r = np.where(th > vision.crowding_fovea_deg * DEG, np.maximum(r, 0.5 * c * c * (1.0 + 1.0 / (dep * dep))), r)
    if vision.foveated:
        r = np.where(th <= (vision.field_of_view_deg * DEG if limit is None else limit), r, np.inf)
    shape = np.broadcast_shapes(d.shape, th.shape, np.shape(slip), np.shape(depression_sin))
    return np.broadcast_to(r, shape).copy() if np.shape(r) != shape else r


@dataclass(frozen=True)
class ScheduleSet:
    """Every fixation schedule of one planning problem: ``targets`` (C, N) the stone (index into the
    candidate list) fixated in each node, ``switch`` (C, N) whether a saccade starts in that node; and
    the flat indices the vectorised rollout gathers with (``rows`` (N, C): node k's row ``k m + target``
    of an (N m, J) table; the switches' node, schedule, previous and new stone)."""

    targets: np.ndarray
    switch: np.ndarray
    rows: np.ndarray
    sw_node: np.ndarray
    sw_sched: np.ndarray
    sw_prev: np.ndarray
    sw_new: np.ndarray


@functools.lru_cache(maxsize=256)
def schedules(m: int, n: int, current: int, earliest: int, gap: int, max_switches: int = 2) -> ScheduleSet:
    """Piecewise-constant schedules over ``n`` nodes among ``m`` stones with at most ``max_switches``
    switches after the first node, switches ``>= gap`` nodes apart. ``current`` (-1: none) is the
    stone fixated now: starting on another one is a switch in node 0, allowed only when ``earliest``
    (the first node at which the plant can start a saccade) is 0 or nothing is fixated."""
    rows, sw = [], []

    def extend(seq, flags, last_switch, switches_left):
        rows.append(list(seq) + [seq[-1]] * (n - len(seq)))
        sw.append(list(flags) + [False] * (n - len(flags)))
        if switches_left == 0:
            return
        start = max(len(seq), earliest, last_switch + gap)
        for k in range(start, n):
            for b in range(m):
                if b == seq[-1]:
                    continue
                extend(list(seq) + [seq[-1]] * (k - len(seq)) + [b],
                       list(flags) + [False] * (k - len(flags)) + [True], k, switches_left - 1)

    for a in range(m):
        first_switch = a != current
        if first_switch and current >= 0 and earliest > 0:
            continue
        extend([a], [first_switch], 0 if first_switch else -gap, max_switches)
    T = np.array(rows, dtype=np.int64)
    SW = np.array(sw, dtype=bool)
    prev = np.empty_like(T)
    prev[:, 1:] = T[:, :-1]
    prev[:, 0] = current
    c_idx, k_idx = np.nonzero(SW)
    flat = (np.arange(n)[:, None] * m + T.T).copy()  # (N, C)
    for a in (T, SW, flat, c_idx, k_idx):
        a.setflags(write=False)
    return ScheduleSet(T, SW, flat, k_idx, c_idx, prev[c_idx, k_idx], T[c_idx, k_idx])


def saccade_duration_s(amplitude_rad):
    """The plant's main sequence (``oculomotor.plant``; as ``BeliefMPCAgent._gaze_request``)."""
    a = np.asarray(amplitude_rad) / DEG
    return np.maximum(0.021 + 0.0022 * a, 1.875 * a / 800.0)


@dataclass
class GazePlan:
    targets: np.ndarray  # (N,) fixated candidate per node
    cost: float
    costs: np.ndarray  # cost of every schedule
    schedule_set: ScheduleSet
    sp: np.ndarray  # (N+1, M) planned compact covariance along the chosen schedule


def plan_gaze(stones_xy: np.ndarray, sp0: np.ndarray, eye0: np.ndarray, eye_vel: np.ndarray, gaze0: np.ndarray,
              commit_s: np.ndarray, current: int, earliest_s: float, vision: VisionParams, *, h: float, n: int,
              dt: float, q_node: float, w_uct: float, w_tsk: float, plane_z: float, refractory_s: float,
              max_switches: int = 2) -> GazePlan:
    """Choose the fixation schedule that minimises Eom's cost (module docstring).

    ``stones_xy`` (M, 2) believed centres of the candidate stones (the tracked ones still to be committed),
    ``sp0`` (M,) their compact covariance now, ``eye0`` (3,) and ``eye_vel`` (3,) the eye's position and
    velocity (path frame; the eye is extrapolated along it), ``gaze0`` (3,) the unit line of sight now,
    ``commit_s`` (M,) seconds until each stone's foothold is committed (inf: beyond the window),
    ``current`` the candidate fixated now (-1: none), ``earliest_s`` the time until the plant can start a
    saccade. ``q_node`` is the process noise per node, ``dt`` the control period (one sample per step).
    """
    m = len(stones_xy)
    tk = (np.arange(n) + 0.5) * h  # node midpoints
    eye = eye0[None, :] + tk[:, None] * eye_vel[None, :]  # (N, 3)
    P = np.concatenate([stones_xy, np.full((m, 1), plane_z)], axis=1)  # (M, 3)
    rel = P[None, :, :] - eye[:, None, :]  # (N, M, 3)
    d = np.linalg.norm(rel, axis=2)
    u = rel / d[..., None]
    # d u / dt for a still point seen from an eye moving at v: -(v - (v.u) u) / d
    vu = np.einsum("nmi,i->nm", u, eye_vel)
    du = -(eye_vel[None, None, :] - vu[..., None] * u) / d[..., None]
    cosang = np.clip(np.einsum("nfi,nji->nfj", u, u), -1.0, 1.0)  # (N, F, J)
    theta = np.arccos(cosang)
    slip = np.linalg.norm(du[:, None, :, :] - du[:, :, None, :], axis=3)  # (N, F, J)
    dep = -u[..., 2]
    # the field around each fixated candidate f, in the direction of each j (the cone: a scalar)
    limit = field_limit(u[:, :, None, :], u[:, None, :, :], vision) if vision.foveated else None
    r = plane_variance(d[:, None, :], theta, slip, dep[:, None, :], vision, limit=limit)  # (N, F, J)
    # saccade blindness in a switch node: the amplitude from the previous stone (theta) or the gaze now
    amp_0 = np.arccos(np.clip(u[0] @ gaze0, -1.0, 1.0))  # (M,) from the gaze now
    per_node = max(1, int(round(h / dt)))

    earliest = int(math.ceil(max(earliest_s, 0.0) / h - 1e-9))
    gap = max(1, int(math.ceil(refractory_s / h - 1e-9)))
    S = schedules(m, n, current, earliest, gap, max_switches)
    C = S.targets.shape[0]
    # samples per node: all of them, less the saccade's blindness in a switch node
    samples = np.full((n, C), float(per_node))
    if S.sw_node.size:
        k, prev, new = S.sw_node, S.sw_prev, S.sw_new
        amp = np.where(prev >= 0, theta[k, np.maximum(prev, 0), new], amp_0[new])
        blind = np.ceil(saccade_duration_s(amp) / dt - 1e-9)
        samples[k, S.sw_sched] = np.maximum(per_node - blind, 0.0)
    inv_r = (1.0 / r).reshape(n * m, m)  # 0 where not seen
    info = np.take(inv_r, S.rows, axis=0)  # (N, C, J)
    info *= samples[..., None]

    # nodes whose samples count before each commitment (a node that has begun counts: 0.1 s resolution)
    commit_node = np.where(np.isfinite(commit_s), np.ceil(np.asarray(commit_s) / h - 1e-9), np.inf)
    sp = np.empty((C, m))
    sp[:] = np.asarray(sp0, dtype=float)
    cost = np.zeros(C)
    tmp = np.empty((C, m))
    for k in range(n):
        live = np.where(commit_node > k, w_uct, 0.0)  # stones still to be committed during node k
        sp += q_node
        np.multiply(sp, info[k], out=tmp)
        tmp += 1.0
        sp /= tmp
        cost += (sp * sp) @ live
        at = commit_node == k + 1
        if at.any():
            cost += sp @ np.where(at, 2.0 * w_tsk, 0.0)
    best = int(np.argmin(cost))
    # the chosen schedule's covariance, for the log
    traj = np.empty((n + 1, m))
    s = np.asarray(sp0, dtype=float).copy()
    traj[0] = s
    for k in range(n):
        s = (s + q_node) / (1.0 + (s + q_node) * info[k, best])
        traj[k + 1] = s
    return GazePlan(targets=S.targets[best], cost=float(cost[best]), costs=cost, schedule_set=S, sp=traj)


__all__ = ["GazePlan", "ScheduleSet", "plan_gaze", "plane_variance", "saccade_duration_s", "schedules",
           "static_sigma_step"]
