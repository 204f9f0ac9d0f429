"""Arms and legs as two-segment limbs: swing frames, bend ↔ reach, movements.

A limb symbol (whole ``right_arm`` …, or ``upper_arm`` / ``forearm``,
``thigh`` / ``shin``) sets a target *upper-segment frame* ``Q`` (body frame,
its −z along the upper segment) and a middle-joint bend ``β`` (radians,
0 straight).  :func:`apply_move` fills the frames between a movement's start
and end with the Effort progress ``s(τ)``:

* a whole limb's bound→free direction runs along the great circle (the direct
  path), its twist turning uniformly with ``s``; Space modulates the
  extremity's distance from the bound joint mid-movement (Neagle eq. 5.5
  inward, 5.6 outward when the limb is bent at both ends) by bending the
  middle joint;
* segment symbols turn the upper frame about a fixed axis.

Arms swing from a reference direction whose antipode points through the
torso, so they pass through place high / low without flipping; legs swing
from hanging (their singular direction, straight up, is out of the hip's
reach).  Elbows flex with rx > 0, knees with rx < 0.
"""

from __future__ import annotations

import numpy as np

from capture2notation.body import Body, joint_index
from capture2notation.errors import SyntheticError
from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.effort import progress, space_radius
from capture2notation.notation.model import Effort

from .motion import euler_near
from .rotations import Z as _Z
from .rotations import axis_angle, great_circle_frames, rot_between, rot_x, slerp_frames, unit

__all__ = ["LIMBS", "Limb", "apply_move", "group_moves", "limb_target"]

# Limbs: name -> (whole part, upper part, lower part, bound, middle, free joint, sign).
# sign +1: the middle joint flexes forward (elbow rx > 0); −1: backward (knee rx < 0).
LIMBS = {
    "right_arm": ("right_arm", "right_upper_arm", "right_forearm", "right_shoulder", "right_elbow", "right_wrist", 1),
    "left_arm": ("left_arm", "left_upper_arm", "left_forearm", "left_shoulder", "left_elbow", "left_wrist", 1),
    "right_leg": ("right_leg", "right_thigh", "right_shin", "right_hip", "right_knee", "right_ankle", -1),
    "left_leg": ("left_leg", "left_thigh", "left_shin", "left_hip", "left_knee", "left_ankle", -1),
}


class Limb:
    """Geometry of one two-segment limb (lengths, bend ↔ reach, swing frames)."""

    def __init__(self, name: str, body: Body):
        whole, upper, lower, a, m, b, sign = LIMBS[name]
        self.name, self.whole, self.upper, self.lower = name, whole, upper, lower
        self.joints = (joint_index(a), joint_index(m), joint_index(b))
        self.sign = sign
        self.L1 = body.segment_length(a, m)
        self.L2 = body.segment_length(m, b)
        self.reach = self.L1 + self.L2
        self.limits = body.limits[self.joints[0]]
        self.is_arm = name.endswith("arm")
        side = 1.0 if name.startswith("right") else -1.0
        # Arms swing from a reference direction whose antipode points through
        # the torso (left-back-low for the right arm), so every reachable
        # direction, place high included, has one continuous swing frame.
        self.ref = unit([side, 1.0, 1.0]) if self.is_arm else None
        self.prefer = np.array([0.0, 1.0, 0.0])  # half turns go through the front

    def radius(self, beta):
        beta = np.asarray(beta, float)
        return np.sqrt(self.L1**2 + self.L2**2 + 2 * self.L1 * self.L2 * np.cos(beta))

    def bend_for_radius(self, r):
        c = (np.asarray(r, float) ** 2 - self.L1**2 - self.L2**2) / (2 * self.L1 * self.L2)
        return np.arccos(np.clip(c, -1.0, 1.0))

    def gamma(self, beta):
        """Angle between the upper segment and the whole limb at bend `beta`."""
        beta = np.asarray(beta, float)
        return np.arctan2(self.L2 * np.sin(beta), self.L1 + self.L2 * np.cos(beta))

    def swing(self, d):
        """Frame whose −z is the unit direction `d` (continuous in `d`)."""
        if self.ref is None:
            return rot_between(-_Z, d, [1.0, 0.0, 0.0])
        return rot_between(self.ref, d, [1.0, 0.0, 0.0]) @ rot_between(-_Z, self.ref, [1.0, 0.0, 0.0])

    def whole_frame(self, Q, beta):
        """Upper-segment frame(s) `Q` → frame whose −z is bound→free."""
        return Q @ rot_x(self.sign * self.gamma(beta))

    def upper_frame(self, P, beta):
        return P @ rot_x(-self.sign * self.gamma(beta))

    def fit_twist(self, P, beta, parent=None):
        """Upper-segment frames for whole-limb frames `P`, twisted into the extremes.

        A whole-limb symbol fixes the bound→free direction and the bend, not
        the limb's twist about its own axis.  The bound joint's extremes are
        a box in Euler angles, so near its gimbal lock (e.g. a leg to the side
        at middle level) a pose a few degrees off the box's edge can need a
        large twist to come back in.  Each frame keeps `P`'s own twist when
        that is within the extremes, else takes the smallest twist about the
        limb's axis (1° grid) that is, or failing that the one nearest them.

        Parameters
        ----------
        P : (n, 3, 3) ndarray
            Whole-limb frames (−z bound→free) in the body frame.
        beta : (n,) ndarray
            Middle-joint bend, radians.
        parent : (n, 3, 3) ndarray, optional
            Transposed world frame of the bound joint's parent (the chest for
            arms); identity (the pelvis never turns) by default.

        Returns
        -------
        (n, 3, 3) ndarray
            Upper-segment frames ``Q``.
        """
        P = np.asarray(P, float)
        beta = np.broadcast_to(np.asarray(beta, float), P.shape[:-2])
        Q = self.upper_frame(P, beta)
        bad = self.excess(Q, parent) > 1e-9
        if not np.any(bad):
            return Q
        # Twists in order of size, so that ties keep the smallest.
        grid = np.radians(np.arange(0.0, 180.5, 1.0))
        grid = np.stack([grid, -grid], axis=1).ravel()[1:]
        Rz = axis_angle(np.broadcast_to(_Z, grid.shape + (3,)), grid)
        cand = P[bad][:, None] @ Rz[None] @ rot_x(-self.sign * self.gamma(beta[bad]))[:, None]
        par = None if parent is None else np.asarray(parent)[bad][:, None]
        ex = self.excess(cand, par)
        k = np.argmin(ex + 1e-6 * np.arange(len(grid)), axis=1)
        Q = Q.copy()
        Q[bad] = cand[np.arange(len(k)), k]
        return Q

    def excess(self, Q, parent=None):
        """Summed excess (radians) of the bound joint's Euler angles over its extremes.

        Parameters
        ----------
        Q : (..., 3, 3) ndarray
            Upper-segment frames in the body frame.
        parent : (..., 3, 3) ndarray, optional
            As in :meth:`fit_twist`.

        Returns
        -------
        (...) ndarray
        """
        local = Q if parent is None else parent @ Q
        e = euler_near(local, 0.0, self.limits)
        lo, hi = self.limits[:, 0], self.limits[:, 1]
        return np.sum(np.maximum(lo - e, 0.0) + np.maximum(e - hi, 0.0), axis=-1)

    def middle_angle(self, beta):
        return self.sign * np.asarray(beta, float)


def apply_move(limb: Limb, Q, beta, f0: int, f1: int, syms, eff: Effort, hold_until: int, parent=None):
    """Fill frames (f0, f1] of `Q`, `beta` with one movement; hold to `hold_until`.

    A whole-limb movement keeps the bound joint within its extremes by its
    twist where it can (:meth:`Limb.fit_twist`); paths that still leave them
    are straightened afterwards (:func:`synthetic.extremes.keep_paths_within`).

    Parameters
    ----------
    Q : (T, 3, 3) ndarray
        Upper-segment frames in the body frame, updated in place.
    beta : (T,) ndarray
        Middle-joint bend, radians, updated in place.
    f0, f1 : int
        Start and end frames of the movement.
    syms : list of Symbol
        One whole-limb symbol, or upper and/or lower segment symbols.
    eff : Effort
    hold_until : int
        The target is held on frames (f1, hold_until).
    parent : (T, 3, 3) ndarray, optional
        Transposed world frames of the bound joint's parent (arms: the chest).

    Returns
    -------
    s : (f1 − f0,) ndarray
        The progress used, for callers that move other joints along.
    """
    Qa, ba = Q[f0].copy(), float(beta[f0])
    Qb, bb, whole = limb_target(limb, Qa, ba, syms, None if parent is None else parent[f1])
    n = np.arange(f0 + 1, f1 + 1)
    tau = (n - f0) / max(f1 - f0, 1)
    s = progress(tau, eff.time, eff.weight)
    if whole:
        Pa, Pb = limb.whole_frame(Qa, ba), limb.whole_frame(Qb, bb)
        P = great_circle_frames(Pa, Pb, s, limb.prefer)
        r = limb.radius(ba + s * (bb - ba))
        # Space: bend the middle joint so the reach follows eq. 5.5 (5.6 when
        # the limb is bent at both ends and so can reach out).
        outward = min(ba, bb) >= np.radians(29.0)
        l = space_radius(r, eff.space, tau, outward=outward, reach=limb.reach * 0.999)
        b_t = limb.bend_for_radius(l)
        Q[n] = limb.fit_twist(P, b_t, None if parent is None else parent[n])
        beta[n] = b_t
    else:
        Q[n] = slerp_frames(Qa, Qb, s, limb.prefer)
        beta[n] = ba + s * (bb - ba)
    Q[f1 + 1 : hold_until] = Qb
    beta[f1 + 1 : hold_until] = bb
    return s


def limb_target(limb: Limb, Qa, ba, syms, parent=None):
    """Target (Q, β, whole) of a movement of `limb` by `syms` (one whole, or upper and/or lower).

    `parent` (3, 3), as in :meth:`Limb.fit_twist`, at the end frame.
    """
    by_part = {s.part: s for s in syms}
    if limb.whole in by_part:
        s = by_part[limb.whole]
        d = canonical_vector(s.direction, s.level)
        bb = np.radians(30.0 * s.bend)
        par = None if parent is None else parent[None]
        return limb.fit_twist(limb.swing(d)[None], np.array([bb]), par)[0], bb, True
    Q, beta = Qa, ba
    if limb.upper in by_part:
        s = by_part[limb.upper]
        d1 = canonical_vector(s.direction, s.level)
        # The upper segment takes its swing frame, keeping its twist about its
        # own axis (so a carried forearm keeps its plane); legs, with little
        # twist range, drop the twist.
        M = limb.swing(Q @ -_Z).T @ Q
        psi = np.arctan2(M[1, 0], M[0, 0]) if limb.is_arm else 0.0
        Q = limb.swing(d1) @ axis_angle(_Z, psi)
    if limb.lower in by_part:
        s = by_part[limb.lower]
        d2 = canonical_vector(s.direction, s.level)
        d1 = Q @ -_Z
        beta = float(np.arccos(np.clip(d1 @ d2, -1.0, 1.0)))
        t = d2 - (d2 @ d1) * d1
        if np.linalg.norm(t) > 1e-9:
            u = Q @ np.array([0.0, limb.sign, 0.0])  # where the middle joint flexes to
            t = t / np.linalg.norm(t)
            psi = np.arctan2(np.cross(u, t) @ d1, u @ t)
            Q = axis_angle(d1, psi) @ Q
    return Q, beta, False


def group_moves(limb: Limb, symbols, frame, T):
    """Movements of one limb: (f0, f1, symbols) in time order; reject conflicts."""
    syms = [s for s in symbols if s.part in (limb.whole, limb.upper, limb.lower)]
    moves: list = []
    for s in syms:
        f0, f1 = frame(s.start), frame(s.end)
        if (
            moves
            and (s.start, s.end) == moves[-1][3]
            and s.part != limb.whole
            and all(p.part != limb.whole and p.part != s.part for p in moves[-1][2])
        ):
            moves[-1][2].append(s)
            continue
        if moves and s.start < moves[-1][3][1]:
            prev = moves[-1][2][0]
            raise SyntheticError(
                f"{s.part} at beat {s.start} overlaps {prev.part} at beat {prev.start}-{prev.end}: "
                "segments of one limb may move together only over the same span, never with the whole limb"
            )
        moves.append((f0, f1, [s], (s.start, s.end)))
    return [(f0, f1, ss) for f0, f1, ss, _ in moves]
