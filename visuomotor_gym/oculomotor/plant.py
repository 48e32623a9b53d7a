"""Oculomotor plant: world-anchored gaze driven by saccades and smooth pursuit.

The plant's state is the **gaze direction in the world** (a unit vector). Holding a command of zero
keeps gaze fixed in space while the head and torso move: the vestibulo-ocular reflex is the env
converting this world gaze into eye-in-head angles after each physics step (until the eye reaches
its range, Eom et al. 2019 section 4.1).

Each control step the agent requests a gaze target. If the requested change exceeds
``saccade_threshold_deg`` and ``saccade_refractory_s`` (200 ms: Young & Stark 1963, Eyecatch 4.1,
Eom 4.1) have passed since the last saccade onset, a **saccade** starts:

* duration from the main sequence, ``D = 21 ms + 2.2 ms/deg * A`` (Carpenter 1988; Leigh & Zee),
  lengthened if needed so the peak speed ``1.875 A / D`` never exceeds 800 deg/s (Eyecatch 4.1);
* minimum-jerk position profile, whose speed is Eyecatch Eq. 15, along the great circle;
* ballistic: commands are ignored until it ends; optional endpoint noise proportional to A.

Otherwise the eye **pursues**: it turns toward the target at ``A / dt`` (Eyecatch 4.1,
``v = (p_target - p) / dt``), capped at 100 deg/s (Meyer et al. 1985).

The profile is evaluated at every physics substep inside a control step, so a 40 ms saccade is
resolved at 500 Hz; ``record=True`` keeps that substep trace for tests and plots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from visuomotor_gym.geometry import angle_between, cross, unit_from_angles

DEG = math.pi / 180.0


@dataclass(frozen=True)
class OculomotorParams:
    """Limits of the eye and head. Degrees, seconds and metres, as the names say."""

    saccade_threshold_deg: float = 3.0  # requested changes above this trigger a saccade
    saccade_refractory_s: float = 0.2  # min time between saccade onsets (Young & Stark 1963)
    main_sequence_intercept_s: float = 0.021  # D = 21 ms + 2.2 ms/deg * A (Carpenter 1988)
    main_sequence_slope_s_per_deg: float = 0.0022
    saccade_peak_deg_s: float = 800.0  # Eyecatch 4.1, Eom 4.1
    saccade_endpoint_noise: float = 0.0  # std of the landing error as a fraction of amplitude
    pursuit_max_deg_s: float = 100.0  # Meyer et al. 1985, Eyecatch 4.1, Eom 4.1
    eye_azimuth_range_deg: tuple[float, float] = (-44.2, 44.2)  # Eom et al. 2019, 4.1
    eye_elevation_range_deg: tuple[float, float] = (-47.1, 27.7)  # Eom et al. 2019, 4.1
    fixation_range_m: tuple[float, float] = (0.1, 20.0)
    vergence_max_diopter_s: float = 20.0  # rate limit of the fixation distance, in 1/m per second
    head_max_deg_s: float = 300.0  # head peak speed (4-8/s x amplitude, Eyecatch 4.2)

    def __post_init__(self) -> None:
        positive = (
            "saccade_threshold_deg",
            "main_sequence_slope_s_per_deg",
            "saccade_peak_deg_s",
            "pursuit_max_deg_s",
            "vergence_max_diopter_s",
            "head_max_deg_s",
        )
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"OculomotorParams.{name} must be finite and > 0, got {value!r}")
        for name in ("eye_azimuth_range_deg", "eye_elevation_range_deg", "fixation_range_m"):
            lo, hi = getattr(self, name)
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"OculomotorParams.{name} must be (low, high) with low < high, got {(lo, hi)!r}")
        if self.fixation_range_m[0] <= 0:
            raise ValueError("OculomotorParams.fixation_range_m must be positive")
        for name in ("saccade_refractory_s", "main_sequence_intercept_s", "saccade_endpoint_noise"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"OculomotorParams.{name} must be finite and >= 0, got {value!r}")

    def saccade_duration(self, amplitude_rad: float) -> float:
        """Main-sequence duration (s) of a saccade, stretched so its peak stays <= the cap."""
        amp_deg = amplitude_rad / DEG
        main_sequence = self.main_sequence_intercept_s + self.main_sequence_slope_s_per_deg * amp_deg
        # Minimum-jerk peak speed is 1.875 * A / D (Eq. 15 at its midpoint).
        return max(main_sequence, 1.875 * amp_deg / self.saccade_peak_deg_s)


def minimum_jerk(u: np.ndarray | float):
    """Minimum-jerk position profile s(u) = 10u^3 - 15u^4 + 6u^5 on u in [0, 1]; s' is Eq. 15."""
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def direction_from_angles(azimuth: float, elevation: float) -> np.ndarray:
    """Unit vector for (azimuth about z, then elevation up): x forward, y left, z up."""
    return np.array(unit_from_angles(azimuth, elevation))


def angles_from_direction(direction: np.ndarray) -> tuple[float, float]:
    """Inverse of :func:`direction_from_angles` (azimuth, elevation) in radians."""
    x, y, z = float(direction[0]), float(direction[1]), float(direction[2])
    return math.atan2(y, x), math.atan2(z, math.hypot(x, y))


def _tangent(a: np.ndarray, b: np.ndarray, angle: float) -> np.ndarray:
    """Unit vector perpendicular to ``a`` in the plane of the great circle from ``a`` toward ``b``.

    For exactly opposite ``a`` and ``b`` every great circle qualifies; we take the horizontal one
    (rotation about the world z axis), or one about y if ``a`` is vertical.
    """
    s = math.sin(angle)
    if s > 1e-9:
        return (b - math.cos(angle) * a) / s
    ax, ay, az = a.tolist()
    w = np.array([-ay, ax, 0.0]) if abs(az) < 0.9 else np.array([az, 0.0, -ax])
    return w / math.sqrt(float(w @ w))


def _slerp(a: np.ndarray, b: np.ndarray, angle: float, fractions):
    """Points at ``fractions`` of the great-circle arc from ``a`` to ``b`` (``angle`` apart)."""
    if angle < 1e-12:
        if isinstance(fractions, float):
            return np.array(b, dtype=float)
        return np.broadcast_to(b, (np.size(fractions), 3)).copy()
    w = _tangent(a, b, angle)
    if isinstance(fractions, float):
        t = fractions * angle
        return math.cos(t) * a + math.sin(t) * w
    t = np.asarray(fractions, dtype=float) * angle
    return np.cos(t)[:, None] * a + np.sin(t)[:, None] * w


@dataclass
class Saccade:
    """One ballistic saccade in world coordinates."""

    onset: float  # s
    duration: float  # s
    start: np.ndarray  # unit gaze direction at onset
    end: np.ndarray  # unit gaze direction at landing
    amplitude: float  # rad
    axis: np.ndarray  # unit rotation axis (world) from start to end
    tangent: np.ndarray | None = None  # unit vector across ``start`` toward ``end`` (the great circle)

    def __post_init__(self) -> None:
        if self.tangent is None:
            self.tangent = _tangent(self.start, self.end, self.amplitude)
        self._arc = (self.start.tolist(), self.tangent.tolist())

    def direction(self, fraction: float) -> tuple[float, float, float]:
        """Gaze direction at ``fraction`` (0..1) of the path (as ``_slerp``, with the tangent kept)."""
        t = fraction * self.amplitude
        c, s = math.cos(t), math.sin(t)
        (ax, ay, az), (wx, wy, wz) = self._arc
        return c * ax + s * wx, c * ay + s * wy, c * az + s * wz


@dataclass
class PlantStep:
    """What happened during one control step."""

    saccade_started: bool  # a saccade began at the start of this step
    saccading: bool  # a saccade was in flight during some part of this step
    in_saccade: bool  # a saccade is still in flight at the end of this step


class OculomotorPlant:
    """Saccade/pursuit generator for a world-anchored gaze direction (see the module docstring)."""

    def __init__(self, params: OculomotorParams | None = None, record: bool = False):
        self.params = params or OculomotorParams()
        self.record = record
        self.reset(np.array([1.0, 0.0, 0.0]), time=0.0)

    def reset(self, gaze: np.ndarray, time: float = 0.0) -> None:
        """Start at ``gaze`` (unit vector, world) with the saccade generator recharged."""
        self.gaze = np.asarray(gaze, dtype=float) / np.linalg.norm(gaze)
        self.time = float(time)
        self._omega = (None, np.zeros(3), 0.0)  # angular velocity = (cross(a, b) if a else b) * k
        self.last_onset = -math.inf
        self.saccade: Saccade | None = None
        self.saccades: list[Saccade] = []
        self.trace_t: list[float] = []
        self.trace_gaze: list[np.ndarray] = []
        if self.record:
            self.trace_t.append(self.time)
            self.trace_gaze.append(self.gaze.copy())

    @property
    def angular_velocity(self) -> np.ndarray:
        """Angular velocity of the gaze (world, rad/s) over the last step (computed when asked)."""
        a, b, k = self._omega
        return (cross(a, b) if a is not None else b) * k

    @property
    def ready_for_saccade(self) -> bool:
        """Whether a saccade could start now (none in flight, refractory period over)."""
        return self.saccade is None and self.time - self.last_onset >= self.params.saccade_refractory_s - 1e-9

    def step(
        self,
        target: np.ndarray,
        dt: float,
        n_substeps: int,
        rng: np.random.Generator | None = None,
    ) -> PlantStep:
        """Advance one control step of ``dt`` seconds toward the unit world direction ``target``.

        ``rng`` draws the optional saccade endpoint noise (only used when that noise is > 0).
        """
        p = self.params
        t0 = self.time
        started = False
        amplitude = None  # of the requested change; computed once when no saccade is in flight
        if self.saccade is None:
            amplitude = angle_between(self.gaze, target)
            if amplitude > p.saccade_threshold_deg * DEG and self.ready_for_saccade:
                end = np.asarray(target, dtype=float)
                if p.saccade_endpoint_noise > 0.0 and rng is not None:
                    end = _perturb(end, rng.standard_normal(2) * p.saccade_endpoint_noise * amplitude)
                    amplitude = angle_between(self.gaze, end)
                tangent = _tangent(self.gaze, end, amplitude)
                axis = cross(self.gaze, tangent)
                self.saccade = Saccade(t0, p.saccade_duration(amplitude), self.gaze.copy(), end, amplitude, axis,
                                       tangent)
                self.saccades.append(self.saccade)
                self.last_onset = t0
                started = True

        t_end = t0 + dt
        saccading = self.saccade is not None
        if self.record:
            sub_t = t0 + dt * np.arange(1, n_substeps + 1) / n_substeps
        if self.saccade is not None:
            sac = self.saccade
            if self.record:
                u = np.clip((sub_t - sac.onset) / sac.duration, 0.0, 1.0)
                points = _slerp(sac.start, sac.end, sac.amplitude, minimum_jerk(u))
            u_end = min(max((t_end - sac.onset) / sac.duration, 0.0), 1.0)
            gx, gy, gz = sac.direction(minimum_jerk(u_end))
            speed = sac.amplitude * 30.0 * u_end**2 * (1.0 - u_end) ** 2 / sac.duration  # Eq. 15
            self._omega = (None, sac.axis, speed)
            if u_end >= 1.0:
                self.saccade = None
        else:  # pursuit (no saccade started, so the gaze and the amplitude are unchanged)
            travel = min(amplitude, p.pursuit_max_deg_s * DEG * dt)
            start = self.gaze
            if amplitude > 1e-12:
                if self.record:
                    fractions = np.arange(1, n_substeps + 1) / n_substeps * (travel / amplitude)
                    points = _slerp(start, target, amplitude, fractions)
                # _slerp(start, target, amplitude, travel / amplitude) in scalars (same operations)
                (ax, ay, az), (bx, by, bz) = start.tolist(), np.asarray(target, dtype=float).tolist()
                sa = math.sin(amplitude)
                if sa > 1e-9:  # _tangent's general case
                    ca = math.cos(amplitude)
                    wx, wy, wz = (bx - ca * ax) / sa, (by - ca * ay) / sa, (bz - ca * az) / sa
                else:
                    wx, wy, wz = _tangent(start, target, amplitude).tolist()
                t = travel / amplitude * amplitude
                c, s = math.cos(t), math.sin(t)
                gx, gy, gz = c * ax + s * wx, c * ay + s * wy, c * az + s * wz
                self._omega = (start, (wx, wy, wz), travel / dt)
            else:
                if self.record:
                    points = np.broadcast_to(start, (n_substeps, 3)).copy()
                self._omega = (None, np.zeros(3), 0.0)
                gx, gy, gz = start.tolist()
        n = math.sqrt(gx * gx + gy * gy + gz * gz)
        self.gaze = np.array([gx / n, gy / n, gz / n])
        self.time = t_end
        if self.record:
            self.trace_t.extend(sub_t.tolist())
            self.trace_gaze.extend(points)
        return PlantStep(started, saccading, self.saccade is not None)

    def constrain(self, achieved: np.ndarray) -> None:
        """Replace the gaze with the direction the eye actually reached (it hit its range).

        A saccade in flight keeps its ballistic course; the next substeps may clamp again.
        """
        self.gaze = np.asarray(achieved, dtype=float)
        if self.record and self.trace_gaze:
            self.trace_gaze[-1] = self.gaze.copy()

    def trace(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, gaze directions) at every physics substep since reset (needs ``record=True``)."""
        if not self.record:
            raise RuntimeError("construct the plant with record=True to keep a substep trace")
        return np.asarray(self.trace_t), np.asarray(self.trace_gaze)


def _perturb(direction: np.ndarray, offsets_rad: np.ndarray) -> np.ndarray:
    """Tilt a unit direction by two small perpendicular angular offsets."""
    az, el = angles_from_direction(direction)
    return direction_from_angles(az + offsets_rad[0] / max(math.cos(el), 1e-3), el + offsets_rad[1])
