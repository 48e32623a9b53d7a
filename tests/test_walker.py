"""The walker body and its scripted gait (``envs_assets/walker.xml``, ``visuomotor_gym/body/gait.py``), with
the task-side obstacle pool (``tasks/walk_scene.py``) and trip and misstep classification
(``tasks/walk_contacts.py``).

Real MuJoCo physics and contacts throughout: the servos track the gait, obstacles are real geoms, and
trips and missteps are read from ``data.contact``.
"""

from __future__ import annotations

import math
import pickle
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from visuomotor_gym import assets
from visuomotor_gym.body import names
from visuomotor_gym.body import walker_names as wn
from visuomotor_gym.body.gait import DEG, GaitParams, TurningGait, WalkerGait
from visuomotor_gym.tasks.walk_contacts import LegContacts
from visuomotor_gym.tasks.walk_scene import ObstaclePool

OBJ = {
    "body": mujoco.mjtObj.mjOBJ_BODY,
    "joint": mujoco.mjtObj.mjOBJ_JOINT,
    "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR,
    "geom": mujoco.mjtObj.mjOBJ_GEOM,
    "site": mujoco.mjtObj.mjOBJ_SITE,
    "camera": mujoco.mjtObj.mjOBJ_CAMERA,
}
DT = 0.02  # control period of the catch family (10 physics substeps)
NSUB = 10


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(assets.asset_path(wn.WALKER_SCENE)))


class Walker:
    """A gait (a ``gait_cls``) with ObstacleWalk's task-side parts: the obstacle pool and the trip and
    misstep classifier, wired as the task wires them."""

    def __init__(self, model, gait_cls=WalkerGait, params=None):
        self.model = model
        self.gait = gait_cls(model, params)
        self.pool = ObstaclePool(model)
        self.contacts = LegContacts(model, self.gait, self.pool)


def walk(model, duration_s, command=None, setup=None, x=0.0, y=0.0, yaw=0.0, record=None, params=None,
         gait_cls=WalkerGait):
    """Reset a fresh :class:`Walker`, optionally place obstacles (``setup(walker, data)``), and walk
    ``duration_s`` seconds; ``command(gait)`` returns the footstep to set each control step. Returns
    (walker, data)."""
    model = model if params is None else mujoco.MjModel.from_xml_path(str(assets.asset_path(wn.WALKER_SCENE)))
    data = mujoco.MjData(model)
    w = Walker(model, gait_cls, params)
    gait = w.gait
    w.pool.park_all(model, data)
    if setup is not None:
        setup(w, data)
    gait.reset(model, data, x, y, yaw)
    w.contacts.reset()
    n = round(duration_s / DT)
    for _ in range(n):
        if command is not None:
            gait.set_next_footstep(*command(gait))
        gait.advance(data, DT)
        w.contacts.step_physics(model, data, NSUB)
        if record is not None:
            record(gait, data)
    return w, data


def _quiet(w):
    """No trip, no misstep, no event."""
    c = w.contacts
    return c.events == [] and not c.tripped and not c.misstepped


def test_model_compiles_and_every_walker_name_resolves(model):
    for kind, group in wn.WALKER_ALL_NAMES.items():
        missing = [n for n in group if mujoco.mj_name2id(model, OBJ[kind], n) < 0]
        assert not missing, f"{kind} names missing from walker.xml: {missing}"


def test_every_element_is_named(model):
    unnamed = []
    for kind, count in (("joint", model.njnt), ("actuator", model.nu), ("site", model.nsite),
                        ("camera", model.ncam), ("geom", model.ngeom)):
        unnamed += [(kind, i) for i in range(count) if not mujoco.mj_id2name(model, OBJ[kind], i)]
    unnamed += [("body", i) for i in range(1, model.nbody) if not mujoco.mj_id2name(model, OBJ["body"], i)]
    assert not unnamed


def test_walker_carries_the_shared_head_eye_and_root_joints_come_first(model):
    # The same neck and eye as the seated body (common/head_eye.xml), same ranges.
    catch = mujoco.MjModel.from_xml_path(str(assets.asset_path("catch.xml")))
    for j in names.NECK_JOINTS + (names.EYE_AZIMUTH, names.EYE_ELEVATION, names.EYE_FIXATION):
        np.testing.assert_array_equal(model.joint(j).range, catch.joint(j).range)
    for i, j in enumerate(wn.WALKER_ROOT_JOINTS):  # RootFrame / the gait read qpos 0..3 as the pelvis pose
        assert model.jnt_qposadr[model.joint(j).id] == i
    assert model.body(wn.WALKER_PELVIS).mocapid[0] == -1
    assert all(model.body(n).mocapid[0] >= 0 for n in wn.WALKER_OBSTACLES)
    assert 60.0 < model.body_subtreemass[model.body(wn.WALKER_PELVIS).id] < 85.0  # an adult (kg)


def test_feet_collide_with_obstacles_only(model):
    """Legs touch obstacles (contype/conaffinity 2), never the floor, each other or the trunk."""
    floor = model.geom(wn.WALKER_FLOOR)
    ob = model.geom(wn.WALKER_OBSTACLES[0])

    def collide(a, b):
        return bool(a.contype[0] & b.conaffinity[0]) or bool(b.contype[0] & a.conaffinity[0])

    legs = [model.geom(n) for side in wn.WALKER_LEG_GEOMS for n in side]
    for g in legs:
        assert collide(g, ob) and not collide(g, floor)
        assert not any(collide(g, h) for h in legs)
    assert not collide(ob, floor)


def _touchdowns(record_list, side):
    """Times at which a foot's heel site comes down to the floor (z < 3 mm after being higher)."""
    out, prev = [], True
    for t, heels, _, _ in record_list:
        down = heels[side] < 0.003
        if down and not prev:
            out.append(t)
        prev = down
    return out


def test_flat_15m_walk_nominal_footsteps(model):
    """15 m on flat ground with nominal footsteps: no events, feet on their footholds, human speed and
    cadence, the head bobbing once per step."""
    rows = []
    heel_sites = [model.site(n).id for n in wn.WALKER_HEELS]
    eye = model.site(names.EYE_CENTER).id
    landed = []

    def record(gait, data):
        rows.append((gait.time, data.site_xpos[heel_sites, 2].copy(), float(data.qpos[0]),
                     float(data.site_xpos[eye, 2])))
        k = gait.current_step()
        if gait.tick - k * gait.T == round(0.2 / gait.timestep):  # 0.2 s after heel strike: foot flat
            sole = data.site_xpos[gait.sole_sites[gait.side_of(k)]]
            landed.append((sole[0], sole[1], sole[2]) + gait.foothold_world(k))

    w, data = walk(model, 12.0, record=record)
    gait = w.gait
    assert float(data.qpos[0]) > 15.0
    assert _quiet(w)
    landed = np.array(landed)
    err = np.hypot(landed[:, 0] - landed[:, 3], landed[:, 1] - landed[:, 4])
    assert len(landed) >= 22 and err.max() < 0.01, err.max()  # within 1 cm of the commanded foothold
    assert np.abs(landed[:, 2]).max() < 0.005  # the sole on the floor

    t = np.array([r[0] for r in rows])
    x = np.array([r[2] for r in rows])
    steady = t >= 1.0
    speed = (x[steady][-1] - x[steady][0]) / (t[steady][-1] - t[steady][0])
    assert 1.2 <= speed <= 1.4, speed  # ~1.2-1.4 m/s (Bohannon 1997: 1.27-1.46 comfortable)
    touch = sorted(_touchdowns(rows, 0) + _touchdowns(rows, 1))
    step_s = np.diff(touch)
    assert len(touch) >= 20 and 0.45 <= step_s.mean() <= 0.55 and step_s.std() < 0.01  # ~0.5 s per step
    # Head bob: the eye rises and falls once per step, a few cm peak to peak, highest near mid-stance.
    z = np.array([r[3] for r in rows])[steady]
    assert 0.025 < z.max() - z.min() < 0.06
    assert 1.55 < z.mean() < 1.68  # eye height ~1.6 m (Iwao's h)
    spectrum = np.abs(np.fft.rfft(z - z.mean()))
    freq = np.fft.rfftfreq(len(z), DT)
    assert abs(freq[spectrum.argmax()] - 1.0 / gait.p.step_s) < 0.1


def test_commanded_footsteps_land_where_told(model):
    """Varied lengths and lateral offsets (read at mid-stance) land within 1 cm of the plan."""
    rng = np.random.default_rng(3)
    plan = {}

    def command(gait):
        j = gait.next_footstep_index
        if j not in plan:
            plan[j] = (float(rng.uniform(0.4, 0.9)), float(rng.uniform(-0.15, 0.15)), 0.05)
        return plan[j]

    landed = {}

    def record(gait, data):
        k = gait.current_step()
        if gait.tick - k * gait.T == round(0.2 / gait.timestep):
            landed[k] = data.site_xpos[gait.sole_sites[gait.side_of(k)], :2].copy()

    w, _ = walk(model, 8.0, command=command, record=record, x=1.0, y=-2.0, yaw=0.4)
    gait = w.gait
    assert not w.contacts.events
    checked = 0
    for j, cmd in plan.items():
        if j in landed and j in gait.commanded:
            assert gait.commanded[j] == cmd  # latched unchanged
            x, y = gait.foothold_world(j)
            assert math.hypot(landed[j][0] - x, landed[j][1] - y) < 0.01
            # The foothold is where the command put it: length along the heading from the previous one.
            pu, pv = gait.u[j - 1], gait.v[j - 1]
            assert gait.u[j] - pu == pytest.approx(cmd[0])
            sign = 1.0 if gait.side_of(j) == 0 else -1.0
            width = max(gait.p.step_width_m + sign * cmd[1], gait.p.min_step_width_m)  # feet never cross
            assert gait.v[j] - pv == pytest.approx(sign * width)
            checked += 1
    assert checked >= 10


def test_footstep_is_read_at_mid_stance_for_the_next_step_of_that_foot(model):
    data = mujoco.MjData(model)
    gait = WalkerGait(model)
    gait.reset(model, data)
    assert gait.next_footstep_index == 2 and gait.next_latch_time == pytest.approx(0.3)
    gait.set_next_footstep(0.8, 0.0, 0.1)
    for _ in range(14):  # up to 0.28 s: not yet read
        gait.advance(data, DT)
    assert 2 not in gait.u
    gait.advance(data, DT)  # 0.30 s: mid-stance of foothold 0
    assert gait.u[2] == pytest.approx(gait.u[1] + 0.8) and gait.clearance[2] == pytest.approx(0.1)
    assert gait.next_footstep_index == 3
    for _ in range(25):  # no command: the nominal footstep
        gait.advance(data, DT)
    assert gait.u[3] == pytest.approx(gait.u[2] + gait.p.nominal_step_m)


def _bar_at_mid_step(w, data, height):
    """A 1 m wide, 5 cm deep bar across the path midway between footholds 4 and 5 (u = 2.925 m)."""
    u = 0.5 * (w.gait.u.get(4, 4 * 0.65) + w.gait.u.get(5, 5 * 0.65))
    w.pool.place(w.model, data, 0, u, 0.0, 0.05, 1.0, height)


def _clearance_over(steps, clearance):
    def command(gait):
        return (0.65, 0.0, clearance if gait.next_footstep_index in steps else 0.05)
    return command


def test_low_clearance_over_a_bar_trips(model):
    w, _ = walk(model, 4.0, command=_clearance_over((5, 6), 0.08),
                setup=lambda g, d: _bar_at_mid_step(g, d, 0.20))
    assert w.contacts.tripped and w.contacts.events[0].kind == "trip"
    first = w.contacts.events[0]
    assert first.side == 1 and first.part == "foot"  # the right foot swinging to foothold 5 strikes it
    assert abs(first.normal_z) < 0.5  # against the bar's face
    assert 2.1 < first.time < 2.5  # during that swing (2.1 .. 2.5 s)


def test_enough_clearance_steps_over_the_same_bar(model):
    w, data = walk(model, 4.0, command=_clearance_over((5, 6), 0.30),
                   setup=lambda g, d: _bar_at_mid_step(g, d, 0.20))
    assert _quiet(w)
    assert float(data.qpos[0]) > 4.5  # both feet are past the bar


def test_a_box_under_the_planned_foothold_is_a_misstep(model):
    def setup(w, data):  # a 10 cm box under foothold 5 (right foot, u = 3.25 m)
        w.pool.place(model, data, 0, 5 * 0.65, -0.06, 0.4, 0.3, 0.10)

    w, _ = walk(model, 4.0, command=_clearance_over((5,), 0.15), setup=setup)
    c = w.contacts
    assert c.misstepped and not c.tripped
    assert [(e.kind, e.side) for e in c.events] == [("misstep", 1)]
    assert c.events[0].normal_z > 0.9  # standing on its top
    # A flat mat (1 cm, like Iwao's 70 cm cloth) stepped on is a misstep too.
    w, _ = walk(model, 4.0, setup=lambda g, d: g.pool.place(model, d, 0, 5 * 0.65, 0.0, 0.7, 0.7, 0.01))
    assert [e.kind for e in w.contacts.events] == ["misstep"] and not w.contacts.tripped


def test_resized_obstacles_collide_over_their_whole_extent(model):
    """A bar made 4 m wide still trips a walker 1.5 m from its centre (sizes and bounding volumes are
    updated), and a parked pool touches nothing."""
    def setup(w, data):
        w.pool.place(model, data, 0, 2.925, 1.5, 0.05, 4.0, 0.20)

    w, _ = walk(model, 3.0, setup=setup)
    assert w.contacts.tripped
    w, data = walk(model, 3.0)
    assert w.contacts.events == [] and data.ncon == 0
    with pytest.raises(ValueError, match="positive"):
        w.pool.place(model, data, 0, 0.0, 0.0, 0.1, 0.0, 0.1)


def test_walking_is_deterministic(model):
    def run():
        traj = []
        walk(model, 3.0, command=_clearance_over((5, 6), 0.08), setup=lambda g, d: _bar_at_mid_step(g, d, 0.2),
             record=lambda g, d: traj.append(np.concatenate([d.qpos, d.qvel, d.act])))
        return np.array(traj)

    a, b = run(), run()
    np.testing.assert_array_equal(a, b)


def test_bad_input_is_refused(model):
    data = mujoco.MjData(model)
    gait = WalkerGait(model)
    gait.reset(model, data)
    with pytest.raises(ValueError, match="finite"):
        gait.set_next_footstep(float("nan"), 0.0, 0.1)
    with pytest.raises(ValueError, match="whole number"):
        gait.advance(data, 0.003)
    with pytest.raises(ValueError, match="whole number"):
        WalkerGait(model, GaitParams(step_s=0.5005))
    # Out-of-range commands are clipped to the stated ranges.
    gait.set_next_footstep(5.0, -3.0, 9.0)
    assert gait.pending == (gait.p.step_range_m[1], gait.p.lateral_range_m[0], gait.p.clearance_range_m[1])
    with pytest.raises(ValueError, match="no joint"):
        WalkerGait(mujoco.MjModel.from_xml_path(str(assets.asset_path("catch.xml"))))


def test_throughput_benchmark_runs_and_reports_a_ratio(tmp_path):
    """Tiny-budget smoke run of benchmarks/walker_throughput.py (its numbers are reported, not asserted)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "walker_throughput.py"
    spec = importlib.util.spec_from_file_location("walker_throughput", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.main(["--steps", "60", "--repeats", "1", "--json", str(tmp_path / "r.json")])
    assert result["ratio_walker_over_raw"] > 0 and (tmp_path / "r.json").exists()
    assert result["substeps_per_control_step"] == 10 and result["trips_and_missteps"] == 0


def _per_substep_reference(contacts, model, data, n, short_circuit):
    """The plain contact checks: one mj_step per substep and a check after each (``short_circuit``: as
    the env's substep loop, no check after the first that reports a new event)."""
    new = False
    for _ in range(n):
        mujoco.mj_step(model, data)
        if short_circuit:
            if not new and contacts.check(data):
                new = True
        else:
            new |= contacts.check(data)
    return new


@pytest.mark.parametrize("short_circuit", [False, True])
def test_watched_substeps_classify_contacts_as_checks_after_every_substep(model, short_circuit):
    """The watched substeps (one mj_step call, replayed from the saved state only when MuJoCo saw a
    contact) give the same states, events and touches as checking after every substep, over walks
    that trip, misstep and step over (bars of random heights, random footsteps)."""
    rng = np.random.default_rng(3)
    n_events = 0
    for _trial in range(3):
        bars = [(2.0 + 1.3 * i + rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), rng.uniform(0.03, 0.4),
                 rng.uniform(0.3, 1.2), rng.uniform(0.05, 0.3)) for i in range(6)]
        steps = [(rng.uniform(0.3, 0.9), rng.uniform(-0.2, 0.2), rng.uniform(0.0, 0.4)) for _ in range(300)]
        runs = []
        for watched in (False, True):
            data = mujoco.MjData(model)
            w = Walker(model)
            gait, contacts = w.gait, w.contacts
            w.pool.park_all(model, data)
            for i, bar in enumerate(bars):
                w.pool.place(model, data, i, *bar)
            gait.reset(model, data)
            log = []
            for step in steps:
                gait.set_next_footstep(*step)
                gait.advance(data, DT)
                if watched:
                    contacts.watch(data)
                    mujoco.mj_step(model, data, nstep=NSUB)
                    new = contacts.watched(data, NSUB, every=not short_circuit, final=short_circuit)
                else:
                    new = _per_substep_reference(contacts, model, data, NSUB, short_circuit)
                    if short_circuit and not new:
                        new = contacts.check(data)  # the env's check on the final state
                log.append((new, data.qpos.tobytes(), data.qvel.tobytes(), sorted(contacts.touching)))
            runs.append((log, [(e.time, e.kind, e.side, e.part, e.obstacle, e.normal_z) for e in contacts.events]))
        assert runs[0] == runs[1]
        n_events += len(runs[0][1])
    assert n_events > 0  # the walks did touch obstacles


def test_watched_substeps_after_a_divergence_replay_the_checks(model):
    """When the physics diverged (MuJoCo resets the data), ``replay=True`` still classifies the
    contacts of the substeps before it from the saved state."""
    data = mujoco.MjData(model)
    w = Walker(model)
    gait, contacts = w.gait, w.contacts
    w.pool.park_all(model, data)
    gait.reset(model, data)
    w.pool.place(model, data, 0, float(data.qpos[0]) + 0.3, 0.0, 0.05, 1.0, 0.3)  # in the swing's way
    for _ in range(40):
        gait.advance(data, DT)
        contacts.watch(data)
        mujoco.mj_step(model, data, nstep=NSUB)
        if data.maxuse_con > 0:
            break
        contacts.watched(data, NSUB)
    assert data.maxuse_con > 0
    mujoco.mj_resetData(model, data)  # what a divergence does to the data
    assert contacts.watched(data, NSUB, final=False, replay=True)
    assert contacts.events and not contacts.watching
    assert contacts._scratch is not None and pickle.loads(pickle.dumps(contacts))._scratch is None  # rebuilt on need


def _reference_targets(gait, tick):
    """The gait's joint targets by the plain formulas (FootPlan-free copies of the original
    ``_stance_foot``, ``_swing_foot``, ``targets_at`` with numpy's clip), for the bit-identity test."""
    from visuomotor_gym.body.gait import DEG, _smooth

    p, g = gait.p, gait

    def stance(j, s_tick):
        u, v = g.u[j], g.v[j]
        if s_tick < g.T_ds:
            pitch = p.heel_strike_deg * DEG * (1.0 - _smooth(s_tick / g.T_ds))
            au, az = g._foot_from_pivot(u - g.l_heel, -g.l_heel, pitch)
        elif s_tick < g.T_ho:
            pitch, au, az = 0.0, u, g.h_ankle
        else:
            pitch = -p.toe_off_deg * DEG * _smooth((s_tick - g.T_ho) / (g.T + g.T_ds - g.T_ho))
            au, az = g._foot_from_pivot(u + g.l_toe, g.l_toe, pitch)
        return au, v, az, pitch, True, 0.0

    def swing(j_from, j_to, tau):
        a0u, _ = g._foot_from_pivot(g.u[j_from] + g.l_toe, g.l_toe, -p.toe_off_deg * DEG)
        a1u, _ = g._foot_from_pivot(g.u[j_to] - g.l_heel, -g.l_heel, p.heel_strike_deg * DEG)
        m0, m1 = p.swing_move
        prog = _smooth((tau - m0) / (m1 - m0))
        au = a0u + (a1u - a0u) * prog
        av = g.v[j_from] + (g.v[j_to] - g.v[j_from]) * prog
        pitch = (-p.toe_off_deg * (1.0 - _smooth(tau / 0.4)) + p.heel_strike_deg * _smooth((tau - 0.6) / 0.4)) * DEG
        if tau < p.swing_rise:
            lift = _smooth(tau / p.swing_rise)
        elif tau > p.swing_fall:
            lift = _smooth((1.0 - tau) / (1.0 - p.swing_fall))
        else:
            lift = 1.0
        h = g.clearance[j_to] * lift
        sp, cp = math.sin(pitch), math.cos(pitch)
        lowest = min(g.l_toe * sp, -g.l_heel * sp) - g.h_ankle * cp
        return au, av, h - lowest, pitch, False, h

    def leg_ik(fx, fy, fz):
        roll = math.atan2(fy, -fz)
        dperp = math.sqrt(fy * fy + fz * fz)
        d2 = min(fx * fx + dperp * dperp, g.d_max * g.d_max)
        cos_k = (d2 - g.L1 * g.L1 - g.L2 * g.L2) / (2.0 * g.L1 * g.L2)
        knee = math.acos(min(max(cos_k, -1.0), 1.0))
        hip = math.atan2(fx, dperp) + math.atan2(g.L2 * math.sin(knee), g.L1 + g.L2 * math.cos(knee))
        return roll, hip, knee

    pu, pv = g.pelvis_at(tick)
    phase = 2.0 * math.pi * ((tick - g.T_mid) % g.T) / g.T
    z = p.pelvis_height_m - 0.5 * p.bob_m * (1.0 - math.cos(phase))
    k = tick // g.T
    s = tick - k * g.T
    lead = stance(k, s)
    trail = stance(k - 1, s + g.T) if s < g.T_ds else swing(k - 1, k + 1, (s - g.T_ds) / (g.T - g.T_ds))
    feet = (lead, trail) if k % 2 == 0 else (trail, lead)
    hips = []
    for side, foot in enumerate(feet):
        hy = g.hip_y if side == 0 else -g.hip_y
        du, dv = foot[0] - pu, foot[1] - (pv + hy)
        zmax = foot[2] + math.sqrt(max(g.d_max * g.d_max - du * du - dv * dv, 0.0))
        if zmax < z:  # the original's form
            z = zmax
        hips.append((du, dv))
    pc, ps = g.path_cos, g.path_sin
    out = [g.origin[0] + pc * pu - ps * pv, g.origin[1] + ps * pu + pc * pv, z, g.yaw]
    for side, foot in enumerate(feet):
        fx, fy = hips[side]
        roll, hip, knee = leg_ik(fx, fy, foot[2] - z)
        ankle = foot[3] - (hip - knee)
        ia, n_fix = 7 + 5 * side, 0
        while not foot[4] and not g._lo[ia] <= ankle <= g._hi[ia] and n_fix < 4:
            pitch = min(max(ankle, g._lo[ia]), g._hi[ia]) + (hip - knee)
            sp, cp = math.sin(pitch), math.cos(pitch)
            lowest = min(g.l_toe * sp, -g.l_heel * sp) - g.h_ankle * cp
            roll, hip, knee = leg_ik(fx, fy, foot[5] - lowest - z)
            ankle = pitch - (hip - knee)
            n_fix += 1
        out += [roll, hip, knee, ankle, -roll]
    arm = p.arm_swing_deg * DEG * math.cos(math.pi * (tick % (2 * g.T)) / g.T)
    out += [-arm, arm]
    return np.minimum(np.maximum(np.array(out), np.array(g._lo)), np.array(g._hi))


def test_targets_are_bit_identical_to_the_plain_formulas(model):
    """The per-step path (scalar Python, cached constants, comparisons for min/max) gives the very
    floats of the plain formulas, over random footsteps (long, wide, high swings that hit the ankle's
    limit) and headings."""
    rng = np.random.default_rng(7)
    gait = WalkerGait(model)
    for _ in range(4):
        gait.reset_plan(*rng.uniform(-3.0, 3.0, 2), rng.uniform(-1.0, 1.0))
        for tick in range(-250, 1500):
            while gait.next_latch_tick <= tick + 1:
                gait.set_next_footstep(rng.uniform(0.2, 1.0), rng.uniform(-0.35, 0.35), rng.uniform(0.0, 0.5))
                gait._latch()
            assert gait.targets_at(tick).tobytes() == _reference_targets(gait, tick).tobytes(), tick


def _turning_walk(model, duration_s, command, record=None, x=0.0, y=0.0, yaw=0.0):
    return walk(model, duration_s, command, x=x, y=y, yaw=yaw, record=record, gait_cls=TurningGait)


def test_turning_gait_follows_its_footholds_headings(model):
    """Footsteps turning by up to +-45 deg (SteppingStones' gait): the feet land within 1 cm of the
    commanded footholds, the pelvis and the stance foot face each foothold's heading at its
    mid-stance, the soles stay on the floor, nothing trips, and the heading drifts far beyond 20 deg."""
    rng = np.random.default_rng(5)
    plan = {}
    lim = GaitParams().max_turn_deg * DEG

    def command(gait):
        j = gait.next_footstep_index
        if j not in plan:
            plan[j] = (float(rng.uniform(0.55, 0.8)), float(rng.uniform(-0.05, 0.05)), 0.05,
                       float(rng.uniform(-lim, lim)) if j % 3 else lim)
        return plan[j]

    landed, mid = {}, {}
    feet = [model.body(n).id for n in wn.WALKER_FEET]

    def record(gait, data):
        k = gait.current_step()
        s = gait.tick - k * gait.T
        side = gait.side_of(k)
        if s == round(0.2 / gait.timestep):  # foot flat
            sole = data.site_xpos[gait.sole_sites[side]]
            landed[k] = (sole[0], sole[1], sole[2])
        if s == gait.T_mid:  # mid-stance of foothold k
            fx = data.xmat[feet[side]].reshape(3, 3)[:, 0]
            mid[k] = (float(data.qpos[3]), math.atan2(fx[1], fx[0]))

    w, data = _turning_walk(model, 10.0, command, record, x=0.5, y=1.0, yaw=-0.3)
    gait = w.gait
    assert _quiet(w)
    assert np.isfinite(data.qpos).all()
    checked = 0
    for j, cmd in plan.items():
        if j in landed and j in gait.commanded and j in mid:
            assert gait.commanded[j] == pytest.approx(cmd)
            x, y = gait.foothold_world(j)
            assert math.hypot(landed[j][0] - x, landed[j][1] - y) < 0.01, (j, landed[j], (x, y))
            assert abs(landed[j][2]) < 0.01  # the sole on the floor (servo lag in the sharpest turns: ~5 mm)
            h = gait.heading_of(j)
            assert abs(math.remainder(mid[j][0] - h, 2 * math.pi)) < 2.0 * DEG  # pelvis yaw
            assert abs(math.remainder(mid[j][1] - h, 2 * math.pi)) < 2.0 * DEG  # the stance foot points along it
            # The foothold is the command in the new heading's frame.
            assert gait.h[j] - gait.h[j - 1] == pytest.approx(cmd[3])
            c, s = math.cos(gait.h[j]), math.sin(gait.h[j])
            du, dv = gait.u[j] - gait.u[j - 1], gait.v[j] - gait.v[j - 1]
            sign = 1.0 if gait.side_of(j) == 0 else -1.0
            assert c * du + s * dv == pytest.approx(cmd[0])
            assert -s * du + c * dv == pytest.approx(sign * max(gait.p.step_width_m + sign * cmd[1], gait.p.min_step_width_m))
            checked += 1
    assert checked >= 14
    assert max(abs(h) for h in gait.h.values()) > 60.0 * DEG


def test_turning_gait_without_turns_walks_as_the_straight_gait(model):
    """Zero turns: the same footholds as :class:`WalkerGait` and targets within float rounding."""
    a, b = WalkerGait(model), TurningGait(model)
    rng = np.random.default_rng(11)
    for g in (a, b):
        g.reset_plan(0.3, -0.2, 0.25)
    for tick in range(-250, 1500):
        while a.next_latch_tick <= tick + 1:
            cmd = (rng.uniform(0.3, 0.9), rng.uniform(-0.3, 0.3), rng.uniform(0.02, 0.4))
            a.set_next_footstep(*cmd)
            b.set_next_footstep(*cmd, turn=0.0)
            a._latch()
            b._latch()
        np.testing.assert_allclose(b.targets_at(tick), a.targets_at(tick), rtol=0, atol=1e-9)
    for j in a.u:
        assert a.foothold_world(j) == pytest.approx(b.foothold_world(j), abs=1e-12)


def test_turns_are_clipped_and_checked(model):
    g = TurningGait(model)
    g.set_next_footstep(0.6, 0.0, 0.05, turn=2.0)
    assert g.pending_turn == pytest.approx(g.p.max_turn_deg * DEG)
    with pytest.raises(ValueError):
        g.set_next_footstep(0.6, 0.0, 0.05, turn=float("nan"))
    g2 = pickle.loads(pickle.dumps(g))
    assert g2.pending_turn == g.pending_turn


PACKAGE = Path(__file__).resolve().parent.parent / "visuomotor_gym"


def test_no_task_or_body_reaches_into_the_gaits_privates():
    """Tasks, bodies, envs and baselines read the gait through its public methods and attributes: no
    ``gait._name`` (nor ``g._name`` where ``g = self.gait``) outside the gait's own module."""
    roots = [PACKAGE / "tasks", PACKAGE / "body", PACKAGE / "envs", PACKAGE.parent / "baselines"]
    reach = re.compile(r"\bgait\._\w|\bg\._(?!cos\b|sin\b)\w")  # (g._cos/_sin: a RootFrame's, not the gait's)
    found = []
    for root in roots:
        for path in sorted(root.rglob("*.py")):
            if path.name == "gait.py":
                continue
            for n, line in enumerate(path.read_text().splitlines(), 1):
                if reach.search(line.split("#", 1)[0]):
                    found.append(f"{path.relative_to(PACKAGE.parent)}:{n}: {line.strip()}")
    assert not found, "\n".join(found)


def test_turning_gait_changes_only_the_hooks():
    """TurningGait is WalkerGait with other hooks: it re-writes none of the per-step path."""
    per_step = {"_targets", "_leg_targets", "_leg_ik", "_latch", "_pelvis_at", "_pelvis_segment", "advance",
                "_swing_height"}
    hooks = {"place_foothold", "pelvis_waypoint", "stance_pose", "swing_pose", "ankles_from_hips", "root_yaw"}
    assert not per_step & set(vars(TurningGait))
    assert hooks <= set(vars(TurningGait)) and hooks <= set(vars(WalkerGait))
    for name in hooks:
        assert getattr(WalkerGait, name).__doc__.startswith("Hook:"), name


def test_the_walker_module_still_exports_the_gait():
    """``visuomotor_gym.body.walker`` is a thin re-export of ``visuomotor_gym.body.gait``; the gait holds
    no obstacles and classifies no contacts (task side: walk_scene, walk_contacts)."""
    from visuomotor_gym.body import gait, walker

    for name in walker.__all__:
        assert getattr(walker, name) is getattr(gait, name)
    for name in ("pool", "events", "tripped", "misstepped", "check_contacts", "step_physics", "watch_substeps"):
        assert not hasattr(WalkerGait, name) and not hasattr(WalkerGait(mujoco.MjModel.from_xml_path(
            str(assets.asset_path(wn.WALKER_SCENE)))), name), name


def test_the_pool_and_the_classifier_refuse_a_scene_without_them():
    catch = mujoco.MjModel.from_xml_path(str(assets.asset_path("catch.xml")))
    with pytest.raises(ValueError, match="obstacle pool"):
        ObstaclePool(catch)
