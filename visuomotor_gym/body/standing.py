"""The standing body of PushRecovery (Eom et al. 2019, section 7): a body that can fall.

The walker's legs and pelvis on a **free joint** (``envs_assets/push.xml``), the seated body's waist
(3-DOF torso joints), 7-DOF right arm with its palm and that arm mirrored as the left, and the shared head
and eye. It stands on the
floor through real foot-floor contact; the legs hold a fixed stance through position servos (their
gains: ``envs_assets/README.md``, PushRecovery), so a push that carries the centre of mass past the
feet's edge tips it over: nothing keeps it upright but its feet and, if it puts it there, its hand.

Gravity compensation is switched off on every body of the model (the shared head fragment asks for it,
as the seated and walking bodies are kinematically held): a compensated head would be an external force
holding the body up.

Actions: ``hand_target`` (3 values in [-1, 1] onto :data:`HAND_WORKSPACE`, stance frame) that the seated
body's damped-least-squares controller (:mod:`visuomotor_gym.control.hand`) turns into waist and arm
setpoints on the floating base, then ``brace`` (1 value): the arms' stiffness, from relaxed (-1:
:data:`RELAXED_STIFFNESS` of the servos' gain) to braced (+1: the full gain of the seated arm's servos), then
``arm`` (1 value, since PushRecovery's eighth pass): which arm the hand target drives, <= 0 the right, > 0 the left
(the sign of the stance frame's y on that side). The left arm is the right one mirrored (``l_`` names), driven
by the same controller mirrored; the idle arm returns to hang at the side (:data:`REST_POSTURE_DEG`), and the
arm taking over starts its reference where its hand is. At reset the right arm is active (in the ready posture)
and the left one hangs. The target stays in the stance frame (world axes) whichever arm moves.

Observations are in the **stance frame** (:data:`STANCE_FRAME`): origin at the pelvis's start (0, 0,
0.93 m), axes of the world (x forward, y left, z up); the body does not walk, so the frame stays put
while it sways or falls.
"""

from __future__ import annotations

import math
from collections import deque

import mujoco
import numpy as np

from visuomotor_gym.body import names
from visuomotor_gym.control.hand import HandController, HandControlParams
from visuomotor_gym.core.frames import FixedFrame
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Body
from visuomotor_gym.oculomotor.plant import DEG

# --- names of envs_assets/push.xml beyond those of body/names.py (the arm, head and eye keep theirs) ----
SCENE = "push.xml"
PELVIS = "pelvis"
ROOT_JOINT = "root"
FLOOR_GEOM = "floor"
FEET_GEOMS = ("left_foot", "right_foot")
SOLE_SITES = ("left_sole", "right_sole")
HAND_GEOMS = ("palm", "forearm", "l_palm", "l_forearm")  # each hand and the forearm that carries it (a brace)
# The left arm (PushRecovery's eighth pass): the right arm mirrored across the sagittal plane, its names prefixed "l_"
# (envs_assets/push.xml; the mirrored joints keep the right arm's angle meanings and ranges).
LEFT_PREFIX = "l_"
LEFT_ARM_JOINTS = tuple(LEFT_PREFIX + n for n in names.ARM_JOINTS)
LEFT_ARM_ACTUATORS = LEFT_ARM_JOINTS
LEFT_HAND = LEFT_PREFIX + names.HAND
LEFT_PALM_CENTER = LEFT_PREFIX + names.PALM_CENTER
LEG_JOINTS = ("left_hip_roll", "left_hip_pitch", "left_knee", "left_ankle_pitch", "left_ankle_roll",
              "right_hip_roll", "right_hip_pitch", "right_knee", "right_ankle_pitch", "right_ankle_roll")
LEG_ACTUATORS = LEG_JOINTS
# The stance the leg servos hold (rad, LEG_JOINTS order). Hips abducted 0.08 rad (4.6 deg) with the ankles
# rolled back so the soles stay flat: sole centres 32 cm apart, about shoulder width (modelling choice: a
# braced, shoulder-width stance; the walker's hips alone put them 18 cm apart). Ankles dorsiflexed 0.03 rad
# so that the centre of mass stands ~4 cm ahead of the ankles, as in human quiet standing (Winter 1995,
# "Human balance and posture control during standing and walking", Gait & Posture 3: the CoM a few cm
# anterior to the ankle joint; recalled, modelling choice); at 0 the CoM sits over the heels' edge and any
# backward arm movement tips the body over.
STANCE_HIP_ROLL_RAD = 0.08
STANCE_ANKLE_PITCH_RAD = 0.03
STANCE_RAD = (STANCE_HIP_ROLL_RAD, 0.0, 0.0, STANCE_ANKLE_PITCH_RAD, -STANCE_HIP_ROLL_RAD,
              -STANCE_HIP_ROLL_RAD, 0.0, 0.0, STANCE_ANKLE_PITCH_RAD, STANCE_HIP_ROLL_RAD)
# The automatic postural response of the legs: the ankle strategy is ON in the definition since the fourth pass
# of PushRecovery (it stops the slow forward or backward topple once the hand has reversed the sideways fall; the
# hip strategies stay off: docs/reproductions/eom.md, third and fourth passes). Each control step the
# leg servos' setpoints are the stance plus offsets driven by the extrapolated centre of mass
# (XCoM = x + v / omega0, Hof, Gazendam & Sinke 2005, J Biomech 38:1) seen POSTURAL_LATENCY_S earlier:
# sagittally an ankle strategy (ankle pitch) and a hip strategy (hip pitch: the trunk bends to move the
# centre of mass back over the feet; Horak & Nashner 1986, J Neurophysiol 55:1369: ankle strategy for small
# perturbations, hip strategy for larger ones or a short support), laterally a hip load/unload strategy
# (hip roll: mediolateral balance is a hip mechanism, Winter 1995, Gait & Posture 3:193). Signs: a positive
# hip pitch offset moves the centre of mass forward, a positive hip roll offset (both hips) to the left
# (measured on the model at rest: +0.1 rad gives +2.6 and +5 cm).
# Latency of automatic postural responses: EMG onsets ~90-100 ms after a support-surface perturbation
# (Horak & Nashner 1986; recalled, to confirm): 0.1 s.
POSTURAL_LATENCY_S = 0.1
OMEGA0 = math.sqrt(9.81 / 0.97)  # the inverted pendulum's eigenfrequency, l = the CoM's 0.97 m height
POSTURE_REF_X_M = 0.05  # the CoM's x in quiet stance (measured: 4.9 cm ahead of the pelvis origin)
POSTURE_DEAD_ZONE_M = 0.02  # within 2 cm the stiff stance alone holds (modelling choice)
HIP_STRATEGY_GAIN = 0.0  # rad of hip pitch per m of XCoM error; 4 tried (modelling choice)
HIP_STRATEGY_MAX_RAD = 0.5  # modelling choice
ANKLE_STRATEGY_GAIN = 1.0  # rad of ankle pitch per m (modelling choice; 1 and 2 measured alike, seeds 0-79)
ANKLE_STRATEGY_MAX_RAD = 0.15  # modelling choice
HIP_ROLL_GAIN = 0.0  # rad of hip roll per m of lateral XCoM; 2 tried (modelling choice)
HIP_ROLL_MAX_RAD = 0.3  # modelling choice


def _dead_zone(e: float, width: float) -> float:
    return 0.0 if abs(e) <= width else e - math.copysign(width, e)


def _clip(v: float, limit: float) -> float:
    return max(-limit, min(limit, v))
N_BLOCKS = 6  # the pool of cube blocks in push.xml (block_0 ... block_5)
BLOCKS = tuple(f"block_{i}" for i in range(N_BLOCKS))
SCENE_CAMERA = "scene_camera"
FRONT_CAMERA = "front_camera"
ALL_NAMES = {
    "body": (PELVIS, names.TORSO, names.HEAD, names.HAND, LEFT_HAND, *BLOCKS),
    "joint": (ROOT_JOINT, *LEG_JOINTS, *names.BODY_JOINTS, *LEFT_ARM_JOINTS, *names.NECK_JOINTS, names.GRASP),
    "actuator": (*LEG_ACTUATORS, *names.BODY_ACTUATORS, *LEFT_ARM_ACTUATORS, *names.NECK_ACTUATORS,
                 names.GRASP_ACTUATOR),
    "geom": (FLOOR_GEOM, *FEET_GEOMS, *HAND_GEOMS, *BLOCKS),
    "site": (*SOLE_SITES, names.PALM_CENTER, LEFT_PALM_CENTER),
    "camera": (SCENE_CAMERA, FRONT_CAMERA, names.EYE_CAMERA),
}

# The stance: the pelvis's start position (straight legs: hip joints 0.93 m above the soles, the walker's
# proportions), axes of the world. A test checks it against the compiled model.
STANCE_ORIGIN = np.array([0.0, 0.0, 0.93])
STANCE_FRAME = FixedFrame(STANCE_ORIGIN)
# The right shoulder in the stance frame (envs_assets/push.xml: upper_arm; the left one mirrored, y -> -y): the
# task's bracing shoulder (which cubes are nearest it) and the eom_brace agent's.
RIGHT_SHOULDER = (0.0, -0.2, 0.4)
# Hand workspace of the hand_target action (stance frame, min/max, metres). Modelling choice: an arm's reach
# (upper arm 0.29 m + forearm 0.265 m + hand) from its shoulder (RIGHT_SHOULDER, mirrored) with the waist's help,
# and a body that leans up to ~30 deg toward a wall on its side: y from -1.1 (the right arm's far reach) to 1.1
# (the left arm's, mirrored; 0.3 before the left arm: the right arm's reach across the body).
HAND_WORKSPACE = np.array([[-0.5, 0.7], [-1.1, 1.1], [-0.5, 0.9]])
# Ready posture at reset (degrees): the seated body's (hand in front of the belly), modelling choice.
READY_POSTURE_DEG = {"shoulder_flex": 30.0, "shoulder_abd": 10.0, "shoulder_rot": 0.0, "elbow": 80.0,
                     "forearm_rot": 0.0, "wrist_flex": 0.0, "wrist_dev": 0.0}
# The idle arm's posture (degrees; the mirrored joints of the left arm take the same angles): hanging at the side,
# slightly abducted, as the fixed left arm of the one-armed body (modelling choice).
REST_POSTURE_DEG = {"shoulder_flex": 0.0, "shoulder_abd": 5.0, "shoulder_rot": 0.0, "elbow": 0.0,
                    "forearm_rot": 0.0, "wrist_flex": 0.0, "wrist_dev": 0.0}
# ... to which an idle arm returns, its setpoints closing the gap with this time constant (s; modelling choice).
IDLE_RETURN_S = 0.2
# The hand controller of the standing body: the seated one's, with the waist weighted 0.05 instead of 0.35
# (modelling choice: a standing person reaches with the arm; a waist that swings the trunk to move the
# hand shifts the centre of mass over the heels' edge and tips the stance backward, as measured while
# building this body).
STANDING_HAND_PARAMS = HandControlParams(torso_weight=0.05)
# brace = -1 leaves the shoulder and elbow servos this fraction of their gain (a relaxed arm that cannot
# carry the body's weight; modelling choice: a co-contraction command, stiffness rising with it).
RELAXED_STIFFNESS = 0.15
BRACED_JOINTS = ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")
# The brace command sets both arms' stiffness (one co-contraction command; the idle arm returns to hang at the side).
BRACED_ACTUATORS = BRACED_JOINTS + tuple(LEFT_PREFIX + n for n in BRACED_JOINTS)

STANDING_BLOCKS = (
    Block("body_qpos", 10, "rad", "waist (yaw, pitch, roll) and arm (7) joint angles"),
    Block("body_qvel", 10, "rad/s", "waist and arm joint velocities"),
    Block("hand_pos", 3, "m", "right palm-centre position, stance frame"),
    Block("hand_vel", 3, "m/s", "right palm-centre velocity, stance frame"),
    Block("brace", 1, "0..1", "arm stiffness: 0 relaxed, 1 braced"),
    Block("left_arm_qpos", 7, "rad", "left arm joint angles (the right arm's, mirrored)"),
    Block("left_arm_qvel", 7, "rad/s", "left arm joint velocities"),
    Block("left_hand_pos", 3, "m", "left palm-centre position, stance frame"),
    Block("left_hand_vel", 3, "m/s", "left palm-centre velocity, stance frame"),
    Block("arm", 1, "0/1", "the arm the hand target drives: 0 right, 1 left"),
    Block("vestibular", 8, "rad, rad/s, m/s",
          "trunk (pelvis) tilt: roll and pitch; its angular velocity (roll, pitch, yaw rates); pelvis linear "
          "velocity (x, y, z): the semicircular canals' and otoliths' signal of a push"),
    Block("feet", 6, "m", "left and right sole centres, stance frame"),
    Block("foot_pressure", 4, "m, 0..", "centre of pressure (x, y, stance frame; 0 without foot contact) and the "
          "left and right feet's normal forces over body weight"),
)


class StandingBody(Body):
    """Hand and brace actions, proprioception and contacts of the standing body (``push.xml``)."""

    frame = STANCE_FRAME
    observation_blocks = STANDING_BLOCKS
    trace_step_fields = ("hand_pos", "pelvis_pos", "cop")
    action_structure = {"hand_target": 3, "brace": 1, "arm": 1}  # noqa: RUF012  (read only)
    n_action = 5

    def __init__(self, model: mujoco.MjModel, hand_params: HandControlParams, dt: float) -> None:
        m = model
        self.model = m
        self.dt = float(dt)
        m.body_gravcomp[:] = 0.0  # a body that can fall (see the module docstring)

        def jid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)

        def aid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)

        def gid(name):
            return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name)

        body_j = [jid(n) for n in names.BODY_JOINTS]
        self._qpos = np.array([m.jnt_qposadr[j] for j in body_j])
        self._dof = np.array([m.jnt_dofadr[j] for j in body_j])
        self.joint_range = m.jnt_range[body_j].copy()
        body_act = [aid(n) for n in names.BODY_ACTUATORS]
        self._act = np.array(body_act)
        self._actadr = np.array([m.actuator_actadr[a] for a in body_act])
        self._leg_act = np.array([aid(n) for n in LEG_ACTUATORS])
        self._leg_q = np.array([m.jnt_qposadr[jid(n)] for n in LEG_JOINTS])
        self._braced = np.array([aid(n) for n in BRACED_ACTUATORS])
        self._gain = m.actuator_gainprm[self._braced, 0].copy()
        self._grasp_act = aid(names.GRASP_ACTUATOR)
        root = jid(ROOT_JOINT)
        self._root_q = int(m.jnt_qposadr[root])
        self._root_v = int(m.jnt_dofadr[root])
        self.pelvis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, PELVIS)
        self.head_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names.HEAD)
        # The hand point the controller moves and the observation reports: the palm's centre (its face), the
        # point that touches a cube (the catch site of the seated body floats 3 cm in front of the palm).
        self.catch_site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, names.PALM_CENTER)
        self.soles = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, n) for n in SOLE_SITES]
        self.feet_geoms = tuple(gid(n) for n in FEET_GEOMS)
        self.hand_geoms = tuple(gid(n) for n in HAND_GEOMS)
        self.floor_geom = gid(FLOOR_GEOM)
        self.weight = float(m.body_subtreemass[self.pelvis]) * 9.81
        self.ready = np.array([0.0, 0.0, 0.0] + [READY_POSTURE_DEG[n] * DEG for n in names.ARM_JOINTS])
        self.rest = np.array([0.0, 0.0, 0.0] + [REST_POSTURE_DEG[n] * DEG for n in names.ARM_JOINTS])
        self.hand_params = hand_params
        self.hand = HandController(m, self.catch_site, self._dof, self._qpos, self.joint_range, self.ready,
                                   n_torso=len(names.TORSO_JOINTS), params=hand_params)
        # The left arm: the same controller on the waist and the left arm (the waist is driven by the active arm).
        left_j = [jid(n) for n in (*names.TORSO_JOINTS, *LEFT_ARM_JOINTS)]
        self._l_qpos = np.array([m.jnt_qposadr[j] for j in left_j])
        self._l_dof = np.array([m.jnt_dofadr[j] for j in left_j])
        left_act = [aid(n) for n in (*names.TORSO_JOINTS, *LEFT_ARM_ACTUATORS)]
        self._l_act = np.array(left_act)
        self._l_actadr = np.array([m.actuator_actadr[a] for a in left_act])
        self._l_arm_act = self._l_act[len(names.TORSO_JOINTS):]
        self._r_arm_act = self._act[len(names.TORSO_JOINTS):]
        self.left_site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, LEFT_PALM_CENTER)
        self.left_hand = HandController(m, self.left_site, self._l_dof, self._l_qpos, m.jnt_range[left_j].copy(),
                                        self.ready, n_torso=len(names.TORSO_JOINTS), params=hand_params)
        self.arm = 0  # the active arm: 0 right, 1 left (the action's "arm" block)
        self._left_prev = (0.0, 0.0, 0.0)
        ws_lo = HAND_WORKSPACE[:, 0] + STANCE_ORIGIN
        ws_half = 0.5 * (HAND_WORKSPACE[:, 1] - HAND_WORKSPACE[:, 0])
        self._ws = (ws_lo, ws_half)
        self._force = np.zeros(6)
        self.brace_level = 1.0
        self._brace_set = False  # whether the model's braced gains hold brace_level (see _set_brace)
        self._hand_prev = (0.0, 0.0, 0.0)
        self._cop = (0.0, 0.0, 0.0, 0.0)
        self._com_prev: float | None = None
        self._xcom: deque = deque(maxlen=max(1, round(POSTURAL_LATENCY_S / self.dt)) + 1)

    # --- episode ------------------------------------------------------------------------------
    def reset_pose(self, data: mujoco.MjData) -> None:
        """Standing still at the stance origin, legs straight (their servos' setpoints 0), the arm in the
        ready posture."""
        q = self._root_q
        data.qpos[q:q + 3] = STANCE_ORIGIN
        data.qpos[q + 3:q + 7] = (1.0, 0.0, 0.0, 0.0)
        data.qpos[self._qpos] = self.ready
        data.act[self._actadr] = self.ready
        data.qpos[self._l_qpos] = self.ready  # both arms start in the ready posture (mirrored joints: same angles)
        data.act[self._l_actadr] = self.ready
        self.arm = 0
        data.ctrl[self._leg_act] = STANCE_RAD
        self._com_prev = None
        self._xcom.clear()
        data.qpos[self._leg_q] = STANCE_RAD
        self._brace_set = False
        self._set_brace(1.0)

    def start(self, data: mujoco.MjData) -> None:
        site = data.site_xpos[self.catch_site]
        self.hand.reset(site)
        self._hand_prev = tuple(site.tolist())
        self.left_hand.reset(data.site_xpos[self.left_site])
        self._left_prev = tuple(data.site_xpos[self.left_site].tolist())
        self._cop = self.centre_of_pressure(data)

    # --- control ------------------------------------------------------------------------------
    def _set_brace(self, level: float) -> None:
        if level == self.brace_level and self._brace_set:
            return  # the gains already hold this level (the model arrays are written only on a change)
        self._brace_set = True
        self.brace_level = level
        kp = self._gain * (RELAXED_STIFFNESS + (1.0 - RELAXED_STIFFNESS) * level)
        self.model.actuator_gainprm[self._braced, 0] = kp
        self.model.actuator_biasprm[self._braced, 1] = -kp

    def command(self, data: mujoco.MjData, a: np.ndarray, al: list, dt: float) -> None:
        d = data
        lo, half = self._ws
        target = lo + (a[:3] + 1.0) * half
        arm = 1 if al[4] > 0.0 else 0
        if arm != self.arm:  # the other arm takes over: its reference starts where its hand is
            self.arm = arm
            (self.left_hand if arm else self.hand).reset(d.site_xpos[self.left_site if arm else self.catch_site])
        if arm:
            ctl, adr, act, idle = self.left_hand, self._l_actadr, self._l_act, self._r_arm_act
        else:
            ctl, adr, act, idle = self.hand, self._actadr, self._act, self._l_arm_act
        ctl.advance_reference(target, dt)
        setpoint = d.act[adr]
        new_setpoint = ctl.setpoints(d, setpoint)
        d.ctrl[act] = (new_setpoint - setpoint) / dt  # MuJoCo clamps to ctrlrange: a rate limit
        idle_adr = self._l_actadr[3:] if not arm else self._actadr[3:]
        d.ctrl[idle] = (self.rest[3:] - d.act[idle_adr]) / IDLE_RETURN_S  # the idle arm returns to hang at the side
        self._set_brace(0.5 * (al[3] + 1.0))
        d.ctrl[self._grasp_act] = 0.0
        d.ctrl[self._leg_act] = self._postural_response(d)  # the stance, and its automatic response

    def _postural_response(self, data: mujoco.MjData) -> list:
        """The leg servos' setpoints: the stance plus the automatic postural response to the extrapolated
        centre of mass (x + v / omega0, Hof et al. 2005) seen :data:`POSTURAL_LATENCY_S` ago; the stance
        alone while every gain is 0 (the definition)."""
        if not (HIP_STRATEGY_GAIN or ANKLE_STRATEGY_GAIN or HIP_ROLL_GAIN):
            return list(STANCE_RAD)
        com = data.subtree_com[self.pelvis]
        x, y = float(com[0]), float(com[1])
        if self._com_prev is None:
            vx = vy = 0.0
        else:
            vx = (x - self._com_prev[0]) / self.dt
            vy = (y - self._com_prev[1]) / self.dt
        self._com_prev = (x, y)
        self._xcom.append((x + vx / OMEGA0, y + vy / OMEGA0))
        if len(self._xcom) < self._xcom.maxlen:  # nothing seen POSTURAL_LATENCY_S ago yet: the stance
            return list(STANCE_RAD)
        cx, cy = self._xcom[0]
        ex = _dead_zone(POSTURE_REF_X_M - cx, POSTURE_DEAD_ZONE_M)  # > 0: falling backward
        ey = _dead_zone(-cy, POSTURE_DEAD_ZONE_M)  # > 0: falling to the right
        hip = _clip(HIP_STRATEGY_GAIN * ex, HIP_STRATEGY_MAX_RAD)
        ank = _clip(ANKLE_STRATEGY_GAIN * ex, ANKLE_STRATEGY_MAX_RAD)
        roll = _clip(HIP_ROLL_GAIN * ey, HIP_ROLL_MAX_RAD)
        out = list(STANCE_RAD)
        out[0] += roll
        out[5] += roll
        out[1] += hip
        out[6] += hip
        out[3] += ank
        out[8] += ank
        return out

    # --- state --------------------------------------------------------------------------------
    def hand_pos(self, data: mujoco.MjData) -> np.ndarray:
        """The active arm's palm centre (world)."""
        return data.site_xpos[self.left_site if self.arm else self.catch_site]

    def head_height(self, data: mujoco.MjData) -> float:
        return float(data.xpos[self.head_body][2])

    def pelvis_pos(self, data: mujoco.MjData) -> np.ndarray:
        return data.xpos[self.pelvis]

    def centre_of_pressure(self, data: mujoco.MjData) -> tuple[float, float, float, float]:
        """(x, y) of the centre of pressure of the foot-floor contacts (world; 0, 0 without contact) and
        the left and right feet's normal forces over body weight."""
        d = data
        fl = fr = sx = sy = 0.0
        left, right = self.feet_geoms
        floor = self.floor_geom
        if not d.ncon:
            return 0.0, 0.0, 0.0, 0.0
        contacts = d.contact
        positions = contacts.pos
        for i, (g1, g2) in enumerate(contacts.geom.tolist()):  # (a contact object per contact costs more)
            if g1 == floor:
                g1, g2 = g2, g1
            elif g2 != floor:
                continue
            if g1 != left and g1 != right:
                continue
            mujoco.mj_contactForce(self.model, d, i, self._force)
            fn = float(self._force[0])
            if fn <= 0.0:
                continue
            if g1 == left:
                fl += fn
            else:
                fr += fn
            px, py = float(positions[i, 0]), float(positions[i, 1])
            sx += fn * px
            sy += fn * py
        total = fl + fr
        if total <= 0.0:
            return 0.0, 0.0, 0.0, 0.0
        return sx / total, sy / total, fl / self.weight, fr / self.weight

    def support_polygon(self, data: mujoco.MjData) -> np.ndarray:
        """(8, 2) corners of the two feet's soles (world x, y): their convex hull is the support polygon."""
        out = []
        for g in self.feet_geoms:
            r = data.geom_xmat[g].reshape(3, 3)
            c = data.geom_xpos[g]
            hx, hy = self.model.geom_size[g, 0], self.model.geom_size[g, 1]
            for sx, sy in ((1, 1), (1, -1), (-1, -1), (-1, 1)):
                out.append((c + r @ np.array([sx * hx, sy * hy, 0.0]))[:2])
        return np.array(out)

    def observe(self, values: list, data: mujoco.MjData) -> None:
        """Append the :data:`STANDING_BLOCKS`."""
        d = data
        ox, oy, oz = self.frame.origin_list
        hx, hy, hz = d.site_xpos[self.catch_site].tolist()
        px, py, pz = self._hand_prev
        dt = self.dt
        values += d.qpos[self._qpos].tolist()
        values += d.qvel[self._dof].tolist()
        values += (hx - ox, hy - oy, hz - oz, (hx - px) / dt, (hy - py) / dt, (hz - pz) / dt, self.brace_level)
        self._hand_prev = (hx, hy, hz)
        values += d.qpos[self._l_qpos[len(names.TORSO_JOINTS):]].tolist()
        values += d.qvel[self._l_dof[len(names.TORSO_JOINTS):]].tolist()
        hx, hy, hz = d.site_xpos[self.left_site].tolist()
        px, py, pz = self._left_prev
        values += (hx - ox, hy - oy, hz - oz, (hx - px) / dt, (hy - py) / dt, (hz - pz) / dt, float(self.arm))
        self._left_prev = (hx, hy, hz)
        r = d.xmat[self.pelvis]  # row-major world rotation of the pelvis
        roll = math.atan2(float(r[7]), float(r[8]))
        pitch = -math.asin(max(-1.0, min(1.0, float(r[6]))))
        v = self._root_v
        values += (roll, pitch)
        values += d.qvel[v + 3:v + 6].tolist()  # angular velocity (free joint: local frame)
        values += d.qvel[v:v + 3].tolist()  # linear velocity (world)
        for s in self.soles:
            x, y, z = d.site_xpos[s].tolist()
            values += (x - ox, y - oy, z - oz)
        cx, cy, fl, fr = self.centre_of_pressure(d)
        self._cop = (cx, cy, fl, fr)
        values += ((cx - ox) if (fl + fr) > 0 else 0.0, (cy - oy) if (fl + fr) > 0 else 0.0, fl, fr)

    def info(self, data: mujoco.MjData) -> dict:
        cx, cy, fl, fr = self._cop
        return {"hand_pos": self.hand_pos(data).copy(),  # the active arm's
                "arm": self.arm,
                "pelvis_pos": data.xpos[self.pelvis].copy(),
                "cop": np.array([cx, cy, fl + fr]),
                "head_height": self.head_height(data)}


def hand_target_action(target_world) -> np.ndarray:
    """The hand_target block (3 values in [-1, 1]) for a world point (clipped to the workspace)."""
    lo, hi = HAND_WORKSPACE[:, 0] + STANCE_ORIGIN, HAND_WORKSPACE[:, 1] + STANCE_ORIGIN
    return np.clip(2.0 * (np.asarray(target_world, dtype=float) - lo) / (hi - lo) - 1.0, -1.0, 1.0)
