"""A small iterative LQR solver (Gauss-Newton DDP), written for receding-horizon use in real time.

Eom et al. (TOG 2019, section 6) solve their belief MDP with DDP over a short window. We use iLQR, the
Gauss-Newton variant of DDP (Li & Todorov 2004; Tassa, Erez & Todorov 2012): the backward pass drops the
second derivatives of the dynamics, which keeps every ``Q_uu`` positive definite for convex costs and
costs a fraction of full DDP. Everything else is DDP as Eom use it: a quadratic model of the cost-to-go
propagated backward, a feedback policy ``u = u_bar + a k + K (x - x_bar)``, a forward rollout with a line
search, Levenberg-Marquardt regularisation of ``Q_uu``, and warm starts from the previous window.

The problem is any object with

* ``n``, ``m``, ``N`` (state size, control size, number of control steps),
* ``step(x, u, i) -> x'`` for a *batch* of states ``x`` (B, n) and controls ``u`` (B, m) at step ``i``,
* ``cost(X, U) -> (B,)`` for batched trajectories ``X`` (B, N+1, n), ``U`` (B, N, m),
* ``dynamics_jacobians(X, U) -> (A (N, n, n), B (N, n, m))`` along one trajectory,
* ``cost_derivatives(X, U) -> (lx (N+1, n), lu (N, m), lxx (N+1, n, n), luu (N, m, m), lux (N, m, n))``,
  where row ``N`` of ``lx`` / ``lxx`` is the terminal cost.

The line search rolls out every step length at once as one batch, so its Python cost is one rollout.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

LINE_SEARCH = np.array([1.0, 0.5, 0.25, 0.1, 0.025])


@dataclass
class ILQRResult:
    X: np.ndarray  # (N+1, n) state trajectory
    U: np.ndarray  # (N, m) controls
    K: np.ndarray  # (N, m, n) feedback gains
    k: np.ndarray  # (N, m) feed-forward terms of the last backward pass
    cost: float
    iterations: int
    accepted: int  # iterations whose step was accepted
    reg: float  # regularisation at exit (warm-start it too)


def rollout(problem, x0: np.ndarray, U: np.ndarray) -> np.ndarray:
    """Open-loop rollout of one control sequence; (N+1, n)."""
    X = np.empty((problem.N + 1, problem.n))
    X[0] = x0
    x = x0[None, :]
    for i in range(problem.N):
        x = problem.step(x, U[i][None, :], i)
        X[i + 1] = x[0]
    return X


def rollout_batch(problem, x0: np.ndarray, U: np.ndarray) -> np.ndarray:
    """Open-loop rollouts of a batch of control sequences ``U`` (B, N, m) from one ``x0``; (B, N+1, n)."""
    nb = U.shape[0]
    X = np.empty((nb, problem.N + 1, problem.n))
    x = np.broadcast_to(x0, (nb, problem.n)).copy()
    X[:, 0] = x
    for i in range(problem.N):
        x = problem.step(x, U[:, i], i)
        X[:, i + 1] = x
    return X


def backward_pass(A, B, lx, lu, lxx, luu, lux, reg: float):
    """Riccati-like recursion of iLQR. Returns (k, K, dV1, dV2) or None if a Q_uu is not PD.

    Written in homogeneous coordinates ``z = [1, x, u]`` so that one node costs two products of
    (1+n+m)-square matrices and one (m x m) solve: ``Q = L + F^T Vbar F`` with ``F = [[1, 0, 0],
    [0, A, B]]``, ``Vbar = [[., Vx^T], [Vx, Vxx]]`` and ``L`` the cost's quadratic model; ``Q_u``, ``Q_ux``
    and ``Q_uu`` are its last rows. The value update is Tassa et al.'s (2012), robust to the
    regularisation of ``Q_uu``.
    """
    N, n, m = B.shape[0], A.shape[1], B.shape[2]
    a = 1 + n  # size of [1, x]
    F = np.zeros((N, a, a + m))
    F[:, 0, 0] = 1.0
    F[:, 1:, 1:a] = A
    F[:, 1:, a:] = B
    L = np.zeros((N, a + m, a + m))
    L[:, 0, 1:a] = lx[:N]
    L[:, 0, a:] = lu
    L[:, 1:a, 0] = lx[:N]
    L[:, a:, 0] = lu
    L[:, 1:a, 1:a] = lxx[:N]
    L[:, a:, a:] = luu
    L[:, a:, 1:a] = lux
    L[:, 1:a, a:] = np.swapaxes(lux, 1, 2)
    V = np.zeros((a, a))
    V[0, 1:] = lx[N]
    V[1:, 0] = lx[N]
    V[1:, 1:] = lxx[N]
    k = np.empty((N, m))
    K = np.empty((N, m, n))
    dV1 = 0.0
    dV2 = 0.0
    reg_eye = reg * np.eye(m)
    for i in range(N - 1, -1, -1):
        Fi = F[i]
        Q = L[i] + Fi.T @ V @ Fi
        Quu = Q[a:, a:]
        Qua = Q[a:, :a]  # [Q_u | Q_ux]
        try:
            G = -np.linalg.solve(Quu + reg_eye, Qua)  # [k | K]
        except np.linalg.LinAlgError:
            return None
        ki = G[:, 0]
        if not np.isfinite(G).all():
            return None
        k[i] = ki
        K[i] = G[:, 1:]
        qk = Quu @ ki
        dV1 += float(ki @ Qua[:, 0])
        dV2 += 0.5 * float(ki @ qk)
        if float(ki @ qk) < -1e-12:  # Q_uu not positive definite along k
            return None
        GtQua = G.T @ Qua
        V = Q[:a, :a] + G.T @ (Quu @ G) + GtQua + GtQua.T
        V = 0.5 * (V + V.T)
    return k, K, dV1, dV2


def forward_pass(problem, x0, X, U, k, K, alphas: np.ndarray):
    """Closed-loop rollouts of ``u = U + a k + K (x - X)`` for every step length ``a`` at once."""
    nb = len(alphas)
    Xn = np.empty((nb, problem.N + 1, problem.n))
    Un = np.empty((nb, problem.N, problem.m))
    x = np.broadcast_to(x0, (nb, problem.n)).copy()
    Xn[:, 0] = x
    a = alphas[:, None]
    for i in range(problem.N):
        u = U[i] + a * k[i] + (x - X[i]) @ K[i].T
        Un[:, i] = u
        x = problem.step(x, u, i)
        Xn[:, i + 1] = x
    return Xn, Un


def solve(problem, x0: np.ndarray, U0: np.ndarray, iterations: int = 3, reg: float = 1e-6,
          reg_min: float = 1e-8, reg_max: float = 1e8, tol: float = 1e-9, X0: np.ndarray | None = None,
          alphas: np.ndarray = LINE_SEARCH, timing: dict | None = None) -> ILQRResult:
    """Run at most ``iterations`` iLQR iterations from the control sequence ``U0``.

    ``X0`` may pass the rollout of ``U0`` from ``x0`` when the caller already has it. ``timing``, if
    given, accumulates seconds under "derivatives", "backward", "forward" and "cost".
    """
    clock = time.perf_counter
    tick = clock()

    def lap(name):
        nonlocal tick
        now = clock()
        if timing is not None:
            timing[name] = timing.get(name, 0.0) + now - tick
        tick = now

    U = np.array(U0, dtype=float, copy=True)
    X = rollout(problem, x0, U) if X0 is None else X0
    lap("forward")
    J = float(problem.cost(X[None], U[None])[0])
    lap("cost")
    K = np.zeros((problem.N, problem.m, problem.n))
    k = np.zeros((problem.N, problem.m))
    accepted = 0
    it = 0
    for it in range(1, iterations + 1):  # noqa: B007 (returned below: the iterations run)
        A, B = problem.dynamics_jacobians(X, U)
        lx, lu, lxx, luu, lux = problem.cost_derivatives(X, U)
        lap("derivatives")
        result = None
        while result is None:
            result = backward_pass(A, B, lx, lu, lxx, luu, lux, reg)
            if result is None:
                reg = min(max(reg * 10.0, 1e-6), reg_max)
                if reg >= reg_max:
                    break
        if result is None:
            lap("backward")
            break
        k, K, dV1, dV2 = result
        lap("backward")
        Xn, Un = forward_pass(problem, x0, X, U, k, K, alphas)
        lap("forward")
        Jn = problem.cost(Xn, Un)
        lap("cost")
        expected = -(alphas * dV1 + alphas * alphas * dV2)  # predicted decrease (> 0)
        ok = (J - Jn) > 1e-4 * np.maximum(expected, 0.0)
        ok &= np.isfinite(Jn)
        if np.any(ok):
            best = int(np.flatnonzero(ok)[0])  # the longest step that decreases the cost enough
            improvement = J - float(Jn[best])
            X, U, J = Xn[best], Un[best], float(Jn[best])
            accepted += 1
            reg = max(reg / 4.0, reg_min)
            if improvement < tol * max(1.0, abs(J)):
                break
        else:
            reg = min(max(reg * 10.0, 1e-6), reg_max)
    return ILQRResult(X=X, U=U, K=K, k=k, cost=J, iterations=it, accepted=accepted, reg=reg)
