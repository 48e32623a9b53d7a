# The per-step path writes min/max as the builtins' comparisons, on purpose.
"""The walker's scripted gait: a footstep-level interface on a kinematic gait that physics servos track.

The gait only: the footstep plan, the pelvis and foot trajectories, the legs' inverse kinematics and the
servo setpoints. What the walker walks among (the obstacle pool, :mod:`visuomotor_gym.tasks.walk_scene`)
and what a leg touching it means (trips and missteps, :mod:`visuomotor_gym.tasks.walk_contacts`) belong
to the tasks; they read the gait through its public methods (:meth:`WalkerGait.phase_of`,
:meth:`WalkerGait.foothold_of`, :meth:`WalkerGait.tick_of`, :attr:`WalkerGait.qpos_index`).

No learned gait (as footstep-planner controllers such as DeepLoco do): the pelvis follows a trajectory planned through the
footholds, the legs follow analytic two-link inverse kinematics toward planned foot poses, and MuJoCo
contacts between the legs and the obstacles decide what happens. The agent chooses footsteps, as the
high-level controller of footstep-planner gaits such as DeepLoco does.

Timing (one *step* = heel strike to the other foot's heel strike; step ``j`` lands foothold ``j`` at
time ``j * step_s``; even ``j`` = left foot)::

    heel strike of j      toe-off of j-1          mid-stance of j        heel strike of j+1
    |-- double support --|--------- swing of the other foot (j-1 -> j+1) ----------|
    0                   0.1 s                    0.3 s                            0.5 s

* **Footstep action.** :meth:`WalkerGait.set_next_footstep` stores ``(length, lateral, clearance)``;
  at the mid-stance of foothold ``j`` the latest one is *latched* for foothold ``j + 2``, the next step
  of the same foot: ``length`` forward of foothold ``j + 1``, ``lateral`` beside the nominal step width,
  ``clearance`` = the lowest sole point's height during the carry phase of that swing. The foot lifts
  ~0.3 s after the latch and lands ~0.7 s after it (the window from mid-stance to toe-off is when humans
  use vision to choose the next foothold: Matthis, Barton & Fajen 2017, PNAS). Without a command the
  nominal footstep is used.
* **Pelvis.** Waypoints at each mid-stance (over the stance ankle, a little ahead, shifted toward the
  stance foot) joined by a Catmull-Rom spline in time: each segment is fixed when it starts (its four
  waypoints are known then), so the trajectory is C1 and never replanned. Height: a cosine bob peaking
  at mid-stance (the head translates with the foot cycle: Iwao, Maejima, Kubo & Morishima, section 1,
  Figure 4; the paper carries no year), lowered where a long step needs it so both legs reach.
* **Feet.** Stance: heel rocker during double support, flat, toe rocker from heel-off to toe-off (Perry's
  gait phases). Swing: the ankle moves horizontally on a minimum-jerk profile while the lowest sole point
  rises to ``clearance``, holds, and comes down onto the heel.
* **Servos.** Every gait joint has an integrated-velocity servo (``force = kp (act - q) - kv q'``). Once
  per control step the gait sets the setpoint velocity so the setpoint ramps (inside MuJoCo, every
  substep) to the next target plus a velocity lead ``(kv + damping) / kp * q'_target``, which cancels the
  servo's velocity lag: the joint tracks ``q_target`` with feed-forward, without Python per substep.

* **Hooks.** A gait variant changes what a footstep means by overriding the documented hooks, never the
  per-step path (``_targets``, ``_latch``): :meth:`WalkerGait.place_foothold` (a latched command ->
  the foothold), :meth:`WalkerGait.pelvis_waypoint` (the pelvis channels at a mid-stance),
  :meth:`WalkerGait.stance_pose` and :meth:`WalkerGait.swing_pose` (a foot on or between footholds),
  :meth:`WalkerGait.ankles_from_hips` (the ankles in the pelvis heading frame) and
  :meth:`WalkerGait.root_yaw`.
* **Turning** (:class:`TurningGait`, SteppingStones only): a fourth footstep value turns the new
  foothold's heading from the previous one's by up to ``max_turn_deg`` (45 deg: between the 30 and 60
  deg one-step turns of Patla et al. 1991); length and lateral offset count in the new heading's frame,
  the pelvis yaws through each foothold's heading at its mid-stance (a Catmull-Rom channel like its
  position) and the feet point along the pelvis (no hip-yaw joint). :class:`WalkerGait` itself, the
  gait of ObstacleWalk and ObstacleDodge, never turns. It is not :class:`TurningGait` at heading 0: the
  two write the same foot and hip offsets with their floating-point operations associated differently
  (``u - l_heel - ...`` vs ``u + cos(h) * (-l_heel + ...)``), so their targets differ in the last bits
  (within 1e-9 rad, tests/test_walker.py) and every ObstacleWalk and ObstacleDodge golden episode would
  change.

The ground is flat at z = 0 and supports the feet by construction: the floor is not in contact with the
feet, the gait puts the stance soles at z = 0 (see ``envs_assets/README.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import acos, atan2, cos, sin, sqrt

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.core import args
from visuomotor_gym.core.args import Num, Pair

DEG = math.pi / 180.0
LEFT, RIGHT = 0, 1


# What each GaitParams field accepts (visuomotor_gym.core.args.check_fields). Modelling choices: the
# ranges the scripted gait was built and tested for (a walker with ~0.86 m legs: 0.43 m thigh and shank,
# envs_assets/walker_body.xml), generous around the defaults; none is sourced. The timings must also be
# whole numbers of physics steps (WalkerGait checks that: it knows the model's timestep).
GAIT_RULES = {
    "step_s": Num(0.2, 2.0),
    "double_support_s": Num(0.0, 1.0, low_open=True),
    "heel_off_s": Num(0.0, 2.0, low_open=True),
    "nominal_step_m": Num(0.05, 1.5),
    "step_range_m": Pair(Num(0.05, 1.5)),
    "lateral_range_m": Pair(Num(-0.5, 0.5)),
    "step_width_m": Num(0.0, 0.5),
    "min_step_width_m": Num(0.0, 0.5),
    "nominal_clearance_m": Num(0.0, 0.6, low_open=True),
    "clearance_range_m": Pair(Num(0.0, 0.6, low_open=True)),
    "pelvis_height_m": Num(0.5, 1.0),
    "bob_m": Num(0.0, 0.2),
    "sway_m": Num(0.0, 0.2),
    "pelvis_lead_m": Num(-0.3, 0.3),
    "heel_strike_deg": Num(0.0, 60.0),
    "toe_off_deg": Num(0.0, 80.0),
    # Each phase of the swing lasts >= 5 % of it, the horizontal move >= half of it: shorter ones ask the
    # servos for speeds the physics cannot follow (a 1e-6 move diverges at once).
    "swing_rise": Num(0.05, 0.5),
    "swing_fall": Num(0.5, 0.95),
    "swing_move": Pair(Num(0.0, 1.0), min_width=0.5),
    "arm_swing_deg": Num(0.0, 90.0),
    "max_reach": Num(0.5, 1.0, high_open=True),
    "max_turn_deg": Num(0.0, 90.0),
}
# Orders between fields: the gait's phases follow one another, the nominal footstep is a commandable one.
GAIT_ORDER = (
    ("double_support_s", "<", "step_s"),
    ("min_step_width_m", "<=", "step_width_m"),
    ("nominal_step_m", "in", "step_range_m"),
    ("nominal_clearance_m", "in", "clearance_range_m"),
    ("swing_rise", "<", "swing_fall"),
)


@dataclass(frozen=True)
class GaitParams:
    """Timing, geometry and limits of the scripted gait (SI units; angles in degrees)."""

    # 0.5 s per step = 120 steps/min (modelling choice at the top of free walking cadence, ~100-120
    # steps/min); with the nominal 0.65 m step the speed is 1.3 m/s, inside the comfortable speeds of
    # adults, 1.27-1.46 m/s (Bohannon 1997, Age Ageing 26:15).
    step_s: float = 0.5
    # Each double support is 10 % of the stride (Perry's gait phases: loading response 0-10 %).
    double_support_s: float = 0.1
    # Heel rise at ~31 % of the stride (Perry: terminal stance 31-50 %, toe-off at 60 %).
    heel_off_s: float = 0.31
    nominal_step_m: float = 0.65
    # Step length and lateral offset limits of the action (modelling choice: what the leg reaches in
    # 0.5 s with the pelvis lowered at most ~5 cm).
    step_range_m: tuple[float, float] = (0.25, 0.95)
    lateral_range_m: tuple[float, float] = (-0.3, 0.3)
    # Lateral distance between the feet (modelling choice within the ~0.10-0.13 m reported for
    # preferred walking); feet never come closer than ``min_step_width_m`` (they would cross).
    step_width_m: float = 0.12
    min_step_width_m: float = 0.06
    # The lowest sole point's height in the carry phase of the swing (action "toe clearance").
    # Nominal 5 cm and 2-45 cm range: modelling choice (covers ObstacleWalk's 5-30 cm obstacles with
    # ~10-15 cm to spare).
    nominal_clearance_m: float = 0.05
    clearance_range_m: tuple[float, float] = (0.02, 0.45)
    # Hip-joint height at mid-stance and the vertical excursion of the pelvis (and head) per step,
    # peak to peak: modelling choice within the 3-5 cm usually reported for the centre of mass at
    # 1.2-1.4 m/s (e.g. Orendurff et al. 2004, J Rehabil Res Dev 41:829 [recalled]).
    pelvis_height_m: float = 0.915
    bob_m: float = 0.04
    # Pelvis side-to-side amplitude toward the stance foot, and how far ahead of the stance ankle it
    # passes at mid-stance (modelling choices: COM sway ~4 cm peak to peak; the COM passes over the
    # mid-foot, a few cm ahead of the ankle).
    sway_m: float = 0.02
    pelvis_lead_m: float = 0.06
    # Foot angle to the floor at heel strike (toe up) and at toe-off (toe down): modelling choices
    # (a neutral ankle under a shank inclined ~25 deg at initial contact; a steep push-off).
    heel_strike_deg: float = 25.0
    toe_off_deg: float = 45.0
    # Swing profile, in fractions of the swing: the sole reaches the clearance at ``swing_rise``,
    # starts down at ``swing_fall``; the ankle moves horizontally between ``swing_move`` (modelling choice).
    swing_rise: float = 0.3
    swing_fall: float = 0.7
    swing_move: tuple[float, float] = (0.1, 0.9)
    # Arm swing amplitude about the shoulder, opposite to the legs (modelling choice).
    arm_swing_deg: float = 15.0
    # The IK never asks for more than this fraction of the hip-ankle reach (the knee keeps >= ~16 deg).
    max_reach: float = 0.99
    # Largest heading change of one footstep (:class:`TurningGait` only, SteppingStones; the gait of
    # ObstacleWalk and ObstacleDodge never turns). Walkers at their preferred speed turn by 30 and 60 deg
    # within a step when told a step ahead (Patla, Prentice, Robinson & Neufeld 1991, J Exp Psychol Hum
    # Percept Perform 17(3):603-634: its abstract confirms cued direction changes planned in the previous
    # step; the 30/60 deg values are recalled, not checked in its text); 45 deg is a modelling choice
    # between the two, above ALLSTEPS'
    # +-30 deg path changes (Xie et al. 2020) plus the ~10 deg the alternating feet add.
    max_turn_deg: float = 45.0

    def __post_init__(self) -> None:
        args.check_fields(self, GAIT_RULES, GAIT_ORDER)
        mid, toe_off = 0.5 * (self.step_s + self.double_support_s), self.step_s + self.double_support_s
        if not mid < self.heel_off_s < toe_off:  # the phases in order (WalkerGait, in physics steps)
            raise args.ParamValueError(type(self).__name__, (
                f"heel_off_s must lie between mid-stance, (step_s + double_support_s) / 2 = {mid:g} s, and toe-off, "
                f"step_s + double_support_s = {toe_off:g} s; got {self.heel_off_s!r}"))


def _smooth(s: float) -> float:
    """Minimum-jerk (quintic) 0 -> 1 on s in [0, 1], clipped outside."""
    if s <= 0.0:
        return 0.0
    if s >= 1.0:
        return 1.0
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


@dataclass(slots=True)
class FootPlan:
    """A foot's planned pose at one instant (path frame u forward, v left; z up)."""

    u: float
    v: float
    z: float  # ankle height
    pitch: float  # radians, toe up positive
    stance: bool
    swing_fraction: float  # 0..1 in swing, -1 in stance
    sole_h: float = 0.0  # planned height of the lowest sole point


class WalkerGait:
    """Scripted gait of the walker (``envs_assets/walker.xml``): footstep commands in, servo setpoints out.

    Use::

        gait = WalkerGait(model)
        gait.reset(model, data, x=0.0, y=0.0, yaw=0.0)     # walking at the nominal speed, left heel down at (x, y)
        every control step (dt = n_substeps * timestep):
            gait.set_next_footstep(length, lateral, clearance)   # latched at the next mid-stance
            gait.advance(data, dt)                              # sets the servos' ctrl for this step
            mujoco.mj_step(model, data, nstep=n_substeps)
            # (a task that classifies leg contacts steps through
            #  visuomotor_gym.tasks.walk_contacts.LegContacts.step_physics instead)
    """

    # Horizontal distance from the pelvis within which an obstacle could touch a leg (m): a toe is at
    # most ~0.85 m from the pelvis (0.95 m step, toe 0.2 m ahead of the ankle); 1.0 m keeps a margin.
    # Contact classifiers check only obstacles this near (LegContacts.near).
    CONTACT_RADIUS_M = 1.0

    def __init__(self, model: mujoco.MjModel, params: GaitParams | None = None) -> None:
        self.p = p = params or GaitParams()
        m = self.model = model
        ts = float(m.opt.timestep)
        self.timestep = ts

        def ticks(seconds: float, what: str) -> int:
            n = round(seconds / ts)
            if n <= 0 or abs(n * ts - seconds) > 1e-9:
                raise ValueError(f"{what}={seconds} s is not a whole number of {ts} s physics steps")
            return n

        self.T = ticks(p.step_s, "step_s")
        self.T_ds = ticks(p.double_support_s, "double_support_s")
        self.T_ho = ticks(p.heel_off_s, "heel_off_s")
        self.T_mid = self.T_ds + (self.T - self.T_ds) // 2  # mid-stance = mid-swing of the other foot
        if not self.T_ds < self.T_mid < self.T_ho < self.T + self.T_ds:
            raise ValueError("gait timing must satisfy double support < mid-stance < heel-off < toe-off")

        def jid(name):
            j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
            if j < 0:
                raise ValueError(f"the model has no joint {name!r}: is it envs_assets/{wn.WALKER_SCENE}?")
            return j

        def bid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)

        def sid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)

        # Geometry read from the compiled model (one source: the XML).
        thigh = bid(wn.WALKER_THIGHS[LEFT])
        self.hip_y = float(m.body_pos[thigh][1])  # hip joint offset from the pelvis origin (left, +y)
        self.L1 = -float(m.body_pos[bid(wn.WALKER_SHINS[LEFT])][2])
        self.L2 = -float(m.body_pos[bid(wn.WALKER_FEET[LEFT])][2])
        self.h_ankle = -float(m.site_pos[sid(wn.WALKER_SOLES[LEFT])][2])
        self.l_toe = float(m.site_pos[sid(wn.WALKER_TOES[LEFT])][0])
        self.l_heel = -float(m.site_pos[sid(wn.WALKER_HEELS[LEFT])][0])
        self.d_max = p.max_reach * (self.L1 + self.L2)

        joints = [jid(n) for n in wn.WALKER_GAIT_JOINTS]
        self._qpos_idx = [int(m.jnt_qposadr[j]) for j in joints]
        self._dof_idx = [int(m.jnt_dofadr[j]) for j in joints]
        # Public read-only copies: where each gait joint (``WALKER_GAIT_JOINTS`` order: root x, y, z, yaw
        # first) sits in ``qpos`` and ``qvel``.
        self.qpos_index, self.dof_index = tuple(self._qpos_idx), tuple(self._dof_idx)
        acts = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in wn.WALKER_GAIT_ACTUATORS]
        if min(acts) < 0:
            raise ValueError("the model lacks some walker gait actuators")
        self._act = np.array(acts)
        if not np.array_equal(self._act, np.arange(acts[0], acts[0] + len(acts))):
            raise ValueError("walker gait actuators must be consecutive")
        self._ctrl = slice(acts[0], acts[0] + len(acts))
        adr = [int(m.actuator_actadr[a]) for a in acts]
        self._actslice = slice(adr[0], adr[0] + len(adr))
        kp = m.actuator_gainprm[acts, 0]
        kv = -m.actuator_biasprm[acts, 2]
        damping = m.dof_damping[self._dof_idx]
        self._lead = ((kv + damping) / kp).tolist()  # velocity lead of each servo setpoint (s)
        rng = m.jnt_range[joints]
        limited = m.jnt_limited[joints].astype(bool)
        margin = 1.0 * DEG
        self._lo = [float(r[0]) + margin if lim else -math.inf for r, lim in zip(rng, limited)]
        self._hi = [float(r[1]) - margin if lim else math.inf for r, lim in zip(rng, limited)]
        self._lo_a, self._hi_a = np.array(self._lo), np.array(self._hi)
        self._lead_a = np.array(self._lead)

        self.pelvis_body = bid(wn.WALKER_PELVIS)
        self.sole_sites = [sid(n) for n in wn.WALKER_SOLES]
        self._n_ctrl_ticks = 0
        self._dt_seen, self._dt_ticks = None, 0  # advance(): the last dt and its physics steps
        self._cache_constants()
        self.reset_plan(0.0, 0.0, 0.0)

    # ------------------------------------------------------------------ plan
    def reset_plan(self, x: float, y: float, yaw: float) -> None:
        """Nominal footholds around the start: foothold 0 (left) at the path origin (x, y)."""
        p = self.p
        self.origin = (float(x), float(y))
        self.yaw = float(yaw)
        # The path frame's axes in the world (u forward, v left): foothold_world's rotation.
        self.path_cos, self.path_sin = math.cos(self.yaw), math.sin(self.yaw)
        self.tick = 0
        self.u = {}
        self.v = {}
        self.clearance = {}
        half = 0.5 * p.step_width_m
        for j in range(-3, 2):
            self.u[j] = j * p.nominal_step_m
            self.v[j] = half if j % 2 == LEFT else -half
            self.clearance[j] = p.nominal_clearance_m
        self.commanded = {}  # foothold index -> the (length, lateral, clearance) latched for it
        self.pending = None
        self.next_latch_tick = self.T_mid  # mid-stance of foothold 0 latches foothold 2
        self._seg_j, self._seg = None, None
        self._hist: list = []  # the last targets (tick, q), for the velocity lead

    @staticmethod
    def side_of(j: int) -> int:
        return j % 2  # 0 = left (even footholds), 1 = right

    def set_next_footstep(self, length: float, lateral: float = 0.0, clearance: float | None = None) -> None:
        """The footstep to take next (metres): latched for the next step of the foot now in mid-stance.

        ``length``: forward distance from the previous foothold (the other foot's); ``lateral``: offset
        from the nominal step width, positive to the left; ``clearance``: height of the lowest sole point
        over the swing's carry phase. Values are clipped to the ranges of :class:`GaitParams`."""
        p = self.p
        if (length is not None and lateral is not None and clearance is not None and math.isfinite(length)
                and math.isfinite(lateral) and math.isfinite(clearance)):
            # The common case, clipped with the comparisons min(max(x, lo), hi) makes.
            (l0, l1), (a0, a1), (c0, c1) = p.step_range_m, p.lateral_range_m, p.clearance_range_m
            x, y, c = float(length), float(lateral), float(clearance)
            if l0 > x:
                x = l0
            if l1 < x:
                x = l1
            if a0 > y:
                y = a0
            if a1 < y:
                y = a1
            if c0 > c:
                c = c0
            if c1 < c:
                c = c1
            self.pending = (x, y, c)
            return
        for name, value in (("length", length), ("lateral", lateral), ("clearance", clearance)):
            if value is not None and not math.isfinite(value):
                raise ValueError(f"footstep {name} must be finite, got {value}")
        c = p.nominal_clearance_m if clearance is None else clearance
        self.pending = (
            min(max(float(length), p.step_range_m[0]), p.step_range_m[1]),
            min(max(float(lateral), p.lateral_range_m[0]), p.lateral_range_m[1]),
            min(max(float(c), p.clearance_range_m[0]), p.clearance_range_m[1]),
        )

    @property
    def nominal_footstep(self) -> tuple:
        """The command latched when none is pending: the nominal step, straight, nominal clearance."""
        p = self.p
        return (p.nominal_step_m, 0.0, p.nominal_clearance_m)

    def _latch(self) -> None:
        """Mid-stance of foothold k: fix foothold k + 2 from the pending command (or the nominal one)."""
        k = (self.next_latch_tick - self.T_mid) // self.T
        j = k + 2
        cmd = self.pending or self.nominal_footstep
        self.pending = None
        self.place_foothold(j, cmd)
        self.commanded[j] = cmd
        self.next_latch_tick += self.T

    # ------------------------------------------------------------------ hooks (a gait variant overrides these)
    def place_foothold(self, j: int, cmd: tuple) -> None:
        """Hook: fix foothold ``j`` (``u``, ``v``, ``clearance``) from the latched command ``cmd``
        (:meth:`set_next_footstep`'s values, clipped): ``length`` forward of foothold ``j - 1`` along
        the path, the step width (never under ``min_step_width_m``) plus ``lateral`` across it."""
        p = self.p
        length, lateral, clearance = cmd
        sign = 1.0 if self.side_of(j) == LEFT else -1.0
        width = max(p.step_width_m + sign * lateral, p.min_step_width_m)
        self.u[j] = self.u[j - 1] + length
        self.v[j] = self.v[j - 1] + sign * width
        self.clearance[j] = clearance

    def pelvis_waypoint(self, i: int) -> tuple:
        """Hook: the pelvis channels at the mid-stance of foothold ``i`` (path frame ``(u, v)``; a
        variant may add channels, e.g. a yaw): a little ahead of the stance ankle, shifted toward it."""
        p = self.p
        sign = 1.0 if self.side_of(i) == LEFT else -1.0
        return (self.u[i] + p.pelvis_lead_m, self.v[i] - sign * (0.5 * p.step_width_m - p.sway_m))

    def ankles_from_hips(self, left: tuple, right: tuple, pelvis: tuple) -> tuple[float, float, float, float]:
        """Hook: each ankle's offset (forward, left) from its hip joint in the pelvis heading frame,
        ``(du_left, dv_left, du_right, dv_right)``, for the feet's plans ``left``, ``right``
        (:meth:`stance_pose` tuples) and the pelvis channels ``pelvis``. The pelvis keeps the path
        heading here."""
        pu, pv, hy = pelvis[0], pelvis[1], self.hip_y
        return left[0] - pu, left[1] - (pv + hy), right[0] - pu, right[1] - (pv + -hy)

    def root_yaw(self, pelvis: tuple) -> float:
        """Hook: the root yaw joint's target (rad, world) for the pelvis channels ``pelvis``: the path
        heading here."""
        return self.yaw

    # ------------------------------------------------------------------ kinematic plan at one tick
    def _pelvis_at(self, tick: int) -> tuple:
        """Catmull-Rom through the mid-stance waypoints (uniform in time), every channel of
        :meth:`pelvis_waypoint`; a segment's cubics are built once, when first needed (its four
        waypoints are all latched by then)."""
        j = (tick - self.T_mid) // self.T  # segment from waypoint j to j + 1
        s = (tick - self.T_mid - j * self.T) / self.T
        if self._seg_j != j:
            self._seg_j, self._seg = j, self._pelvis_segment(j)
        return tuple(c[0] + s * (c[1] + s * (c[2] + s * c[3])) for c in self._seg)

    def pelvis_at(self, tick: int) -> tuple:
        """The planned pelvis channels at ``tick``: path-frame ``(u, v)`` (and, on :class:`TurningGait`,
        the yaw relative to the start)."""
        return self._pelvis_at(tick)

    def _pelvis_segment(self, j: int) -> tuple:
        pts = [self.pelvis_waypoint(i) for i in (j - 1, j, j + 1, j + 2)]
        out = []
        for a in range(len(pts[0])):
            p0, p1, p2, p3 = pts[0][a], pts[1][a], pts[2][a], pts[3][a]
            out.append((p1, 0.5 * (p2 - p0), 0.5 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3),
                        0.5 * (3.0 * p1 - p0 - 3.0 * p2 + p3)))
        return tuple(out)

    def _foot_from_pivot(self, pu: float, pivot_x: float, pitch: float) -> tuple[float, float]:
        """Ankle (u, z) of a foot pitched by ``pitch`` whose sole point at foot-x ``pivot_x`` is on the
        ground at u = ``pu``."""
        c, s = math.cos(pitch), math.sin(pitch)
        # ankle = pivot + R(pitch) (-pivot_x, h_ankle), R rotating x toward z (toe up positive)
        return pu - pivot_x * c - self.h_ankle * s, -pivot_x * s + self.h_ankle * c

    # The per-step path below (``stance_pose``, ``swing_pose``, ``_targets``, ``advance``) is written out in
    # scalar Python on tuples, with the gait's constants computed once (``_cache_constants``) and
    # ``min``/``max`` written as the comparisons the builtins make: every floating-point operation is
    # the one of the plain formulas (``_foot_from_pivot``, ``_smooth``, the FootPlan fields, the numpy
    # clip), in the same order, so the targets are bit-identical to them; only Python overhead is gone.
    def _cache_constants(self) -> None:
        p = self.p
        self._heel_rad = p.heel_strike_deg * DEG
        self._neg_toe_rad = -p.toe_off_deg * DEG
        self._neg_toe_deg, self._heel_deg = -p.toe_off_deg, p.heel_strike_deg
        self._toe_span = self.T + self.T_ds - self.T_ho  # ticks from heel-off to toe-off
        self._swing_ticks = self.T - self.T_ds
        # The swing's start and end ankle positions relative to their footholds (_foot_from_pivot with
        # the toe-off and heel-strike pitches): u - pivot_x cos - h_ankle sin, the two products fixed.
        t0, t1 = -p.toe_off_deg * DEG, p.heel_strike_deg * DEG
        self._a0c, self._a0s = self.l_toe * math.cos(t0), self.h_ankle * math.sin(t0)
        self._a1c, self._a1s = -self.l_heel * math.cos(t1), self.h_ankle * math.sin(t1)
        self._move0, self._move_span = p.swing_move[0], p.swing_move[1] - p.swing_move[0]
        self._fall_span = 1.0 - p.swing_fall
        self._two_pi = 2.0 * math.pi
        self._half_bob = 0.5 * p.bob_m
        self._d_max2 = self.d_max * self.d_max
        self._L1sq, self._L2sq, self._L12x2 = self.L1 * self.L1, self.L2 * self.L2, 2.0 * self.L1 * self.L2
        self._arm_rad = p.arm_swing_deg * DEG
        # The clip of the targets to the joints' ranges: each leg's five joints in target order, and
        # the other limited joints (a min/max against an infinite bound is the identity).
        lo, hi = self._lo, self._hi
        self._leg_bounds = tuple(tuple((lo[i], hi[i]) for i in range(4 + 5 * side, 9 + 5 * side)) for side in (LEFT, RIGHT))
        self._other_clip = [(i, lo[i], hi[i]) for i in (0, 1, 2, 3, 14, 15)
                            if lo[i] != -math.inf or hi[i] != math.inf]

    def stance_pose(self, j: int, s_tick: int) -> tuple:
        """Hook: the foot standing on foothold ``j``, ``s_tick`` physics steps after its heel strike,
        as a tuple ``(u, v, z, pitch, stance, sole_h)`` (ankle in the path frame, pitch toe up; the
        per-step form of :class:`FootPlan`): heel rocker, flat, toe rocker along the path."""
        u = self.u[j]
        if s_tick < self.T_ds:  # heel rocker
            s = s_tick / self.T_ds  # _smooth(s) inline
            sm = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
            pitch = self._heel_rad * (1.0 - sm)
            c, s = cos(pitch), sin(pitch)
            lh, ha = self.l_heel, self.h_ankle
            return (u - lh - -lh * c - ha * s, self.v[j], lh * s + ha * c, pitch, True, 0.0)
        if s_tick < self.T_ho:
            return (u, self.v[j], self.h_ankle, 0.0, True, 0.0)
        # toe rocker until toe-off
        s = (s_tick - self.T_ho) / self._toe_span
        sm = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
        pitch = self._neg_toe_rad * sm
        c, s = cos(pitch), sin(pitch)
        lt, ha = self.l_toe, self.h_ankle
        return (u + lt - lt * c - ha * s, self.v[j], -lt * s + ha * c, pitch, True, 0.0)

    def swing_pose(self, j_from: int, j_to: int, tau: float) -> tuple:
        """Hook: the foot swinging from foothold ``j_from`` to ``j_to`` at swing fraction ``tau``, as
        :meth:`stance_pose`'s tuple: the ankle moves along the path between its toe-off and heel-strike
        places; height and pitch from :meth:`_swing_height`."""
        u, v = self.u, self.v
        a0u = u[j_from] + self.l_toe - self._a0c - self._a0s
        a1u = u[j_to] - self.l_heel - self._a1c - self._a1s
        s = (tau - self._move0) / self._move_span  # prog = _smooth(s), inline
        prog = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
        au = a0u + (a1u - a0u) * prog
        v0 = v[j_from]
        av = v0 + (v[j_to] - v0) * prog
        z, pitch, h = self._swing_height(j_to, tau)
        return (au, av, z, pitch, False, h)

    def _swing_height(self, j_to: int, tau: float) -> tuple[float, float, float]:
        """(ankle height, pitch, lowest sole point's height) of a swing toward foothold ``j_to`` at
        swing fraction ``tau``: the pitch from toe-off to heel strike, the sole lifted to the
        foothold's clearance, held, set down."""
        s = tau / 0.4
        s1 = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
        s = (tau - 0.6) / 0.4
        s2 = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
        pitch = (self._neg_toe_deg * (1.0 - s1) + self._heel_deg * s2) * DEG
        p = self.p
        if tau < p.swing_rise:
            s = tau / p.swing_rise
        elif tau > p.swing_fall:
            s = (1.0 - tau) / self._fall_span
        else:
            s = 1.0
        lift = 0.0 if s <= 0.0 else 1.0 if s >= 1.0 else s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
        h = self.clearance[j_to] * lift
        sp, cp = sin(pitch), cos(pitch)
        a, b = self.l_toe * sp, -self.l_heel * sp
        lowest = (b if b < a else a) - self.h_ankle * cp  # sole corners vs the ankle
        return h - lowest, pitch, h

    def _stance_foot(self, j: int, s_tick: int) -> FootPlan:
        u, v, z, pitch, _, _ = self.stance_pose(j, s_tick)
        return FootPlan(u, v, z, pitch, True, -1.0)

    def _swing_foot(self, j_from: int, j_to: int, tau: float) -> FootPlan:
        u, v, z, pitch, _, h = self.swing_pose(j_from, j_to, tau)
        return FootPlan(u, v, z, pitch, False, tau, h)

    def feet_at(self, tick: int) -> tuple[FootPlan, FootPlan]:
        """Both feet's planned poses at ``tick`` (physics steps since reset), (left, right)."""
        k = tick // self.T  # the current step: foothold k landed last
        s = tick - k * self.T
        lead = self._stance_foot(k, s)
        if s < self.T_ds:
            trail = self._stance_foot(k - 1, s + self.T)
        else:
            trail = self._swing_foot(k - 1, k + 1, (s - self.T_ds) / (self.T - self.T_ds))
        return (lead, trail) if self.side_of(k) == LEFT else (trail, lead)

    def targets_at(self, tick: int) -> np.ndarray:
        """Joint targets of every gait joint (``WALKER_GAIT_JOINTS`` order) at ``tick``, inside the
        joints' ranges."""
        return np.array(self._targets(tick))

    def _targets(self, tick: int) -> list[float]:
        """:meth:`targets_at` as a list of floats (the per-step path, through the hooks)."""
        T = self.T
        pelvis = self._pelvis_at(tick)
        pu, pv = pelvis[0], pelvis[1]
        phase = self._two_pi * ((tick - self.T_mid) % T) / T
        z = self.p.pelvis_height_m - self._half_bob * (1.0 - cos(phase))
        # The feet (feet_at): the one that landed last in stance, the other in stance or swing.
        k = tick // T  # the current step: foothold k landed last
        s = tick - k * T
        lead = self.stance_pose(k, s)
        if s < self.T_ds:
            trail = self.stance_pose(k - 1, s + T)
        else:
            trail = self.swing_pose(k - 1, k + 1, (s - self.T_ds) / self._swing_ticks)
        left, right = (lead, trail) if k % 2 == LEFT else (trail, lead)
        du0, dv0, du1, dv1 = self.ankles_from_hips(left, right, pelvis)
        # Lower the pelvis where a leg would otherwise over-reach (long steps).
        d_max2 = self._d_max2
        r = d_max2 - du0 * du0 - dv0 * dv0
        zmax = left[2] + sqrt(0.0 if r < 0.0 else r)  # max(r, 0.0)
        if zmax < z:
            z = zmax
        r = d_max2 - du1 * du1 - dv1 * dv1
        zmax = right[2] + sqrt(0.0 if r < 0.0 else r)
        if zmax < z:
            z = zmax
        c, s = self.path_cos, self.path_sin
        ox, oy = self.origin
        out = [ox + c * pu - s * pv, oy + s * pu + c * pv, z, self.root_yaw(pelvis)]
        return self._leg_targets(out, left, du0, dv0, right, du1, dv1, z, tick)

    def _leg_targets(self, out: list, left: tuple, du0: float, dv0: float, right: tuple, du1: float, dv1: float,
                     z: float, tick: int) -> list[float]:
        """Append the legs' and arms' targets to ``out`` (the root's four): each foot's plan tuple and
        its ankle's offset (forward, left) from its hip joint in the pelvis heading frame, the pelvis
        height ``z``; clipped to the joints' ranges."""
        T = self.T
        leg_ik = self._leg_ik
        for foot, fx, fy, bounds in ((left, du0, dv0, self._leg_bounds[LEFT]), (right, du1, dv1, self._leg_bounds[RIGHT])):
            roll, hip, knee = leg_ik(fx, fy, foot[2] - z)
            ankle = foot[3] - (hip - knee)
            (lo0, hi0), (lo1, hi1), (lo2, hi2), (lo, hi), (lo4, hi4) = bounds
            if not foot[4]:
                n_fix = 0
                while not lo <= ankle <= hi and n_fix < 4:
                    # A high swing behind the body needs more dorsiflexion than the ankle has: let the foot
                    # hang at the ankle's limit and raise the ankle so the lowest sole point keeps its height
                    # (a few fixed-point passes: the raised ankle changes the shank's angle a little).
                    a = lo if lo > ankle else ankle  # min(max(ankle, lo), hi)
                    pitch = (hi if hi < a else a) + (hip - knee)
                    sp, cp = sin(pitch), cos(pitch)
                    a, b = self.l_toe * sp, -self.l_heel * sp
                    lowest = (b if b < a else a) - self.h_ankle * cp
                    roll, hip, knee = leg_ik(fx, fy, foot[5] - lowest - z)
                    ankle = pitch - (hip - knee)
                    n_fix += 1
            # The targets clipped to the ranges: min(max(x, lo), hi) for each.
            nroll = -roll
            if lo0 > roll:
                roll = lo0
            if hi0 < roll:
                roll = hi0
            if lo1 > hip:
                hip = lo1
            if hi1 < hip:
                hip = hi1
            if lo2 > knee:
                knee = lo2
            if hi2 < knee:
                knee = hi2
            if lo > ankle:
                ankle = lo
            if hi < ankle:
                ankle = hi
            if lo4 > nroll:
                nroll = lo4
            if hi4 < nroll:
                nroll = hi4
            out += (roll, hip, knee, ankle, nroll)
        arm = self._arm_rad * cos(math.pi * (tick % (2 * T)) / T)
        out += (-arm, arm)  # left arm back when the left foot lands
        for i, lo, hi in self._other_clip:
            x = out[i]
            if lo > x:
                x = lo
            if hi < x:
                x = hi
            out[i] = x
        return out

    def _leg_ik(self, fx: float, fy: float, fz: float) -> tuple[float, float, float]:
        """Hip roll, hip pitch and knee placing the ankle at (fx, fy, fz) from the hip joint (pelvis
        heading frame): roll turns the leg's plane toward the ankle, then the two-link law of cosines in
        that plane (the knee bends backward); beyond ``max_reach`` the leg stays at that reach."""
        roll = atan2(fy, -fz)
        dperp = sqrt(fy * fy + fz * fz)
        d2 = fx * fx + dperp * dperp
        d_max2 = self._d_max2
        if d_max2 < d2:  # min(d2, d_max^2)
            d2 = d_max2
        cos_k = (d2 - self._L1sq - self._L2sq) / self._L12x2
        if cos_k < -1.0:  # min(max(cos_k, -1), 1)
            cos_k = -1.0
        if cos_k > 1.0:
            cos_k = 1.0
        knee = acos(cos_k)
        L2 = self.L2
        hip = atan2(fx, dperp) + atan2(L2 * sin(knee), self.L1 + L2 * cos(knee))
        return roll, hip, knee

    # ------------------------------------------------------------------ MuJoCo side
    def reset(self, model: mujoco.MjModel, data: mujoco.MjData, x: float = 0.0, y: float = 0.0,
              yaw: float = 0.0) -> None:
        """Start walking at the nominal speed: left heel striking at the path origin (x, y), heading
        ``yaw``; joint positions, velocities and servo setpoints consistent with the plan; the rest of
        the scene (obstacles: :class:`visuomotor_gym.tasks.walk_scene.ObstaclePool`) is left as it is."""
        self.reset_plan(x, y, yaw)
        q0 = self.targets_at(0)
        qd = (self.targets_at(1) - self.targets_at(-1)) / (2.0 * self.timestep)
        data.qpos[self._qpos_idx] = q0
        data.qvel[self._dof_idx] = qd
        data.act[self._actslice] = q0 + self._lead_a * qd
        data.ctrl[self._ctrl] = qd
        self._hist = [(0, q0.tolist())]
        self.t0 = float(data.time)
        mujoco.mj_forward(model, data)

    def _set_dt(self, dt: float) -> None:
        """Check a control period (a whole number of physics steps, else ValueError) and keep it."""
        n = round(dt / self.timestep)
        if n < 1 or abs(n * self.timestep - dt) > 1e-9:
            raise ValueError(f"dt={dt} is not a whole number of {self.timestep} s physics steps")
        self._dt_seen, self._dt_ticks = dt, n

    def advance(self, data: mujoco.MjData, dt: float) -> None:
        """Plan the next ``dt`` seconds (a whole number of physics steps): latch footsteps whose
        mid-stance falls in it, and set every gait servo's setpoint velocity so that its setpoint
        reaches the target (with velocity lead) at the end of the step."""
        if dt != self._dt_seen:
            self._set_dt(dt)
        n = self._dt_ticks
        ts = self.timestep
        end = self.tick + n
        while self.next_latch_tick <= end:
            self._latch()
        q1 = self._targets(end)
        # Target velocity at ``end`` by a second-order backward difference over the last targets (the
        # plan up to a latch never changes, so earlier targets stay valid); after a reset or a change
        # of dt, from one more evaluation a physics step earlier. Element by element, the operations
        # of the array expressions qd = (3 q1 - 4 q_-1 + q_-2) * (0.5 / (n ts)) and
        # ctrl = (q1 + lead qd - act) * (1 / (n ts)).
        h = self._hist
        act = data.act[self._actslice].tolist()
        k2 = 1.0 / (n * ts)
        if len(h) == 2 and h[1][0] == end - n and h[0][0] == end - 2 * n:
            k = 0.5 / (n * ts)
            ctrl = [(q + lead * ((3.0 * q - 4.0 * b + c) * k) - a) * k2
                    for q, b, c, lead, a in zip(q1, h[1][1], h[0][1], self._lead, act)]
        else:
            ctrl = [(q + lead * ((q - b) / ts) - a) * k2
                    for q, b, lead, a in zip(q1, self._targets(end - 1), self._lead, act)]
        self._hist = [h[-1], (end, q1)] if h else [(end, q1)]
        data.ctrl[self._ctrl] = ctrl
        self.tick = end

    # ------------------------------------------------------------------ phases (what contact classifiers read)
    def phase_of(self, side: int, tick: int) -> tuple[bool, float]:
        """(in stance, swing fraction or -1) of foot ``side`` at ``tick``."""
        k = tick // self.T
        s = tick - k * self.T
        if self.side_of(k) == side or s < self.T_ds:
            return True, -1.0
        return False, (s - self.T_ds) / (self.T - self.T_ds)

    def foothold_of(self, side: int, tick: int) -> int:
        """The foothold foot ``side`` stands on (stance) or is swinging to (swing) at ``tick``."""
        k = tick // self.T
        if self.side_of(k) == side:
            return k
        return k - 1 if tick - k * self.T < self.T_ds else k + 1

    def tick_of(self, data: mujoco.MjData) -> int:
        """The gait tick (physics steps since :meth:`reset`) of ``data``'s time."""
        return round((float(data.time) - self.t0) / self.timestep)

    # ------------------------------------------------------------------ read-outs for tasks
    @property
    def time(self) -> float:
        """Gait time (s) of the last planned target."""
        return self.tick * self.timestep

    def step_phase(self, tick: int | None = None) -> float:
        """Fraction of the current step (0 at a heel strike) — the cycle of the head bob."""
        t = self.tick if tick is None else tick
        return (t % self.T) / self.T

    def stride_phase(self, tick: int | None = None) -> float:
        """Fraction of the stride (0 at a left heel strike)."""
        t = self.tick if tick is None else tick
        return (t % (2 * self.T)) / (2 * self.T)

    @property
    def next_footstep_index(self) -> int:
        """Index of the foothold that the next latch (at the coming mid-stance) will fix."""
        return (self.next_latch_tick - self.T_mid) // self.T + 2

    @property
    def next_latch_time(self) -> float:
        """Gait time (s) of the coming mid-stance, when the pending footstep is read."""
        return self.next_latch_tick * self.timestep

    def current_step(self, tick: int | None = None) -> int:
        """Index of the foothold that landed last."""
        return (self.tick if tick is None else tick) // self.T

    def foothold_world(self, j: int) -> tuple[float, float]:
        """World (x, y) of planned foothold ``j`` (the sole point under the ankle when flat)."""
        u, v = self.u[j], self.v[j]
        return self.origin[0] + self.path_cos * u - self.path_sin * v, self.origin[1] + self.path_sin * u + self.path_cos * v

    def feet_world(self, data: mujoco.MjData) -> np.ndarray:
        """(2, 3) sole-site positions, left then right."""
        return data.site_xpos[self.sole_sites].copy()

    def pelvis_pose(self, data: mujoco.MjData) -> tuple[np.ndarray, float]:
        """Pelvis world position and heading (rad)."""
        return data.xpos[self.pelvis_body].copy(), float(data.qpos[self._qpos_idx[3]])


class TurningGait(WalkerGait):
    """The scripted gait with a heading per footstep (SteppingStones): a footstep may turn.

    :meth:`set_next_footstep` takes a fourth value, ``turn`` (rad, + = left, clipped to
    ``GaitParams.max_turn_deg``): the heading ``h[j]`` of the latched foothold ``j`` is ``h[j - 1] +
    turn``, and the footstep's ``length`` and ``lateral`` count in *that* heading's frame (forward of the
    previous foothold along ``h[j]``, the step width across it). With every turn 0 the footholds are
    those of :class:`WalkerGait`. Footholds stay in the start's path frame (``u``, ``v``, so
    :meth:`foothold_world` and the observation read them unchanged); ``h`` is relative to the start yaw.

    * **Pelvis.** Its mid-stance waypoint over foothold ``j`` is placed in ``h[j]``'s frame (ahead of
      the stance ankle along ``h[j]``, shifted toward it across), and its **yaw** is a third Catmull-Rom
      channel through ``h[j]`` at the mid-stance of ``j`` (fixed when the segment starts, like the
      position: C1, never replanned). So the pelvis faces foothold ``j``'s heading at its mid-stance and
      turns smoothly between footholds (a 45 deg turn takes one 0.5 s step).
    * **Feet.** The walker has no hip-yaw joint (``walker_body.xml``, shared with ObstacleWalk and
      ObstacleDodge, is unchanged), so each foot points along the pelvis's yaw: at foothold ``j``'s
      mid-stance, flat, it points along ``h[j]``; in double support the stance foot pivots about its sole
      centre as the pelvis turns (modelling choice: the hip's internal/external rotation of a human step
      turn, Hase & Stein 1999, lumped into a pivot of the foot). The heel and toe rockers and the swing's
      start and end are placed along the foothold's heading (the foot's yaw differs from it by at most
      ~40 % of the step's turn there: a few cm of heel or toe slide in the sharpest turns; the supports
      only sense the feet). Legs follow by the same inverse kinematics, with each ankle taken into the
      pelvis's heading frame.
    """

    def reset_plan(self, x: float, y: float, yaw: float) -> None:
        super().reset_plan(x, y, yaw)
        self.h = dict.fromkeys(range(-3, 2), 0.0)  # foothold -> heading (rad) relative to the start yaw
        self.hc = dict.fromkeys(range(-3, 2), 1.0)  # its cosine and sine
        self.hs = dict.fromkeys(range(-3, 2), 0.0)

    @property
    def nominal_footstep(self) -> tuple:
        """:attr:`WalkerGait.nominal_footstep` and no turn."""
        p = self.p
        return (p.nominal_step_m, 0.0, p.nominal_clearance_m, 0.0)

    @property
    def pending_turn(self) -> float:
        """The turn (rad) of the pending footstep, 0 when none is pending."""
        return 0.0 if self.pending is None else self.pending[3]

    def set_next_footstep(self, length: float, lateral: float = 0.0, clearance: float | None = None,
                          turn: float = 0.0) -> None:
        """As :meth:`WalkerGait.set_next_footstep`, with ``turn`` (rad, + = left): the new foothold's
        heading change from the previous foothold's, clipped to +-``max_turn_deg``. The pending command
        is ``(length, lateral, clearance, turn)``."""
        if turn is None or not math.isfinite(turn):
            raise ValueError(f"footstep turn must be finite, got {turn}")
        super().set_next_footstep(length, lateral, clearance)
        lim = self.p.max_turn_deg * DEG
        self.pending = (*self.pending, min(max(float(turn), -lim), lim))

    def heading_of(self, j: int) -> float:
        """Heading (rad, world) of planned foothold ``j``."""
        return self.yaw + self.h[j]

    def pelvis_yaw_at(self, tick: int) -> float:
        """Planned pelvis yaw (rad, world) at ``tick``."""
        return self.yaw + self._pelvis_at(tick)[2]

    # --- the hooks ----------------------------------------------------------------------------
    def place_foothold(self, j: int, cmd: tuple) -> None:
        """Foothold ``j`` from ``(length, lateral, clearance, turn)``: heading ``h[j - 1] + turn``,
        ``length`` along it and the step width across it."""
        p = self.p
        length, lateral, clearance, turn = cmd
        sign = 1.0 if self.side_of(j) == LEFT else -1.0
        width = sign * max(p.step_width_m + sign * lateral, p.min_step_width_m)
        h = self.h[j - 1] + turn
        c, s = math.cos(h), math.sin(h)
        self.u[j] = self.u[j - 1] + c * length - s * width
        self.v[j] = self.v[j - 1] + s * length + c * width
        self.h[j], self.hc[j], self.hs[j] = h, c, s
        self.clearance[j] = clearance

    def pelvis_waypoint(self, i: int) -> tuple:
        """``(u, v, yaw)``: the straight gait's waypoint placed in foothold ``i``'s heading frame, and
        that heading (relative to the start yaw) as a third channel."""
        p = self.p
        sign = 1.0 if self.side_of(i) == LEFT else -1.0
        a, b = p.pelvis_lead_m, -sign * (0.5 * p.step_width_m - p.sway_m)
        c, s = self.hc[i], self.hs[i]
        return (self.u[i] + c * a - s * b, self.v[i] + s * a + c * b, self.h[i])

    def ankles_from_hips(self, left: tuple, right: tuple, pelvis: tuple) -> tuple[float, float, float, float]:
        """Each ankle taken into the pelvis's (turning) heading frame, from its hip joint."""
        pu, pv, ph = pelvis
        cph, sph = cos(ph), sin(ph)
        hy = self.hip_y
        rel = []
        for foot, off in ((left, hy), (right, -hy)):
            du, dv = foot[0] - pu, foot[1] - pv
            rel.append((cph * du + sph * dv, -sph * du + cph * dv - off))
        (du0, dv0), (du1, dv1) = rel
        return du0, dv0, du1, dv1

    def root_yaw(self, pelvis: tuple) -> float:
        """The start yaw plus the pelvis's yaw channel."""
        return self.yaw + pelvis[2]

    def stance_pose(self, j: int, s_tick: int) -> tuple:
        """The foot standing on foothold ``j``: the rockers along the foothold's heading."""
        if s_tick < self.T_ds:  # heel rocker
            sm = _smooth(s_tick / self.T_ds)
            pitch = self._heel_rad * (1.0 - sm)
            c, s = cos(pitch), sin(pitch)
            lh, ha = self.l_heel, self.h_ankle
            d, z = -lh + lh * c - ha * s, lh * s + ha * c
        elif s_tick < self.T_ho:
            return (self.u[j], self.v[j], self.h_ankle, 0.0, True, 0.0)
        else:  # toe rocker until toe-off
            pitch = self._neg_toe_rad * _smooth((s_tick - self.T_ho) / self._toe_span)
            c, s = cos(pitch), sin(pitch)
            lt, ha = self.l_toe, self.h_ankle
            d, z = lt - lt * c - ha * s, -lt * s + ha * c
        return (self.u[j] + self.hc[j] * d, self.v[j] + self.hs[j] * d, z, pitch, True, 0.0)

    def swing_pose(self, j_from: int, j_to: int, tau: float) -> tuple:
        """The swing from foothold ``j_from`` to ``j_to``: the ankle's start and end offsets along each
        foothold's heading, its path a straight line between them; height and pitch as
        :class:`WalkerGait`'s."""
        u, v, hc, hs = self.u, self.v, self.hc, self.hs
        d0 = self.l_toe - self._a0c - self._a0s
        d1 = -self.l_heel - self._a1c - self._a1s
        a0u, a0v = u[j_from] + hc[j_from] * d0, v[j_from] + hs[j_from] * d0
        a1u, a1v = u[j_to] + hc[j_to] * d1, v[j_to] + hs[j_to] * d1
        prog = _smooth((tau - self._move0) / self._move_span)
        au, av = a0u + (a1u - a0u) * prog, a0v + (a1v - a0v) * prog
        z, pitch, h = self._swing_height(j_to, tau)
        return (au, av, z, pitch, False, h)
