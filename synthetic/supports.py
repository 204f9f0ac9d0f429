"""Supports: where the feet stand, where the weight is, and the legs that follow.

Support symbols (``support`` = both feet, ``right_support``,
``left_support``): level low = plié (knees bent :data:`PLIE_BEND_DEG`),
middle, high = relevé (ankles plantar-flexed :data:`RELEVE_DEG`, heels
raised, the body rises); a direction other than place is a step of
:data:`STEP_LENGTH` × height that way, the foot lifting on the way.  At the
end of each support symbol the pelvis is over the mean of the weight-bearing
feet and as high as their levels allow, so the supporting feet stay on the
floor; a foot whose support ended is free as soon as a gesture of its leg
starts.  A foot that steps on the frame it lands (or on the first frame)
stays on the floor one frame more, so its landing is seen as a support.
A gesturing foot never goes below the floor (the knee bends and the foot
flexes instead).

:class:`Support` plans the root (pelvis) trajectory and the world targets of
both ankles; :func:`leg_tracks` turns them, and the leg gestures, into
thigh frames, knee bends and ankle angles.
"""

from __future__ import annotations

import itertools
import logging

import numpy as np

from capture2notation.body import Body, euler_to_matrix, joint_index
from capture2notation.errors import SyntheticError
from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.effort import progress
from capture2notation.notation.model import AIR, Effort, Score

from .extremes import keep_paths_within
from .flight import land, plan_flight
from .limbs import Limb, apply_move, group_moves
from .motion import euler_near
from .rotations import rot_x, slerp_frames, unit

__all__ = ["PLIE_BEND_DEG", "RELEVE_DEG", "STEP_LENGTH", "STEP_LIFT", "SUPPORT_FEET", "Support", "leg_tracks"]

log = logging.getLogger(__name__)

#: Step length as a fraction of body height.
STEP_LENGTH = 0.18
#: Knee bend of a plié (support level low), degrees (> 30° so it reads low).
PLIE_BEND_DEG = 45.0
#: Ankle plantar flexion of a relevé (support level high), degrees.
RELEVE_DEG = 35.0
#: Height a stepping foot is lifted mid-step, fraction of body height.
STEP_LIFT = 0.03
#: Vertical speed (m/s) at which a stepping or landing foot leaves and meets
#: the floor.  It exceeds DESIGN.md's 0.2 m/s support threshold, so a foot
#: reads as supporting from the end frame of its support symbol (within one
#: frame), not while it is still settling: the step arrives at the end of its
#: symbol, like a gesture.
FOOT_CONTACT_SPEED = 0.5
#: Height (m) of the lowest point of a gesturing foot above the floor that
#: the foot reaches, rising at :data:`LIFT_OFF_SPEED`, when its gesture
#: leaves the floor: above DESIGN.md's 3 cm support height, so the foot
#: stops reading as supporting on the frame after the gesture's start (the
#: Effort logistic alone starts so slowly that a foot would go on reading
#: as supporting for a fifth of the gesture).
LIFT_OFF_CLEARANCE = 0.04
#: Vertical speed (m/s) of that lift-off: above the 0.2 m/s support speed,
#: yet gentle (the knee bends about 20° a frame at 25 fps, not 30°).
LIFT_OFF_SPEED = 0.25

#: DESIGN.md: a foot slower than this (m/s) on the floor supports.
_SUPPORT_SPEED = 0.2

SUPPORT_FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}


def _foot_events(score: Score, foot: str):
    """Support symbols naming `foot`, gesture symbols of its leg and flights, in time order."""
    leg = {f"{foot}_leg", f"{foot}_thigh", f"{foot}_shin"}
    sup = [s for s in score.symbols if s.part in SUPPORT_FEET and foot in SUPPORT_FEET[s.part] and not s.is_air]
    ges = [s for s in score.symbols if s.part in leg]
    airs = [s for s in score.symbols if s.is_air]
    for a, b in itertools.pairwise(sup):
        if b.start < a.end:
            raise SyntheticError(
                f"{b.part} at beat {b.start} overlaps {a.part} at beat {a.start}-{a.end} on the {foot} foot"
            )
    for s in sup:
        for g in ges:
            if g.start < s.end and s.start < g.end:
                raise SyntheticError(
                    f"{s.part} at beat {s.start}-{s.end} overlaps the {foot} leg's gesture {g.part} "
                    f"at beat {g.start}-{g.end}: a leg cannot gesture and support at once"
                )
    return sup, ges, airs


def _planted_after(sup, ges, airs, beat, arriving: bool = False) -> bool:
    """Whether a foot bears weight just after `beat` (or, `arriving`, at it).

    Feet start planted; a gesture of the leg frees the foot from its start, a
    support symbol plants it at its end; at a tie the gesture wins.  A
    flight frees the feet after its start (at the take-off beat itself they
    still bear the weight they push off with), and so does a gesture that
    begins with the flight (the take-off leg of a leap).  `arriving`: the
    weight a support symbol ending at `beat` arrives on, which a gesture
    beginning at `beat` has not yet taken off the foot (DESIGN.md: a
    movement begins at its start, so the weight leaves the foot after it).
    """
    take_offs = {a.start for a in airs}
    effects = [(s.end, 0, True) for s in sup if s.end <= beat]
    effects += [
        (g.start, 1, False)
        for g in ges
        if g.start < beat or (g.start == beat and beat not in take_offs and not arriving)
    ]
    effects += [(a.start, 1, False) for a in airs if a.start < beat]
    return max(effects)[2] if effects else True


def foot_lift(tau, seconds: float, height: float):
    """Height of a stepping or landing foot above its path, metres.

    A trapezoid: the foot rises at :data:`FOOT_CONTACT_SPEED` from the
    symbol's start, travels at `height` and comes down at the same speed to
    touch the floor exactly at the symbol's end.

    Parameters
    ----------
    tau : (n,) ndarray
        Normalised time in [0, 1].
    seconds : float
        Duration of the symbol, seconds.
    height : float
        Greatest lift, metres.

    Returns
    -------
    (n,) ndarray
    """
    t = np.asarray(tau, float) * seconds
    return np.clip(np.minimum(FOOT_CONTACT_SPEED * t, FOOT_CONTACT_SPEED * (seconds - t)), 0.0, height)


def _weight_feet(sups, events, beat, arriving: bool = False) -> list:
    """Feet bearing the weight just after `beat` (`arriving`: at `beat`).

    Those named by the support symbols in force at `beat` (begun before it,
    not yet ended), less feet whose leg starts a gesture by then (`arriving`:
    before it); with no support symbol in force, every planted foot; none
    in flight.
    """
    if any(s.is_air and s.start < beat <= s.end for s in sups):
        return []
    named = {f for s in sups if s.start < beat <= s.end and not s.is_air for f in SUPPORT_FEET[s.part]}
    if not named:
        return [f for f in ("right", "left") if _planted_after(*events[f], beat, arriving)]
    return [f for f in ("right", "left") if f in named and _planted_after(*events[f], beat, arriving)]


class Support:
    """Root trajectory and foot targets implied by the support symbols."""

    def __init__(self, score: Score, frame, T: int, eff: Effort, body: Body, fps: float):
        self.body, self.T, self.eff, self.frame, self.fps = body, T, eff, frame, float(fps)
        self.limbs = {f: Limb(f"{f}_leg", body) for f in ("right", "left")}
        self.hip_off = {f: body.offsets[joint_index(f"{f}_hip")] for f in ("right", "left")}
        self.ankle0 = body.rest[joint_index("right_ankle")][2]
        self.toe0 = body.rest[joint_index("right_toe")][2]
        toe = body.offsets[joint_index("right_toe")]
        self.toe_offset = toe  # the toe from the ankle, in the foot's frame (both feet alike)
        self.toe_clearance = LIFT_OFF_CLEARANCE  # least toe height of a foot off the floor: gesturing or in the air
        pitch = -np.radians(RELEVE_DEG)
        self.rise = toe[2] - (rot_x(pitch) @ toe)[2]
        self.level_z = {"low": self.ankle0, "middle": self.ankle0, "high": self.ankle0 + self.rise}
        self.level_pitch = {"low": 0.0, "middle": 0.0, "high": pitch}
        self.events = {f: _foot_events(score, f) for f in ("right", "left")}
        self.root = np.tile(body.rest[0], (T, 1))
        # Per foot and frame: ankle target (world), pitch, whether the leg is
        # driven by the floor (planted or stepping) and whether it is landing.
        self.ankle = {f: np.tile(body.rest[joint_index(f"{f}_ankle")], (T, 1)) for f in ("right", "left")}
        self.pitch = {f: np.zeros(T) for f in ("right", "left")}
        self.floor = {f: np.ones(T, bool) for f in ("right", "left")}
        self.landing = {f: np.zeros(T, bool) for f in ("right", "left")}
        # Frames on which a foot that a support released holds its leg.
        self.released = {f: np.zeros(T, bool) for f in ("right", "left")}
        self.step = STEP_LENGTH * body.height
        self.leg_reach = float(self.limbs["right"].reach)
        # Touchdown frame of each flight -> pelvis velocity then (m/s).
        self.touchdown: dict[int, np.ndarray] = {}
        self._plan(score)

    def pivot(self, turn) -> np.ndarray | None:
        """Plan-coordinate pivot track of `turn` (:mod:`synthetic.turning`), None to pivot about the pelvis.

        Per frame, the mean centre (midpoint of ankle and toe) of the feet
        the weight arrives on at the turn's end: a centre moves only as its
        foot rises or lowers, so the foot spins on the spot.  A gesture or
        support beginning at that beat has not yet moved the weight (it
        begins there, DESIGN.md), so a turn on both feet that ends as one
        lifts still pivots about both.  None in the air or with no foot
        bearing weight.

        Returns
        -------
        (T, 2) ndarray or None
        """
        if any(a.is_air and a.start < turn.end and turn.start < a.end for a in self.sups):
            return None
        feet = _weight_feet(self.sups, self.events, turn.end, arriving=True)
        if not feet:
            return None
        toe = self.body.offsets[joint_index("right_toe")]
        centres = [self.ankle[f][:, :2] + 0.5 * (rot_x(self.pitch[f]) @ toe)[:, :2] for f in feet]
        return np.mean(centres, axis=0)

    def foot_symbols(self, foot: str) -> list:
        """Support symbols naming `foot` and gestures of its leg."""
        sup, ges, _ = self.events[foot]
        return list(sup) + list(ges)

    def _just_landed(self, foot: str, f0: int) -> bool:
        """Whether `foot` comes down onto the floor at frame `f0` (or `f0` is the first frame).

        A heel lowered from relevé slower than DESIGN.md's 0.2 m/s already
        rests on `f0` (its incoming step is slow): it needs no frame of rest.
        """
        if f0 == 0:
            return True
        drop = self.ankle[foot][f0 - 1, 2] - self.ankle[foot][f0, 2]
        return bool(self.landing[foot][f0]) or (drop > 1e-9 and drop * self.fps >= _SUPPORT_SPEED)

    def _leg_length(self, level):
        limb = self.limbs["right"]
        return float(limb.radius(np.radians(PLIE_BEND_DEG) if level == "low" else 0.0))

    def _plan(self, score: Score):
        frame, T, body = self.frame, self.T, self.body
        xy = {f: body.rest[joint_index(f"{f}_ankle")][:2].copy() for f in ("right", "left")}
        level = dict.fromkeys(("right", "left"), "middle")
        sups = sorted((s for s in score.symbols if s.is_support), key=lambda s: (s.end, s.start))
        self.sups = sups
        touchdowns = {s.end for s in sups if s.is_air}
        landings = [s for s in sups if not s.is_air and s.start in touchdowns]
        for s in sups:
            if s.part == "support" and s.direction not in ("place", AIR) and s not in landings:
                raise SyntheticError(
                    f"support at beat {s.start}: a step on both feet ({s.direction}) is not supported "
                    "except as a landing; notate right_support / left_support steps instead"
                )
        last_key = 0
        for s in sups:
            f0, f1 = frame(s.start), frame(s.end)
            if s.is_air:
                before = _weight_feet(sups, self.events, s.start)
                plan_flight(self, s, [x for x in landings if x.start == s.end], before, xy, level)
                last_key = max(last_key, f1)
                continue
            n = np.arange(f0 + 1, f1 + 1)
            tau = (n - f0) / max(f1 - f0, 1)
            # The foot travels with the Effort progress and touches down on
            # the end frame; the transfer of weight takes the whole symbol.
            sf = progress(tau, self.eff.time, self.eff.weight)
            lift = foot_lift(tau, (f1 - f0) / self.fps, STEP_LIFT * body.height)
            # A foot bears weight if the supports in force name it (a step
            # onto the other foot releases it, as a gesture of its leg does).
            bearing = _weight_feet(sups, self.events, s.start)
            for foot in () if s in landings else SUPPORT_FEET[s.part]:
                planted = foot in bearing
                other = "left" if foot == "right" else "right"
                if planted:
                    base = xy[foot]
                elif other in bearing:
                    # Closing: beside the supporting foot, at standing width.
                    base = xy[other] + (self.hip_off[foot] - self.hip_off[other])[:2]
                else:
                    base = self.root[f0, :2] + self.hip_off[foot][:2]
                target = base.copy()
                if s.direction != "place":
                    target = base + STEP_LENGTH * body.height * canonical_vector(s.direction, "middle")[:2]
                za, zb = self.ankle[foot][f0, 2], self.level_z[s.level]
                pa, pb = self.pitch[foot][f0], self.level_pitch[s.level]
                a = self.ankle[foot]
                sf_foot, lift_foot = sf, lift
                if s.direction != "place" and planted and self._just_landed(foot, f0) and f1 - f0 > 3:
                    # A foot that arrives on the floor at f0 (or stands on the
                    # first frame, whose incoming speed is unknown) rests one
                    # frame before it steps: a foot lifted again on its
                    # landing frame is never still on the floor, so the
                    # support it landed for would never be seen.  Only
                    # with more than three frames to step: a shorter step
                    # that rested would still be on the floor two frames
                    # before it lands (it must arrive within one).
                    tau1 = (n - f0 - 1) / (f1 - f0 - 1)
                    sf_foot = np.where(tau1 > 0, progress(np.maximum(tau1, 1e-9), self.eff.time, self.eff.weight), 0.0)
                    lift_foot = foot_lift(tau1, (f1 - f0 - 1) / self.fps, STEP_LIFT * body.height)
                a[n, :2] = base + sf_foot[:, None] * (target - base)
                a[n, 2] = za + sf * (zb - za)
                if s.direction != "place" and planted:
                    a[n, 2] += lift_foot
                self.pitch[foot][n] = pa + sf * (pb - pa)
                if not planted:
                    # Landing from a gesture: :func:`leg_tracks` blends the
                    # leg from its gesture pose to these (lifted) targets.
                    a[n] = [target[0], target[1], zb]
                    a[n, 2] += lift
                    self.pitch[foot][n] = pb
                    self.landing[foot][n] = True
                    self.floor[foot][f0 + 1 : f1 + 1] = True
                a[f1 + 1 :] = [target[0], target[1], zb]
                self.pitch[foot][f1 + 1 :] = pb
                xy[foot], level[foot] = target, s.level
            # Weight: the pelvis ends over the mean of the weight-bearing feet,
            # as high as their legs (at their levels) allow.  Where another
            # support symbol starts at this one's end, the weight arrives on
            # this symbol's feet and the next one moves it (DESIGN.md: a
            # movement begins at its start), even if a gesture starting then
            # is to free a foot; otherwise a gesture starting at the end needs
            # its foot free already (the left leg of Wolofsky's Figure 7).
            handed_on = any(x is not s and x.start == s.end and not x.is_air for x in sups)
            feet = _weight_feet(sups, self.events, s.end, arriving=handed_on)
            if not feet:
                log.info("no foot bears weight after beat %s; the pelvis holds", s.end)
                continue
            key = self.root[f1].copy()
            key[:2] = np.mean([xy[f] for f in feet], axis=0)
            zs = []
            for f in feet:
                h = np.linalg.norm(key[:2] + self.hip_off[f][:2] - xy[f])
                L = self._leg_length(level[f])
                zs.append(self.level_z[level[f]] + np.sqrt(max(L * L - h * h, 0.0)))
            key[2] = min(zs)
            if s in landings:
                land(self, s, key)
                last_key = max(last_key, f1)
                continue
            fa = max(f0, last_key)
            m = np.arange(fa + 1, f1 + 1)
            if f1 > fa:
                # The weight arrives with the foot, on the end frame.
                tau = (m - fa) / (f1 - fa)
                sr = progress(tau, self.eff.time, self.eff.weight)
                ra = self.root[fa].copy()
                self.root[m] = ra + sr[:, None] * (key - ra)
            self.root[f1:] = key
            last_key = max(last_key, f1)
        self._release(sups)
        # Gesturing frames: from a gesture's start to the next support's start,
        # or to the take-off of a flight the foot lands from (its landing blend).
        for foot in ("right", "left"):
            sup, ges, airs = self.events[foot]
            lands_from = [a for a in airs if any(x.start == a.end for x in sup)]
            for g in ges:
                nxt = min((x.start for x in sup + lands_from if x.start >= g.end), default=None)
                stop = T if nxt is None else frame(nxt) + 1
                self.floor[foot][frame(g.start) + 1 : stop] = False

    def _release(self, sups):
        """Mark the frames on which a foot released by a support holds its leg.

        A support that takes the weight off a foot without naming it (a step
        onto the other foot) leaves that foot free, and an unnotated part
        holds (DESIGN.md): from the support's end frame the leg keeps its
        pose in the body frame until its next symbol starts, instead of
        reaching for the spot it left while the pelvis moves on (a drift
        that reads as an unwritten gesture).
        """
        for s in sups:
            if s.is_air:
                continue  # the flight releases the feet that do not land (synthetic.flight)
            before = _weight_feet(sups, self.events, s.start)
            after = _weight_feet(sups, self.events, s.end)
            f1 = self.frame(s.end)
            for foot in ("right", "left"):
                if foot in SUPPORT_FEET[s.part] or foot not in before or foot in after:
                    continue
                sup, ges, _ = self.events[foot]
                nxt = min([x.start for x in sup + ges if x.start >= s.end], default=None)
                stop = self.T - 1 if nxt is None else self.frame(nxt)
                self.released[foot][f1 + 1 : stop + 1] = True
                self.floor[foot][f1 + 1 : stop + 1] = False

    def ik(self, foot: str, ankle_pos=None, foot_R=None, frames=slice(None), toe_min=None):
        """Leg pose putting the ankle at `ankle_pos` with the foot turned to `foot_R`.

        Parameters
        ----------
        foot : str
            ``"right"`` or ``"left"``.
        ankle_pos : (n, 3) ndarray, optional
            World ankle targets; default the planned ones.
        foot_R : (n, 3, 3) ndarray, optional
            World foot orientations; default flat or in relevé as planned.
        frames : slice or index array
            Frames concerned (the hip follows the root there).
        toe_min : (n,) ndarray, optional
            Least toe height, metres; default the toe's standing height.

        Returns
        -------
        Q : (n, 3, 3) ndarray
            Thigh frames (body frame).
        beta : (n,) ndarray
            Knee bend, radians.
        ankle : (n, 3) ndarray
            Ankle Euler angles, within the extremes.
        """
        limb = self.limbs[foot]
        hip = (self.root + self.hip_off[foot])[frames]
        ankle_pos = (self.ankle[foot][frames] if ankle_pos is None else ankle_pos).copy()
        foot_R = rot_x(self.pitch[foot][frames]) if foot_R is None else foot_R
        ja = joint_index(f"{foot}_ankle")
        lim = self.body.limits[ja]
        toe = self.body.offsets[joint_index(f"{foot}_toe")]
        for _ in range(4):
            v = ankle_pos - hip
            l = np.linalg.norm(v, axis=-1)
            beta = limb.bend_for_radius(np.minimum(l, limb.reach))
            Q = limb.fit_twist(limb.swing(v / l[:, None]), beta)
            shin = Q @ rot_x(limb.middle_angle(beta))
            ankle = np.clip(euler_near(shin.transpose(0, 2, 1) @ foot_R, 0.0, lim), lim[:, 0], lim[:, 1])
            # Past the ankle's extremes (a plié with the feet far apart) the
            # foot cannot stay flat: the heel lifts so the toe stays on the floor.
            deficit = (self.toe0 if toe_min is None else toe_min) - (ankle_pos + (shin @ euler_to_matrix(ankle)) @ toe)[
                :, 2
            ]
            if not np.any(deficit > 1e-6):
                break
            ankle_pos[:, 2] += np.maximum(deficit, 0.0)
        return Q, beta, ankle


def leg_tracks(sup: Support, symbols, frame, T: int, eff: Effort):
    """Final leg poses: floor-driven where planted, gestures elsewhere."""
    out = {}
    for foot in ("right", "left"):
        limb = sup.limbs[foot]
        Q, beta, ankle = sup.ik(foot)
        floor, landing = sup.floor[foot], sup.landing[foot]
        Qg, bg = Q.copy(), beta.copy()
        ankle_g = ankle.copy()
        held = np.flatnonzero(sup.released[foot])
        for run in np.split(held, np.flatnonzero(np.diff(held) > 1) + 1) if held.size else []:
            # A released leg holds the pose it had when the support ended.
            Qg[run], bg[run], ankle_g[run] = Q[run[0] - 1], beta[run[0] - 1], ankle[run[0] - 1]
        for f0, f1, syms in group_moves(limb, symbols, frame, T):
            stop = f1 + 1 + int(np.argmax(floor[f1 + 1 :])) if np.any(floor[f1 + 1 :]) else T
            a0 = ankle_g[f0].copy()
            s = apply_move(limb, Qg, bg, f0, f1, syms, eff, stop)
            ankle_g[f0 + 1 : f1 + 1] = a0 * (1.0 - s)[:, None]
            ankle_g[f1 + 1 : stop] = 0.0
        own = [(x, frame(x.start), frame(x.end)) for x in symbols if x.part in (limb.whole, limb.upper, limb.lower)]
        Qg, bg = _within_extremes(limb, Qg, bg, own, eff, sup.body)
        hip = sup.root + sup.hip_off[foot]
        gest = ~floor
        Q[gest], beta[gest], ankle[gest] = Qg[gest], bg[gest], ankle_g[gest]
        free = gest
        # The free foot stays above the floor (z = 0): the ankle no lower than
        # the sole's thickness (its standing height less the toe's), and the
        # toe above the floor too (a pitched foot reaches lower than its
        # ankle), by bending the knee.  A foot leaving the floor for a
        # gesture lifts off at once (:data:`LIFT_OFF_CLEARANCE`), so the
        # gesture visibly begins at its start.  Once off the floor, a leg
        # hanging near the floor (place low beside the supporting foot)
        # flexes its foot instead (:func:`_flex_clear`): a straight leg
        # lifted by a bent knee would read as bent (DESIGN.md bend ≥ 1).
        clear = _lift_off(floor, sup.toe0, sup.fps)
        floor_z = _ankle_floor(clear, sup.ankle0 - sup.toe0, sup.fps)
        Qf, bf = _keep_above_floor(limb, Q, beta, hip, floor_z, free)
        ja = limb.joints[2]
        lim = sup.body.limits[ja]
        steady = free & (clear >= LIFT_OFF_CLEARANCE)
        for _ in range(20):
            deficit = clear - _toe(sup.body, foot, limb, Qf, bf, ankle, hip)[:, 2]
            low = free & (deficit > 1e-6)
            if not np.any(low):
                break
            # Near the floor the free foot flexes towards flat, and the knee
            # bends (which also tips the foot down: overshoot a little, but
            # not while lifting off, where a doubled lift would jerk the
            # thigh forward in one frame).
            shin = Qf[low] @ rot_x(limb.middle_angle(bf[low]))
            flat = np.clip(euler_near(shin.transpose(0, 2, 1), 0.0, lim), lim[:, 0], lim[:, 1])
            ankle[low, 0] = np.maximum(ankle[low, 0], flat[:, 0])
            flex = low & steady
            if np.any(flex):
                ankle[flex] = _flex_clear(
                    sup.body, foot, limb, Qf[flex], bf[flex], ankle[flex], hip[flex], clear[flex], lim
                )
                deficit = clear - _toe(sup.body, foot, limb, Qf, bf, ankle, hip)[:, 2]
                low = free & (deficit > 1e-6)
                if not np.any(low):
                    break
            floor_z[low] += np.where(clear[low] > 0, 1.0, 2.0) * deficit[low] + 1e-4
            Qf, bf = _keep_above_floor(limb, Q, beta, hip, floor_z, free)
        # Landing: the ankle travels from where the gesture left it (clear
        # of the floor) to its floor target while the foot turns flat
        # (faster, so the toe does not catch the floor); the leg follows by
        # IK, the toe kept up until it comes down at
        # :data:`FOOT_CONTACT_SPEED` onto the end frame: a foot that
        # touched down earlier would read as landing there.
        idx = np.flatnonzero(landing)
        for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if idx.size else []:
            g = run[0] - 1
            w = progress(np.arange(1, run.size + 1) / run.size, eff.time, eff.weight)
            shin_g = Qf[g] @ rot_x(limb.middle_angle(bf[g]))
            a_g = hip[g] + Qf[g] @ sup.body.offsets[limb.joints[1]] + shin_g @ sup.body.offsets[limb.joints[2]]
            F_g = shin_g @ euler_to_matrix(ankle[g])
            target = sup.ankle[foot][run]
            wo = np.minimum(1.0, 1.5 * w)
            F = slerp_frames(F_g, rot_x(sup.pitch[foot][run[-1]]), wo * wo * (3.0 - 2.0 * wo))
            # About the hip, not along a straight line: the leg keeps its
            # length as it comes down and folds only near the floor, so a
            # high leg does not bend its knee (which would lift the thigh
            # past the hip's extreme).
            u_g = a_g - hip[g]
            v_t = target - hip[run]
            r = np.linalg.norm(u_g) + w**3 * (np.linalg.norm(v_t, axis=-1) - np.linalg.norm(u_g))
            u = (1.0 - w)[:, None] * u_g / np.linalg.norm(u_g) + w[:, None] * unit(v_t)
            toe_min = np.minimum(LIFT_OFF_CLEARANCE, sup.toe0 + FOOT_CONTACT_SPEED * (run[-1] - run) / sup.fps)
            Qf[run], bf[run], ankle[run] = sup.ik(foot, hip[run] + r[:, None] * unit(u), F, run, toe_min)
        out[f"{foot}_leg"] = (Qf, bf, ankle)
    return out


def _lift_off(floor, toe0: float, fps: float) -> np.ndarray:
    """(T,) least height of a free foot's toe above the floor, metres.

    From each frame where a foot driven by the floor starts gesturing, the
    clearance rises from the toe's standing height `toe0` at
    :data:`LIFT_OFF_SPEED` to :data:`LIFT_OFF_CLEARANCE` and stays
    there while the leg gestures (a gesture that naturally carries the foot
    higher is not affected); elsewhere it is zero (the floor).
    """
    T = len(floor)
    out = np.zeros(T)
    starts = np.flatnonzero(floor[:-1] & ~floor[1:])
    ends = np.r_[np.flatnonzero(~floor[:-1] & floor[1:]) + 1, T]
    for f0 in starts:
        f1 = int(ends[np.searchsorted(ends, f0 + 1)])
        k = np.arange(f0 + 1, f1)
        out[k] = np.minimum(toe0 + LIFT_OFF_SPEED * (k - f0) / fps, LIFT_OFF_CLEARANCE)
    return out


def _ankle_floor(clear, sole: float, fps: float) -> np.ndarray:
    """(T,) least height of a free foot's ankle, metres.

    While a foot lifts off (`clear` rising to :data:`LIFT_OFF_CLEARANCE`)
    the whole foot rises: the ankle stays a sole's thickness `sole` above
    the toe's clearance, so the foot reads as moving (DESIGN.md's support
    speed) from the gesture's first frame.  Afterwards the ankle may come
    down, at :data:`LIFT_OFF_SPEED` so the knee straightens smoothly, to the
    clearance itself, the toe kept up by flexing the foot
    (:func:`_flex_clear`).
    """
    T = len(clear)
    out = sole + np.asarray(clear, float)
    steady = clear >= LIFT_OFF_CLEARANCE
    since = 0
    for k in range(T):
        since = since + 1 if steady[k] else 0
        if since:
            out[k] = max(LIFT_OFF_CLEARANCE, sole + LIFT_OFF_CLEARANCE - LIFT_OFF_SPEED * since / fps)
    return out


def _flex_clear(body: Body, foot: str, limb: Limb, Q, beta, ankle, hip, clear, lim):
    """Ankle angles of free feet flexed (toe up) just enough to lift the toe to `clear`.

    Parameters
    ----------
    Q : (n, 3, 3) ndarray
        Thigh frames.
    beta : (n,) ndarray
        Knee bends, radians.
    ankle : (n, 3) ndarray
        Ankle Euler angles; the flexion (rx) only grows.
    hip : (n, 3) ndarray
    clear : (n,) ndarray
        Least toe height, metres.
    lim : (3, 2) ndarray
        The ankle's extremes.

    Returns
    -------
    (n, 3) ndarray
        The ankle angles, flexed at most to the extreme (the knee makes up
        the rest).
    """
    out = ankle.copy()
    todo = np.ones(len(out), bool)
    for rx in np.arange(0.0, lim[0, 1] + 1e-9, np.radians(0.25)):
        cand = out[todo].copy()
        cand[:, 0] = np.maximum(cand[:, 0], rx)
        ok = _toe(body, foot, limb, Q[todo], beta[todo], cand, hip[todo])[:, 2] >= clear[todo] + 1e-4
        idx = np.flatnonzero(todo)
        out[idx[ok]] = cand[ok]
        todo[idx[ok]] = False
        if not todo.any():
            break
    out[todo, 0] = np.maximum(out[todo, 0], lim[0, 1])
    return out


def _within_extremes(limb: Limb, Q, beta, events, eff: Effort, body: Body):
    """Leg gestures whose direct path leaves the hip's extremes, straightened.

    Done here, before the floor is enforced, so a straightened leg still
    stays above the floor (:func:`synthetic.extremes.keep_paths_within`).
    """
    if not events:
        return Q, beta
    ja, jm, _ = limb.joints
    a = np.zeros((len(Q), len(body.rest), 3))
    a[:, ja] = euler_near(Q, 0.0, body.limits[ja])
    a[:, jm, 0] = limb.middle_angle(beta)
    keep_paths_within(a, body, events, eff)
    return euler_to_matrix(a[:, ja]), limb.sign * a[:, jm, 0]


def _toe(body: Body, foot: str, limb: Limb, Q, beta, ankle, hip):
    """(T,3) toe positions of a leg posed by hip frames `Q`, bend `beta`, ankle angles."""
    shin = Q @ rot_x(limb.middle_angle(beta))
    knee = hip + Q @ body.offsets[joint_index(f"{foot}_knee")]
    ank = knee + shin @ body.offsets[joint_index(f"{foot}_ankle")]
    return ank + (shin @ euler_to_matrix(ankle)) @ body.offsets[joint_index(f"{foot}_toe")]


def _keep_above_floor(limb: Limb, Q, beta, hip, floor_z, mask):
    """Bend the knee of free legs whose ankle would go below `floor_z` (T,)."""
    P = limb.whole_frame(Q, beta)
    d = -P[:, :, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        lmax = np.where(d[:, 2] < -1e-9, (hip[:, 2] - floor_z) / -d[:, 2], np.inf)
    bad = mask & (limb.radius(beta) > lmax)
    if np.any(bad):
        nb = limb.bend_for_radius(np.maximum(lmax[bad], abs(limb.L1 - limb.L2) + 1e-6))
        beta = beta.copy()
        beta[bad] = np.maximum(beta[bad], nb)
        Q = Q.copy()
        Q[bad] = limb.upper_frame(P[bad], beta[bad])
    return Q, beta
