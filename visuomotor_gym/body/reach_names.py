"""Every MuJoCo name of the ShelfReach scene (``envs_assets/reach.xml``) that is not already in
:mod:`visuomotor_gym.body.names` (the seated body, head and eye keep those names).

A test compiles the scene and checks that each name below exists.
"""

from __future__ import annotations

SCENE = "reach.xml"

# The three towers of Faraway, Reed & Wang's layout (2007, Sec. 2: "in front of the subject,
# to the right-hand side and 45 deg to the right"), in target order.
TOWER_KEYS = ("front", "right45", "right90")
TOWERS = tuple(f"tower_{k}" for k in TOWER_KEYS)
LEVELS = 5
DEPTH_KEYS = ("near", "far")

# Geoms: one board under each of the 30 targets (visual), one back panel per tower (collides).
BOARDS = tuple(f"board_{t}_{k}_{d}" for t in TOWER_KEYS for k in range(LEVELS) for d in DEPTH_KEYS)
PANELS = tuple(f"panel_{t}" for t in TOWER_KEYS)

# The object: a mocap body with one cylinder geom.
OBJECT = "reach_object"
OBJECT_GEOM = "reach_object"

# The shelf clutter: 29 distractors (one for each other target), mocap bodies with one cylinder geom each
# (body and geom share the name), parked below the floor while unused.
N_DISTRACTORS = 29
DISTRACTORS = tuple(f"reach_distractor_{i:02d}" for i in range(N_DISTRACTORS))

# Cameras (the eye camera comes with the head fragment: visuomotor_gym.body.names.EYE_CAMERA).
SCENE_CAMERA = "scene_camera"
OVER_SHOULDER_CAMERA = "over_shoulder"
TOP_CAMERA = "top_camera"
CAMERAS = (SCENE_CAMERA, OVER_SHOULDER_CAMERA, TOP_CAMERA)

ALL_NAMES = {
    "body": (*TOWERS, OBJECT, *DISTRACTORS),
    "geom": BOARDS + PANELS + (OBJECT_GEOM, *DISTRACTORS),
    "camera": CAMERAS,
}
