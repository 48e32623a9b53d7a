"""The planner's reduced internal model of the catcher and its beliefs, with closed-form derivatives.

Eom et al. plan over the full-body dynamics plus the eye and the beliefs (their state has 43 + 9 N_obj
dimensions; their motions were generated at 1-6 frames per second). Our env already owns a Cartesian hand controller
(damped least squares on the torso + arm Jacobian) and an oculomotor plant, so the planner only needs
what those low levels are driven by:

=========  ======================================  =====================================
index      state ``x``                             control ``u`` (rates)
=========  ======================================  =====================================
0-1        gaze azimuth, elevation (world, rad)    gaze angular velocity (rad/s)
2-3        head yaw, pitch (rad)                   head angular velocity (rad/s)
4-6        hand point (catch site, world, m)       hand velocity (m/s)
7+3j..     compact covariance ``sigma_j`` of       -
           object ``j`` (Eom 4.3), one per object
=========  ======================================  =====================================

The dynamics are integrators for the body and Eom's compact covariance update for the beliefs
(:mod:`.belief`), whose observation noise depends on the gaze: ``B`` is constant and ``A`` couples the
gaze to every ``sigma_j``. Under the deterministic mean update of Eom section 6 the belief means do not
depend on the controls, so they enter as a precomputed, time-varying parameter (the predicted ball
positions at every node) rather than as 6 N_obj more states: iLQR would carry their rows along with
zero deviations and reach the same iterates.

Cost per node (Eom section 6; weights in :class:`PlannerWeights`)::

    c = w_uct  sum_j |sigma_j|^2                                    uncertainty (Eom c_uct)
      + w_eye |u_gaze|^2 + w_head |u_head|^2 + w_hand |u_hand|^2     energy (Eom c_eng)
      + w_trk_head |head|^2 + w_trk_hand |hand - ready|^2             tracking the reference posture (c_trk)
      + w_bnd [ smax^2 bounds of the eye-in-head and neck angles       soft bounds (Eom c_bnd)
                + smax^2(|u_gaze| - B) + smax^2(|u_hand| - V) ]
      + w_tsk(t) |hand - p_arrival|^2                                 the catching task (Eom section 7)

with ``smax(z; gamma) = (sqrt(z^2 + gamma^2) - z) / 2`` (Tassa et al. 2012) applied to the distance to
each bound. Eom use ``smax`` itself (linear beyond the bound); we square it (``Limits.bound_power``):
a linear penalty has no curvature past the bound, so Newton-type steps cannot tell how far to move, and
with one iLQR iteration per control step the planned gaze ran far past the eye's range instead of
turning the head.

The model separates exactly: no cost term and no dynamics couple the hand to the gaze, head and
beliefs. It is therefore solved as two iLQR problems over the same window, :class:`GazeBeliefProblem`
(gaze, head, covariances) and :class:`HandProblem` (hand point). This is the joint iLQR with a step
length chosen per block: with one shared line search the hard, non-convex gaze part (the fovea is
2 deg wide) shrinks the step of the easy, nearly linear-quadratic hand part, which then lags its
target by centimetres. ``w_tsk`` is small in the reactive phase and large in the proactive phase (Eom: 1e-3 and 0.1;
ours keep their ratio of 100). The terminal node has no energy term. ``gaze_cost="distance"`` replaces
the uncertainty term by the sum of squared angular distances from the line of sight to the objects, the
alternative Eom compare against in their Fig. 4.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import solveh_banded

from visuomotor_gym.core.head import neck_range_deg
from visuomotor_gym.oculomotor.plant import OculomotorParams

from .belief import (
    ObservationNoise,
    covariance_step,
    gaze_vector,
    gaze_vector_derivatives,
    observation_variance,
)

DEG = np.pi / 180.0
N_BODY = 7  # gaze (2) + head (2) + hand (3): the body part of the joint state (see the table above)
M = 7


@dataclass(frozen=True)
class PlannerWeights:
    """Cost weights (SI units; see the module docstring). Eom's values are for torques and joint
    angles of a full body, so ours are re-scaled for rates and points; their ratios follow Eom."""

    uct: float = 1.0  # w_uct (Eom 1.0)
    eye: float = 1e-4  # energy of gaze rates ((rad/s)^2): cheap, as eye muscles are
    head: float = 2e-3  # energy of head rates: 20x the eye's, so the eye leads
    hand: float = 2e-3  # energy of hand velocity ((m/s)^2)
    trk_head: float = 0.05  # head toward straight ahead (the reference posture has no gaze)
    trk_hand: float = 0.1  # hand toward its ready point (Eom w_trk = 0.1)
    bnd: float = 1e3  # soft bounds (Eom w_bnd = 0.1 on a linear penalty; ours is squared, in rad and m/s)
    tsk_reactive: float = 0.1  # Eom 1e-3 ...
    tsk_proactive: float = 10.0  # ... and 0.1: the same ratio of 100
    dist: float = 1.0  # gaze_cost="distance": weight of sum_j |g - u_j|^2


@dataclass(frozen=True)
class Limits:
    """Bounds enforced softly by the planner (degrees, m/s)."""

    # One source each: the eye ranges of OculomotorParams (Eom 4.1), the neck joints of the head+eye MJCF.
    eye_azimuth_deg: tuple[float, float] = OculomotorParams().eye_azimuth_range_deg
    eye_elevation_deg: tuple[float, float] = OculomotorParams().eye_elevation_range_deg
    neck_yaw_deg: tuple[float, float] = field(default_factory=lambda: neck_range_deg()[0])
    neck_pitch_deg: tuple[float, float] = field(default_factory=lambda: neck_range_deg()[1])
    eye_speed_deg_s: float = 800.0  # B of Eom 4.1 (peak saccade speed)
    hand_speed_m_s: float = 2.0  # Eyecatch 4.3
    range_margin_deg: float = 4.0  # keep this far inside the eye range (the env clamps at it)
    gamma: float = 0.02  # smax smoothing (rad, m/s)
    bound_power: int = 2  # penalty smax(z)^p (Eom: p = 1)


def smax(z, gamma):
    """Smoothed max(-z, 0) of Eom section 6 and its first two derivatives with respect to z."""
    root = np.sqrt(z * z + gamma * gamma)
    return 0.5 * (root - z), 0.5 * (z / root - 1.0), 0.5 * gamma * gamma / root**3


def bound_penalty(z, gamma, power=2):
    """``smax(z; gamma) ** power`` and its first two derivatives with respect to z."""
    f, d, dd = smax(z, gamma)
    if power == 1:
        return f, d, dd
    return f**power, power * f ** (power - 1) * d, power * (power - 1) * f ** (power - 2) * d * d + power * f ** (power - 1) * dd


def speed_bound(V, vmax, gamma, power=2):
    """``smax(vmax - |v|)^p`` with a smoothed |v|: cost (...), gradient (..., k), Hessian (..., k, k)."""
    sp = np.sqrt(np.sum(V * V, axis=-1) + 1e-6)
    f, d, dd = bound_penalty(vmax - sp, gamma, power)
    unit = V / sp[..., None]
    grad = -d[..., None] * unit
    k = V.shape[-1]
    outer = unit[..., :, None] * unit[..., None, :]
    hess = dd[..., None, None] * outer - d[..., None, None] * (np.eye(k) - outer) / sp[..., None, None]
    return f, grad, hess


class GazeBeliefProblem:
    """Gaze, head and the compact covariances over one window (iLQR problem API, see :mod:`.ilqr`).

    State ``[gaze az, el, head yaw, pitch, sigma_0 (3), sigma_1 (3), ...]``, control ``[gaze rates (2),
    head rates (2)]``. Set the per-window data with :meth:`configure`.
    """

    def __init__(self, n_objects: int, N: int, h: float, noise: ObservationNoise, q: float,
                 weights: PlannerWeights = PlannerWeights(), limits: Limits = Limits(),
                 gaze_cost: str = "uncertainty"):
        if gaze_cost not in ("uncertainty", "distance"):
            raise ValueError(f"gaze_cost must be 'uncertainty' or 'distance', got {gaze_cost!r}")
        self.nb = int(n_objects)
        self.N = int(N)
        self.n = 4 + 3 * self.nb
        self.m = 4
        self.h = float(h)
        self.noise = noise
        self.q = float(q)
        self.w = weights
        self.lim = limits
        self.gaze_cost = gaze_cost
        self.B = np.zeros((self.N, self.n, self.m))
        self.B[:, :4, :] = self.h * np.eye(4)
        w = weights
        self.u_weight = np.array([w.eye, w.eye, w.head, w.head])
        margin = limits.range_margin_deg * DEG
        self.lo = np.concatenate([np.array([limits.eye_azimuth_deg[0], limits.eye_elevation_deg[0]]) * DEG + margin,
                                  np.array([limits.neck_yaw_deg[0], limits.neck_pitch_deg[0]]) * DEG])
        self.hi = np.concatenate([np.array([limits.eye_azimuth_deg[1], limits.eye_elevation_deg[1]]) * DEG - margin,
                                  np.array([limits.neck_yaw_deg[1], limits.neck_pitch_deg[1]]) * DEG])
        self.eye_vmax = limits.eye_speed_deg_s * DEG
        self.configure(eye=np.zeros(3), eih_offset=np.zeros(2), ball_pos=np.zeros((self.N + 1, self.nb, 3)),
                       active=np.zeros(self.nb, bool))

    def configure(self, *, eye, eih_offset, ball_pos, active, uct_weight=None):
        """Per-window data: ``eye`` (3) eye position (held over the window); ``eih_offset`` (2):
        eye-in-head = gaze - head - offset (the torso's share, held); ``ball_pos`` (N+1, nb, 3): the
        predicted belief means at the nodes; ``active`` (nb,): objects in the cost (the others'
        covariances are frozen); ``uct_weight`` (nb,): optional factor per object on the uncertainty."""
        self.eye = np.asarray(eye, dtype=float)
        self.eih_offset = np.asarray(eih_offset, dtype=float)
        self.ball_pos = np.asarray(ball_pos, dtype=float)
        self.active = np.asarray(active, dtype=bool)
        factor = np.ones(self.nb) if uct_weight is None else np.asarray(uct_weight, dtype=float)
        uct = self.w.uct if self.gaze_cost == "uncertainty" else 0.0
        self.uct_vec = np.repeat(np.where(self.active, factor, 0.0) * uct, 3)  # per sigma component
        rel = self.ball_pos - self.eye
        d2 = np.maximum(np.sum(rel * rel, axis=-1), 1e-12)
        self.ball_dir = rel / np.sqrt(d2)[..., None]  # (N+1, nb, 3)
        self.dist_obj = np.where(self.active, self.w.dist if self.gaze_cost == "distance" else 0.0, 0.0)
        # Hot-path constants of step(): r = k2 d^2 (1 + theta / E2)^2 + floor per node and object.
        self._ux, self._uy, self._uz = (np.ascontiguousarray(self.ball_dir[..., c]) for c in range(3))
        self._kd2 = self.noise.k2 * (np.ones_like(d2) if self.noise.angular else d2)
        self._all_active = bool(np.all(self.active))
        # Retinal slip (belief.py): the objects' angular velocity over each interval (azimuth and
        # elevation rates, rad/s) against the gaze rate u; the azimuth difference is weighted by cos^2 of
        # the elevation at the observed node (arc length on the sphere).
        self._slip_coef = self.noise.slip_coef
        az = np.arctan2(self.ball_dir[..., 1], self.ball_dir[..., 0])
        el = np.arcsin(np.clip(self.ball_dir[..., 2], -1.0, 1.0))
        self._w_az = ((np.diff(az, axis=0) + np.pi) % (2.0 * np.pi) - np.pi) / self.h  # (N, nb)
        self._w_el = np.diff(el, axis=0) / self.h
        self._c2 = np.cos(el[1:]) ** 2

    def slip2(self, U: np.ndarray, i=slice(None)) -> np.ndarray:
        """Squared retinal slip (rad/s)^2 of every object over interval(s) ``i`` for gaze rates ``U``
        (..., m): ``cos^2(el) (u_az - w_az)^2 + (u_el - w_el)^2`` -> (..., nb)."""
        da = U[..., 0:1] - self._w_az[i]
        de = U[..., 1:2] - self._w_el[i]
        return self._c2[i] * da * da + de * de

    # --- dynamics -----------------------------------------------------------------------------
    def step(self, x: np.ndarray, u: np.ndarray, i: int) -> np.ndarray:
        """Batched dynamics (B, n), (B, m) -> (B, n). The object is observed at its predicted position
        at the next node with the current gaze (Eom: R_j from the current eye pose)."""
        xn = np.empty_like(x)
        h, q, nz = self.h, self.q, self.noise
        xn[:, :4] = x[:, :4] + h * u
        az, el = x[:, 0:1], x[:, 1:2]
        ce = np.cos(el)
        j = i + 1
        # observation_variance() inlined (this is the innermost loop of every rollout)
        gu = ce * np.cos(az) * self._ux[j] + ce * np.sin(az) * self._uy[j] + np.sin(el) * self._uz[j]
        amp = 1.0 + np.sqrt(np.maximum(2.0 - 2.0 * gu, 0.0) + nz.eps_rad**2) / nz.e2_rad
        if self._slip_coef:
            r = self._kd2[j] * amp * amp * (1.0 + self._slip_coef * self.slip2(u, i)) + nz.floor_m2  # (B, nb)
        else:
            r = self._kd2[j] * amp * amp + nz.floor_m2
        sp, sv, spv = x[:, 4::3], x[:, 5::3], x[:, 6::3]
        a = sp + 2.0 * h * spv + h * h * sv + q
        b = spv + h * sv
        inv_s = 1.0 / (a + r)
        xn[:, 4::3] = a * r * inv_s
        xn[:, 5::3] = sv + q - b * b * inv_s
        xn[:, 6::3] = b * r * inv_s
        if not self._all_active:
            keep = np.repeat(~self.active, 3)
            xn[:, 4:][:, keep] = x[:, 4:][:, keep]
        return xn

    def dynamics_jacobians(self, X: np.ndarray, U: np.ndarray):
        """A (N, n, n) and B (N, n, m) along one trajectory, in closed form."""
        N, nb = self.N, self.nb
        A = np.zeros((N, self.n, self.n))
        A[:, [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
        slip2 = self.slip2(U[:N]) if self._slip_coef else None
        out = observation_variance(self.noise, X[:N, 0][:, None], X[:N, 1][:, None], self.ball_pos[1:],
                                   self.eye, with_grad=True, slip2=slip2)
        r, dr_dg = out[0], out[1]
        _, dsig, dr = covariance_step(X[:N, 4:].reshape(N, nb, 3), r, self.h, self.q, with_grad=True)
        B = self.B
        if slip2 is not None:  # the gaze rate changes the slip, so B depends on the trajectory
            B = self.B.copy()
            dr_ds = out[3]  # dr/dslip2 (N, nb)
            dr_du = np.stack([dr_ds * 2.0 * self._c2 * (U[:N, 0:1] - self._w_az),
                              dr_ds * 2.0 * (U[:N, 1:2] - self._w_el)], axis=-1)  # (N, nb, 2)
        for j in range(nb):
            s = slice(4 + 3 * j, 7 + 3 * j)
            if self.active[j]:
                A[:, s, s] = dsig[:, j]
                A[:, s, 0:2] = dr[:, j, :, None] * dr_dg[:, j, None, :]
                if slip2 is not None:
                    B[:, s, 0:2] = dr[:, j, :, None] * dr_du[:, j, None, :]
            else:
                A[:, s, s] = np.eye(3)
        return A, B

    # --- cost ---------------------------------------------------------------------------------
    def _bounds(self, X):
        """Soft bounds on (eye-in-head az, el, neck yaw, pitch): cost (...), gradient and Hessian
        with respect to those four coordinates (..., 4)."""
        vals = np.concatenate([X[..., 0:2] - X[..., 2:4] - self.eih_offset, X[..., 2:4]], axis=-1)
        p = self.lim.bound_power
        f_hi, d_hi, dd_hi = bound_penalty(self.hi - vals, self.lim.gamma, p)
        f_lo, d_lo, dd_lo = bound_penalty(vals - self.lo, self.lim.gamma, p)
        return np.sum(f_hi + f_lo, axis=-1), d_lo - d_hi, dd_hi + dd_lo

    def cost(self, X: np.ndarray, U: np.ndarray) -> np.ndarray:
        """Total cost of batched trajectories X (B, N+1, n), U (B, N, m) -> (B,)."""
        w = self.w
        sig = X[..., 4:]
        c = np.sum(self.uct_vec * sig * sig, axis=(-1, -2))
        c += np.sum(self.u_weight * U * U, axis=(-1, -2))
        c += w.trk_head * np.sum(X[..., 2:4] ** 2, axis=(-1, -2))
        c += w.bnd * np.sum(self._bounds(X)[0], axis=-1)
        c += w.bnd * np.sum(speed_bound(U[..., 0:2], self.eye_vmax, self.lim.gamma, self.lim.bound_power)[0], axis=-1)
        if np.any(self.dist_obj):
            diff = gaze_vector(X[..., 0], X[..., 1])[..., None, :] - self.ball_dir
            c += np.sum(self.dist_obj * np.sum(diff * diff, axis=-1), axis=(-1, -2))
        return c

    def cost_derivatives(self, X: np.ndarray, U: np.ndarray):
        """lx, lu, lxx, luu, lux (exact, except the Gauss-Newton Hessian of the distance term)."""
        w = self.w
        N, n, m = self.N, self.n, self.m
        lx = np.zeros((N + 1, n))
        lxx = np.zeros((N + 1, n, n))
        lx[:, 4:] = 2.0 * self.uct_vec * X[:, 4:]
        di = np.arange(4, n)
        lxx[:, di, di] = 2.0 * self.uct_vec
        lx[:, 2:4] = 2.0 * w.trk_head * X[:, 2:4]
        lxx[:, [2, 3], [2, 3]] = 2.0 * w.trk_head
        # eye-in-head = gaze - head - offset couples gaze k and head k.
        _, g, hs = self._bounds(X)
        g, hs = w.bnd * g, w.bnd * hs
        for k in range(2):
            lx[:, k] += g[:, k]
            lx[:, 2 + k] += g[:, 2 + k] - g[:, k]
            lxx[:, k, k] += hs[:, k]
            lxx[:, 2 + k, 2 + k] += hs[:, k] + hs[:, 2 + k]
            lxx[:, k, 2 + k] -= hs[:, k]
            lxx[:, 2 + k, k] -= hs[:, k]
        if np.any(self.dist_obj):
            gv, g_az, g_el = gaze_vector_derivatives(X[:, 0], X[:, 1])
            diff = gv[:, None, :] - self.ball_dir
            wd = self.dist_obj
            lx[:, 0] += 2.0 * np.sum(wd * np.sum(diff * g_az[:, None, :], axis=-1), axis=-1)
            lx[:, 1] += 2.0 * np.sum(wd * np.sum(diff * g_el[:, None, :], axis=-1), axis=-1)
            s = 2.0 * np.sum(wd)
            lxx[:, 0, 0] += s * np.sum(g_az * g_az, axis=-1)
            lxx[:, 1, 1] += s * np.sum(g_el * g_el, axis=-1)
            cross = s * np.sum(g_az * g_el, axis=-1)
            lxx[:, 0, 1] += cross
            lxx[:, 1, 0] += cross
        lu = 2.0 * self.u_weight * U
        luu = np.zeros((N, m, m))
        luu[:, np.arange(m), np.arange(m)] = 2.0 * self.u_weight
        _, ge, he = speed_bound(U[:, 0:2], self.eye_vmax, self.lim.gamma, self.lim.bound_power)
        lu[:, 0:2] += w.bnd * ge
        luu[:, 0:2, 0:2] += w.bnd * he
        return lx, lu, lxx, luu, np.zeros((N, m, n))


class HandProblem:
    """The hand point over one window: ``x`` = catch-site position (world), ``u`` = its velocity.

    Cost: energy, tracking of the ready point, the catching task ``w_tsk(t) |hand - p_arrival|^2`` and a
    soft speed bound. Linear dynamics and a convex cost: iLQR converges in one or two iterations.
    """

    def __init__(self, N: int, h: float, weights: PlannerWeights = PlannerWeights(), limits: Limits = Limits()):
        self.N, self.n, self.m = int(N), 3, 3
        self.h = float(h)
        self.w = weights
        self.lim = limits
        self.A = np.broadcast_to(np.eye(3), (self.N, 3, 3))
        self.B = np.broadcast_to(self.h * np.eye(3), (self.N, 3, 3))
        self.configure(ready=np.zeros(3), target=np.zeros(3), w_task=np.zeros(self.N + 1))

    def configure(self, *, ready, target, w_task):
        """``ready`` (3): hand reference; ``target`` (3): task point; ``w_task`` (N+1): weight per node."""
        self.ready = np.asarray(ready, dtype=float)
        self.target = np.asarray(target, dtype=float)
        self.w_task = np.asarray(w_task, dtype=float)

    def solve_lq(self, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The exact optimum without the speed bound (what one iLQR iteration converges to).

        The cost is quadratic in the positions ``x_1..x_N`` once ``u_k = (x_{k+1} - x_k) / h``, with the
        same weights on the three axes, so its normal equations are one symmetric tridiagonal system
        with three right-hand sides: O(N) instead of a Riccati sweep over 3x3 blocks.
        """
        w, N, h = self.w, self.N, self.h
        alpha = w.hand / (h * h)
        wk = w.trk_hand + self.w_task[1:]  # nodes 1..N
        diag = wk + 2.0 * alpha
        diag[-1] -= alpha
        rhs = w.trk_hand * self.ready + self.w_task[1:, None] * self.target
        rhs[0] += alpha * x0
        ab = np.empty((2, N))
        ab[0, 0] = 0.0
        ab[0, 1:] = -alpha
        ab[1] = diag
        X = np.empty((N + 1, 3))
        X[0] = x0
        X[1:] = solveh_banded(ab, rhs, check_finite=False)
        return X, np.diff(X, axis=0) / h

    def step(self, x, u, i):
        return x + self.h * u

    def dynamics_jacobians(self, X, U):
        return self.A, self.B

    def cost(self, X, U):
        w = self.w
        c = w.hand * np.sum(U * U, axis=(-1, -2))
        c += w.trk_hand * np.sum((X - self.ready) ** 2, axis=(-1, -2))
        c += np.sum(self.w_task * np.sum((X - self.target) ** 2, axis=-1), axis=-1)
        c += w.bnd * np.sum(speed_bound(U, self.lim.hand_speed_m_s, self.lim.gamma, self.lim.bound_power)[0], axis=-1)
        return c

    def cost_derivatives(self, X, U):
        w = self.w
        N = self.N
        lx = 2.0 * w.trk_hand * (X - self.ready) + 2.0 * self.w_task[:, None] * (X - self.target)
        lxx = (2.0 * (w.trk_hand + self.w_task))[:, None, None] * np.eye(3)
        _, g, hs = speed_bound(U, self.lim.hand_speed_m_s, self.lim.gamma, self.lim.bound_power)
        lu = 2.0 * w.hand * U + w.bnd * g
        luu = 2.0 * w.hand * np.eye(3) + w.bnd * hs
        return lx, lu, lxx, luu, np.zeros((N, 3, 3))
