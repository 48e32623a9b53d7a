"""The throw distribution of the catch family (Eyecatch section 5: throws from a few metres, flights of about a second), drawn from ``np_random`` only.

A throw is sampled *backwards* from where it should arrive:

1. a release point 3-6 m in front of the catcher, 1.0-2.0 m high, up to 1 m to either side;
2. an arrival point inside the catchable region in front of the right shoulder;
3. a flight time of 0.8-1.4 s;
4. the launch velocity that carries the ball from 1 to 2 in exactly that time under gravity.

Step 4 inverts MuJoCo's semi-implicit Euler integrator exactly (``p_N = p_0 + N dt v_0 +
g dt^2 N (N+1) / 2``), so the simulated ball passes the arrival point at the sampled time to
floating-point precision, not just to O(dt).

Every throw consumes the same random numbers in the same order whatever the variant, so a seed
gives the same throw across the whole observability ladder. ``EyeCatchBounce-v0`` additionally
places an invisible vertical wall beside the flight and aims the ball at the arrival point's mirror
image, so that after an elastic, frictionless bounce it still reaches the arrival point
(Eyecatch section 5). MuJoCo's soft contact delays the bounce by a few milliseconds, so in that
variant the ball passes 4-9 cm from ``arrival_pos`` (measured over 30 seeds: median 4.5 cm); it is
still catchable, and scoring always uses the simulated ball, never ``arrival_pos``.

``EyeCatchTwoBalls-v0`` draws a second throw after the first (:func:`sample_second_throw`), so its first
ball is the ladder's throw for the seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from visuomotor_gym.core import args
from visuomotor_gym.core.args import Num, Pair

GRAVITY = np.array([0.0, 0.0, -9.81])
BALL_RADIUS = 0.025


# What each ThrowDistribution field accepts (visuomotor_gym.core.args.check_fields): modelling choices
# around the defaults (releases within 20 m, flights of at most 5 s, arrivals within 2 m of the seat
# axis and 3 m up, a gaze jitter of at most 30 deg); the longest second flight must exceed the shortest
# first one.
THROW_RULES = {
    "release_x_m": Pair(Num(0.5, 20.0)),
    "release_y_m": Pair(Num(-10.0, 10.0)),
    "release_z_m": Pair(Num(0.0, 5.0)),
    "flight_time_s": Pair(Num(0.0, 5.0, low_open=True)),
    "arrival_x_m": Pair(Num(-2.0, 2.0)),
    "arrival_y_m": Pair(Num(-2.0, 2.0)),
    "arrival_z_m": Pair(Num(0.0, 3.0)),
    "gaze_jitter_deg": Num(0.0, 30.0),
    "wall_clearance_m": Pair(Num(0.0, 10.0, low_open=True)),
    "second_release_lateral_m": Pair(Num(0.0, 10.0)),
    "second_stagger_s": Pair(Num(0.0, 5.0, low_open=True)),
    "second_arrival_gap_s": Pair(Num(0.0, 5.0, low_open=True)),
    "second_max_flight_s": Num(0.0, 10.0, low_open=True),
}


@dataclass(frozen=True)
class ThrowDistribution:
    """Uniform ranges (min, max) of the throw, in world coordinates (metres, seconds, degrees)."""

    release_x_m: tuple[float, float] = (3.0, 6.0)  # distance in front of the catcher
    release_y_m: tuple[float, float] = (-1.0, 1.0)  # lateral offset (+y is the catcher's left)
    release_z_m: tuple[float, float] = (1.0, 2.0)  # release height above the floor
    flight_time_s: tuple[float, float] = (0.8, 1.4)
    arrival_x_m: tuple[float, float] = (0.30, 0.45)  # catchable region of the right arm
    arrival_y_m: tuple[float, float] = (-0.40, -0.10)
    arrival_z_m: tuple[float, float] = (0.85, 1.20)
    gaze_jitter_deg: float = 2.0  # initial gaze: at the thrower's hand, +- this (std)
    wall_clearance_m: tuple[float, float] = (0.8, 1.4)  # Bounce: wall distance beyond the path
    # EyeCatchTwoBalls-v0 only (sample_second_throw): the second ball comes from the other side.
    second_release_lateral_m: tuple[float, float] = (1.0, 2.0)  # |y|, opposite to the first release
    second_stagger_s: tuple[float, float] = (0.2, 0.5)  # released this long after the first ball
    second_arrival_gap_s: tuple[float, float] = (0.5, 0.8)  # arrives this long after the first
    second_max_flight_s: float = 1.6  # longer flights are released later instead

    def __post_init__(self) -> None:
        args.check_fields(self, THROW_RULES, (("flight_time_s[0]", "<", "second_max_flight_s"),))


@dataclass(frozen=True)
class Throw:
    """One sampled throw. Positions in metres (world frame), velocities in m/s."""

    release_pos: np.ndarray
    release_vel: np.ndarray
    arrival_pos: np.ndarray  # where the ball centre is at ``flight_time`` (after any bounce)
    flight_time: float  # s, a whole number of physics steps
    gaze_offset: np.ndarray  # initial gaze offset from the release point (azimuth, elevation), rad
    wall_y: float | None = None  # Bounce: y of the wall surface the ball centre reflects from
    wall_side: float = 0.0  # +1: wall on the left of the flight, -1: on the right
    release_time: float = 0.0  # s after the episode start (the second ball of EyeCatchTwoBalls-v0)


def launch_velocity(release: np.ndarray, arrival: np.ndarray, n_steps: int, dt: float) -> np.ndarray:
    """Initial velocity that lands exactly on ``arrival`` after ``n_steps`` semi-implicit Euler steps."""
    return (arrival - release - GRAVITY * dt * dt * n_steps * (n_steps + 1) / 2.0) / (n_steps * dt)


def sample_throw(
    rng: np.random.Generator, dist: ThrowDistribution, dt: float, bounce: bool = False
) -> Throw:
    """Draw one throw; ``dt`` is the physics timestep the ball is integrated with."""
    u = rng.random(10)  # always ten numbers, in this order, for every variant

    def lerp(rng_range, x):
        return rng_range[0] + (rng_range[1] - rng_range[0]) * x

    release = np.array([lerp(dist.release_x_m, u[0]), lerp(dist.release_y_m, u[1]), lerp(dist.release_z_m, u[2])])
    arrival = np.array([lerp(dist.arrival_x_m, u[3]), lerp(dist.arrival_y_m, u[4]), lerp(dist.arrival_z_m, u[5])])
    n_steps = max(1, int(round(lerp(dist.flight_time_s, u[6]) / dt)))
    gaze_offset = np.deg2rad(dist.gaze_jitter_deg) * np.sqrt(-2.0 * np.log(1.0 - u[7] * 0.999)) * np.array(
        [np.cos(2 * np.pi * u[8]), np.sin(2 * np.pi * u[8])]
    )  # Box-Muller: an isotropic Gaussian offset from two uniforms
    wall_y = None
    side = 0.0
    aim = arrival
    if bounce:
        side = 1.0 if u[9] < 0.5 else -1.0
        clearance = lerp(dist.wall_clearance_m, u[9] * 2.0 % 1.0)
        if side > 0:
            wall_y = max(release[1], arrival[1]) + clearance
        else:
            wall_y = min(release[1], arrival[1]) - clearance
        # Aim at the mirror image of the arrival point in the plane the ball centre reflects from.
        aim = arrival.copy()
        aim[1] = 2.0 * wall_y - arrival[1]
    velocity = launch_velocity(release, aim, n_steps, dt)
    return Throw(release, velocity, arrival, n_steps * dt, gaze_offset, wall_y, side)


def sample_second_throw(
    rng: np.random.Generator, dist: ThrowDistribution, dt: float, control_dt: float, first: Throw
) -> Throw:
    """The second ball of EyeCatchTwoBalls-v0, drawn after ``first`` (so the first throw is the ladder's).

    Released from the other side of the first release (``second_release_lateral_m``, same distance and
    height ranges), ``second_stagger_s`` after the first ball (rounded up to a whole control step, so it
    is released between control steps), arriving in the same catchable region ``second_arrival_gap_s``
    after the first ball's arrival; a flight longer than ``second_max_flight_s`` is released later.
    ``release_time`` is the release time; ``flight_time`` counts from it.
    """
    u = rng.random(8)

    def lerp(rng_range, x):
        return rng_range[0] + (rng_range[1] - rng_range[0]) * x

    side = -1.0 if first.release_pos[1] >= 0.0 else 1.0
    release = np.array([lerp(dist.release_x_m, u[0]), side * lerp(dist.second_release_lateral_m, u[1]),
                        lerp(dist.release_z_m, u[2])])
    arrival = np.array([lerp(dist.arrival_x_m, u[3]), lerp(dist.arrival_y_m, u[4]), lerp(dist.arrival_z_m, u[5])])
    arrives = first.release_time + first.flight_time + lerp(dist.second_arrival_gap_s, u[6])
    stagger = max(lerp(dist.second_stagger_s, u[7]), arrives - dist.second_max_flight_s)
    stagger = math.ceil(stagger / control_dt - 1e-9) * control_dt  # the next control step
    n_steps = max(1, int(round((arrives - stagger) / dt)))
    velocity = launch_velocity(release, arrival, n_steps, dt)
    return Throw(release, velocity, arrival, n_steps * dt, np.zeros(2), release_time=stagger)
