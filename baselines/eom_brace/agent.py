"""The ``eom_brace`` baseline for PushRecovery: Eom et al.'s (2019, section 7) behaviour after a push.

The agent sees observations only (the cubes only as the eye's samples of their faces). Each 20 ms step:

1. **Perception**: every visual sample of a cube's face (eye frame at sampling time; the eye pose of that
   time is kept for the visual delay) is turned into the stance frame and fused per cube as a
   precision-weighted mean, weighted by the depth precision of the vision model at the sample's
   eccentricity (Eyecatch Eq. 2, as the ``faraway`` baseline): a peripheral sample knows the direction
   well and the depth badly, a fixated one both.
2. **Before the push**: ``look_latency_s`` after the start the eye and head turn to the wall's expected
   middle (modelling choice: Eom's character stands near the wall; the wall is on the right), so that the
   cubes are seen, peripherally, before anything happens; the hand waits at the body's right side.
3. **Detection**: the push is detected when the centre of pressure (the ``foot_pressure`` block) comes
   within ``cop_margin_m`` of the right foot's outer edge, i.e. leaves the support polygon's interior
   (Eom et al.: "the trajectory of the center of pressure crosses over the boundary of the supporting
   polygon"), or the left foot unloads.
4. **Brace**: ``reaction_latency_s`` after the detection, the agent chooses the **nearest believed cube** to the right shoulder, saccades to the
   centre of its face and keeps gaze there (Eom: "keeping the visual attention at the center of the
   block on which it places the hand") while the hand aligns in front of the believed face
   (``approach_offset_m``, to within ``align_m``) and then moves in, at most ``approach_speed_m_s``, to
   ``reach_depth_m`` beyond it. The choice and the target follow the belief as it sharpens under the
   fovea. When the hand stops (speed below ``contact_speed_m_s``), it holds there, and the braced arm
   acts as a strut along the wall's normal (the hand keeps its distance from the head as the body leans).
5. **Look away**: once the trunk is still (vestibular rates below ``still_rad_s`` for ``still_s``), gaze and
   head return straight ahead (Eom: "it turns the head away from the wall"). The hand stays on the cube
   (not released: releasing tips the leaning body back over; see the reproduction page).

Since PushRecovery's fourth pass (the wall turned per episode) the defaults are: samples that may be crowded
are dropped and the rest fused to 40 deg (``drop_crowded``); the push is detected along the vestibular fall
direction and the hand braces along it (``fall_direction``); the cube is chosen, looked at (verged at the wall's
expected distance) and first aimed at by the mean direction of its samples (``choose_by_ray``,
``verge_on_ray``, ``hand_on_cut``) until a fixated sample gives its depth; and the hand on the cube pushes
with the trunk's lean (``hold_lean_gain``, ``hold_lean_damp``) instead of holding a fixed strut.

Since the eighth pass (the wall on a random side, two arms) every right-side constant is mirrored for a wall on
the left and the left arm braces there (the action's ``arm`` value): the side is that of the cubes' first samples
before the push (the human field reaches 100 deg to each side), then that of the vestibular fall direction. An eye
that never sees a cube (a static posture turned away from the wall) has none to brace on: the hand stays at its
ready point, as the legs-only reference.

Since the eleventh pass (loose cubes, seen only by central vision: the ``block_firm`` percept) the agent identifies
before the push the cube nearest the shoulder, and the second nearest if the first is loose (``identify``), each look
verged by the vergence search (``depth_search``, on for a foveated eye), and braces on the nearest cube believed firm
(docs/reproductions/eom.md, eleventh pass).

``gaze_blind`` is the twin with gaze, vergence and head held (zero actions); the registered
``gaze_blind:eom_brace`` wrapper gives the same. ``use_hand=false`` is the legs-only reference: the same
agent whose hand stays at its ready point.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, fields, replace

import numpy as np
from visuomotor_gym.baselines.crowding import crowded

from visuomotor_gym.body import standing as sn
from visuomotor_gym.core.head import neck_range_deg
from visuomotor_gym.core.observation import ObservationLayout
from visuomotor_gym.envs.actions import eye_head_action
from visuomotor_gym.envs.push import push_observation
from visuomotor_gym.registration import env_vision
from visuomotor_gym.vision import foveation
from visuomotor_gym.vision.foveation import VisionParams

DEG = math.pi / 180.0
_LAYOUT = ObservationLayout(push_observation())
_S = _LAYOUT.slices
_NECK = neck_range_deg()
N = sn.N_BLOCKS
SHOULDER = np.array(sn.RIGHT_SHOULDER)  # right shoulder, stance frame (envs_assets/push.xml: upper_arm)
# The wall's side (PushRecovery's eighth pass: tasks.push_recovery.WALL_SIDE_RANDOM): every right-side constant below
# (the shoulder, the hand's ready point, the scan's y, the expected wall normal) is mirrored (y -> -y) for a wall
# on the left, and the left arm braces. Before the push the side is the sign of y of the cubes' lines of sight
# (any sample, at any eccentricity: the human field reaches 100 deg to each side, Spector 1990); SIDE_SAMPLES
# samples decide it (modelling choice); once the push is detected, the fall's direction (vestibular) decides.
SIDE_SAMPLES = 2
# A wall in front (PushRecovery's tenth pass: tasks.push_recovery.WALL_FRONT_P): the right-wall constants turned 90 deg
# to the front (the scan's point, the expected normal; the shoulders and hands stay where they are). Before the push
# the place is read from the cubes' lines of sight: once PLACE_CUBES cubes have been sampled (at any eccentricity),
# each is put where its mean line of sight meets the height PRIOR_FACE_Z_M (stance frame: the middle of the task's
# 1.00-1.35 m, a person standing by a wall knows roughly how high its cubes are), a line is fitted through them on
# the floor plane, and the wall is in front when that line's normal lies within FRONT_AZIMUTH_DEG of straight ahead
# (the scene's front normals lie within 30 deg of it, the side walls' 60-90 deg off; checked on 400 scenes with
# the true lines of sight: 49 deg at most, 54 at least; modelling choices). Once the push is detected, the fall's
# direction decides, by the same angle. In front the arm is the one whose shoulder's fall line passes nearest the
# chosen cube.
PLACE_CUBES = 3
PRIOR_FACE_Z_M = 0.245  # 1.175 m above the floor, minus the stance origin's 0.93 m
FRONT_AZIMUTH_DEG = 52.0
FOOT_HALF_WIDTH_M = 0.045  # envs_assets/push.xml: the foot box's half width
FOOT_HALF_LENGTH_M = 0.13  # ... and half length (the sole site is at the box's centre)
SAMPLE_DISTANCE_RANGE_M = (0.2, 2.0)  # samples outside are rejected: the cubes are 0.5-1.5 m from the eye (modelling choice)


@dataclass(frozen=True)
class EomBraceParams:
    """Every constant of the baseline, with its source; override by name (``eom_brace:name=value``)."""

    vision_noise_scale: float = 1.0
    foveated: bool = True
    visual_delay_s: float = 0.0
    gaze_action_range_deg: float = 60.0
    look_latency_s: float = 0.2  # first saccade 180-200 ms after the start (REFERENCES.md, saccade latency)
    # Before the push the eye looks at the wall's expected row at these x (stance frame; y and z below), a
    # fixation of scan_dwell_s at each in turn (modelling choice: a person standing by a wall knows where its
    # cubes are). Default: one long look at the wall's middle beside the shoulder (a three-point scan,
    # x = -0.25, 0.1, 0.45 m, did worse on seeds 0-39: 24-25/40 against 29/40).
    scan_x_m: tuple = (0.05,)
    scan_y_m: float = -0.75
    scan_z_m: float = 0.35
    scan_dwell_s: float = 0.3
    # Options tried in PushRecovery's third pass (off by default; docs/reproductions/eom.md, "Tried in the
    # third pass"): after the scan_x_m looks, fixate the scan_blocks believed cubes nearest the fall line in
    # turn, scan_dwell_s each (0: keep looking at the wall's middle); verge on the fixated cube's latest
    # sample distance when it lies within verge_ecc_deg of the fovea instead of on the belief's distance
    # (modelling choices: both made the foveated agent worse on seeds 0-39, see the page).
    scan_blocks: int = 0
    # wall_normal: the scan_blocks looks choose the cubes nearest the line through the shoulder along the wall's
    # normal as the believed faces give it (a line fitted through them on the floor plane; the push comes
    # toward the wall), not along the body's right (modelling choice; for a wall turned per episode).
    wall_normal: bool = False
    # choose_by_ray: after the detection, choose the cube by the DIRECTION of its samples, not by its believed
    # position: the mean line of sight of its fused samples (from the mean eye position they were seen from)
    # is cut with the plane ray_plane_m from the stance origin along the fall's direction (the wall's expected
    # distance: modelling choice, the middle of the task's 0.60-0.80 m), and the cube whose cut lies nearest
    # the fall line through the shoulder is chosen. A peripheral sample's direction is precise and its depth
    # coarse (the vision model), so a far cube believed near is not chosen (modelling choice).
    choose_by_ray: bool = True  # on since the fourth pass (the wall turned per episode)
    # drop_crowded: samples that may be crowded this step (another cube's perceived line of sight within the
    # critical spacing, baselines/crowding.py; Bouma 1970) are not fused: a pooled sample carries a
    # neighbour's position (modelling choice, as the walker baselines).
    drop_crowded: bool = True  # on since the fourth pass
    ray_plane_m: float = 0.7
    # ... and the chosen cube is looked at on its mean line of sight at that plane until its belief's best
    # sample weight reaches cut_until_w (1/m^2: a depth std of 1/sqrt(w), 400 = 5 cm; modelling choice)
    cut_until_w: float = 25.0  # 400 before the eleventh pass (the looks before the push now measure the cubes)
    hand_on_cut: bool = True  # ... and the hand aims there too until then (modelling choice; on since the fourth pass)
    # verge_on_ray: the vergence distance of a look at a cube is its line of sight's cut with that plane, not
    # the belief's distance (a belief from peripheral samples is wrong mostly along the line of sight, and a
    # fixation verged at the wrong distance keeps the depth coarse: the depth pedestal; modelling choice).
    verge_on_ray: bool = True  # on since the fourth pass
    verge_on_sample: bool = True  # on since the eleventh pass (the looks at the cubes before the push)
    verge_ecc_deg: float = 5.0
    hand_ready: tuple = (0.1, -0.4, 0.27)  # stance frame: the hand waits beside the hip, toward the wall (modelling choice)
    # The reaction: saccade and hand start this long after the detection. Arm reactions to a perturbation
    # start ~100-150 ms after it (Maki & McIlroy's reviews, REFERENCES.md, unconfirmed): modelling choice.
    reaction_latency_s: float = 0.1
    # Samples beyond this eccentricity are not fused: there a cube's depth is coarse and, beyond ~40 deg, its
    # position crowded by its neighbours (Bouma 1970: within ~0.5 x eccentricity; the cubes are ~20-25 deg apart
    # at the wall's distance); modelling choice: 40 with drop_crowded since the fourth pass (20 before).
    fuse_max_ecc_deg: float = 40.0
    reset_ratio: float = 10.0  # a sample this much more precise restarts a cube's mean (modelling choice)
    cop_margin_m: float = 0.01  # CoP within 1 cm of the foot's outer edge: leaving the polygon (modelling choice)
    # ... and for a fall straight ahead (within FRONT_AZIMUTH_DEG) toward a wall believed in front (tenth pass): CoP within this of
    # the toes. The stance's forward margin is long (the soles reach 13 cm ahead of the ankles) and a forward push
    # carries the trunk 0.3-0.5 m toward the wall before the CoP reaches the toes, into a cube at chest height
    # (measured on the Oracle rung, docs/reproductions/eom.md, tenth pass): modelling choice.
    front_cop_margin_m: float = 0.3
    # front_wall (tenth pass, opt-in, with tasks.push_recovery.WALL_FRONT_P > 0): the wall may stand in front (see
    # PLACE_CUBES); off, it is on a side, as in the registered scene.
    front_wall: bool = False
    # ... and toward a wall in front the last approach at <= this: the side brace's 1 m/s lands the hand after the
    # trunk has leant into the cubes (the forward fall is faster; 16/31 front walls held on the Oracle rung, seeds
    # 0-99, against 24/31 at 2 m/s, 28/31 at 3, eom.md tenth pass). Within human protective arm movements: the
    # wrist's peak speed during a forward fall's descent is 3.57 m/s (Tan, Eng, Robinovitch & Warnick 2006,
    # "Wrist impact velocities are smaller in forward falls than backward falls from standing"). Modelling choice.
    front_approach_speed_m_s: float = 3.0
    # ... once the pelvis moves faster than this: the stance settling after the start reaches 0.15 m/s, a push
    # 0.2-0.5 m/s within 0.1 s (measured; modelling choice).
    front_fall_speed_m_s: float = 0.25
    unload_fraction: float = 0.05  # or a foot carrying < 5 % of body weight (modelling choice)
    # fall_direction: detect the push from the pelvis's velocity direction (vestibular; once faster than
    # fall_speed_m_s) and the CoP within cop_margin_m of the support polygon's extent along it, then choose the
    # cube nearest the fall line through the shoulder and brace along that direction, for a wall that is not
    # beside the body (task WALL_YAW_DEG; on since the fourth pass). Off: the wall assumed on the right.
    fall_direction: bool = True
    # reach_max_m (fifth pass, opt-in; 0 = off): a cube whose believed face lies farther than this from the
    # shoulder along the fall's direction is out of reach and not chosen while a nearer one is believed
    # (modelling choice: the arm's ~0.6 m plus the lean; a back row of cubes, tasks.push_recovery.BACK_ROW_M).
    reach_max_m: float = 0.0
    # verify_reach (with reach_max_m): a cube is chosen only once a fixation has measured it within reach (a
    # sample of weight >= verify_w); until then the eye checks the candidates nearest the fall line in turn,
    # verify_dwell_s each, the hand does not move in, and the scan before the push looks at the cubes on the
    # expected wall plane (modelling choice: a depth seen only in the periphery, ~0.4 m std at 20 deg, cannot
    # tell a cube within reach from one behind it).
    verify_reach: bool = False
    verify_w: float = 100.0  # a depth std under 10 cm: the rows 0.3-0.4 m apart are told apart (modelling choice)
    verify_dwell_s: float = 0.15  # a candidate looked at this long without a measured depth is passed over (modelling choice)
    # depth_search (sixth pass, opt-in; with reach_max_m): a VERGENCE SEARCH before the push. Each cube's distance
    # along its mean line of sight is believed on a grid (depth_grid_m, every depth_grid_step_m) by the likelihood
    # of its fused samples' distances under the vision model's depth law at each hypothesised distance (the
    # std d x depth_std_fraction / acuity, x (1 + eta / eta_2) with eta the disparity pedestal from the vergence of
    # that sample's time; Blakemore 1970): a scatter of samples is itself evidence that the cube is not at the
    # vergence distance. Before the push the eye fixates the search_blocks cubes nearest the expected fall line
    # in turn, each verged at its most probable distance (vergence follows the fixated object's depth: Erkelens
    # et al. 1989; Collewijn et al. 1995), until it is known within reach or beyond (posterior probability
    # search_sure, or search_max_s on one cube); after the push the brace chooses among the cubes believed within
    # reach (probability >= 0.5) and aims at the believed face given that it is within reach (modelling choices).
    depth_search: bool = True  # on since the eleventh pass (with identify: the looks at the cubes verge on them)
    depth_grid_m: tuple = (0.3, 2.0)
    depth_grid_step_m: float = 0.02
    search_blocks: int = 3
    search_sure: float = 0.9
    search_max_s: float = 0.3
    # the expected fall direction before the push: the wall's normal turned forward by this (deg; the middle of
    # the task's 0..30 deg: modelling choice, a person standing by a wall knows roughly how it runs)
    search_yaw_deg: float = 15.0
    # trust_ecc_deg (seventh pass, opt-in; 0 = off): a wall with visual-only clutter of the cubes' own kind
    # (tasks.push_recovery.CLUTTER_PER_CUBE) crowds every peripheral sample of a cube (Bouma 1970: flankers within
    # 0.5 x eccentricity pool; the clutter itself is never seen as a cube, so baselines/crowding.py cannot flag
    # it): a sample beyond this eccentricity is taken as possibly pooled. It still places the cube coarsely (the
    # looks and the choice use it) until the cube's first sample within trust_ecc_deg, which restarts its belief
    # (position and direction) from the trusted samples only; the look at a cube without one goes to its latest
    # sample (a corrective saccade: a pooled percept nearer the fovea has fewer flankers), and the hand moves in
    # only once the chosen cube has a trusted sample, or align_timeout_s after the reaction (modelling choices).
    trust_ecc_deg: float = 0.0
    fall_speed_m_s: float = 0.15  # the pelvis moving faster than this: its direction is the fall's (modelling choice)
    approach_offset_m: float = 0.10  # align the palm 10 cm in front of the believed face first (modelling choice)
    align_m: float = 0.04  # ... to within 4 cm along the wall, then move in (modelling choice)
    align_timeout_s: float = 0.25  # ... or after this long, aligned or not (modelling choice)
    approach_speed_m_s: float = 1.0  # the last approach at <= 1 m/s: a hand that slams in bounces the body off
    reach_depth_m: float = 0.02  # aim 2 cm beyond the believed face, so the hand arrives pushing (modelling choice)
    contact_speed_m_s: float = 0.2  # the hand has stopped (on the cube, or short of it) (modelling choice)
    min_reach_s: float = 0.06  # ... no sooner than this after the approach began (modelling choice)
    # The brace yields once the body moves back away from the wall faster than this (pelvis velocity
    # along +y): the hand target follows the hand, so the arm stops pushing and the push-off does not
    # throw the body over its left foot (modelling choice; measured on seeds 0-39, see the Eom page).
    # A negative value switches the yield off (the arm pushes as a strut throughout).
    yield_speed_m_s: float = 0.0
    yield_brace: float = 0.0  # the brace command while the arm yields (-1 relaxed .. 1 braced; modelling choice)
    # The active hold (on since the fourth pass; 0 switches it off): once the hand is on the cube, it pushes along the fall's direction by
    # hold_lean_gain m per rad of the trunk's lean toward the wall beyond hold_lean_ref, plus hold_lean_damp m
    # per rad/s of the lean's rate (the vestibular tilt and rates), clipped to [-hold_retract_m, hold_push_m]:
    # the arm is a balance controller, not a fixed strut (modelling choice).
    hold_lean_gain: float = 2.0
    hold_lean_ref: float = 0.0
    hold_lean_damp: float = 0.1
    hold_push_m: float = 0.15
    hold_retract_m: float = 0.05
    still_rad_s: float = 0.15  # trunk still: every vestibular rate below this (modelling choice)
    still_s: float = 0.5  # ... for this long before looking away (modelling choice)
    head_dead_zone_deg: float = 20.0  # Eyecatch Sec. 4.2 Eq. 17
    gaze_blind: bool = False
    # identify (PushRecovery's eleventh pass: loose cubes, tasks.push_recovery.LOOSE_CUBES): before the push, once the
    # wall has been looked at for ident_wall_s, the eye fixates the cube nearest the shoulder (by the horizontal
    # distance of its mean line of sight's cut with the expected wall plane), and the second nearest if the first is
    # identified loose (Johansson et al. 2001: gaze goes to the contact points before the hand; Eom section 7: gaze
    # on the block's centre); the identities (the block_firm percept) are remembered. The scene's rule (exactly one
    # of the two cubes nearest the shoulder is loose) completes the pair's identities once one is identified. After
    # the push the hand goes to the nearest cube believed firm; of the two nearest, an unidentified one counts as
    # possibly firm (a gamble when none is identified), a cube beyond them only ident_other_m farther; a cube
    # believed loose only when no other is believed. Modelling choices.
    identify: bool = True
    ident_wall_s: float = 0.35
    ident_other_m: float = 0.25
    ident_scan: int = 2  # ... the cubes looked at before the push (modelling choice)
    ident_measured_w: float = 25.0  # ... a cube placed by its fused estimate once a sample this precise came (1/m^2)
    ident_choose: bool = True  # off: the looks only, the choice as without identities (a diagnostic)
    # The legs-only reference: the same agent with its hand kept at the ready point (no brace).
    use_hand: bool = True

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("foveated", "gaze_blind", "use_hand", "verge_on_sample", "fall_direction", "wall_normal",
                          "choose_by_ray", "drop_crowded", "verge_on_ray",
                          "hand_on_cut", "verify_reach", "depth_search", "front_wall", "identify", "ident_choose"):
                if not isinstance(v, bool):
                    raise ValueError(f"EomBraceParams.{f.name} must be true or false, got {v!r}")
            elif f.name == "depth_grid_m":
                if not (isinstance(v, tuple) and len(v) == 2 and all(isinstance(x, (int, float)) for x in v)
                        and 0.0 < v[0] < v[1] and math.isfinite(v[1])):
                    raise ValueError(f"EomBraceParams.depth_grid_m must be (lo, hi) with 0 < lo < hi, got {v!r}")
            elif f.name == "search_sure":
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.5 < v < 1.0:
                    raise ValueError(f"EomBraceParams.search_sure must be a probability in (0.5, 1), got {v!r}")
            elif f.name == "depth_grid_step_m":
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 < v <= 0.5:
                    raise ValueError(f"EomBraceParams.depth_grid_step_m must be in (0, 0.5] m, got {v!r}")
            elif f.name == "search_yaw_deg":
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not -90.0 <= v <= 90.0:
                    raise ValueError(f"EomBraceParams.search_yaw_deg must be a number in [-90, 90], got {v!r}")
            elif f.name in ("scan_blocks", "search_blocks"):
                if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                    raise ValueError(f"EomBraceParams.{f.name} must be an integer >= 0, got {v!r}")
            elif isinstance(v, tuple):
                if len(v) < 1 or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in v):
                    raise ValueError(f"EomBraceParams.{f.name} must be finite numbers, got {v!r}")
            elif isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or (v < 0 and f.name not in ("scan_y_m", "scan_z_m", "yield_speed_m_s", "yield_brace",
                                           "hold_lean_ref")):
                raise ValueError(f"EomBraceParams.{f.name} must be a finite number >= 0, got {v!r}")


def encode(hand_target, brace: float, gaze, fixation_m, head, gaze_range: float, left: bool = False) -> np.ndarray:
    """The 10-dim PushRecovery action: hand target (stance frame), brace (-1..1), the arm (``left``: the left arm,
    else the right), gaze change (rad), fixation distance (m; None keeps the neutral value), neck (yaw, pitch;
    rad)."""
    a = np.zeros(10, dtype=np.float32)
    a[:3] = sn.hand_target_action(np.asarray(hand_target) + sn.STANCE_ORIGIN)
    a[3] = brace
    a[4] = 1.0 if left else -1.0
    a[5:10] = eye_head_action(gaze, fixation_m, head, gaze_range)
    return a


class EomBraceAgent:
    """Detect the push, look at the nearest believed cube, put the hand on it (SB3 ``predict`` interface)."""

    def __init__(self, params: EomBraceParams | None = None, dt: float = 0.02, vision: VisionParams | None = None):
        self.params = params or EomBraceParams()
        if self.params.depth_search and self.params.identify and not self.params.foveated:
            # The vergence search is for the foveated eye's depth law; an eye without a periphery (the Oracle and
            # FullView rungs) places every cube by its fused samples (measured: the search cost the Oracle rung).
            self.params = replace(self.params, depth_search=False)
        p = self.params
        self.dt = float(dt)
        base = vision if vision is not None else VisionParams()  # the env's eye (for_env: its vision defaults)
        self.vision = replace(base, noise_scale=max(p.vision_noise_scale, 1e-6), foveated=p.foveated)
        self.delay_steps = round(p.visual_delay_s / self.dt)
        self.gaze_range = p.gaze_action_range_deg * DEG
        self.reset()

    @classmethod
    def for_env(cls, env_id: str, **overrides) -> EomBraceAgent:
        """An agent whose assumed vision matches the registered env (noise, foveation, latency)."""
        base = EomBraceParams(**env_vision(env_id))
        known = {f.name for f in fields(EomBraceParams)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise TypeError(f"unknown eom_brace parameter(s) {unknown}; known: {sorted(known)}")
        from visuomotor_gym.registration import env_vision_params

        return cls(replace(base, **overrides), vision=replace(env_vision_params(env_id), noise_scale=1.0))

    def reset(self) -> None:
        self.started = False
        self.w = np.zeros(N)
        self.sum = np.zeros((N, 3))
        self.best_w = np.zeros(N)
        self.dir_sum = np.zeros((N, 3))  # sum of the fused samples' unit lines of sight (stance frame)
        self.dir_eye = np.zeros((N, 3))  # ... and of the eye positions they were seen from
        self.dir_n = np.zeros(N)
        self.trusted = np.zeros(N, dtype=bool)  # trust_ecc_deg: a sample within it has come
        self.last_seen = np.zeros((N, 3))  # trust_ecc_deg: the latest sample (stance frame)
        # depth_search: every fused sample of each cube as (eye position, unit line of sight (stance frame),
        # distance, eccentricity, vergence distance of its time)
        self.samples: list[list] = [[] for _ in range(N)]
        self._post: dict = {}  # this step's posteriors, by cube
        self._search_target: int | None = None
        self._search_since: float | None = None
        self.poses: deque = deque(maxlen=self.delay_steps + 1)
        self._pose_pairs: deque = deque(maxlen=self.delay_steps + 2)  # depth_search: the pose before a sample's
        self._slip_pose = None
        self.home: np.ndarray | None = None
        self.detected_at: float | None = None
        self.side = -1  # the wall's side: -1 right (y < 0), +1 left; the right until the cubes or the fall say
        self._side_sum = 0.0  # the summed y of the cubes' unit lines of sight (stance frame)
        self._side_n = 0
        self._side_known = False
        self.front = False  # the wall in front (tenth pass)
        self._los = np.zeros((N, 3))  # summed unit lines of sight of every sample of each cube (stance frame)
        self._los_eye = np.zeros((N, 3))  # ... and the eye positions they were seen from
        self._los_n = np.zeros(N)
        self.shoulder = SHOULDER.copy()
        self.normal = np.array([0.0, -1.0, 0.0])
        self._scan_order = None
        self._look_normal = np.array([0.0, -1.0, 0.0])
        self._set_side(-1)
        self._scan_k = -1
        self._scan_target = 0
        self.chosen: int | None = None
        self._checked: set = set()  # verify_reach: cubes ruled out (measured beyond reach, or not seen well)
        self._check_since: float | None = None
        self.hold: np.ndarray | None = None
        self.hold_eye: np.ndarray | None = None
        self.approach_since: float | None = None
        self.still_since: float | None = None
        self.looked_away = False
        self.events: list[tuple[float, str]] = []
        self.firm = np.zeros(N)  # identify: each cube's remembered identity, +1 firm, -1 loose, 0 unknown

    # --- belief -----------------------------------------------------------------------------------
    def estimate(self, i: int) -> np.ndarray:
        if self.w[i] <= 0.0:  # identify with depth_search: only lines of sight recorded so far
            return self._direction_cut(i, self.normal)
        return self.sum[i] / self.w[i]

    def _fuse(self, i: int, pos_eye: np.ndarray, rot: np.ndarray, eye: np.ndarray, fixation: float) -> None:
        """Add one sample, weighted by its expected depth precision under the vision model (Eyecatch Eq. 2
        at its eccentricity, and the depth pedestal from the vergence distance of that time when the
        vision has it). The noise is taken at the sample's own distance. A sample ``reset_ratio`` times
        more precise than the best one so far restarts the mean: the earlier, coarse samples are dropped
        (a cube first seen in the periphery, then fixated)."""
        if self.params.depth_search:
            self._record(i, pos_eye, rot, eye, fixation)
        if pos_eye[0] <= 0.0:
            return
        dist = float(np.linalg.norm(pos_eye))
        if not SAMPLE_DISTANCE_RANGE_M[0] <= dist <= SAMPLE_DISTANCE_RANGE_M[1]:
            return
        v = self.vision
        ecc = foveation.eccentricity(pos_eye)
        if self.params.trust_ecc_deg > 0 and v.foveated:
            self.last_seen[i] = eye + rot @ pos_eye
            if ecc <= self.params.trust_ecc_deg * DEG:
                if not self.trusted[i]:  # the first trusted sample: forget the pooled ones
                    self.trusted[i] = True
                    self.w[i] = self.best_w[i] = 0.0
                    self.sum[i] = 0.0
                    self.dir_sum[i] = 0.0
                    self.dir_eye[i] = 0.0
                    self.dir_n[i] = 0.0
            elif self.trusted[i]:
                return  # possibly pooled with the clutter: a trusted belief keeps to trusted samples
        if v.foveated and ecc > self.params.fuse_max_ecc_deg * DEG:
            return  # far periphery: crowded and coarse, not fused (a full view has no periphery)
        depth_std = dist * v.depth_std_fraction * v.noise_scale / foveation.acuity(ecc, v)
        if v.depth_pedestal_arcmin is not None and v.foveated:
            # Depth is precise only near the vergence distance (the env's depth law, Blakemore 1970).
            eta = v.interocular_m * abs(1.0 / dist - 1.0 / max(fixation, 0.1)) / foveation.ARCMIN
            depth_std *= 1.0 + eta / v.depth_pedestal_arcmin
        w = 1.0 / max(depth_std, 1e-6) ** 2
        if w > self.params.reset_ratio * self.best_w[i]:
            self.w[i] = 0.0
            self.sum[i] = 0.0
            self.best_w[i] = w
        self.best_w[i] = max(self.best_w[i], w)
        self.w[i] += w
        self.sum[i] += w * (eye + rot @ pos_eye)
        if not self.params.depth_search:
            self.dir_sum[i] += rot @ (pos_eye / dist)
            self.dir_eye[i] += eye
            self.dir_n[i] += 1.0

    def _crowded_by_belief(self, seen: list, los: list, rot: np.ndarray, eye: np.ndarray) -> set:
        """depth_search: the samples that may be crowded judged by where the cubes are BELIEVED to be (their
        mean lines of sight cut with the expected wall plane, in the eye frame of the sample), not only by where
        this step's samples put them: a pooled percept lies between its cube and the flankers, at a smaller
        eccentricity than its cube, so its own critical spacing understates the crowding zone (Bouma 1970;
        the env pools flankers within crowding_bouma x the target's eccentricity)."""
        v = self.vision
        if not (v.crowding and v.foveated):
            return set()
        yaw = self.params.search_yaw_deg * DEG
        n0 = self.normal if self.detected_at is not None else self._m(np.array([math.sin(yaw), -math.cos(yaw), 0.0]))
        believed = {}
        for j in range(N):
            if self.dir_n[j] > 0.0:
                d = rot.T @ (self._direction_cut(j, n0) - eye)
                nd = float(np.linalg.norm(d))
                if nd > 0.0 and d[0] > 0.0:
                    believed[j] = d / nd
        out = set()
        fovea = v.crowding_fovea_deg * DEG
        for i, p in zip(seen, los):
            u = p / max(float(np.linalg.norm(p)), 1e-12)
            own = believed.get(i, u)
            theta = max(foveation.eccentricity(own), foveation.eccentricity(u))
            if theta <= fovea:
                continue
            for j, b in believed.items():
                if j != i and min(math.acos(min(1.0, float(own @ b))), math.acos(min(1.0, float(u @ b)))) \
                        < v.crowding_bouma * theta:
                    out.add(i)
                    break
        return out

    def _record(self, i: int, pos_eye: np.ndarray, rot: np.ndarray, eye: np.ndarray, fixation: float) -> None:
        """depth_search: keep a sample for the depth likelihood (its signed distance: negative for a sample
        that the depth error put behind the eye) and add its line of sight to the cube's mean direction,
        weighted by its lateral precision (the vision model's position law at its eccentricity: a foveal
        direction outweighs a peripheral one)."""
        dist = float(np.linalg.norm(pos_eye))
        if dist <= 0.0:
            return
        u = pos_eye / dist if pos_eye[0] > 0.0 else -pos_eye / dist
        signed = dist if pos_eye[0] > 0.0 else -dist
        ecc = foveation.eccentricity(u)
        v = self.vision
        if v.foveated and ecc > self.params.fuse_max_ecc_deg * DEG:
            return
        # The image's retinal slip (it blurs the direction: the vision model's slip factor), taken as the
        # believed cube's angular speed in the eye frame between the previous pose and the sample's.
        slip = 0.0
        if self._slip_pose is not None and self.dir_n[i] > 0.0:
            x = self._direction_cut(i, self.normal)
            a, b = rot.T @ (x - eye), self._slip_pose[0].T @ (x - self._slip_pose[1])
            c = float(a @ b) / max(float(np.linalg.norm(a) * np.linalg.norm(b)), 1e-12)
            slip = math.acos(max(-1.0, min(1.0, c))) / self.dt
        lat = float(foveation.standard_deviations(1.0, ecc, slip, v)[1])  # rad per m of distance
        wd = 1.0 / max(lat, 1e-6) ** 2
        self.samples[i].append((eye.copy(), rot @ u, signed, ecc, fixation, wd))
        self.dir_sum[i] += wd * (rot @ u)
        self.dir_eye[i] += wd * eye
        self.dir_n[i] += wd

    def posterior(self, i: int, n: np.ndarray):
        """depth_search: cube ``i``'s belief along its mean line of sight, ``(points, probabilities,
        p_reach)``: the grid's points (stance frame), their posterior probabilities (flat prior on the grid)
        and the probability that the face lies within ``reach_max_m`` of the shoulder along ``n``. The
        likelihood of each sample's distance ``s`` at a hypothesised distance ``D`` is N(s; D, sigma(D)) with
        the vision model's depth std at ``D``, the sample's eccentricity and its vergence distance (the env's
        depth law), so a fixation verged far from a cube, whose samples scatter, still says where it is not."""
        key = (i, float(n[0]), float(n[1]))
        if key in self._post:
            return self._post[key]
        p, v = self.params, self.vision
        rows = self.samples[i]
        eyes = np.array([r[0] for r in rows])
        dist = np.array([r[2] for r in rows])
        ecc = np.array([r[3] for r in rows])
        verg = np.maximum(np.array([r[4] for r in rows]), 0.1)
        origin = self.dir_eye[i] / max(self.dir_n[i], 1e-12)
        u = self.dir_sum[i] / max(float(np.linalg.norm(self.dir_sum[i])), 1e-12)
        grid = np.arange(p.depth_grid_m[0], p.depth_grid_m[1] + 1e-9, p.depth_grid_step_m)
        points = origin + np.outer(grid, u)
        d = np.linalg.norm(points[None, :, :] - eyes[:, None, :], axis=2)  # samples x grid
        sig = d * v.depth_std_fraction * v.noise_scale
        if v.foveated:
            e2 = v.fovea_e2_deg * DEG
            sig = sig * ((e2 + ecc) / e2)[:, None]  # / acuity
            if v.depth_pedestal_arcmin is not None:
                eta = v.interocular_m * np.abs(1.0 / d - 1.0 / verg[:, None]) / foveation.ARCMIN
                sig = sig * (1.0 + eta / v.depth_pedestal_arcmin)
        sig = np.maximum(sig, 1e-3)
        ll = np.sum(-0.5 * ((dist[:, None] - d) / sig) ** 2 - np.log(sig), axis=0)
        prob = np.exp(ll - ll.max())
        prob /= prob.sum()
        reach = float(prob[(points - self.shoulder) @ n <= p.reach_max_m].sum()) if p.reach_max_m > 0 else 1.0
        out = (points, prob, reach)
        self._post[key] = out
        return out

    def _depth_point(self, i: int, n: np.ndarray, within_reach: bool = False) -> np.ndarray:
        """depth_search: the believed face of cube ``i`` (the posterior mean of its grid points; given that it
        lies within reach along ``n`` when ``within_reach`` and that has any probability)."""
        points, prob, _ = self.posterior(i, n)
        if within_reach and self.params.reach_max_m > 0:
            m = prob * (((points - self.shoulder) @ n) <= self.params.reach_max_m)
            if m.sum() > 1e-12:
                prob = m / m.sum()
        x = prob @ points
        # The grid lies on the samples' mean line of sight, which is not a line of sight of any one eye position
        # once the body has moved (parallax): the face is then the lateral-precision-weighted mean of each
        # sample's own line of sight at its eye's distance to that point, iterated with Huber weights (a sample
        # whose line of sight misses the point by more than twice its lateral std counts less: a pooled, crowded
        # percept the crowding test missed; modelling choice).
        rows = self.samples[i]
        eyes = np.array([r[0] for r in rows])
        dirs = np.array([r[1] for r in rows])
        wd = np.array([r[5] for r in rows])
        sd = 1.0 / np.sqrt(wd)
        w = wd
        for _ in range(4):
            rel = x - eyes
            dist = np.linalg.norm(rel, axis=1)
            q = eyes + dirs * dist[:, None]
            x = w @ q / w.sum()
            rel = x - eyes
            cosang = np.sum(rel * dirs, axis=1) / np.maximum(np.linalg.norm(rel, axis=1), 1e-12)
            miss = np.arccos(np.clip(cosang, -1.0, 1.0))
            w = wd / np.maximum(1.0, miss / (2.0 * sd))
        return x

    def _depth_mode(self, i: int, n: np.ndarray) -> np.ndarray:
        """depth_search: cube ``i``'s most probable face point (where the search verges next)."""
        points, prob, _ = self.posterior(i, n)
        return points[int(np.argmax(prob))]

    # --- policy -----------------------------------------------------------------------------------
    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=float)
        if episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0]) and self.started:
            self.reset()
        if obs.shape != (_LAYOUT.size,):
            raise ValueError(f"EomBraceAgent expects the flat PushRecovery observation of size {_LAYOUT.size}, "
                             f"got shape {obs.shape}")
        return self._act(obs), state

    def _act(self, obs: np.ndarray) -> np.ndarray:
        p = self.params
        t = float(obs[_S["time"]][0])
        rot = obs[_S["eye_rot"]].reshape(3, 3)
        eye = obs[_S["eye_pos"]].copy()
        if not self.started:
            self.started = True
        self.poses.append((rot.copy(), eye.copy(), float(obs[_S["fixation"]][0])))
        self._pose_pairs.append((rot.copy(), eye.copy()))
        if "block_firm" in _S:
            fr = obs[_S["block_firm"]]
            for i in range(N):
                if fr[i] != 0.0:
                    if self.firm[i] == 0.0:
                        self.events.append((t, f"identified {i} {'firm' if fr[i] > 0 else 'loose'}"))
                    self.firm[i] = 1.0 if fr[i] > 0 else -1.0
        if len(self.poses) == self.delay_steps + 1:
            r0, e0, f0 = self.poses[0]
            self._slip_pose = self._pose_pairs[0] if len(self._pose_pairs) == self.delay_steps + 2 else None
            pos = obs[_S["block_pos"]].reshape(N, 3)
            vis = obs[_S["block_visible"]]
            if self.params.depth_search:
                # A sample whose depth error put it behind the eye is still a sample (of the line of sight,
                # reversed; its distance negative): the scatter is the evidence the search uses.
                seen = [i for i in range(N) if vis[i] > 0.5 and float(pos[i] @ pos[i]) > 0.0]
                los = [pos[i] if pos[i][0] > 0.0 else -pos[i] for i in seen]
            else:
                seen = [i for i in range(N) if vis[i] > 0.5 and pos[i][0] > 0.0]
                los = [pos[i] for i in seen]
            skip = set()
            if self.params.drop_crowded and len(seen) > 1:
                skip = {seen[k] for k in crowded(los, seen, self.vision)}
            if self.params.depth_search and self.params.drop_crowded:
                skip |= self._crowded_by_belief(seen, los, r0, e0)
            for i in seen:
                if i not in skip:
                    self._fuse(i, pos[i].copy(), r0, e0, f0)
            if self.detected_at is None:  # the wall's side, from any sample's line of sight
                for i in range(N):
                    if vis[i] > 0.5 and float(pos[i] @ pos[i]) > 0.0:
                        u = pos[i] if pos[i][0] > 0.0 else -pos[i]
                        w = r0 @ u / max(float(np.linalg.norm(u)), 1e-12)
                        self._side_sum += float(w[1])
                        self._side_n += 1
                        self._los[i] += w
                        self._los_eye[i] += e0
                        self._los_n[i] += 1
                if self._side_n >= SIDE_SAMPLES and self._side_sum != 0.0:
                    self._side_known = True
                    self._set_side(1 if self._side_sum > 0.0 else -1, self._front_from_lines())
        self._post = {}

        # --- detection: the CoP at the support polygon's edge (or a foot unloaded) ---------------------
        cop = obs[_S["foot_pressure"]]
        feet = obs[_S["feet"]].reshape(2, 3)
        vel = obs[_S["vestibular"]][5:8]
        if self.detected_at is None and (cop[2] + cop[3]) > 0 and not p.fall_direction:
            # The wall beside the body: the CoP at the right foot's outer edge, or the left foot unloaded.
            edge = feet[1, 1] - FOOT_HALF_WIDTH_M
            if cop[1] < edge + p.cop_margin_m or cop[2] < p.unload_fraction:
                self.detected_at = t
                self.events.append((t, "detect"))
        elif self.detected_at is None and (cop[2] + cop[3]) > 0:
            # Any direction: the fall's is the pelvis's horizontal velocity (vestibular), once it is a push's;
            # detected when the CoP comes within cop_margin_m of the support polygon's extent along it (the
            # soles' corners), or a foot unloads. The hand then braces along that direction.
            vh = np.array([vel[0], vel[1], 0.0])
            speed = float(np.linalg.norm(vh))
            if speed > p.fall_speed_m_s:
                u = vh / speed
                ext = max(float(u[0] * (f[0] + sx * FOOT_HALF_LENGTH_M) + u[1] * (f[1] + sy * FOOT_HALF_WIDTH_M))
                          for f in feet for sx in (-1, 1) for sy in (-1, 1))
                forward = abs(math.degrees(math.atan2(u[1], u[0]))) < FRONT_AZIMUTH_DEG  # a fall straight ahead
                ahead = self.front and forward
                margin = p.front_cop_margin_m if ahead and speed > p.front_fall_speed_m_s else p.cop_margin_m
                if float(u[0] * cop[0] + u[1] * cop[1]) > ext - margin \
                        or min(cop[2], cop[3]) < p.unload_fraction:
                    self.detected_at = t
                    front = p.front_wall and forward
                    self._set_side(self.side if front else (1 if u[1] > 0.0 else -1), front)
                    self.normal = u
                    self.events.append((t, "detect"))
        n = self.normal
        left = self.side > 0
        hand = obs[_S["left_hand_pos" if left else "hand_pos"]].copy()

        # --- which cube, and the hand ------------------------------------------------------------------
        target = self.home
        brace = 1.0
        look_at = None
        look_block = None
        known = [i for i in range(N) if self.w[i] > 0
                 or (p.identify and p.depth_search and self.dir_n[i] > 0)]  # identify: a recorded line of sight
        search_look = False
        if t >= p.look_latency_s - 1e-9 and self._side_known:
            k = int((t - p.look_latency_s + 1e-9) // p.scan_dwell_s)
            if p.depth_search and known and k >= len(p.scan_x_m) and self.detected_at is None and not p.identify:
                look_at, look_block = self._search_look(known, t)
                search_look = True
            elif p.identify and known \
                    and t >= p.look_latency_s + p.ident_wall_s - 1e-9:
                # Fixate, nearest first, the ident_scan cubes nearest the shoulder that are not yet identified (or
                # measured: a fixated sample of weight >= ident_measured_w); then rest on the nearest believed firm.
                yaw = p.search_yaw_deg * DEG
                n0 = self._m(np.array([math.sin(yaw), -math.cos(yaw), 0.0])) if p.depth_search else self._look_normal
                if self.detected_at is not None:
                    n0 = n
                order, belief = self._pair_beliefs(known, n0, full=True)
                cand = order[:p.ident_scan]
                todo = [i for i in cand if self.firm[i] == 0.0
                        or (not p.depth_search and self.best_w[i] < p.ident_measured_w)]
                if belief.get(order[0], 0.0) != 0.0 and len(order) > 1 and belief.get(order[1], 0.0) != 0.0:
                    todo = [i for i in todo if i not in order[:2]]  # the pair known: look at nothing farther
                    todo = []
                firm = [i for i in order[:2] if belief[i] > 0.0]
                tgt = todo[0] if todo else (firm[0] if firm else order[0])
                if p.depth_search:  # along its line of sight, verged at its most probable distance
                    look_at = self._depth_mode(tgt, n0)
                    search_look = True
                else:
                    look_at = self._direction_cut(tgt, n0)
                look_block = tgt
            elif p.scan_blocks <= 0:
                look_at = self._m(np.array([p.scan_x_m[k % len(p.scan_x_m)], p.scan_y_m, p.scan_z_m]))
            elif k < len(p.scan_x_m) or not known:
                k = min(k, len(p.scan_x_m) - 1)
                look_at = self._m(np.array([p.scan_x_m[k], p.scan_y_m, p.scan_z_m]))
            else:
                # Then fixate the believed cubes nearest the shoulder in turn (they are where the hand may
                # go): a fixated cube is localised by the fovea, laterally and, verged on, in depth.
                if self._scan_order is None or k != self._scan_k:
                    faces = np.array([self.estimate(i) for i in known]) - self.shoulder
                    if p.wall_normal:
                        n = self._wall_normal(faces, n)
                        self._look_normal = n
                    lateral = faces - np.outer(faces @ n, n)
                    order = [known[j] for j in np.argsort(np.linalg.norm(lateral, axis=1))][:p.scan_blocks]
                    self._scan_order = order
                    self._scan_k = k
                    self._scan_target = order[(k - len(p.scan_x_m)) % len(order)]
                look_at = self.estimate(self._scan_target)
                if p.trust_ecc_deg > 0 and self.vision.foveated and not self.trusted[self._scan_target]:
                    look_at = self.last_seen[self._scan_target].copy()  # its latest percept (corrective)
                if p.verify_reach:  # verged at the expected wall: a front cube's depth is measured there
                    look_at = self._direction_cut(self._scan_target, n)
                look_block = self._scan_target
        if self.detected_at is not None and known and t >= self.detected_at + p.reaction_latency_s - 1e-9:
            hand_speed = float(np.linalg.norm(obs[_S["left_hand_vel" if left else "hand_vel"]]))
            if self.hold is None:
                # The nearest believed face to the line of the fall through the right shoulder.
                faces = np.array([self.estimate(i) for i in known]) - self.shoulder
                depth = faces @ n
                if p.choose_by_ray:
                    faces = np.array([self._direction_cut(i, n) for i in known]) - self.shoulder
                if p.identify and p.depth_search:
                    faces = np.array([self._depth_point(i, n) for i in known]) - self.shoulder
                lateral = np.linalg.norm(faces - np.outer(faces @ n, n), axis=1)
                if p.depth_search and p.reach_max_m > 0:
                    # The cubes believed within reach (the vergence search's posterior), the nearest to the
                    # fall line by the face believed given reach; none: the likeliest to be within reach.
                    faces = np.array([self._depth_point(i, n, True) for i in known]) - self.shoulder
                    lateral = np.linalg.norm(faces - np.outer(faces @ n, n), axis=1)
                    pr = np.array([self.posterior(i, n)[2] for i in known])
                    lateral = np.where(pr >= 0.5, lateral, np.inf) if np.any(pr >= 0.5) else lateral + 10.0 * (1 - pr)
                elif p.reach_max_m > 0 and p.verify_reach:
                    # A cube a fixation has measured within reach is chosen (the nearest such); until one is,
                    # the eye checks the candidates nearest the fall line in turn, each for verify_dwell_s.
                    sure = self.best_w[known] >= p.verify_w
                    ok = sure & (depth <= p.reach_max_m)
                    for j, i in enumerate(known):
                        if sure[j] and not ok[j]:
                            self._checked.add(i)
                    if self.chosen in known and self.chosen in self._checked:
                        self.chosen = None
                    if np.any(ok):
                        lateral = np.where(ok, lateral, np.inf)
                    else:
                        lateral = np.where([i in self._checked for i in known], lateral + 10.0, lateral)
                        if self.chosen in known and self._check_since is not None \
                                and t - self._check_since >= p.verify_dwell_s:
                            self._checked.add(self.chosen)
                            lateral[known.index(self.chosen)] += 10.0
                        elif self.chosen in known:
                            lateral[known.index(self.chosen)] = -1.0  # keep checking it
                elif p.reach_max_m > 0 and np.any(depth <= p.reach_max_m):
                    lateral = np.where(depth <= p.reach_max_m, lateral, np.inf)
                if self.front:
                    # In front: the fall line through either shoulder; the chosen cube's nearer one braces.
                    base = faces + self.shoulder
                    other = self._mirror(self.shoulder)
                    lat2 = np.linalg.norm((base - other) - np.outer((base - other) @ n, n), axis=1)
                    lat2 = lat2 + (lateral - np.linalg.norm(faces - np.outer(faces @ n, n), axis=1))
                    j = int(np.argmin(np.minimum(lateral, lat2)))
                    if lat2[j] < lateral[j] and self.hold is None and self.approach_since is None:
                        self._set_side(-self.side, True)
                        left = self.side > 0
                        hand = obs[_S["left_hand_pos" if left else "hand_pos"]].copy()
                        hand_speed = float(np.linalg.norm(obs[_S["left_hand_vel" if left else "hand_vel"]]))
                        lateral = lat2
                if p.identify and p.ident_choose:
                    pair, belief = self._pair_beliefs(known, n)
                    pen = np.array([10.0 if belief[i] < 0 else (0.0 if (i in pair or belief[i] > 0) else p.ident_other_m)
                                    for i in known])
                    lateral = lateral + pen
                previous = self.chosen
                self.chosen = known[int(np.argmin(lateral))]
                if self.chosen != previous:
                    self._check_since = t
                face = self.estimate(self.chosen)
                if p.depth_search:
                    face = self._depth_point(self.chosen, n, True)
                elif p.hand_on_cut and self.best_w[self.chosen] < p.cut_until_w:
                    face = self._direction_cut(self.chosen, n)  # not yet fixated: the direction at the plane
                if self.approach_since is None:
                    # Align first: in front of the face, then toward it (a hand that sweeps along the wall
                    # catches an edge); move in anyway once align_timeout_s has passed.
                    target = face - n * p.approach_offset_m
                    late = t - self.detected_at - p.reaction_latency_s >= p.align_timeout_s - 1e-9
                    off = hand - face
                    verified = not p.verify_reach or self.best_w[self.chosen] >= p.verify_w
                    aligned = float(np.linalg.norm(off - n * float(off @ n))) < p.align_m
                    if p.trust_ecc_deg > 0 and self.vision.foveated:
                        aligned = aligned and bool(self.trusted[self.chosen])
                    if verified and (aligned or late):
                        self.approach_since = t
                        self.events.append((t, "approach"))
                if self.approach_since is not None:
                    goal = face + n * p.reach_depth_m
                    step = goal - hand
                    dist = float(np.linalg.norm(step))
                    speed = p.front_approach_speed_m_s if self.front else p.approach_speed_m_s
                    target = hand + step * min(1.0, 2.0 * speed * self.dt / max(dist, 1e-9))
                    if t - self.approach_since >= p.min_reach_s and hand_speed < p.contact_speed_m_s:
                        self.hold = hand.copy()
                        self.hold_eye = eye.copy()
                        self.events.append((t, "hold"))
            if self.hold is not None:
                # The braced arm as a strut along the fall's direction: the hand keeps its distance from
                # the head as the body leans (a hand held fixed in the room would let the arm fold).
                target = self.hold + n * float((eye - self.hold_eye) @ n)
                if p.hold_lean_gain > 0:
                    ves = obs[_S["vestibular"]]
                    lean = float(ves[1]) * n[0] - float(ves[0]) * n[1]  # trunk tilt toward the wall (rad)
                    lean_rate = float(ves[3]) * n[0] - float(ves[2]) * n[1]
                    push = p.hold_lean_gain * (lean - p.hold_lean_ref) + p.hold_lean_damp * lean_rate
                    target = self.hold + n * min(max(push, -p.hold_retract_m), p.hold_push_m)
            if p.yield_speed_m_s >= 0 and -float(vel @ n) > p.yield_speed_m_s:
                target = hand.copy()  # the body moves back over its feet: the arm yields
                brace = p.yield_brace
                if self.hold is not None:
                    self.hold = hand.copy()
                    self.hold_eye = eye.copy()
            look_at = self.estimate(self.chosen)
            if p.depth_search:
                look_at = self._depth_point(self.chosen, n, True)
                search_look = True
            elif p.choose_by_ray and self.hold is None and self.best_w[self.chosen] < p.cut_until_w:
                look_at = self._direction_cut(self.chosen, n)  # the cube's direction, at the plane's distance
            if p.trust_ecc_deg > 0 and self.vision.foveated and not self.trusted[self.chosen] \
                    and self.hold is None:
                look_at = self.last_seen[self.chosen].copy()  # a corrective saccade to its latest percept
            look_block = self.chosen
            rates = obs[_S["vestibular"]][2:5]
            if self.hold is not None and float(np.max(np.abs(rates))) < p.still_rad_s:
                self.still_since = t if self.still_since is None else self.still_since
                if t - self.still_since >= p.still_s and not self.looked_away:
                    self.looked_away = True
                    self.events.append((t, "look_away"))
            else:
                self.still_since = None
            if self.looked_away:
                look_at = eye + np.array([3.0, 0.0, 0.0])
                look_block = None
                search_look = False

        if not p.use_hand:
            target = self.home
        gaze, head, fixation = (0.0, 0.0), (0.0, 0.0), None
        if look_at is not None and not p.gaze_blind:
            d_eye = rot.T @ (look_at - eye)
            gaze = (math.atan2(d_eye[1], d_eye[0]), math.atan2(d_eye[2], math.hypot(d_eye[0], d_eye[1])))
            d = look_at - eye
            az, el = math.atan2(d[1], d[0]), math.atan2(d[2], math.hypot(d[0], d[1]))
            head = (self._beyond_dead_zone(az, 0), self._beyond_dead_zone(el, 1))
            fixation = float(np.linalg.norm(d))
            if p.verge_on_ray and look_block is not None and not search_look:
                nl = n if self.detected_at is not None else self._look_normal
                fixation = float(np.linalg.norm(self._ray_cuts(look_at[None, :], eye, nl)[0] - eye))
            if p.verge_on_sample and look_block is not None and not search_look and obs[_S["block_visible"]][look_block] > 0.5:
                # Vergence follows the fixated cube's own disparity: its latest sample's distance when it is
                # near the fovea (the vergence loop closes on the fixated target, not on the belief).
                sample = obs[_S["block_pos"]].reshape(N, 3)[look_block]
                if sample[0] > 0 and foveation.eccentricity(sample) < p.verge_ecc_deg * DEG:
                    fixation = float(np.linalg.norm(sample))
        return encode(target, brace, gaze, fixation, head, self.gaze_range, left=left)

    def _pair_beliefs(self, known: list, n: np.ndarray, full: bool = False) -> tuple[list, dict]:
        """identify: the two cubes nearest the shoulder (horizontal distance of their mean lines of sight's cuts with
        the plane along ``n``) and every known cube's believed identity (+1 firm, -1 loose, 0 unknown): the
        remembered one, the pair's completed by the scene's rule (exactly one of the two is loose)."""
        w = self.params.ident_measured_w
        if self.params.depth_search:
            cuts = np.array([self._depth_point(i, n) for i in known]) - self.shoulder
        else:
            cuts = np.array([self.estimate(i) if self.best_w[i] >= w else self._direction_cut(i, n) for i in known]) \
                - self.shoulder
        order = [known[j] for j in np.argsort(np.linalg.norm(cuts[:, :2], axis=1), kind="stable")]
        pair = order[:2]
        belief = {i: float(self.firm[i]) for i in known}
        if len(pair) == 2:
            a, b = pair
            if belief[a] != 0.0 and belief[b] == 0.0:
                belief[b] = -belief[a]
            elif belief[b] != 0.0 and belief[a] == 0.0:
                belief[a] = -belief[b]
        return (order if full else pair), belief

    def _m(self, p: np.ndarray) -> np.ndarray:
        """A point or direction of the scene given for the wall on the right: mirrored (y -> -y) for the wall on the
        left, turned 90 deg to the front (x, y -> -y, x) for the wall in front."""
        if self.front:
            return np.array([-p[1], p[0], p[2]])
        return p if self.side < 0 else self._mirror(p)

    @staticmethod
    def _mirror(p: np.ndarray) -> np.ndarray:
        return np.array([p[0], -p[1], p[2]])

    def _front_from_lines(self) -> bool:
        """Whether the cubes' lines of sight put the wall in front (PLACE_CUBES cubes sampled; see FRONT_AZIMUTH_DEG)."""
        seen = np.flatnonzero(self._los_n > 0)
        if not self.params.front_wall or len(seen) < PLACE_CUBES:
            return self.front
        pts = []
        for i in seen:
            u = self._los[i] / self._los_n[i]
            e = self._los_eye[i] / self._los_n[i]
            if u[2] >= -1e-3:
                continue  # level or above the eye: no cut with the cubes' height
            pts.append((e + u * ((PRIOR_FACE_Z_M - e[2]) / u[2]))[:2])
        if len(pts) < PLACE_CUBES:
            return self.front
        pts = np.array(pts)
        c = pts - pts.mean(axis=0)
        along = np.linalg.eigh(c.T @ c)[1][:, -1]
        normal = np.array([-along[1], along[0]])
        if normal @ pts.mean(axis=0) < 0:
            normal = -normal
        return abs(math.degrees(math.atan2(normal[1], normal[0]))) < FRONT_AZIMUTH_DEG

    def _set_side(self, side: int, front: bool | None = None) -> None:
        """The wall's side (-1 right, +1 left: the arm that braces) and whether it stands in front: the shoulder,
        the hand's ready point and the expected normal."""
        front = self.front if front is None else bool(front)
        if side == self.side and front == self.front and self.home is not None:
            return
        self.side = side
        self.front = front
        self.shoulder = SHOULDER if side < 0 else self._mirror(SHOULDER)
        ready = np.array(self.params.hand_ready, dtype=float)
        self.home = ready if side < 0 else self._mirror(ready)
        if self.detected_at is None:
            self.normal = self._m(np.array([0.0, -1.0, 0.0]))
            self._look_normal = self.normal.copy()

    def _search_look(self, known: list, t: float):
        """depth_search before the push: the cube to fixate and where (its most probable face: the gaze goes along
        its line of sight and the vergence to that distance). The search_blocks cubes nearest the expected fall
        line through the shoulder (by their directions, cut with the expected wall plane) are fixated in turn
        until each is known within reach or beyond; then the nearest believed within reach is kept."""
        p = self.params
        yaw = p.search_yaw_deg * DEG
        n0 = self._m(np.array([math.sin(yaw), -math.cos(yaw), 0.0]))
        cuts = np.array([self._direction_cut(i, n0) for i in known]) - self.shoulder
        lateral = np.linalg.norm(cuts - np.outer(cuts @ n0, n0), axis=1)
        order = [known[j] for j in np.argsort(lateral)][:max(p.search_blocks, 1)]
        reach = {i: self.posterior(i, n0)[2] for i in order}
        undecided = [i for i in order if 1.0 - p.search_sure < reach[i] < p.search_sure]
        tgt = self._search_target
        timed_out = self._search_since is not None and t - self._search_since >= p.search_max_s - 1e-9
        if tgt not in undecided or timed_out:
            if undecided:
                # the next undecided candidate after the current one (in the order nearest the fall line)
                k = order.index(tgt) + 1 if tgt in order and timed_out else 0
                nxt = next((order[(k + j) % len(order)] for j in range(len(order))
                            if order[(k + j) % len(order)] in undecided), undecided[0])
            else:
                front = [i for i in order if reach[i] >= 0.5]
                nxt = front[0] if front else order[0]
            if nxt != tgt:
                self._search_target, self._search_since = nxt, t
                self.events.append((t, f"search {nxt}"))
            elif timed_out:
                self._search_since = t
        return self._depth_mode(self._search_target, n0), self._search_target

    def _direction_cut(self, i: int, n: np.ndarray) -> np.ndarray:
        """Cube ``i``'s mean line of sight (the mean direction of its fused samples, from the mean eye
        position they were seen from) cut with the plane ``x . n = ray_plane_m``: where the cube is if the wall
        is where expected. A sample's direction is precise even where its depth is not (the vision model)."""
        k = self.dir_n[i] if self.dir_n[i] > 0.0 else 1.0
        origin = self.dir_eye[i] / k
        u = self.dir_sum[i] / max(float(np.linalg.norm(self.dir_sum[i])), 1e-9)
        return self._ray_cuts((origin + u)[None, :], origin, n)[0]

    def _ray_cuts(self, faces: np.ndarray, eye: np.ndarray, n: np.ndarray) -> np.ndarray:
        """Each believed face's line of sight from ``eye`` cut with the plane ``x . n = ray_plane_m``
        (stance frame); a line of sight that does not reach the plane keeps the belief."""
        out = faces.copy()
        for j, f in enumerate(faces):
            r = f - eye
            r = r / max(float(np.linalg.norm(r)), 1e-9)
            rn = float(r @ n)
            if rn > 0.2:
                out[j] = eye + r * ((self.params.ray_plane_m - float(eye @ n)) / rn)
        return out

    @staticmethod
    def _wall_normal(faces: np.ndarray, fallback: np.ndarray) -> np.ndarray:
        """The unit normal (from the body toward the wall) of the line fitted through the believed faces
        (shoulder-relative) on the floor plane; ``fallback`` with fewer than two faces."""
        if len(faces) < 2:
            return fallback
        xy = faces[:, :2] - faces[:, :2].mean(axis=0)
        _u, _s, vt = np.linalg.svd(xy, full_matrices=False)
        along = vt[0]
        nrm = np.array([-along[1], along[0], 0.0])
        if float(nrm[:2] @ faces[:, :2].mean(axis=0)) < 0:
            nrm = -nrm
        return nrm

    def _beyond_dead_zone(self, angle: float, k: int) -> float:
        dz = self.params.head_dead_zone_deg * DEG
        h = 0.0 if abs(angle) <= dz else angle - math.copysign(dz, angle)
        lo, hi = _NECK[k]
        return min(max(h, lo * DEG), hi * DEG)
