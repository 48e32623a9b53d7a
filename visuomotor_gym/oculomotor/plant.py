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

Otherwise the eye **pursues** like a human eye (Eyecatch 4.1 only caps pursuit at 100 deg/s; the
rest is human data, every constant an :class:`OculomotorParams` field with its source):

* pursuit is driven by **target motion**, which the plant reads from the gaze request stream: the
  angular velocity of the requested direction between consecutive control steps. A static offset
  does not drive pursuit (humans cannot pursue without a moving target); a step of the request
  larger than the saccade threshold is a position step, not motion; and a step to a request that
  starts a saccade, taken while a saccade was in flight, or after which the eye was held at its
  range, carries no motion signal
  (saccadic suppression; a carried eye moves an eye-relative request). Without a new sample the
  last one is held;
* the drive reaches the eye after an **onset latency** (``pursuit_latency_s``, Bahill & McDonald 1983);
* the eye's pursuit velocity goes to ``G(|v|) v`` for target velocity ``v``, with a **gain** falling
  from 0.98 at 10 deg/s to 0.75 at 60 deg/s (Schalen 1980), capped at 100 deg/s (Meyer et al. 1985);
* it gets there at no more than ``pursuit_accel_max_deg_s2`` (Robinson 1965: ~130 ms per velocity
  transition), integrated at every physics substep;
* the pursuit velocity persists through saccades (the saccade replaces the eye's motion while in
  flight; afterwards the eye continues at the pursuit velocity);
* a request beyond the saccade threshold that cannot be a saccade (refractory period) is **not**
  carried out as pursuit: it *waits*. The eye keeps pursuing the target motion only, and the saccade
  starts at the first control step the generator is recharged, toward the request of that step
  (``PlantStep.saccade_deferred`` flags the waiting steps). So a refused saccade never moves the eye
  faster than pursuit, and a static target beyond the threshold is reached only by a saccade.

Consequently pursuit lags a fast target and catch-up saccades follow (Schalen 1980: saccades of
3-10 deg at all target speeds), and a sub-threshold static offset is not corrected (the saccade
threshold is the smallest correction).

The profile is evaluated at every physics substep inside a control step, so a 40 ms saccade is
resolved at 500 Hz; ``record=True`` keeps that substep trace for tests and plots.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from visuomotor_gym import _native
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Num, Pair
from visuomotor_gym.geometry import angle_between, cross, unit_from_angles

DEG = math.pi / 180.0
_ZERO = (0.0, 0.0, 0.0)  # "no pursuit drive" (compared by identity in the hot loop)
SACCADE_HISTORY = 256  # saccades kept without record=True: far more than an episode holds (<= 5 per second)


def _gain_points(value, name: str) -> tuple[tuple[float, float], ...]:
    """``pursuit_gain_points``: 1-16 (target deg/s, gain) pairs, speeds increasing in [0, 1000], gains in (0, 1.5]."""
    allowed = "1-16 (deg/s, gain) pairs with increasing speeds in [0, 1000] and gains in (0, 1.5]"
    try:
        points = tuple((float(s), float(g)) for s, g in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {allowed}, got {value!r}") from None
    if not (1 <= len(points) <= 16
            and all(math.isfinite(s) and math.isfinite(g) and 0.0 <= s <= 1000.0 and 0.0 < g <= 1.5 for s, g in points)
            and all(a[0] < b[0] for a, b in itertools.pairwise(points))):
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return points


# What each OculomotorParams field accepts (visuomotor_gym.core.args.check_fields). Positive rates and
# thresholds, non-negative times; the upper bounds are modelling choices well beyond the sourced values
# in the field comments (a 180 deg saccade threshold, 1 s of pursuit latency,
# 3000 deg/s eye speeds); eye ranges within +-90 deg, fixation between 1 cm and 1 km.
OCULOMOTOR_RULES = {
    "saccade_threshold_deg": Num(0.0, 180.0, low_open=True),
    "saccade_refractory_s": Num(0.0, 100.0),  # long ones switch saccades off (a test uses 10 s)
    "main_sequence_intercept_s": Num(0.0, 1.0),
    "main_sequence_slope_s_per_deg": Num(0.0, 0.1, low_open=True),
    "saccade_peak_deg_s": Num(0.0, 3000.0, low_open=True),
    "saccade_endpoint_noise": Num(0.0, 1.0),
    "pursuit_max_deg_s": Num(0.0, 3000.0, low_open=True),
    "pursuit_latency_s": Num(0.0, 1.0),
    "pursuit_gain_points": _gain_points,
    "pursuit_accel_max_deg_s2": Num(0.0, 1e5, low_open=True),
    "eye_azimuth_range_deg": Pair(Num(-90.0, 90.0), strict=True),
    "eye_elevation_range_deg": Pair(Num(-90.0, 90.0), strict=True),
    "fixation_range_m": Pair(Num(0.01, 1000.0), strict=True),
    "vergence_max_diopter_s": Num(0.0, 1000.0, low_open=True),
    "head_max_deg_s": Num(0.0, 3000.0, low_open=True),
}


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
    pursuit_latency_s: float = 0.15  # onset latency of pursuit: "about 150 msec" (Bahill & McDonald
    # 1983, Vision Res 23:1573, abstract); counted from the control step whose request first moves
    pursuit_gain_points: tuple[tuple[float, float], ...] = ((10.0, 0.98), (60.0, 0.75))  # (target
    # deg/s, eye/target velocity gain): Schalen 1980 (Acta Otolaryngol 90:404, 20 subjects), "0.98-0.75,
    # gradually diminishing with increasing target velocities of 10-60 deg/s". Linear in between and
    # constant outside: modelling choice (the abstract gives the ends of the range only)
    pursuit_accel_max_deg_s2: float = 770.0  # |d(eye velocity)/dt| bound in pursuit: the 100 deg/s cap
    # reached in the ~130 ms Robinson (1965, J Physiol 180:569) measured for a pursuit velocity
    # transition (100 / 0.13 = 770). A constant bound is our modelling choice
    eye_azimuth_range_deg: tuple[float, float] = (-44.2, 44.2)  # Eom et al. 2019, 4.1
    eye_elevation_range_deg: tuple[float, float] = (-47.1, 27.7)  # Eom et al. 2019, 4.1
    fixation_range_m: tuple[float, float] = (0.1, 20.0)
    vergence_max_diopter_s: float = 20.0  # rate limit of the fixation distance, in 1/m per second
    head_max_deg_s: float = 300.0  # head peak speed (4-8/s x amplitude, Eyecatch 4.2)

    def __post_init__(self) -> None:
        args.check_fields(self, OCULOMOTOR_RULES)

    def pursuit_gain(self, target_speed_deg_s: float) -> float:
        """Steady-state pursuit gain (eye / target velocity) at a target speed (deg/s)."""
        points = self.pursuit_gain_points
        if target_speed_deg_s <= points[0][0]:
            return points[0][1]
        for (s0, g0), (s1, g1) in itertools.pairwise(points):
            if target_speed_deg_s <= s1:
                return g0 + (g1 - g0) * (target_speed_deg_s - s0) / (s1 - s0)
        return points[-1][1]

    def pursuit_velocity(self, target_speed_deg_s: float) -> float:
        """Steady-state pursuit eye speed (deg/s) for a target speed (deg/s): gain, then the cap."""
        return min(self.pursuit_gain(target_speed_deg_s) * target_speed_deg_s, self.pursuit_max_deg_s)

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
    saccading: bool  # a saccade was in flight during some part of this step (the plant's
    # ``saccade`` attribute says whether one is still in flight at the end of it)
    saccade_deferred: bool = False  # the request was beyond the threshold but the generator was not
    # recharged (refractory period): it waits, and is not carried out as pursuit


class OculomotorPlant:
    """Saccade/pursuit generator for a world-anchored gaze direction (see the module docstring)."""

    def __init__(self, params: OculomotorParams | None = None, record: bool = False):
        self.params = params or OculomotorParams()
        self.record = record
        # The compiled step (visuomotor_gym._native), when built; not for the recorded trace. Its
        # constants in the order of _kernels.c's PlantConsts.
        self._native = _native.enabled() and not record
        p = self.params
        self._native_constants = np.array(
            [p.saccade_threshold_deg * DEG, p.pursuit_latency_s, p.pursuit_accel_max_deg_s2 * DEG,
             p.pursuit_max_deg_s, DEG, p.saccade_refractory_s, len(p.pursuit_gain_points),
             *(x for q in p.pursuit_gain_points for x in q)],
            dtype=np.float64,
        ).tobytes()
        self.reset(np.array([1.0, 0.0, 0.0]), time=0.0)

    def reset(self, gaze: np.ndarray, time: float = 0.0) -> None:
        """Start at ``gaze`` (unit vector, world), still, with the saccade generator recharged."""
        self.gaze = np.asarray(gaze, dtype=float) / np.linalg.norm(gaze)
        self.time = float(time)
        self._omega = (None, np.zeros(3), 0.0)  # angular velocity = (cross(a, b) if a else b) * k
        self.last_onset = -math.inf
        self.saccade: Saccade | None = None
        # The last SACCADE_HISTORY saccades (bounded: an env stepped without end must not grow it);
        # with ``record`` every saccade is kept, as the 500 Hz trace is.
        self.saccades: deque[Saccade] | list[Saccade] = [] if self.record else deque(maxlen=SACCADE_HISTORY)
        # Pursuit: the eye's pursuit angular velocity (world rotation vector, rad/s), the target-motion
        # samples read from the request stream as (time, wx, wy, wz) waiting out the onset latency, the
        # sample now driving the eye, the previous request and whether a saccade flew during the step
        # after it (its motion is then suppressed).
        self.pursuit_omega = (0.0, 0.0, 0.0)
        self._drive_queue: list[tuple[float, float, float, float]] = []
        self._drive = (0.0, 0.0, 0.0)
        self._goal = _ZERO  # the pursuit velocity goal of the current drive (cached)
        self._last_sample = (0.0, 0.0, 0.0)
        self._prev_request: tuple[float, float, float] | None = None
        self._suppressed = False
        self.trace_t: list[float] = []
        self.trace_gaze: list[np.ndarray] = []
        if self.record:
            self.trace_t.append(self.time)
            self.trace_gaze.append(self.gaze.copy())

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._native = self._native and _native.enabled()  # unpickled where the extension is missing

    @property
    def angular_velocity(self) -> np.ndarray:
        """Angular velocity of the gaze (world, rad/s) at the end of the last step (computed when asked)."""
        a, b, k = self._omega
        return (cross(a, b) if a is not None else np.array(b)) * k

    @property
    def ready_for_saccade(self) -> bool:
        """Whether a saccade could start now (none in flight, refractory period over)."""
        return self.saccade is None and self.time - self.last_onset >= self.params.saccade_refractory_s - 1e-9

    def _sample_target_motion(self, target: tuple[float, float, float], dt: float) -> None:
        """Read the target's angular velocity from the request stream and queue it for the latency."""
        p = self.params
        prev = self._prev_request
        sample = self._last_sample  # held when this step carries no motion signal
        if prev is not None and not self._suppressed:
            jump = angle_between(prev, target)
            if jump <= p.saccade_threshold_deg * DEG:  # a larger step is a position step, not motion
                (ax, ay, az), (bx, by, bz) = prev, target
                cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
                s = math.sqrt(cx * cx + cy * cy + cz * cz)
                k = jump / dt / s if s > 1e-15 else 0.0
                sample = (cx * k, cy * k, cz * k)
        self._last_sample = sample
        self._prev_request = target
        self._drive_queue.append((self.time + p.pursuit_latency_s, *sample))

    def _pursuit_goal(self, t: float) -> tuple[float, float, float]:
        """The eye's pursuit velocity goal at time ``t``: the delayed target motion times the gain."""
        queue = self._drive_queue
        if not queue or queue[0][0] > t + 1e-9:  # the drive is unchanged: so is its goal (runs per substep)
            return self._goal
        while queue and queue[0][0] <= t + 1e-9:  # its latency has passed: it drives the eye now
            self._drive = queue.pop(0)[1:]
        wx, wy, wz = self._drive
        speed = math.sqrt(wx * wx + wy * wy + wz * wz)
        if speed < 1e-12:
            self._goal = _ZERO
        else:
            k = self.params.pursuit_velocity(speed / DEG) * DEG / speed
            self._goal = (wx * k, wy * k, wz * k)
        return self._goal

    def step(
        self,
        target: np.ndarray,
        dt: float,
        n_substeps: int,
        rng: np.random.Generator | None = None,
    ) -> PlantStep:
        """Advance one control step of ``dt`` seconds toward the world direction ``target`` (an array
        or a 3-tuple of floats; normalised here).

        ``rng`` draws the optional saccade endpoint noise (only used when that noise is > 0).
        """
        if self._native:  # this method, compiled (_native/_kernels.c: plant_step), unless a saccade starts
            stepped = _native.kernels.plant_step(self, target, dt, n_substeps, self._native_constants, _ZERO)
            if stepped is not None:
                return PlantStep(False, *stepped)
        p = self.params
        t0 = self.time
        tx, ty, tz = target if type(target) is tuple else np.asarray(target, dtype=float).tolist()
        n = math.sqrt(tx * tx + ty * ty + tz * tz)
        request = (tx / n, ty / n, tz / n)
        started = deferred = False
        if self.saccade is None:
            amplitude = angle_between(self.gaze, request)
            if amplitude > p.saccade_threshold_deg * DEG:
                if self.ready_for_saccade:
                    end = np.array(request)
                    if p.saccade_endpoint_noise > 0.0 and rng is not None:
                        end = _perturb(end, rng.standard_normal(2) * p.saccade_endpoint_noise * amplitude)
                        amplitude = angle_between(self.gaze, end)
                    tangent = _tangent(self.gaze, end, amplitude)
                    axis = cross(self.gaze, tangent)
                    self.saccade = Saccade(t0, p.saccade_duration(amplitude), self.gaze.copy(), end, amplitude,
                                           axis, tangent)
                    self.saccades.append(self.saccade)
                    self.last_onset = t0
                    started = True
                else:
                    deferred = True  # waits for the generator; not executed as pursuit
        # A request that starts a saccade is a position command (it may aim ahead of the target):
        # like the steps with a saccade in flight, it carries no motion signal.
        self._suppressed = self._suppressed or started
        self._sample_target_motion(request, dt)

        saccading = self.saccade is not None
        h = dt / n_substeps
        a_max = p.pursuit_accel_max_deg_s2 * DEG * h  # largest velocity change per substep
        gx, gy, gz = self.gaze.tolist()
        vx, vy, vz = self.pursuit_omega
        sac = self.saccade
        points = [] if self.record else None
        in_saccade_last = False
        queue = self._drive_queue
        due = queue[0][0] if queue else math.inf  # when the next target-motion sample drives the eye
        goal = self._goal
        # A substep with no pursuit drive and an eye at rest (exact zeros) changes nothing: the
        # velocity update adds 0 and the rotation has no axis. Such substeps are skipped (the same
        # numbers as running them; this is the plant's hot loop).
        still = goal is _ZERO and vx == 0.0 and vy == 0.0 and vz == 0.0
        for i in range(1, n_substeps + 1):
            t = t0 + h * i
            if due <= (t - h) + 1e-9:  # a new drive at the start of the substep (see _pursuit_goal)
                goal = self._pursuit_goal(t - h)
                due = queue[0][0] if queue else math.inf
                still = goal is _ZERO and vx == 0.0 and vy == 0.0 and vz == 0.0
            if not still:
                # Pursuit velocity: toward the delayed, gain-scaled target motion, acceleration-bounded.
                ux, uy, uz = goal
                ex, ey, ez = ux - vx, uy - vy, uz - vz
                e = math.sqrt(ex * ex + ey * ey + ez * ez)
                if e > a_max:
                    ex, ey, ez = ex * a_max / e, ey * a_max / e, ez * a_max / e
                vx, vy, vz = vx + ex, vy + ey, vz + ez
                # v + (0 - v) is +0.0 exactly: once at rest with no drive, the eye stays still
                still = goal is _ZERO and vx == 0.0 and vy == 0.0 and vz == 0.0
            if sac is not None:  # ballistic: the saccade alone moves the eye until it lands
                u = (t - sac.onset) / sac.duration  # clamped to [0, 1] (as min(max(u, 0), 1))
                if u >= 1.0:
                    u = 1.0
                elif u < 0.0:
                    u = 0.0
                in_saccade_last = u < 1.0
                # Only the last point of the step (or the landing) is kept unless the trace is recorded.
                if u >= 1.0 or i == n_substeps or points is not None:
                    gx, gy, gz = sac.direction(minimum_jerk(u))
                if u >= 1.0:
                    sac = None
            elif not still:
                in_saccade_last = False
                # Rotate the gaze by the pursuit velocity's component across it (Rodrigues).
                d = vx * gx + vy * gy + vz * gz
                wx, wy, wz = vx - d * gx, vy - d * gy, vz - d * gz
                w = math.sqrt(wx * wx + wy * wy + wz * wz)
                if w > 1e-15:
                    ang = w * h
                    c, s = math.cos(ang), math.sin(ang)
                    kx, ky, kz = wx / w, wy / w, wz / w
                    cx, cy, cz = ky * gz - kz * gy, kz * gx - kx * gz, kx * gy - ky * gx
                    gx, gy, gz = c * gx + s * cx, c * gy + s * cy, c * gz + s * cz
                    m = math.sqrt(gx * gx + gy * gy + gz * gz)
                    gx, gy, gz = gx / m, gy / m, gz / m
            else:
                in_saccade_last = False
            if points is not None:
                points.append(np.array([gx, gy, gz]))
        if self.saccade is not None:
            if in_saccade_last:
                u = min(max((t0 + dt - self.saccade.onset) / self.saccade.duration, 0.0), 1.0)
                speed = self.saccade.amplitude * 30.0 * u**2 * (1.0 - u) ** 2 / self.saccade.duration  # Eq. 15
                self._omega = (None, self.saccade.axis, speed)
            else:
                self.saccade = None
        if self.saccade is None:
            d = vx * gx + vy * gy + vz * gz
            self._omega = (None, (vx - d * gx, vy - d * gy, vz - d * gz), 1.0)
        self.pursuit_omega = (vx, vy, vz)
        self._suppressed = saccading
        self.gaze = np.array([gx, gy, gz])
        self.time = t0 + dt
        if self.record:
            self.trace_t.extend((t0 + dt * np.arange(1, n_substeps + 1) / n_substeps).tolist())
            self.trace_gaze.extend(points)
        return PlantStep(started, saccading, deferred)

    def constrain(self, achieved: np.ndarray) -> None:
        """Replace the gaze with the direction the eye actually reached (it hit its range).

        A saccade in flight keeps its ballistic course, pursuit its velocity; the next substeps may
        clamp again.
        """
        self.gaze = np.asarray(achieved, dtype=float)
        # The request stream moves with the carried eye: no target-motion signal from this step
        # (modelling choice, as for saccades; otherwise a "hold gaze" request would drive pursuit).
        self._suppressed = True
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
