"""Small statistics helpers: the Wilson interval for a catch rate, NaN-aware summaries."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion (Wilson 1927), closed form.

    Unlike the normal (Wald) interval it stays inside [0, 1] and keeps its coverage at 0 % and 100 %
    success, which matters for catch rates near either end. ``n == 0`` gives the vacuous ``(0, 1)``.
    Agrees with ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``.
    """
    k, n = int(successes), int(n)
    if n < 0 or not 0 <= k <= max(n, 0):
        raise ValueError(f"need 0 <= successes <= n, got successes={successes}, n={n}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    if n == 0:
        return 0.0, 1.0
    z = NormalDist().inv_cdf(0.5 + 0.5 * confidence)
    p = k / n
    z2n = z * z / n
    centre = (p + 0.5 * z2n) / (1.0 + z2n)
    half = z / (1.0 + z2n) * math.sqrt(p * (1.0 - p) / n + z2n / (4.0 * n))
    return max(0.0, centre - half), min(1.0, centre + half)


def nan_mean(values) -> float:
    """Mean of the finite entries; NaN when there are none (no warning)."""
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")


def nan_median(values) -> float:
    """Median of the finite entries; NaN when there are none (no warning)."""
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else float("nan")


def mean_median(values) -> dict[str, float]:
    """``{"mean", "median"}`` of the finite entries (NaN when none)."""
    return {"mean": nan_mean(values), "median": nan_median(values)}
