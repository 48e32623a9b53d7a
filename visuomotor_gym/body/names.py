"""Every MuJoCo name the package uses, in one place (mirrors ``envs_assets/common/upper_body.xml``).

A test compiles the model and checks that each name below exists, so a renamed element in the XML
fails loudly instead of silently returning the wrong index.
"""

from __future__ import annotations

# Bodies
TORSO = "torso"
HEAD = "head"
EYE = "eye"
FIXATION = "fixation"
UPPER_ARM = "upper_arm"
FOREARM = "forearm"
HAND = "hand"
FINGERS = "fingers"
BALL = "ball"
THROWER = "thrower"
BOUNCE_WALL = "bounce_wall"

# Joints, in the order of the ``control="joint"`` action block and of the proprioceptive observation.
TORSO_JOINTS = ("torso_yaw", "torso_pitch", "torso_roll")
ARM_JOINTS = (
    "shoulder_flex",
    "shoulder_abd",
    "shoulder_rot",
    "elbow",
    "forearm_rot",
    "wrist_flex",
    "wrist_dev",
)
BODY_JOINTS = TORSO_JOINTS + ARM_JOINTS  # the 10 joints the hand controller drives
NECK_JOINTS = ("neck_yaw", "neck_pitch")  # Donders' law: yaw, then pitch
EYE_AZIMUTH = "eye_azimuth"
EYE_ELEVATION = "eye_elevation"
EYE_FIXATION = "eye_fixation"
GRASP = "grasp"
BALL_JOINT = "ball_free"

# Actuators (integrated-velocity servos share their joint's name).
BODY_ACTUATORS = BODY_JOINTS
NECK_ACTUATORS = NECK_JOINTS
GRASP_ACTUATOR = "grasp"

# Geoms
BALL_GEOM = "ball"
PALM_GEOM = "palm"
BOUNCE_WALL_GEOM = "bounce_wall"
FLOOR_GEOM = "floor"

# Sites
CATCH_SITE = "catch_site"
PALM_CENTER = "palm_center"
EYE_CENTER = "eye_center"
SEAT_ORIGIN = "seat_origin"
FIXATION_POINT = "fixation_point"

# Cameras
SCENE_CAMERA = "scene_camera"
EYE_CAMERA = "eye_camera"
OVER_SHOULDER_CAMERA = "over_shoulder"
CAMERAS = (SCENE_CAMERA, EYE_CAMERA, OVER_SHOULDER_CAMERA)

# Equality constraints
CATCH_WELD = "catch_weld"

# The second ball of EyeCatchTwoBalls-v0 (``envs_assets/catch_two_balls.xml``, which includes catch.xml).
TWO_BALLS_SCENE = "catch_two_balls.xml"
BALL2 = "ball2"
BALL2_JOINT = "ball2_free"
BALL2_GEOM = "ball2"
THROWER2 = "thrower2"
CATCH_WELD2 = "catch_weld2"
TWO_BALL_NAMES = {"body": (BALL2, THROWER2), "joint": (BALL2_JOINT,), "geom": (BALL2_GEOM,), "equality": (CATCH_WELD2,)}

ALL_NAMES = {
    "body": (TORSO, HEAD, EYE, FIXATION, UPPER_ARM, FOREARM, HAND, FINGERS, BALL, THROWER, BOUNCE_WALL),
    "joint": BODY_JOINTS + NECK_JOINTS + (EYE_AZIMUTH, EYE_ELEVATION, EYE_FIXATION, GRASP, BALL_JOINT),
    "actuator": BODY_ACTUATORS + NECK_ACTUATORS + (GRASP_ACTUATOR,),
    "geom": (BALL_GEOM, PALM_GEOM, BOUNCE_WALL_GEOM, FLOOR_GEOM),
    "site": (CATCH_SITE, PALM_CENTER, EYE_CENTER, SEAT_ORIGIN, FIXATION_POINT),
    "camera": CAMERAS,
    "equality": (CATCH_WELD,),
}
