"""Trips and missteps: what a walker's leg touching an obstacle means (task semantics, not the gait's).

:class:`LegContacts` classifies the MuJoCo contacts between the walker's leg geoms (thigh, shin, foot of
each side, ``WALKER_LEG_GEOMS``) and the obstacles of an :class:`~visuomotor_gym.tasks.walk_scene.ObstaclePool`,
reading the gait's phase through its public methods (:meth:`~visuomotor_gym.body.gait.WalkerGait.phase_of`,
:meth:`~visuomotor_gym.body.gait.WalkerGait.foothold_of`, :meth:`~visuomotor_gym.body.gait.WalkerGait.tick_of`):

* a *trip* is a leg touching an obstacle in any other way than a foot landing or standing on it;
* a *misstep* is a stance foot on an obstacle, or a swing foot coming down onto an obstacle's top
  (contact normal within 45 deg of vertical) in the last part of its swing (``GaitParams.swing_fall``
  on: the set-down).

Both rules and the 45 deg threshold are modelling choices. The flat mat that a foot must not land on
stands for the black 70 cm cloth on the floor that subjects walked past in Iwao, Maejima, Kubo &
Morishima's experiment (section 1; the paper carries no year).

Checks are cheap when nothing touches (:meth:`LegContacts.check` returns at once when ``data.ncon``
is 0; feet never touch the floor), and the physics substeps near an obstacle run as one ``mj_step``
call, *watched* (:meth:`LegContacts.watch`, :meth:`LegContacts.watched`): replayed one by one with the
checks only when MuJoCo saw a contact in them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from visuomotor_gym.body import walker_names as wn

_INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
_SIDES = (0, 1)  # 0 left, 1 right: the gait's side numbering (walker_names.SIDES)


@dataclass
class GaitEvent:
    """One trip or misstep: when (s since the gait's reset), what, which leg part touched which obstacle
    (pool index), and the contact normal's vertical component (+ = the leg above)."""

    time: float
    kind: str  # "trip" or "misstep"
    side: int  # 0 left, 1 right
    part: str  # "foot", "shin" or "thigh"
    obstacle: int
    normal_z: float


class LegContacts:
    """Trip and misstep classification of one walker (``gait``, a
    :class:`~visuomotor_gym.body.gait.WalkerGait` on ``model``) among the obstacles of ``pool``.

    Use, per episode: :meth:`reset` (before the first step), then per control step either
    :meth:`step_physics`, or the env's substep loop with :meth:`watch` before the substeps (when
    :meth:`near`) and :meth:`watched` after them. :attr:`events`, :attr:`tripped` and
    :attr:`misstepped` hold what happened since the reset.
    """

    def __init__(self, model: mujoco.MjModel, gait, pool) -> None:
        self.model = model
        self.gait = gait
        self.pool = pool
        self.radius = gait.CONTACT_RADIUS_M  # obstacles farther from the pelvis touch no leg
        leg_geoms = {}
        for side in _SIDES:
            for part, name in zip(("thigh", "shin", "foot"), wn.WALKER_LEG_GEOMS[side]):
                g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
                if g < 0:
                    raise ValueError(f"the model has no leg geom {name!r}: is it envs_assets/{wn.WALKER_SCENE}?")
                leg_geoms[g] = (side, part)
        self._leg_geoms = leg_geoms
        self._ob_geom = pool.index_of_geom
        self._root_xy = gait.qpos_index[0], gait.qpos_index[1]
        self._watch_state, self._scratch = None, None  # watched substeps: saved state, replay data
        self.reset()

    def reset(self) -> None:
        """Forget every event and touch (a new episode)."""
        self.events: list[GaitEvent] = []
        self.tripped = False
        self.misstepped = False
        self._touching: set = set()  # (side, part, obstacle) in contact at the last check
        self._reported: set = set()  # (kind, side, foothold, obstacle) already reported
        self._watching = False  # no watched substeps pending

    @property
    def touching(self) -> frozenset:
        """The (side, part, obstacle) touches in contact at the last check."""
        return frozenset(self._touching)

    @property
    def watching(self) -> bool:
        """Whether watched substeps (:meth:`watch`) still await :meth:`watched`."""
        return self._watching

    def near(self, data: mujoco.MjData) -> bool:
        """Whether any placed obstacle is within reach of a leg (``CONTACT_RADIUS_M`` of the pelvis)."""
        ix, iy = self._root_xy
        return self.pool.near(float(data.qpos[ix]), float(data.qpos[iy]), self.radius)

    def check(self, data: mujoco.MjData) -> bool:
        """Classify leg-obstacle contacts; return True when a new trip or misstep began.

        A touch (a leg part's side on one obstacle) is classified when it begins: a foot in stance, or
        a foot in the last part of its swing touching an obstacle's top (normal within 45 deg of
        vertical), is a *misstep*; anything else a *trip*. While the touch lasts it is not classified
        again, a swing foot touching the obstacle it stood on at its last foothold is leaving it (part
        of that misstep, not a trip), and each (kind, side, foothold, obstacle) is reported once."""
        if data.ncon == 0:
            if self._touching:
                self._touching.clear()
            return False
        gait = self.gait
        tick = gait.tick_of(data)
        geom = data.contact.geom
        frame = data.contact.frame
        touching = set()
        new = False
        for i in range(data.ncon):
            g1, g2 = int(geom[i, 0]), int(geom[i, 1])
            if g1 in self._ob_geom:
                ob, leg = self._ob_geom[g1], self._leg_geoms.get(g2)
                nz = float(frame[i, 2])  # MuJoCo's normal points from geom1 to geom2: here up = leg above
            else:
                ob, leg = self._ob_geom.get(g2), self._leg_geoms.get(g1)
                nz = -float(frame[i, 2])
            if ob is None or leg is None:
                continue
            side, part = leg
            touch = (side, part, ob)
            touching.add(touch)
            if touch in self._touching:
                continue
            stance, tau = gait.phase_of(side, tick)
            j = gait.foothold_of(side, tick)
            if not stance and ("misstep", side, j - 2, ob) in self._reported:
                continue  # leaving the obstacle it stood on: part of that misstep
            landing = part == "foot" and (stance or (tau >= gait.p.swing_fall and abs(nz) > math.sqrt(0.5)))
            kind = "misstep" if landing else "trip"
            key = (kind, side, j, ob)
            if key in self._reported:
                continue
            self._reported.add(key)
            if kind == "misstep":
                self.misstepped = True
            else:
                self.tripped = True
            self.events.append(GaitEvent(float(data.time) - gait.t0, kind, side, part, ob, nz))
            new = True
        self._touching = touching
        return new

    def step_physics(self, model: mujoco.MjModel, data: mujoco.MjData, n_substeps: int) -> bool:
        """Run ``n_substeps`` physics steps, checking contacts after each one when an obstacle is
        near the pelvis (else one ``mj_step`` call); return True when a trip or misstep began.

        Near an obstacle the substeps run as one ``mj_step`` call too, watched (:meth:`watch`): only
        when a contact happened in one of them are they replayed one by one with the checks
        (:meth:`watched`), which classifies exactly what checking after every substep would have."""
        if not self.near(data):
            mujoco.mj_step(model, data, nstep=n_substeps)
            return False
        self.watch(data)
        mujoco.mj_step(model, data, nstep=n_substeps)
        return self.watched(data, n_substeps, every=True, final=False)

    # Watched substeps. Checking contacts after every physics substep costs a Python ``mj_step`` call
    # per substep; but contacts with the legs are rare (a trip or a misstep), and MuJoCo keeps the
    # largest number of contacts any step had (``data.maxuse_con``). So the substeps run as one call
    # after the integration state is saved and that maximum cleared; when it comes back 0 no substep
    # had a contact (every check would have found none), else the substeps are replayed from the saved
    # state on a scratch ``MjData`` with the checks after each one. MuJoCo is deterministic given the
    # integration state (``mjSTATE_INTEGRATION``), so the replay visits the very same states and
    # contacts, and ``data`` itself is never stepped twice.
    def watch(self, data: mujoco.MjData) -> None:
        """Before physics substeps that must be checked for contacts: save the integration state and
        clear ``data.maxuse_con``."""
        if self._watch_state is None:
            self._watch_state = np.empty(mujoco.mj_stateSize(self.model, _INTEGRATION))
        mujoco.mj_getState(self.model, data, self._watch_state, _INTEGRATION)
        data.maxuse_con = 0
        self._watching = True

    def watched(self, data: mujoco.MjData, n_substeps: int, *, every: bool = False, final: bool = True,
                replay: bool = False) -> bool:
        """After the substeps (one ``mj_step(..., nstep=n_substeps)`` call on ``data``) that
        :meth:`watch` prepared, classify contacts as :meth:`check` after each substep would have: after
        every one (``every``), or, as the env's physics loop does, until the first that reports a new
        event; then once more on ``data`` (``final``). ``replay``: replay even when ``maxuse_con``
        says no contact happened (after a divergence, which resets ``data``). Without a watch pending,
        the one check on ``data``."""
        if not self._watching:
            return self.check(data)
        self._watching = False
        if not (replay or data.maxuse_con > 0):  # no contact in any substep: every check clears
            return self.check(data)
        scratch = self._scratch
        if scratch is None:
            scratch = self._scratch = mujoco.MjData(self.model)
        mujoco.mj_setState(self.model, scratch, self._watch_state, _INTEGRATION)
        new = False
        for _ in range(n_substeps):
            mujoco.mj_step(self.model, scratch)
            if every:
                new |= self.check(scratch)
            elif not new and self.check(scratch):
                new = True
        if final and not new:
            new = self.check(data)
        return new

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_scratch"] = None  # rebuilt when next needed
        return state


__all__ = ["GaitEvent", "LegContacts"]
