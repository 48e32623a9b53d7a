"""Every MuJoCo name of the walker scene (``envs_assets/walker.xml``), in one place.

The head, neck and eye come from the shared fragment and keep the names of
:mod:`visuomotor_gym.body.names` (``HEAD``, ``EYE``, ``NECK_JOINTS``, ``EYE_*``, ``EYE_CAMERA`` ...).
A test compiles the walker scene and checks that every name below (and those shared ones) exists.
"""

from __future__ import annotations

from visuomotor_gym.body import names as _shared

WALKER_SCENE = "walker.xml"
SIDES = ("left", "right")  # index 0 = left (+y), 1 = right (-y); the gait's side numbering

# Bodies
WALKER_PELVIS = "pelvis"  # the root: origin at the midpoint of the two hip joints
WALKER_TORSO = "walker_torso"  # carries the arms and the shared head+eye fragment
WALKER_THIGHS = ("left_thigh", "right_thigh")
WALKER_SHINS = ("left_shin", "right_shin")
WALKER_FEET = ("left_foot", "right_foot")
WALKER_ARMS = ("left_arm", "right_arm")
WALKER_FINISH = "finish_line"  # a visual marker the task moves to the end of the path
WALKER_WALKWAY_EDGES = ("walkway_left", "walkway_right")  # visual edge lines the task moves to the walkway's width
WALKER_OBSTACLE_POOL = 16  # pre-allocated obstacle bodies (modelling choice: >= obstacles per course)
WALKER_OBSTACLES = tuple(f"obstacle_{i:02d}" for i in range(WALKER_OBSTACLE_POOL))  # mocap bodies and their box geoms

# Joints. The root: three slides and a yaw hinge, in this order, first in the model (qpos 0..3).
WALKER_ROOT_JOINTS = ("root_x", "root_y", "root_z", "root_yaw")
# Per leg, proximal to distal: hip roll (+ moves the foot to +y), hip pitch (+ = flexion, foot
# forward), knee (+ = flexion), ankle pitch (+ = dorsiflexion, toe up), ankle roll.
LEG_JOINT_SUFFIXES = ("hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
WALKER_LEG_JOINTS = tuple(tuple(f"{side}_{j}" for j in LEG_JOINT_SUFFIXES) for side in SIDES)
WALKER_ARM_JOINTS = ("left_shoulder", "right_shoulder")  # + = flexion (hand forward)
# Every joint the gait drives, in actuator order (each integrated-velocity servo shares its joint's name).
WALKER_GAIT_JOINTS = WALKER_ROOT_JOINTS + WALKER_LEG_JOINTS[0] + WALKER_LEG_JOINTS[1] + WALKER_ARM_JOINTS
WALKER_GAIT_ACTUATORS = WALKER_GAIT_JOINTS

# Geoms
WALKER_FLOOR = "floor"
WALKER_LEG_GEOMS = tuple(
    tuple(f"{side}_{part}" for part in ("thigh", "shin", "foot")) for side in SIDES
)  # the geoms that collide with obstacles (feet, shins, thighs)
WALKER_TRUNK_GEOMS = ("pelvis", "abdomen", "chest")

# Sites: the sole centre under the ankle (the foothold reference), toe and heel (sole corners on the
# midline), the ankle joint centre.
WALKER_SOLES = ("left_sole", "right_sole")
WALKER_TOES = ("left_toe", "right_toe")
WALKER_HEELS = ("left_heel", "right_heel")
WALKER_ANKLES = ("left_ankle", "right_ankle")

# Cameras
WALKER_SIDE_CAMERA = "walker_side"  # tracks the pelvis from the left side
WALKER_FOLLOW_CAMERA = "walker_follow"  # tracks the pelvis from behind and above
WALKER_SCENE_CAMERA = "walker_scene"  # fixed overview of the first metres of the path
WALKER_CAMERAS = (WALKER_SIDE_CAMERA, WALKER_FOLLOW_CAMERA, WALKER_SCENE_CAMERA, _shared.EYE_CAMERA)

WALKER_ALL_NAMES = {
    "body": (WALKER_PELVIS, WALKER_TORSO, *WALKER_THIGHS, *WALKER_SHINS, *WALKER_FEET, *WALKER_ARMS,
             WALKER_FINISH, _shared.HEAD, _shared.EYE, _shared.FIXATION, *WALKER_WALKWAY_EDGES,
             *WALKER_OBSTACLES),
    "joint": WALKER_GAIT_JOINTS + _shared.NECK_JOINTS
    + (_shared.EYE_AZIMUTH, _shared.EYE_ELEVATION, _shared.EYE_FIXATION),
    "actuator": WALKER_GAIT_ACTUATORS + _shared.NECK_ACTUATORS,
    "geom": (WALKER_FLOOR,) + WALKER_LEG_GEOMS[0] + WALKER_LEG_GEOMS[1] + WALKER_TRUNK_GEOMS + WALKER_OBSTACLES,
    "site": WALKER_SOLES + WALKER_TOES + WALKER_HEELS + WALKER_ANKLES + (_shared.EYE_CENTER, _shared.FIXATION_POINT),
    "camera": WALKER_CAMERAS,
}
