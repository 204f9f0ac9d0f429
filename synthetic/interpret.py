"""Interpreter: a notation :class:`Score` → a :class:`Motion` of the virtual dancer.

Semantics (``../shared/DESIGN.md``; Wolofsky 1974 ch. IV; Neagle 2005 ch. 5):

* Every gesture symbol sets the target direction of its segment — the
  canonical vector of (direction, level) in the body frame — and, for whole
  arms and legs, the bend of the elbow / knee (β = 30°·bend, with the
  shoulder→wrist, hip→ankle direction still the symbol's).  The movement
  begins at the symbol's start frame and arrives at its end frame
  (``seconds = beats × 60 / tempo``, frame = round(seconds × fps)).
* Progress along the path is the Effort logistic ``s(τ)`` (time b, weight
  x0): a whole limb's bound→free direction runs along the great circle (the
  direct path) and covers the fraction ``s`` of its arc, its twist turning
  uniformly with ``s`` too; segments and head/chest follow ``s`` the same
  way.  Space modulates the
  extremity's distance from the bound joint mid-movement (Neagle eq. 5.5
  inward, or 5.6 outward when the limb is bent at both ends) by bending the
  middle joint.
* Whole limbs use a fixed swing frame per direction, whose one singular
  direction lies through the torso, so limbs pass through place high / low
  without flipping; a half turn (e.g. place low → place high) goes through
  the front.  Elbows flex (rx > 0) and knees flex (rx < 0) the anatomical way.
* ``upper_arm``/``forearm`` and ``thigh``/``shin`` symbols move one segment;
  the other is carried (the elbow keeps its bend) unless notated over the same
  span.  Head: neck→head; chest: waist→neck (shared by waist and chest).
* Supports (``support`` = both feet, ``right_support``, ``left_support``):
  level low = plié (knees bent 45°), middle, high = relevé (ankles
  plantar-flexed 35°, heels raised, the body rises); a direction other than
  place is a step of :data:`STEP_LENGTH` × height that way, the foot lifting
  on the way.  At the end of each support symbol the pelvis is over the mean
  of the weight-bearing feet and as high as their levels allow, so the
  supporting feet stay on the floor; a foot whose support ended is free as
  soon as a gesture of its leg starts.  A gesturing foot never goes below
  the floor (the knee bends and the foot flexes instead).
* Unnotated parts hold.  The start pose is standing on both feet, arms and
  legs hanging straight, head and chest upright.

Timing is returned on the motion: ``Motion.events`` holds
``(symbol, start_frame, end_frame)`` for every symbol of the score.
"""

from __future__ import annotations

import logging
import warnings
from fractions import Fraction

import numpy as np
from scipy.spatial.transform import Rotation

from capture2notation.body import (
    Body,
    body_frame,
    euler_to_matrix,
    forward_kinematics,
    joint_index,
    matrix_to_euler,
    segment_vectors,
)
from capture2notation.effort.model import progress, space_radius
from capture2notation.errors import SyntheticError
from capture2notation.notation.directions import bend_angle, bend_degree, canonical_vector, classify
from capture2notation.notation.model import PART_MIDDLE_JOINT, PART_SEGMENTS, Effort, Score

from .motion import Motion, euler_near

__all__ = ["interpret", "unreachable", "UnreachableWarning", "beat_frame", "STEP_LENGTH", "PLIE_BEND_DEG", "RELEVE_DEG"]

log = logging.getLogger(__name__)

#: Step length as a fraction of body height.
STEP_LENGTH = 0.18
#: Knee bend of a plié (support level low), degrees (> 30° so it reads low).
PLIE_BEND_DEG = 45.0
#: Ankle plantar flexion of a relevé (support level high), degrees.
RELEVE_DEG = 35.0
#: Height a stepping foot is lifted mid-step, fraction of body height.
STEP_LIFT = 0.03
#: Fraction of a support symbol by which a stepping or landing foot is down;
#: the weight transfer takes the rest (Labanotation: the support symbol's
#: length is the transference of weight).
FOOT_ARRIVAL = 0.6

_Z = np.array([0.0, 0.0, 1.0])
# Limbs: name -> (whole part, upper part, lower part, bound, middle, free joint, sign).
# sign +1: the middle joint flexes forward (elbow rx > 0); −1: backward (knee rx < 0).
_LIMBS = {
    "right_arm": ("right_arm", "right_upper_arm", "right_forearm", "right_shoulder", "right_elbow", "right_wrist", 1),
    "left_arm": ("left_arm", "left_upper_arm", "left_forearm", "left_shoulder", "left_elbow", "left_wrist", 1),
    "right_leg": ("right_leg", "right_thigh", "right_shin", "right_hip", "right_knee", "right_ankle", -1),
    "left_leg": ("left_leg", "left_thigh", "left_shin", "left_hip", "left_knee", "left_ankle", -1),
}
_SUPPORT_FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}


class UnreachableWarning(UserWarning):
    """A symbol's pose lies beyond the joint extremes (or the floor)."""


# --- rotation helpers (vectorised over leading axes) -------------------------
def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _rot_x(theta):
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    m = np.zeros(theta.shape + (3, 3))
    m[..., 0, 0] = 1.0
    m[..., 1, 1], m[..., 1, 2] = c, -s
    m[..., 2, 1], m[..., 2, 2] = s, c
    return m


def _cross(a, b):
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    return np.stack(
        [a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
         a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]],
        axis=-1,
    )


def _axis_angle(axis, angle):
    """Rotation matrices (Rodrigues) about `axis` (..., 3) by `angle` (...) radians."""
    k = _unit(axis)
    angle = np.asarray(angle, dtype=float)
    k, angle = np.broadcast_arrays(k, angle[..., None])
    angle = angle[..., 0]
    c, s, x, y, z = np.cos(angle), np.sin(angle), k[..., 0], k[..., 1], k[..., 2]
    t = 1.0 - c
    m = np.empty(angle.shape + (3, 3))
    m[..., 0, 0], m[..., 0, 1], m[..., 0, 2] = c + x * x * t, x * y * t - z * s, x * z * t + y * s
    m[..., 1, 0], m[..., 1, 1], m[..., 1, 2] = y * x * t + z * s, c + y * y * t, y * z * t - x * s
    m[..., 2, 0], m[..., 2, 1], m[..., 2, 2] = z * x * t - y * s, z * y * t + x * s, c + z * z * t
    return m


def _rot_between(a, b, fallback_axis):
    """Minimal rotation taking unit `a` to unit `b`; half turns about `fallback_axis`."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    v = _cross(a, b)
    c = np.sum(a * b, axis=-1)
    n = np.linalg.norm(v, axis=-1)
    angle = np.arctan2(n, c)
    fb = np.broadcast_to(np.asarray(fallback_axis, float), a.shape)
    fb = fb - np.sum(fb * a, -1, keepdims=True) * a
    axis = np.where((n > 1e-9)[..., None], v, fb)
    return _axis_angle(axis, angle)


def _slerp_frames(Pa, Pb, s, prefer=None):
    """Frames turning from `Pa` to `Pb` about a fixed axis: ``Rot(s·θ)·Pa``.

    Parameters
    ----------
    Pa, Pb : (3, 3) ndarray
    s : (n,) ndarray
        Progress.
    prefer : (3,) ndarray, optional
        For a half turn (ambiguous sense), the world direction the image of
        −z should pass through half-way.
    """
    rv = Rotation.from_matrix(Pb @ Pa.T).as_rotvec()
    if prefer is not None and np.linalg.norm(rv) > np.pi - 1e-6:
        mid = Rotation.from_rotvec(0.5 * rv).as_matrix() @ Pa @ -_Z
        if mid @ prefer < 0:
            rv = -rv
    return Rotation.from_rotvec(np.asarray(s)[:, None] * rv).as_matrix() @ Pa


def _great_circle_frames(Pa, Pb, s, prefer):
    """Frames whose −z runs along the great circle from `Pa`'s to `Pb`'s at progress `s`.

    The limb takes the direct (shortest) path, covering the fraction `s` of
    the arc, while its twist about itself turns uniformly with `s` too.  When
    the end directions are opposite, the path passes through `prefer`.

    Parameters
    ----------
    Pa, Pb : (3, 3) ndarray
    s : (n,) ndarray
    prefer : (3,) ndarray

    Returns
    -------
    (n, 3, 3) ndarray
    """
    da, db = Pa @ -_Z, Pb @ -_Z
    n = np.cross(da, db)
    theta = np.arctan2(np.linalg.norm(n), da @ db)
    if np.linalg.norm(n) < 1e-9:
        n = np.cross(da, prefer)
        if np.linalg.norm(n) < 1e-9:
            n = Pa[:, 0]
    G = _axis_angle(n, theta)
    tw = (G @ Pa).T @ Pb  # a turn about the limb's own axis
    psi = np.arctan2(tw[1, 0], tw[0, 0])
    s = np.asarray(s, float)
    return _axis_angle(np.broadcast_to(n, s.shape + (3,)), s * theta) @ Pa @ _axis_angle(
        np.broadcast_to(_Z, s.shape + (3,)), s * psi
    )


def _slerp_dirs(da, db, s):
    """Unit vectors (n, 3) along the great circle from `da` to `db` at progress `s` (n,).

    Opposite ends go through +x (an arbitrary but fixed choice).
    """
    n = np.cross(da, db)
    if np.linalg.norm(n) < 1e-9:
        n = np.cross(da, [1.0, 0.0, 0.0]) if abs(da[0]) < 0.9 else np.cross(da, [0.0, 1.0, 0.0])
    theta = np.arctan2(np.linalg.norm(np.cross(da, db)), da @ db)
    return _axis_angle(np.broadcast_to(n, np.shape(s) + (3,)), np.asarray(s) * theta) @ da


# --- timing --------------------------------------------------------------------
def beat_frame(beat, tempo, fps: float) -> int:
    """Frame index of a beat: round half up of ``beat × 60 / tempo × fps``."""
    x = float(Fraction(beat) * 60 / Fraction(tempo)) * fps
    return int(np.floor(x + 0.5 + 1e-9))


# --- limbs ---------------------------------------------------------------------
class _Limb:
    """Geometry of one two-segment limb (lengths, bend ↔ reach, swing frames)."""

    def __init__(self, name: str, body: Body):
        whole, upper, lower, a, m, b, sign = _LIMBS[name]
        self.name, self.whole, self.upper, self.lower = name, whole, upper, lower
        self.joints = (joint_index(a), joint_index(m), joint_index(b))
        self.sign = sign
        self.L1 = body.segment_length(a, m)
        self.L2 = body.segment_length(m, b)
        self.reach = self.L1 + self.L2
        self.is_arm = name.endswith("arm")
        side = 1.0 if name.startswith("right") else -1.0
        # Arms swing from a reference direction whose antipode points through
        # the torso (left-back-low for the right arm), so every reachable
        # direction, place high included, has one continuous swing frame.
        self.ref = _unit([side, 1.0, 1.0]) if self.is_arm else None
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
            return _rot_between(-_Z, d, [1.0, 0.0, 0.0])
        return _rot_between(self.ref, d, [1.0, 0.0, 0.0]) @ _rot_between(-_Z, self.ref, [1.0, 0.0, 0.0])

    def whole_frame(self, Q, beta):
        """Upper-segment frame(s) `Q` → frame whose −z is bound→free."""
        return Q @ _rot_x(self.sign * self.gamma(beta))

    def upper_frame(self, P, beta):
        return P @ _rot_x(-self.sign * self.gamma(beta))

    def middle_angle(self, beta):
        return self.sign * np.asarray(beta, float)


def _apply_move(limb: _Limb, Q, beta, f0: int, f1: int, syms, eff: Effort, hold_until: int):
    """Fill frames (f0, f1] of `Q`, `beta` with one movement; hold to `hold_until`.

    Parameters
    ----------
    Q : (T, 3, 3) ndarray
        Upper-segment frames in the body frame, updated in place.
    beta : (T,) ndarray
        Middle-joint bend, radians, updated in place.

    Returns
    -------
    s : (f1 − f0,) ndarray
        The progress used, for callers that move other joints along.
    """
    Qa, ba = Q[f0].copy(), float(beta[f0])
    Qb, bb, whole = _limb_target(limb, Qa, ba, syms)
    n = np.arange(f0 + 1, f1 + 1)
    tau = (n - f0) / max(f1 - f0, 1)
    s = progress(tau, eff.time, eff.weight)
    if whole:
        Pa, Pb = limb.whole_frame(Qa, ba), limb.whole_frame(Qb, bb)
        P = _great_circle_frames(Pa, Pb, s, limb.prefer)
        r = limb.radius(ba + s * (bb - ba))
        # Space: bend the middle joint so the reach follows eq. 5.5 (5.6 when
        # the limb is bent at both ends and so can reach out).
        outward = min(ba, bb) >= np.radians(29.0)
        l = space_radius(r, eff.space, tau, outward=outward, reach=limb.reach * 0.999)
        b_t = limb.bend_for_radius(l)
        Q[n] = limb.upper_frame(P, b_t)
        beta[n] = b_t
    else:
        Q[n] = _slerp_frames(Qa, Qb, s, limb.prefer)
        beta[n] = ba + s * (bb - ba)
    Q[f1 + 1 : hold_until] = Qb
    beta[f1 + 1 : hold_until] = bb
    return s


def _limb_target(limb: _Limb, Qa, ba, syms):
    """Target (Q, β) of a movement of `limb` by `syms` (one whole, or upper and/or lower)."""
    by_part = {s.part: s for s in syms}
    if limb.whole in by_part:
        s = by_part[limb.whole]
        d = canonical_vector(s.direction, s.level)
        bb = np.radians(30.0 * s.bend)
        return limb.upper_frame(limb.swing(d), bb), bb, True
    Q, beta = Qa, ba
    if limb.upper in by_part:
        s = by_part[limb.upper]
        d1 = canonical_vector(s.direction, s.level)
        # The upper segment takes its swing frame, keeping its twist about its
        # own axis (so a carried forearm keeps its plane); legs, with little
        # twist range, drop the twist.
        M = limb.swing(Q @ -_Z).T @ Q
        psi = np.arctan2(M[1, 0], M[0, 0]) if limb.is_arm else 0.0
        Q = limb.swing(d1) @ _axis_angle(_Z, psi)
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
            Q = _axis_angle(d1, psi) @ Q
    return Q, beta, False


def _group_moves(limb: _Limb, symbols, frame, T):
    """Movements of one limb: (f0, f1, symbols) in time order; reject conflicts."""
    syms = [s for s in symbols if s.part in (limb.whole, limb.upper, limb.lower)]
    moves: list = []
    for s in syms:
        f0, f1 = frame(s.start), frame(s.end)
        if moves and (s.start, s.end) == moves[-1][3] and s.part != limb.whole and all(
            p.part != limb.whole and p.part != s.part for p in moves[-1][2]
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


# --- head and chest ------------------------------------------------------------
def _direction_track(symbols, part, frame, T, eff):
    """(T,3) body-frame direction of a rigid segment (head, chest); rest = up."""
    d = np.tile(_Z, (T, 1))
    for s in (x for x in symbols if x.part == part):
        f0, f1 = frame(s.start), frame(s.end)
        da, db = d[min(f0, T - 1)].copy(), canonical_vector(s.direction, s.level)
        n = np.arange(f0 + 1, f1 + 1)
        d[n] = _slerp_dirs(da, db, progress((n - f0) / max(f1 - f0, 1), eff.time, eff.weight))
        d[f1 + 1 :] = db
    return d


def _trunk_angles(d, body: Body):
    """Waist and chest Euler angles (T,3) each so that waist→neck points along `d`.

    Both joints turn about the same horizontal axis, the waist taking two
    thirds; the total tilt is found by bisection on the clipped pose so the
    extremes are respected.  Held directions are solved once.
    """
    T = d.shape[0]
    ew, ec = np.zeros((T, 3)), np.zeros((T, 3))
    tilted = d[:, 2] < 1.0 - 1e-12
    if not np.any(tilted):
        return ew, ec
    uniq, inverse = np.unique(np.round(d[tilted], 12), axis=0, return_inverse=True)
    iw, ic = joint_index("waist"), joint_index("chest")
    lw, lc = body.limits[iw], body.limits[ic]
    o1, o2 = body.offsets[ic], body.offsets[joint_index("neck")]
    axis = _cross(_Z, uniq)
    # Straight down has no tilt axis: bow forward (a turn about −x).
    axis[np.linalg.norm(axis, axis=-1) < 1e-9] = [-1.0, 0.0, 0.0]
    axis = _unit(axis)
    target = np.arccos(np.clip(uniq[:, 2], -1, 1))

    def pose(phi):
        # The trunk's extremes lie within the principal Euler ranges.
        w = np.clip(matrix_to_euler(_axis_angle(axis, phi * 2 / 3)), lw[:, 0], lw[:, 1])
        c = np.clip(matrix_to_euler(_axis_angle(axis, phi / 3)), lc[:, 0], lc[:, 1])
        return w, c

    lo, hi = np.zeros(len(uniq)), np.full(len(uniq), np.pi)
    for _ in range(22):
        mid = 0.5 * (lo + hi)
        w, c = pose(mid)
        Rw = euler_to_matrix(w)
        v = Rw @ o1 + (Rw @ euler_to_matrix(c)) @ o2
        low = np.arccos(np.clip(v[:, 2] / np.linalg.norm(v, axis=-1), -1, 1)) < target
        lo, hi = np.where(low, mid, lo), np.where(low, hi, mid)
    w, c = pose(0.5 * (lo + hi))
    ew[tilted], ec[tilted] = w[inverse.ravel()], c[inverse.ravel()]
    return ew, ec


# --- supports --------------------------------------------------------------------
def _foot_events(score: Score, foot: str):
    """Support symbols naming `foot` and gesture symbols of its leg, in time order."""
    leg = {f"{foot}_leg", f"{foot}_thigh", f"{foot}_shin"}
    sup = [s for s in score.symbols if s.part in _SUPPORT_FEET and foot in _SUPPORT_FEET[s.part]]
    ges = [s for s in score.symbols if s.part in leg]
    for a, b in zip(sup, sup[1:]):
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
    return sup, ges


def _planted_after(sup, ges, beat) -> bool:
    """Whether a foot bears weight just after `beat`.

    Feet start planted; a gesture of the leg frees the foot from its start, a
    support symbol plants it at its end; at a tie the gesture wins.
    """
    effects = [(s.end, 0, True) for s in sup if s.end <= beat]
    effects += [(g.start, 1, False) for g in ges if g.start <= beat]
    return max(effects)[2] if effects else True


def _foot_progress(tau, eff: Effort, arrive: float = FOOT_ARRIVAL):
    """Progress of a stepping or landing foot (or the weight) over frames at `tau` (n,).

    Effort logistic, brought to rest (smoothstep) by τ = `arrive` and at the
    latest one frame before the symbol's end, so the feet read as supporting
    on its end frame.
    """
    tau = np.asarray(tau, float)
    arrive = min(arrive, 1.0 - 1.0 / max(len(tau), 1)) if len(tau) > 1 else 1.0
    s = progress(np.minimum(tau / max(arrive, 1e-9), 1.0), eff.time, eff.weight)
    return s * s * (3.0 - 2.0 * s)


def _weight_feet(sups, events, beat) -> list:
    """Feet bearing the weight just after `beat`.

    Those named by the support symbols in force at `beat` (begun before it,
    not yet ended), less feet whose leg starts a gesture by then; with no
    support symbol in force, every planted foot.
    """
    named = {f for s in sups if s.start < beat <= s.end for f in _SUPPORT_FEET[s.part]}
    if not named:
        return [f for f in ("right", "left") if _planted_after(*events[f], beat)]
    return [f for f in ("right", "left") if f in named and _planted_after(*events[f], beat)]


class _Support:
    """Root trajectory and foot targets implied by the support symbols."""

    def __init__(self, score: Score, frame, T: int, eff: Effort, body: Body):
        self.body, self.T, self.eff, self.frame = body, T, eff, frame
        self.limbs = {f: _Limb(f"{f}_leg", body) for f in ("right", "left")}
        self.hip_off = {f: body.offsets[joint_index(f"{f}_hip")] for f in ("right", "left")}
        self.ankle0 = body.rest[joint_index("right_ankle")][2]
        self.toe0 = body.rest[joint_index("right_toe")][2]
        toe = body.offsets[joint_index("right_toe")]
        pitch = -np.radians(RELEVE_DEG)
        self.rise = toe[2] - (_rot_x(pitch) @ toe)[2]
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
        self._plan(score)

    def _leg_length(self, level):
        limb = self.limbs["right"]
        return float(limb.radius(np.radians(PLIE_BEND_DEG) if level == "low" else 0.0))

    def _plan(self, score: Score):
        frame, T, body = self.frame, self.T, self.body
        xy = {f: body.rest[joint_index(f"{f}_ankle")][:2].copy() for f in ("right", "left")}
        level = {f: "middle" for f in ("right", "left")}
        sups = sorted((s for s in score.symbols if s.is_support), key=lambda s: (s.end, s.start))
        for s in sups:
            if s.part == "support" and s.direction != "place":
                raise SyntheticError(
                    f"support at beat {s.start}: a step on both feet ({s.direction}) is not supported; "
                    "notate right_support / left_support steps instead"
                )
        last_key = 0
        for s in sups:
            f0, f1 = frame(s.start), frame(s.end)
            n = np.arange(f0 + 1, f1 + 1)
            tau = (n - f0) / max(f1 - f0, 1)
            # The foot arrives (and comes to rest) within the first part of
            # the symbol; the transfer of weight takes the whole of it.
            sf = _foot_progress(tau, self.eff)
            for foot in _SUPPORT_FEET[s.part]:
                sup, ges = self.events[foot]
                planted = _planted_after(sup, ges, s.start)
                base = xy[foot] if planted else self.root[f0, :2] + self.hip_off[foot][:2]
                target = base.copy()
                if s.direction != "place":
                    target = base + STEP_LENGTH * body.height * canonical_vector(s.direction, "middle")[:2]
                za, zb = self.ankle[foot][f0, 2], self.level_z[s.level]
                pa, pb = self.pitch[foot][f0], self.level_pitch[s.level]
                a = self.ankle[foot]
                a[n, :2] = base + sf[:, None] * (target - base)
                a[n, 2] = za + sf * (zb - za)
                if s.direction != "place" and planted:
                    a[n, 2] += STEP_LIFT * body.height * np.sin(np.pi * sf)
                self.pitch[foot][n] = pa + sf * (pb - pa)
                if not planted:
                    a[n] = [target[0], target[1], zb]
                    self.pitch[foot][n] = pb
                    self.landing[foot][n] = True
                    self.floor[foot][f0 + 1 : f1 + 1] = True
                a[f1 + 1 :] = [target[0], target[1], zb]
                self.pitch[foot][f1 + 1 :] = pb
                xy[foot], level[foot] = target, s.level
            # Weight: the pelvis ends over the mean of the weight-bearing feet,
            # as high as their legs (at their levels) allow.
            feet = _weight_feet(sups, self.events, s.end)
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
            fa = max(f0, last_key)
            m = np.arange(fa + 1, f1 + 1)
            if f1 > fa:
                # The weight settles a frame before the end (a step: with
                # the foot, which can only touch down on a straight leg once
                # the pelvis is over it), so the feet are still on the end frame.
                tau = (m - fa) / (f1 - fa)
                sr = _foot_progress(tau, self.eff, FOOT_ARRIVAL if s.direction != "place" else 1.0)
                ra = self.root[fa].copy()
                self.root[m] = ra + sr[:, None] * (key - ra)
            self.root[f1:] = key
            last_key = max(last_key, f1)
        # Gesturing frames: from a gesture's start to the next support's start.
        for foot in ("right", "left"):
            sup, ges = self.events[foot]
            for g in ges:
                nxt = min((x.start for x in sup if x.start >= g.end), default=None)
                stop = T if nxt is None else frame(nxt) + 1
                self.floor[foot][frame(g.start) + 1 : stop] = False

    def ik(self, foot: str, ankle_pos=None, foot_R=None, frames=slice(None)):
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
        foot_R = _rot_x(self.pitch[foot][frames]) if foot_R is None else foot_R
        ja = joint_index(f"{foot}_ankle")
        lim = self.body.limits[ja]
        toe = self.body.offsets[joint_index(f"{foot}_toe")]
        for _ in range(4):
            v = ankle_pos - hip
            l = np.linalg.norm(v, axis=-1)
            beta = limb.bend_for_radius(np.minimum(l, limb.reach))
            Q = limb.upper_frame(limb.swing(v / l[:, None]), beta)
            shin = Q @ _rot_x(limb.middle_angle(beta))
            ankle = np.clip(euler_near(shin.transpose(0, 2, 1) @ foot_R, 0.0, lim), lim[:, 0], lim[:, 1])
            # Past the ankle's extremes (a plié with the feet far apart) the
            # foot cannot stay flat: the heel lifts so the toe stays on the floor.
            deficit = self.toe0 - (ankle_pos + (shin @ euler_to_matrix(ankle)) @ toe)[:, 2]
            if not np.any(deficit > 1e-6):
                break
            ankle_pos[:, 2] += np.maximum(deficit, 0.0)
        return Q, beta, ankle


def _leg_tracks(sup: _Support, symbols, frame, T: int, eff: Effort):
    """Final leg poses: floor-driven where planted, gestures elsewhere."""
    out = {}
    for foot in ("right", "left"):
        limb = sup.limbs[foot]
        Q, beta, ankle = sup.ik(foot)
        floor, landing = sup.floor[foot], sup.landing[foot]
        Qg, bg = Q.copy(), beta.copy()
        ankle_g = ankle.copy()
        for f0, f1, syms in _group_moves(limb, symbols, frame, T):
            stop = f1 + 1 + int(np.argmax(floor[f1 + 1 :])) if np.any(floor[f1 + 1 :]) else T
            a0 = ankle_g[f0].copy()
            s = _apply_move(limb, Qg, bg, f0, f1, syms, eff, stop)
            ankle_g[f0 + 1 : f1 + 1] = a0 * (1.0 - s)[:, None]
            ankle_g[f1 + 1 : stop] = 0.0
        # Landing: the ankle travels in the world from where the gesture left
        # it to its floor target while the foot turns flat (faster, so the
        # toe does not catch the floor); the leg follows by IK.
        idx = np.flatnonzero(landing)
        hip = sup.root + sup.hip_off[foot]
        for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if idx.size else []:
            g = run[0] - 1
            w = _foot_progress(np.arange(1, run.size + 1) / run.size, eff)
            shin_g = Qg[g] @ _rot_x(limb.middle_angle(bg[g]))
            a_g = hip[g] + Qg[g] @ sup.body.offsets[limb.joints[1]] + shin_g @ sup.body.offsets[limb.joints[2]]
            F_g = shin_g @ euler_to_matrix(ankle_g[g])
            target = sup.ankle[foot][run]
            wo = np.minimum(1.0, 1.5 * w)
            F = _slerp_frames(F_g, _rot_x(sup.pitch[foot][run[-1]]), wo * wo * (3.0 - 2.0 * wo))
            Q[run], beta[run], ankle[run] = sup.ik(foot, a_g + w[:, None] * (target - a_g), F, run)
        gest = ~floor
        Q[gest], beta[gest], ankle[gest] = Qg[gest], bg[gest], ankle_g[gest]
        free = gest
        # The free foot stays above the floor (z = 0): the ankle no lower than
        # the sole's thickness (its standing height less the toe's), and the
        # toe above the floor too (a pitched foot reaches lower than its
        # ankle), by bending the knee.
        floor_z = np.full(T, sup.ankle0 - sup.toe0)
        Qf, bf = _keep_above_floor(limb, Q, beta, hip, floor_z, free)
        ja = limb.joints[2]
        lim = sup.body.limits[ja]
        for _ in range(20):
            deficit = -_toe(sup.body, foot, limb, Qf, bf, ankle, hip)[:, 2]
            low = free & (deficit > 1e-6)
            if not np.any(low):
                break
            # Near the floor the free foot flexes towards flat, and the knee
            # bends (which also tips the foot down: overshoot a little).
            shin = Qf[low] @ _rot_x(limb.middle_angle(bf[low]))
            flat = np.clip(euler_near(shin.transpose(0, 2, 1), 0.0, lim), lim[:, 0], lim[:, 1])
            ankle[low, 0] = np.maximum(ankle[low, 0], flat[:, 0])
            floor_z[low] += 2.0 * deficit[low] + 1e-4
            Qf, bf = _keep_above_floor(limb, Q, beta, hip, floor_z, free)
        out[f"{foot}_leg"] = (Qf, bf, ankle)
    return out


def _toe(body: Body, foot: str, limb: _Limb, Q, beta, ankle, hip):
    """(T,3) toe positions of a leg posed by hip frames `Q`, bend `beta`, ankle angles."""
    shin = Q @ _rot_x(limb.middle_angle(beta))
    knee = hip + Q @ body.offsets[joint_index(f"{foot}_knee")]
    ank = knee + shin @ body.offsets[joint_index(f"{foot}_ankle")]
    return ank + (shin @ euler_to_matrix(ankle)) @ body.offsets[joint_index(f"{foot}_toe")]


def _keep_above_floor(limb: _Limb, Q, beta, hip, floor_z, mask):
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


# --- the interpreter -----------------------------------------------------------
def interpret(score: Score, fps: float = 25.0, body: Body | None = None, effort: Effort | None = None) -> Motion:
    """Animate a score.

    Parameters
    ----------
    score : Score
        The notation; its tempo sets the timing.
    fps : float
        Frames per second of the motion (> 0).
    body : Body, optional
        The dancer; default ``Body()`` (1.70 m).
    effort : Effort, optional
        Overrides ``score.resolved_effort()`` (header effort, emotion preset,
        or neutral).

    Returns
    -------
    Motion
        ``round(score.duration × 60 / tempo × fps) + 1`` frames; frame 0 is
        the start pose.  ``motion.events`` is a tuple of
        ``(symbol, start_frame, end_frame)`` in score order.

    Raises
    ------
    SyntheticError
        If segments of one limb overlap in a way that cannot be combined, a
        leg is notated to gesture and support at once, or ``support`` carries
        a step direction.
    """
    fps = float(fps)
    if not (np.isfinite(fps) and fps > 0):
        raise SyntheticError(f"fps must be a positive number, got {fps!r}")
    if not isinstance(score, Score):
        raise SyntheticError(f"interpret needs a Score, got {type(score).__name__}")
    body = body or Body()
    eff = effort if effort is not None else score.resolved_effort()

    def frame(beat):
        return beat_frame(beat, score.tempo, fps)

    T = frame(score.duration) + 1
    symbols = score.symbols
    angles = np.zeros((T, len(body.rest), 3))

    # Trunk, then head: directions are in the body frame, joints below the chest.
    ew, ec = _trunk_angles(_direction_track(symbols, "chest", frame, T, eff), body)
    angles[:, joint_index("waist")] = ew
    angles[:, joint_index("chest")] = ec
    Rchest = euler_to_matrix(ew) @ euler_to_matrix(ec)
    RchestT = Rchest.transpose(0, 2, 1)
    head_d = _direction_track(symbols, "head", frame, T, eff)
    ineck = joint_index("neck")
    head_R = RchestT @ _rot_between(_Z, head_d, [1.0, 0.0, 0.0])
    angles[:, ineck] = euler_near(head_R, 0.0, body.limits[ineck])

    for name in ("right_arm", "left_arm"):
        limb = _Limb(name, body)
        Q, beta = np.tile(np.eye(3), (T, 1, 1)), np.zeros(T)
        for f0, f1, syms in _group_moves(limb, symbols, frame, T):
            _apply_move(limb, Q, beta, f0, f1, syms, eff, T)
        ja, jm, _ = limb.joints
        angles[:, ja] = euler_near(RchestT @ Q, 0.0, body.limits[ja])
        angles[:, jm, 0] = limb.middle_angle(beta)

    sup = _Support(score, frame, T, eff, body)
    for name, (Q, beta, ankle) in _leg_tracks(sup, symbols, frame, T, eff).items():
        limb = sup.limbs[name.split("_")[0]]
        ja, jm, jb = limb.joints
        angles[:, ja] = euler_near(Q, 0.0, body.limits[ja])  # the pelvis never rotates
        angles[:, jm, 0] = limb.middle_angle(beta)
        angles[:, jb] = ankle

    events = tuple((s, frame(s.start), frame(s.end)) for s in symbols)
    motion = Motion(fps, angles, sup.root, body, events)
    for sym, got in unreachable(motion):
        warnings.warn(
            f"{sym.part} {sym.direction} {sym.level} bend={sym.bend} at beat {sym.start} (frame "
            f"{frame(sym.end)}) is out of reach (joint extremes or floor); the dancer gets to "
            f"{got[0]} {got[1]} bend={got[2]}",
            UnreachableWarning,
            stacklevel=2,
        )
    return motion


def unreachable(motion: Motion) -> list:
    """Gesture events whose end pose does not read back as their symbol.

    Parameters
    ----------
    motion : Motion
        With ``events`` (as made by :func:`interpret`).

    Returns
    -------
    list of (Symbol, (direction, level, bend))
        What the pose at each such event's end frame quantises to (DESIGN.md
        thresholds); empty when every gesture symbol was reached.
    """
    gest = [(s, f1) for s, _, f1 in motion.events if not s.is_support]
    if not gest:
        return []
    frames = np.array([f1 for _, f1 in gest])
    Jf = forward_kinematics(motion.angles[frames], motion.root[frames], motion.body)
    frame = body_frame(Jf)
    out = []
    for i, (sym, f1) in enumerate(gest):
        a, b = PART_SEGMENTS[sym.part]
        v = segment_vectors(Jf[i : i + 1], a, b, frame[i : i + 1])[0]
        d, lv = classify(v)
        bend = sym.bend
        if sym.part in PART_MIDDLE_JOINT:
            m = joint_index(PART_MIDDLE_JOINT[sym.part])
            bend = int(bend_degree(bend_angle(Jf[i, joint_index(a)], Jf[i, m], Jf[i, joint_index(b)])))
        if (d, lv, bend) != (sym.direction, sym.level, sym.bend):
            out.append((sym, (d, lv, bend)))
    return out
