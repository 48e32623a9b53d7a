"""Balancing after a push (Eom et al. 2019, section 7): a standing body near a wall of cube blocks is
pushed toward it; it stays upright only if it puts its hand on a block.

The scene (``envs_assets/push.xml``): a pool of :data:`~visuomotor_gym.body.standing.N_BLOCKS` cube
blocks on mocap bodies, placed and resized per episode in a row beside the body's right side, or with
:data:`WALL_SIDE_RANDOM` on half the episodes mirrored to its left (the "wall of multiple cube blocks"): the wall's distance, each cube's size, the gaps between them, each
cube's height and how far it stands out of the wall plane are drawn from the episode's generator.
With :data:`WALL_FRONT_P` (opt-in, 0 in the definition) the side's wall is turned to stand in front of the
body instead. There is nothing behind or between the cubes: a hand that lands in a gap or misses an edge goes
through, and one that stops short touches nothing. Each cube is a
:class:`~visuomotor_gym.core.retina.PointTarget` at the **centre of its face toward the body** (where a
hand can push): the agent knows the blocks only through the eye's samples of these points.

The push: a horizontal force on the torso (``xfrc_applied``) at a random time, for
:data:`PUSH_DURATION_S`, toward the wall within :data:`PUSH_AZIMUTH_DEG` of its normal, of a magnitude
the legs alone cannot absorb (tested: ``tests/test_push_recovery.py``).

Outcome: a **fall** is any contact between the floor or a block and a body geom other than the feet and
the palm, or the head below :data:`FALL_HEAD_HEIGHT_M` (checked after every physics substep); success
(**upright**) is no fall :data:`HOLD_S` after the push began. Either ends the episode.
"""

from __future__ import annotations

import math
from collections import deque

import mujoco
import numpy as np

from visuomotor_gym.body import names
from visuomotor_gym.body import standing as sn
from visuomotor_gym.core.observation import Block
from visuomotor_gym.core.parts import Task
from visuomotor_gym.core.retina import PointTarget

DEG = math.pi / 180.0

# --- the wall of blocks (world frame: x forward, y left; the wall is on the body's right, y < 0) -------
# Modelling choices (Eom et al. give no dimensions): the wall's face plane 0.60-0.80 m from the body's
# midline (the right hand reaches it at full stretch or once the body leans toward it: the shoulder is
# 0.2 m right of the midline and the arm ~0.6 m long to the palm); cubes of 14-22 cm ("cube blocks");
# gaps of 12-30 cm (wider than the 9 cm palm, so a hand can pass between two cubes); centres 1.00-1.35 m
# above the floor (at and below the shoulder's 1.33 m, where a hand braces a sideways fall); each cube
# standing out of the face plane by 0-10 cm.
WALL_DISTANCE_M = (0.60, 0.80)
BLOCK_HALF_SIZE_M = (0.07, 0.11)
GAP_M = (0.12, 0.30)
BLOCK_HEIGHT_M = (1.00, 1.35)
BLOCK_OFFSET_M = (0.0, 0.10)
# A crowded wall (PushRecovery's fifth pass, opt-in; None in the definition): every cube after the first at the
# first cube's height plus up to +-ROW_HEIGHT_JITTER_M (its own height draw mapped onto that range, so the
# draws and their order are unchanged): a straight row whose neighbours lie side by side in the visual field,
# where crowding (Bouma 1970) can pool them. Modelling choice.
ROW_HEIGHT_JITTER_M: float | None = None
# A back row (fifth pass, opt-in; None in the definition): the odd cubes stand this far behind the wall plane,
# out of the hand's reach, seen through the gaps of the front row. Same kind as the front cubes, so a
# peripheral percept may pool a front cube with the back cube beside it (Bouma 1970), and a peripheral depth
# (~0.4 m std at 20 deg) cannot tell the rows apart: a hand sent to a back cube goes through a gap.
# Modelling choice.
BACK_ROW_M: float | None = None
# Visual-only clutter (seventh pass, opt-in; None in the definition): CLUTTER_PER_CUBE small cubes of the SAME
# kind as the wall's ("block" targets of the retina), drawn but not touchable and not in the observation, placed
# around each reachable cube, irregularly, in the gaps and above and below it, CLUTTER_BEHIND_M behind the wall
# plane (never overlapping a real cube's silhouette on the wall, so nothing is hidden behind one). Crowding
# (Bouma 1970: same-kind flankers within 0.5 x eccentricity pool, the percept is the group's mean) then pools a
# peripheral sample of a cube with its clutter, to one side (each cube's clutter keeps to one side of it, drawn
# per cube, so the pooled mean lands off the cube) and behind; only a fixated cube is seen where it is. As
# ShelfReach's shelf clutter (envs/reach.py). Modelling choices: counts, sizes, spread and depths below.
CLUTTER_PER_CUBE: int | None = None
CLUTTER_HALF_SIZE_M = (0.02, 0.03)
CLUTTER_BEHIND_M = (0.05, 0.15)
CLUTTER_SPREAD_M = 0.06  # a clutter cube's face centre within the cube's half-size + this of the cube's centre
CLUTTER_TRIES = 40  # rejection draws per clutter cube (one that finds no free place stays parked)
N_CLUTTER = 36  # the pool of clutter targets (6 per cube of the pool)
FIRST_BLOCK_X_M = (-0.35, -0.05)  # the row starts beside the body and runs forward (modelling choice)
PARKED = (-20.0, -20.0, -5.0)  # a parked block: 5 m under the floor, out of sight

# --- the push --------------------------------------------------------------------------------------
# Onset 1.0-2.0 s after the start (modelling choice: time to look around first, and unpredictable). 0.6-1.4 s before
# PushRecovery's eleventh pass: with loose cubes the eye needs time to find the wall and fixate one or two cubes
# (eom_brace identifies the first at ~0.4-0.5 s and the second at ~0.7 s, measured), and a push from 0.6 s cut that
# scan short (eom_brace 177/200 at 0.6-1.4 s against 180/200 at 1.0-2.0 s on the pinned seeds; eom.md, eleventh
# pass). The same uniform draw mapped onto the later range: every other draw of a seed is unchanged.
PUSH_TIME_S = (1.0, 2.0)
# A 150 ms shove: the duration of the waist-pull and shoulder-push perturbations of compensatory-reaction
# studies is 100-300 ms (Maki & McIlroy 1997's reviews; REFERENCES.md marks their numbers unconfirmed):
# modelling choice within that range.
PUSH_DURATION_S = 0.15
# 300-350 N for 0.15 s (45-52 N s). Modelling choice: the shoulder-width stance on its own survives a
# 270 N push and tips over from 285 N (0.15 s, toward the wall; tests/test_push_recovery.py), so every push
# here needs the hand.
PUSH_FORCE_N = (300.0, 350.0)
# Direction: toward the wall (-y) within +-10 deg (modelling choice: "toward the wall"; the stance's
# sagittal margin, 10 cm behind the centre of mass to the heels, is the body's weak direction once braced).
PUSH_AZIMUTH_DEG = 10.0
# The wall's yaw, drawn per episode (deg; its normal turned forward from the body's right; the push follows
# the normal), drawn last. 0..30 so that the cube the hand needs is not always beside the shoulder: it moves up to
# ~25 cm forward and ~30 deg of gaze azimuth (modelling choice). PushRecovery's fourth pass
# (docs/reproductions/eom.md) measured the brace on the Oracle rung: 96 % at 0..30, 83.5 % at -20..45 (past ~35 deg
# the next cubes stand in front of the falling chest; a wall turned backward lets the upper arm strike cube 0).
# (0, 0): the wall beside the body, no draw (the definition before the fourth pass).
WALL_YAW_DEG = (0.0, 30.0)
# The wall on a random side (PushRecovery's eighth pass): per episode the wall, its cubes and the push are mirrored
# across the body's sagittal plane (y -> -y) with probability 1/2, drawn after every other draw (so a seed's
# wall is the same up to the side); the body braces with its left arm there. False: the wall on the right.
# The two walls are 180 deg apart, so no one posture of the eye sees both within the foveated agents' trusted
# eccentricity (modelling choice; docs/reproductions/eom.md, eighth pass).
WALL_SIDE_RANDOM = True
# A wall in front (PushRecovery's tenth pass, docs/reproductions/eom.md): with probability WALL_FRONT_P the side's
# wall, its cubes and the push are turned 90 deg toward the front about the body's vertical axis, drawn after every
# other draw: the wall's distance from the body's axis, the cubes and every other draw of the seed are the side
# wall's; the push comes from behind, toward the wall, and the cubes nearest the fall's line stand straight ahead
# (within ~25 deg of it, where the side walls' stand 60-100 deg to the side). With the side draw 50/50, 1/3 makes
# the three places (left, right, front) equally likely, so that no one posture of the eye sees the cubes the hand
# needs on more than one of them well (the ninth pass measured that two places, 180 deg apart, cap the gaze gain
# near +40: a still eye on one side keeps that side's share). Modelling choice. Opt-in (0 in the definition: the
# wall on a side only, the ninth pass's scene): measured at 1/3 the gain stays +37.0, because a still eye turned
# 40-60 deg sees a side wall and half the front one (eom.md, tenth pass).
WALL_FRONT_P = 0.0
# The push toward a wall in front is the side push scaled by this. The bare stance tips from 185 N forward and from
# 285 N sideways (0.15 s pushes, tests/test_push_recovery.py: the soles' toes are a shorter lever than the feet's
# outer edges), a ratio of 0.65; at 0.65 the legs alone kept 22 of 64 front walls (pinned seeds), at 0.72
# (212-252 N) 4 of 64, as on the side walls (6 of 68). Modelling choice, as PUSH_FORCE_N.
FRONT_PUSH_SCALE = 0.72
# The front row slid along the wall so that it straddles the body's midline: turned from a side, it would run 2 m
# across to the other side, into a side-looking eye's view (modelling choice; eom.md, tenth pass).
FRONT_ROW_CENTRED = True

# --- loose cubes and the foveal identity percept (PushRecovery's eleventh pass) --------------------------
# Some cubes are LOOSE: they give way under a hand. Modelled in the simplest way: a loose cube's geom does not
# collide (contype/conaffinity 0 for the episode), so a hand or a trunk goes through it as through a cube that
# falls away (a modelling simplification: a real loose cube would be pushed off, not passed through). Whether a
# cube is firm can be seen only with central vision (BLOCK_FIRM percept, below). Draw rule (modelling choice):
# of the LOOSE_PAIR cubes nearest the bracing shoulder (horizontal distance from the shoulder to the face centre,
# after the wall's side, yaw and front draws), exactly one is loose (a coin flip); every other cube is loose with
# probability LOOSE_P. So a firm cube is always one of the nearest two, and an eye that picks the nearest by its
# position alone picks a loose one half the time. The draws come from a generator of their own, jumped off the
# episode's generator after every other draw of the task (``bit_generator.jumped()``: nothing is taken from the
# episode's stream), so the wall, the push, the gaze jitter, the disarray field and every retinal noise draw of a
# seed are those of the scene without loose cubes. False: every cube firm (the tenth pass's scene).
LOOSE_CUBES = True
LOOSE_PAIR = 2
LOOSE_P = 0.5
# The identity cue is a surface texture whose elements are TEXTURE_SPACING_M apart (modelling choice). By Bouma's
# law (Bouma 1970: critical spacing = crowding_bouma x eccentricity, 0.5, the constant the vision model's crowding
# uses, vision.foveation.VisionParams.crowding_bouma) an element among neighbours s deg apart is identified only
# within s / 0.5 of the fovea: 2 x atan(0.01 m / d), 1.9 deg at 0.6 m, 1.4 deg at 0.8 m. A cube is identified on a
# step when the eye is not in a saccade, the cube is sampled (visible) and the angular distance from the line of
# sight to its face centre, minus the face's angular half-size (atan(half-size / d)), clamped at 0, is within that.
TEXTURE_SPACING_M = 0.01

# --- the outcome -----------------------------------------------------------------------------------
HOLD_S = 2.5  # upright this long after the push's onset: success (modelling choice; Eom's clip ~2-3 s)
FALL_HEAD_HEIGHT_M = 1.0  # the head body's origin (1.43 m standing) below this: fallen (modelling choice)
GAZE_JITTER_DEG = 2.0  # Gaussian jitter of the initial gaze (as the other families' starts, modelling choice)
INITIAL_GAZE_POINT = (3.0, 0.0, 1.3)  # straight ahead, 3 m away (modelling choice: looking ahead, not at the wall)

BLOCK_PERCEPT_BLOCKS = (
    Block("block_pos", 3 * sn.N_BLOCKS, "m",
          "perceived centre of each cube's face toward the body, eye frame at the sample (zeros when not seen)"),
    Block("block_visible", sn.N_BLOCKS, "0/1", "1 if this step produced a visual sample of the cube"),
    Block("block_firm", sn.N_BLOCKS, "-1/0/1",
          "the cube identified as firm (+1) or loose (-1) this step by central vision (its face within the "
          "texture's crowding limit of the line of sight); 0 not identified"),
    Block("block_age", 1, "s", "age of the visual samples (the visual latency; 0 without delay)"),
)
TIME_BLOCK = Block("time", 1, "s", "time since the episode started")
REWARD_TERMS = ("upright", "fall", "effort")
SPARSE_WEIGHTS = {"upright": 1.0}
SHAPED_WEIGHTS = {"upright": 1.0, "fall": -1.0, "effort": -0.001}


def ident_eccentricity(distance_m: float, bouma: float = 0.5) -> float:
    """The eccentricity (rad) within which a cube's texture is identified at ``distance_m``: the angular spacing of
    its elements (:data:`TEXTURE_SPACING_M`) over Bouma's constant (Bouma 1970)."""
    return math.atan(TEXTURE_SPACING_M / max(distance_m, 1e-9)) / bouma


class PushRecoveryTask(Task):
    """Blocks, the push, falls and success of PushRecovery (``body``: a :class:`StandingBody`)."""

    trace_step_fields = ()
    trace_flag_fields = ("hand_on_block",)

    def __init__(self, model: mujoco.MjModel, body: sn.StandingBody, *, reward_weights: dict, dt: float,
                 visual_delay_s: float, push_force_n: tuple[float, float] = PUSH_FORCE_N,
                 n_blocks: int = sn.N_BLOCKS) -> None:
        self.model = model
        self.body = body
        self.reward_weights = reward_weights
        self.dt = dt
        self.visual_delay_s = visual_delay_s
        self.push_force_n = push_force_n
        self.n_blocks = int(n_blocks)
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in sn.BLOCKS]
        self._mocap = [int(model.body_mocapid[b]) for b in ids]
        self._bvh = [int(model.body_bvhadr[b]) for b in ids]
        posts = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"block_post_{i}") for i in range(sn.N_BLOCKS)]
        self._post_mocap = [int(model.body_mocapid[b]) for b in posts]
        self._block_geom = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in sn.BLOCKS]
        self._block_geoms = set(self._block_geom)
        # The cubes' collision bits as the model has them (a firm cube's); a loose cube's are 0 for its episode.
        self._contype = [int(model.geom_contype[g]) for g in self._block_geom]
        self._conaffinity = [int(model.geom_conaffinity[g]) for g in self._block_geom]
        self.loose = np.zeros(sn.N_BLOCKS, dtype=bool)
        self._half = np.zeros(sn.N_BLOCKS)  # each pool cube's half-size this episode (0: parked)
        # The eye, the retina and the rung (the env attaches them once assembled: attach_eye); the identity
        # percept needs the eye's true line of sight and the retina's undelayed samples of this step.
        self.eye = None
        self.retina = None
        self.vision_mode = "foveated"
        self.bouma = 0.5
        self.delay_steps = 0
        self._torso = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, names.TORSO)
        self._allowed = set(body.feet_geoms) | set(body.hand_geoms)
        self._hand = set(body.hand_geoms)
        self._scene = {body.floor_geom} | self._block_geoms
        # Which geom pairs in contact are a fall (check_substep's rule as a set, looked up once per substep):
        # a body geom other than the feet and the palm on the floor or a cube, or the palm on the floor.
        self._fall_pairs = set()
        for s_ in self._scene:
            for b in range(model.ngeom):
                if b not in self._scene and (b not in self._allowed or (b in self._hand and s_ not in self._block_geoms)):
                    self._fall_pairs.update(((s_, b), (b, s_)))
        self.targets = [PointTarget(f"block_{i}") for i in range(sn.N_BLOCKS)]
        # The visual-only clutter follows the cubes in the retina's target list (the observation reads only
        # the cubes' samples); none without CLUTTER_PER_CUBE (the definition's target list).
        self.clutter = [PointTarget(f"clutter_{k}") for k in range(N_CLUTTER)] if CLUTTER_PER_CUBE else []
        self.targets += self.clutter
        for t in self.targets:
            t.kind = "block"
        self.leading_blocks = BLOCK_PERCEPT_BLOCKS
        self.trailing_blocks = (TIME_BLOCK,)
        self.reset_state()

    # --- episode ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.success = False
        self.fallen = False
        self.fall_geoms: tuple[str, str] | None = None
        self.hand_block = -1
        self.first_contact_time: float | None = None
        self.visible = [False] * sn.N_BLOCKS
        self._firm_line: deque = deque(maxlen=self.delay_steps + 1)  # the identity percepts' delay line

    def attach_eye(self, eye, retina, vision_mode: str, bouma: float) -> None:
        """The env's eye and retina (for the identity percept), its rung and the vision's Bouma constant."""
        self.eye, self.retina, self.vision_mode, self.bouma = eye, retina, vision_mode, float(bouma)
        self.delay_steps = int(retina.delay_steps)
        self._firm_line = deque(maxlen=self.delay_steps + 1)

    def reset_episode(self, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Draw the wall (distance, then per cube: size, gap, height, offset), the push (time, force,
        direction), the initial gaze jitter and (only when :data:`WALL_YAW_DEG` is a range) the wall's yaw,
        in that order, from ``rng``."""
        wall = float(rng.uniform(*WALL_DISTANCE_M))
        x = float(rng.uniform(*FIRST_BLOCK_X_M))
        rows = []
        for i in range(sn.N_BLOCKS):
            if i >= self.n_blocks:
                rows.append(None)
                continue
            h = float(rng.uniform(*BLOCK_HALF_SIZE_M))
            gap = float(rng.uniform(*GAP_M))
            z = float(rng.uniform(*BLOCK_HEIGHT_M))
            off = float(rng.uniform(*BLOCK_OFFSET_M))
            if i > 0:
                x += gap
                if ROW_HEIGHT_JITTER_M is not None:
                    lo, hi = BLOCK_HEIGHT_M
                    z = rows[0][2] + ROW_HEIGHT_JITTER_M * (2.0 * (z - lo) / (hi - lo) - 1.0)
            x += h
            rows.append((x, h, z, off))
            x += h
        self.push_time = float(rng.uniform(*PUSH_TIME_S))
        self.push_force = float(rng.uniform(*self.push_force_n))
        az = float(rng.uniform(-PUSH_AZIMUTH_DEG, PUSH_AZIMUTH_DEG)) * DEG
        self.gaze_offset = rng.normal(0.0, GAZE_JITTER_DEG * DEG, 2)
        # The wall's yaw: its normal turned forward from the body's right by yaw (0: beside the body).
        yaw = float(rng.uniform(*WALL_YAW_DEG)) * DEG if WALL_YAW_DEG[1] > WALL_YAW_DEG[0] else WALL_YAW_DEG[0] * DEG
        # The side: -1 the right (y < 0), +1 the left, mirrored (drawn last, only with WALL_SIDE_RANDOM).
        self.wall_side = (1 if rng.random() < 0.5 else -1) if WALL_SIDE_RANDOM else -1
        # The front (drawn last, only with WALL_FRONT_P): the side's scene turned toward the front.
        self.wall_front = bool(WALL_FRONT_P > 0.0 and rng.random() < WALL_FRONT_P)
        mirror = self.wall_side > 0
        if mirror:
            yaw = -yaw  # the mirrored wall turns forward from the body's left
        sgn = 1.0 if mirror else -1.0
        normal = np.array([-sgn * math.sin(yaw), sgn * math.cos(yaw), 0.0])  # from the body toward the wall
        along = np.array([math.cos(yaw), math.sin(yaw), 0.0])  # along the wall, forward at yaw 0
        # The front wall: the side's scene turned by -side x 90 deg about the body's vertical axis (the right wall
        # turns left, to the front; the left wall turns right).
        if self.wall_front:
            turn_by = -self.wall_side * 0.5 * math.pi
            ct, st = math.cos(turn_by), math.sin(turn_by)
            normal, along = (np.array([ct * v[0] - st * v[1], st * v[0] + ct * v[1], 0.0]) for v in (normal, along))
            yaw += turn_by
            self.push_force *= FRONT_PUSH_SCALE
            if FRONT_ROW_CENTRED:
                xs = [r[0] for r in rows if r is not None]
                mid = 0.5 * (min(xs) + max(xs))
                rows = [None if r is None else (r[0] - mid, *r[1:]) for r in rows]
        self.wall_yaw = yaw
        self.wall_normal = normal
        quat = (math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw))
        centres, faces, sizes = [], [], []
        for i, row in enumerate(rows):
            if row is None:
                data.mocap_pos[self._mocap[i]] = PARKED
                data.mocap_pos[self._post_mocap[i]] = PARKED
                self.targets[i].hidden = True
                continue
            xa, h, z, off = row
            face = along * xa + normal * (wall - off) + np.array([0.0, 0.0, z])
            if BACK_ROW_M is not None and i % 2 == 1:
                face = face + normal * BACK_ROW_M
            centre = face + normal * h
            self._resize(i, h)
            data.mocap_pos[self._mocap[i]] = centre
            data.mocap_quat[self._mocap[i]] = quat
            data.mocap_pos[self._post_mocap[i]] = (centre[0], centre[1], centre[2] - h)
            self.targets[i].place(float(face[0]), float(face[1]), float(face[2]))
            centres.append(centre)
            faces.append(face)
            sizes.append(h)
        self.wall_distance = wall
        self.block_centres = np.array(centres)
        self.block_faces = np.array(faces)
        self.block_half_sizes = np.array(sizes)
        self.clutter_faces = self._place_clutter(rng, rows, wall, along, normal) if self.clutter else np.zeros((0, 3))
        self._half[:] = [0.0 if r is None else r[1] for r in rows]
        self._draw_loose(rng)
        if mirror:
            az = -az  # the push mirrored too: a seed's left wall is its right wall's mirror image
        c, sn_ = math.cos(az), math.sin(az)
        self.push_dir = np.array([c * normal[0] - sn_ * normal[1], sn_ * normal[0] + c * normal[1], 0.0])
        data.xfrc_applied[:] = 0.0

    def shoulder_world(self) -> np.ndarray:
        """The bracing shoulder (world) for this episode's wall side (the body's ``RIGHT_SHOULDER``, mirrored for
        a wall on the left)."""
        s = np.array(sn.RIGHT_SHOULDER, dtype=float)
        if self.wall_side > 0:
            s[1] = -s[1]
        return s + sn.STANCE_ORIGIN

    def _draw_loose(self, rng: np.random.Generator) -> None:
        """Which cubes are loose (:data:`LOOSE_CUBES`' rule), from a generator jumped off ``rng`` (nothing is
        drawn from ``rng`` itself), and their collision bits."""
        self.loose[:] = False
        n = len(self.block_faces)
        if LOOSE_CUBES and n:
            bg = rng.bit_generator
            g = np.random.Generator(bg.jumped()) if hasattr(bg, "jumped") else rng
            d = np.linalg.norm(self.block_faces[:, :2] - self.shoulder_world()[:2], axis=1)
            order = [int(i) for i in np.argsort(d, kind="stable")]  # active cubes are pool indices 0..n-1
            pair = order[:LOOSE_PAIR]
            self.loose[pair[int(g.integers(len(pair)))]] = True
            for i in order[LOOSE_PAIR:]:
                self.loose[i] = bool(g.random() < LOOSE_P)
        self.set_loose(self.loose)

    def set_loose(self, loose) -> None:
        """Make the pool's cubes loose where ``loose`` is true (their geoms collide with nothing) and firm elsewhere
        (the model's collision bits)."""
        self.loose[:] = np.asarray(loose, dtype=bool)
        m = self.model
        for i, geom in enumerate(self._block_geom):
            m.geom_contype[geom] = 0 if self.loose[i] else self._contype[i]
            m.geom_conaffinity[geom] = 0 if self.loose[i] else self._conaffinity[i]

    def _identify(self, raw: list) -> list:
        """This step's identity percept (+1 firm, -1 loose, 0 not identified) of each pool cube, from the
        retina's undelayed samples ``raw`` and the eye's true line of sight (see :data:`TEXTURE_SPACING_M`).
        Oracle: every cube in the scene; full view (foveal vision everywhere): every sampled cube."""
        out = [0.0] * sn.N_BLOCKS
        mode = self.vision_mode
        if mode != "oracle" and (self.eye is None or raw is None):
            return out
        if mode != "oracle":
            e = self.eye.pos
            axis = self.eye.rot[:, 0]
        for i in range(sn.N_BLOCKS):
            if self._half[i] <= 0.0 or self.targets[i].hidden:
                continue
            truth = -1.0 if self.loose[i] else 1.0
            if mode == "oracle":
                out[i] = truth
                continue
            if not raw[i][2]:
                continue  # not sampled this step (outside the field, or a saccade in flight)
            if mode == "full_view":
                out[i] = truth
                continue
            r = self.targets[i].position - e
            d = float(np.linalg.norm(r))
            if d <= 0.0:
                continue
            ang = math.acos(max(-1.0, min(1.0, float(r @ axis) / d)))
            ecc = max(0.0, ang - math.atan(self._half[i] / d))
            if ecc <= ident_eccentricity(d, self.bouma):
                out[i] = truth
        return out

    def _place_clutter(self, rng: np.random.Generator, rows: list, wall: float, along: np.ndarray,
                       normal: np.ndarray) -> np.ndarray:
        """Place the visual-only clutter (:data:`CLUTTER_PER_CUBE` around each cube within reach; one
        ``rng.integers`` seeds a generator of its own, after every other draw) and return its faces."""
        g = np.random.default_rng(int(rng.integers(2**31)))
        for t in self.clutter:
            t.hidden = True
        # silhouettes on the wall (along, z, half-size) that a clutter cube may not overlap
        boxes = [(r[0], r[2], r[1]) for r in rows if r is not None]
        faces, k = [], 0
        for i, row in enumerate(rows):
            if row is None or (BACK_ROW_M is not None and i % 2 == 1):
                continue
            xa, h, z, _off = row
            side = 1.0 if g.random() < 0.5 else -1.0
            for _ in range(CLUTTER_PER_CUBE):
                if k >= len(self.clutter):
                    break
                for _try in range(CLUTTER_TRIES):
                    hd = float(g.uniform(*CLUTTER_HALF_SIZE_M))
                    u = xa + side * float(g.uniform(0.0, h + CLUTTER_SPREAD_M))
                    v = z + float(g.uniform(-(h + CLUTTER_SPREAD_M), h + CLUTTER_SPREAD_M))
                    if all(abs(u - bx) >= bh + hd or abs(v - bz) >= bh + hd for bx, bz, bh in boxes):
                        break
                else:
                    continue
                boxes.append((u, v, hd))
                face = along * u + normal * (wall + float(g.uniform(*CLUTTER_BEHIND_M))) + np.array([0.0, 0.0, v])
                self.clutter[k].place(float(face[0]), float(face[1]), float(face[2]))
                faces.append(face)
                k += 1
        return np.array(faces).reshape(-1, 3)

    def _resize(self, i: int, h: float) -> None:
        """Cube ``i`` of half-size ``h``, with the bounding volumes MuJoCo's collision broad- and mid-phase
        read (as :class:`visuomotor_gym.tasks.walk_scene.ObstaclePool` does)."""
        m, g = self.model, self._block_geom[i]
        m.geom_size[g] = (h, h, h)
        m.geom_rbound[g] = math.sqrt(3.0) * h
        m.geom_aabb[g] = (0.0, 0.0, 0.0, h, h, h)
        if self._bvh[i] >= 0:
            m.bvh_aabb[self._bvh[i]] = (0.0, 0.0, 0.0, h, h, h)

    def initial_gaze(self) -> tuple[np.ndarray, tuple[float, float]]:
        return np.array(INITIAL_GAZE_POINT), (float(self.gaze_offset[0]), float(self.gaze_offset[1]))

    def trace_episode_fields(self) -> dict:
        return {"block_faces": self.block_faces.copy(), "block_half_sizes": self.block_half_sizes.copy(),
                "block_loose": self.loose[: len(self.block_faces)].copy(),
                "push_time": self.push_time, "push_force": self.push_force, "push_dir": self.push_dir.copy(),
                "wall_distance": self.wall_distance, "wall_side": self.wall_side}

    @staticmethod
    def trace_final_fields(info: dict) -> dict:
        return {"fell": bool(info["fallen"]), "hand_block": int(info["hand_block"])}

    # --- physics ------------------------------------------------------------------------------
    def before_physics(self, data: mujoco.MjData) -> None:
        t0 = data.time
        # The push acts over [push_time, push_time + duration): the fraction of this step it covers, as
        # a constant force over the step (exact impulse whatever the control period).
        lo = max(t0, self.push_time)
        hi = min(t0 + self.dt, self.push_time + PUSH_DURATION_S)
        frac = max(0.0, hi - lo) / self.dt
        data.xfrc_applied[self._torso, :3] = (self.push_force * frac) * self.push_dir

    def needs_substep_checks(self, data: mujoco.MjData) -> bool:
        return not self.fallen

    def check_substep(self, data: mujoco.MjData) -> bool:
        """True once the body has fallen (a forbidden contact, or the head too low)."""
        if self.fallen:
            return True
        d = data
        if d.ncon:
            fall = self._fall_pairs
            for g1, g2 in d.contact.geom.tolist():
                if (g1, g2) in fall:  # the first such contact, named body geom first
                    if g1 in self._scene:
                        g1, g2 = g2, g1
                    self.fallen = True
                    m = self.model
                    self.fall_geoms = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g1),
                                       mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g2))
                    return True
        if self.body.head_height(d) < FALL_HEAD_HEIGHT_M:
            self.fallen = True
            self.fall_geoms = ("head", "height")
            return True
        return False

    def _hand_contact(self, data: mujoco.MjData) -> int:
        """The block the palm touches now (its index), or -1."""
        if not data.ncon:
            return -1
        hand, blocks = self._hand, self._block_geoms
        for g1, g2 in data.contact.geom.tolist():  # (a contact object per contact costs more)
            if g1 in hand and g2 in blocks:
                return self._block_geom.index(g2)
            if g2 in hand and g1 in blocks:
                return self._block_geom.index(g1)
        return -1

    # --- observation --------------------------------------------------------------------------
    def observe_leading(self, values: list, samples: list) -> None:
        vis = []
        for pos, _vel, visible in samples[: sn.N_BLOCKS]:  # the cubes' samples (not the clutter's)
            values += pos
            vis.append(1.0 if visible else 0.0)
        self.visible = [v > 0.5 for v in vis]
        values += vis
        # The identity percept, computed at the sample's time and delayed as the retina delays the samples.
        self._firm_line.append(self._identify(getattr(self.retina, "last_samples", None)))
        values += self._firm_line[0] if len(self._firm_line) > self.delay_steps else [0.0] * sn.N_BLOCKS
        values.append(self.visual_delay_s)

    def observe_trailing(self, values: list, samples: list, data: mujoco.MjData) -> None:
        values.append(data.time)

    # --- outcome ------------------------------------------------------------------------------
    def evaluate(self, data: mujoco.MjData, fired: bool, a: np.ndarray, eye) -> tuple[float, dict, bool, dict]:
        d = data
        fallen = bool(fired or self.fallen)
        self.hand_block = self._hand_contact(d)
        if self.hand_block >= 0 and self.first_contact_time is None:
            self.first_contact_time = float(d.time)
        upright = (not fallen) and d.time >= self.push_time + HOLD_S - 1e-9
        self.success = upright
        w = self.reward_weights
        terms = {}
        if w.get("upright"):
            terms["upright"] = w["upright"] * float(upright)
        if w.get("fall"):
            terms["fall"] = w["fall"] * float(fallen)
        if w.get("effort"):
            terms["effort"] = w["effort"] * float(a @ a) / a.size
        reward = float(sum(terms.values()))
        return reward, terms, upright or fallen, self.info(d, fallen=fallen)

    def info(self, data: mujoco.MjData, *, fallen: bool = False, diverged: bool = False) -> dict:
        """Task information: the true scene, for scoring only, never for a policy."""
        t = float(data.time)
        return {
            "fallen": bool(fallen),
            "pushed": t >= self.push_time,
            "hand_on_block": self.hand_block >= 0,
            "hand_block": int(self.hand_block),
            "first_contact_time": -1.0 if self.first_contact_time is None else self.first_contact_time,
            "blocks_visible": np.array(self.visible, dtype=bool) if not diverged else np.zeros(sn.N_BLOCKS, bool),
        }
