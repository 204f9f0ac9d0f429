"""Reach: which symbols the dancer cannot perform within its joint extremes.

The check reads the dancer's joints back with the DESIGN.md thresholds (the
same per-frame quantisation a clean render must survive) and reports, each
as an :class:`Unreached` naming the symbol and, where one is to blame, the
joint extreme:

* ``"end"`` — a symbol's pose at its end frame does not read back as the
  symbol (a gesture's direction, level or bend; a support's feet not on the
  floor, not at rest or at the wrong level);
* ``"path"`` — the movement towards a symbol asked a joint for more than its
  extreme on the way (the limb would stop short, then jump), or a foot
  meant to stay on the floor through a change of support level moves too
  fast to read as supporting;
* ``"hold"`` — head, chest or a whole arm, not moving, no longer reads as its
  last symbol (or the start pose): the part is carried off by another's
  movement, e.g. an upright head by a chest bowed further than the neck can
  bend back.

:func:`~synthetic.interpret.interpret` warns about each with an
:class:`UnreachableWarning`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capture2notation.body import JOINTS, body_frame, forward_kinematics, joint_index, key_frame, segment_vectors
from capture2notation.notation.directions import bend_angle, bend_degree, classify_indices
from capture2notation.notation.model import DIRECTIONS, LEVELS, PART_MIDDLE_JOINT, PART_SEGMENTS, Symbol

from .extremes import CLIP_TOL, PART_JOINTS
from .motion import Motion

_PLACE = list(DIRECTIONS).index("place")

__all__ = ["UnreachableWarning", "Unreached", "reach_report", "unreachable"]

_FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}
#: Parts whose holds are checked (legs are driven by the supports between gestures).
_HOLD_PARTS = ("head", "chest", "right_arm", "left_arm")
#: DESIGN.md support conditions: height (m) and speed (m/s) of a supporting
#: foot, knee bend of a plié (degrees); a heel is raised when the foot
#: points this much (degrees) further down than at rest.
_SUPPORT_HEIGHT, _SUPPORT_SPEED, _PLIE_DEG, _RELEVE_PITCH_DEG = 0.03, 0.2, 30.0, 15.0
_AXES = ("rx", "ry", "rz")


class UnreachableWarning(UserWarning):
    """A symbol's pose lies beyond the joint extremes (or the floor)."""


@dataclass(frozen=True)
class Unreached:
    """One symbol (or hold) the dancer does not perform as written.

    Attributes
    ----------
    symbol : Symbol or None
        The symbol concerned (for a hold: the symbol held; None for the
        start pose).
    part : str
        Its part.
    kind : str
        ``"end"``, ``"path"`` or ``"hold"`` (module docstring).
    frame : int
        First frame where it shows.
    got : tuple
        What the pose reads as there: ``(direction, level, bend)``, or for a
        support ``("none", "", 0)`` when a named foot does not support.
    limit : str
        The joint extreme to blame, e.g. ``"neck rx >= -70°: asked -95.0°"``,
        or ``""`` when none was hit (the floor, or another part's pose).
    """

    symbol: Symbol | None
    part: str
    kind: str
    frame: int
    got: tuple
    limit: str = ""

    def message(self) -> str:
        """One line naming the symbol (start, part, direction, level) and the limit."""
        s = self.symbol
        what_sym = (
            f"{s.part} {s.direction}"
            + (f" {s.level} bend={s.bend}" if s.level is not None else "")
            + (f" amount={s.amount}" if s.amount is not None else "")
            + f" at beat {s.start}"
            if s is not None
            else f"{self.part} {_START[self.part]} (the start pose)"
        )
        what = {"end": "is out of reach", "path": "is out of reach on the way", "hold": "cannot be held"}[self.kind]
        got = f": the dancer gets to {' '.join(str(x) for x in self.got)}" if self.got else ""
        why = f"; limit: {self.limit}" if self.limit else "; no joint extreme hit (floor or another part's pose)"
        return f"{what_sym} {what} (frame {self.frame}){got}{why}"


#: The start pose of DESIGN.md, as read back (direction, level).
_START = {"head": "place high", "chest": "place high", "right_arm": "place low", "left_arm": "place low"}


#: Parts read in the body cross of axes when a score is keyed to it.
BODY_KEY_PARTS = frozenset(
    {"head", "right_arm", "left_arm", "right_upper_arm", "right_forearm", "left_upper_arm", "left_forearm"}
)
#: Largest miss of a turn's written front at its end frame, degrees.
FRONT_TOL_DEG = 1.0


def _readings(J: np.ndarray, part: str, axes: str = "standard"):
    """(T,) direction index, level index and bend degree of a gesture part."""
    a, b = PART_SEGMENTS[part]
    frame = key_frame(J, axes) if part in BODY_KEY_PARTS else body_frame(J)
    d, lv = classify_indices(segment_vectors(J, a, b, frame))
    bend = np.zeros(len(J), int)
    if part in PART_MIDDLE_JOINT:
        m = joint_index(PART_MIDDLE_JOINT[part])
        bend = np.asarray(bend_degree(bend_angle(J[:, joint_index(a)], J[:, m], J[:, joint_index(b)])), int)
    return d, lv, bend


def _code(sym: Symbol):
    return list(DIRECTIONS).index(sym.direction), LEVELS.index(sym.level), sym.bend


def _name(d, lv, bend):
    return (list(DIRECTIONS)[d] if d >= 0 else "none", LEVELS[lv] if lv >= 0 else "", int(bend))


def _support_reading(J: np.ndarray, fps: float, foot: str, body):
    """(T,) supporting flag and level index of a foot (DESIGN.md conditions)."""
    ankle, toe = J[:, joint_index(f"{foot}_ankle")], J[:, joint_index(f"{foot}_toe")]
    low = np.minimum(ankle[:, 2], toe[:, 2])
    mid = 0.5 * (ankle + toe)
    step = np.linalg.norm(np.diff(mid, axis=0), axis=-1) * fps
    # Speed at a frame: the slower of the steps into and out of it (a foot
    # that comes to rest on a frame is at rest there); none after the last.
    speed = np.minimum(np.r_[np.inf, step], np.r_[step, 0.0])
    sup = (low < _SUPPORT_HEIGHT) & (speed < _SUPPORT_SPEED)
    knee = bend_angle(J[:, joint_index(f"{foot}_hip")], J[:, joint_index(f"{foot}_knee")], ankle)
    rest = body.rest[joint_index(f"{foot}_toe")] - body.rest[joint_index(f"{foot}_ankle")]
    rest_pitch = np.degrees(np.arctan2(-rest[2], np.hypot(rest[0], rest[1])))
    d = toe - ankle
    pitch = np.degrees(np.arctan2(-d[:, 2], np.hypot(d[:, 0], d[:, 1])))
    level = np.where(knee > _PLIE_DEG, 2, np.where(pitch > rest_pitch + _RELEVE_PITCH_DEG, 0, 1))
    return sup, level


def _clip(raw, clipped, joints, frames):
    """(n,) largest clipping (radians) among `joints` at each of `frames`."""
    idx = [joint_index(n) for n in joints]
    return np.abs(raw[frames][:, idx] - clipped[frames][:, idx]).max(axis=(1, 2))


def _limit_hit(raw, clipped, limits, joints, frames) -> str:
    """The worst extreme among `joints` clipped on `frames`, as text ('' if none)."""
    if raw is None or len(frames) == 0:
        return ""
    best, text = CLIP_TOL, ""
    for name in joints:
        j = joint_index(name)
        over = raw[frames, j] - clipped[frames, j]
        k = np.unravel_index(np.argmax(np.abs(over)), over.shape)
        if abs(over[k]) > best:
            best = abs(over[k])
            side = ">=" if over[k] < 0 else "<="
            bound = limits[j, k[1], 0 if over[k] < 0 else 1]
            text = (
                f"{JOINTS[j]} {_AXES[k[1]]} {side} {np.degrees(bound):.0f}°: "
                f"asked {np.degrees(raw[frames[k[0]], j, k[1]]):.1f}°"
            )
    if not text:
        # Nothing clipped: a joint the interpreter itself held at an extreme
        # (the trunk solves its tilt within them).
        for name in (n for n in joints if n in ("waist", "chest")):
            j = joint_index(name)
            at = np.abs(clipped[frames, j][..., None] - limits[j]) < 1e-6  # (n, 3, 2)
            if at.any():
                _, ax, side = np.argwhere(at)[0]
                return f"{JOINTS[j]} {_AXES[ax]} at its extreme {np.degrees(limits[j, ax, side]):.0f}°"
    return text


def reach_report(motion: Motion, raw_angles: np.ndarray | None = None, axes: str = "standard") -> list:
    """Everything the motion does not perform as its score says.

    Parameters
    ----------
    motion : Motion
        With ``events`` (as made by :func:`~synthetic.interpret.interpret`).
    raw_angles : (T, J, 3) ndarray, optional
        The angles asked for before the extremes were enforced; without them
        ``"path"`` problems are not found and no limit is named.
    axes : {"standard", "body"}
        The score's key: arms and head are read in the body cross for ``"body"``.

    Returns
    -------
    list of Unreached
        In event order; empty when every symbol is performed as written.
    """
    if not motion.events:
        return []
    J = forward_kinematics(motion.angles, motion.root, motion.body)
    limits, clipped = motion.body.limits, motion.angles
    out = []
    readings, feet = {}, {}
    front = None
    written = 0.0
    for sym, f0, f1 in motion.events:
        if sym.is_turn:
            # The front at the turn's end must be every turn written so far.
            front = motion.front if front is None else front
            written += float(sym.signed_amount) * 360.0
            got = front[min(f1, len(front) - 1)]
            if not abs(got - written) <= FRONT_TOL_DEG:
                out.append(Unreached(sym, sym.part, "end", f1, ("front", f"{got:.1f}°"), ""))
            continue
        if sym.is_air:
            # No foot may read as supporting strictly inside a flight.
            for foot in ("right", "left"):
                if foot not in feet:
                    feet[foot] = _support_reading(J, motion.fps, foot, motion.body)
            grounded = [f for f in ("right", "left") if feet[f][0][f0 + 1 : f1].any()]
            if grounded:
                f = f0 + 1 + int(np.argmax(feet[grounded[0]][0][f0 + 1 : f1]))
                out.append(Unreached(sym, sym.part, "path", f, (f"{grounded[0]}_foot", "on the floor", 0), ""))
            continue
        joints = PART_JOINTS[sym.part]
        if raw_angles is not None and f1 > f0 + 1:
            # On the way, the extremes may hold a joint back no more than at
            # the ends: more, and the limb stops short, then jumps.
            way = np.arange(f0 + 1, f1)
            c = _clip(raw_angles, clipped, joints, way)
            worst = int(np.argmax(c))
            if c[worst] > _clip(raw_angles, clipped, joints, [f0, f1]).max() + CLIP_TOL:
                hit = _limit_hit(raw_angles, clipped, limits, joints, way[worst : worst + 1])
                out.append(Unreached(sym, sym.part, "path", int(way[worst]), (), hit))
        if sym.is_support:
            for foot in _FEET[sym.part]:
                if foot not in feet:
                    feet[foot] = _support_reading(J, motion.fps, foot, motion.body)
                sup, lev = feet[foot]
                if sym.direction == "place" and sup[f0] and sup[f1] and not sup[f0 : f1 + 1].all():
                    # A foot that stays on the floor must read as supporting
                    # throughout: a heel dropped or raised too fast does not.
                    f = f0 + int(np.argmin(sup[f0 : f1 + 1]))
                    out.append(
                        Unreached(
                            sym,
                            sym.part,
                            "path",
                            f,
                            ("none", "", 0),
                            f"the {foot} foot moves faster than {_SUPPORT_SPEED} m/s "
                            "(DESIGN.md's support threshold); give the level change more time",
                        )
                    )
                    break
                if not sup[f1] or LEVELS[lev[f1]] != sym.level:
                    got = ("place", LEVELS[lev[f1]], 0) if sup[f1] else ("none", "", 0)
                    leg = PART_JOINTS[f"{foot}_support"]
                    out.append(
                        Unreached(sym, sym.part, "end", f1, got, _limit_hit(raw_angles, clipped, limits, leg, [f1]))
                    )
                    break
            continue
        if sym.part not in readings:
            readings[sym.part] = _readings(J, sym.part, axes)
        d, lv, bend = (r[f1] for r in readings[sym.part])
        if (d, lv, bend) != _code(sym):
            out.append(
                Unreached(
                    sym, sym.part, "end", f1, _name(d, lv, bend), _limit_hit(raw_angles, clipped, limits, joints, [f1])
                )
            )
    out += _holds(motion, J, raw_angles, readings, axes)
    return out


def _holds(motion: Motion, J, raw_angles, readings, axes: str = "standard") -> list:
    """Holds of head, chest and whole arms that the pose does not keep."""
    T = motion.n_frames
    out = []
    for part in _HOLD_PARTS:
        limb = part.rsplit("_", 1)[0] + "_" if part.endswith("_arm") else None
        own = [(s, f0, f1) for s, f0, f1 in motion.events if s.part == part]
        if limb is not None and any(s.part.startswith(limb) and s.part != part for s, _, _ in motion.events):
            continue  # segment symbols: the whole arm's reading is not notated
        moving = np.zeros(T, bool)
        held = np.full(T, -1)
        for i, (_s, f0, f1) in enumerate(own):
            moving[f0 + 1 : f1 + 1] = True  # the end frame is checked as an "end"
            held[f1:] = i
        if part not in readings:
            readings[part] = _readings(J, part, axes)
        d, lv, bend = readings[part]
        syms = [s for s, _, _ in own]
        for i in range(-1, len(syms)):
            sym = None if i < 0 else syms[i]
            frames = np.flatnonzero((held == i) & ~moving)
            code = _code(sym) if sym is not None else (_PLACE, LEVELS.index(_START[part].split()[1]), 0)
            bad = frames[
                (d[frames] != code[0])
                | (lv[frames] != code[1])
                | ((bend[frames] != code[2]) if part in PART_MIDDLE_JOINT else False)
            ]
            if bad.size:
                f = int(bad[0])
                hit = _limit_hit(raw_angles, motion.angles, motion.body.limits, PART_JOINTS[part], [f])
                out.append(Unreached(sym, part, "hold", f, _name(d[f], lv[f], bend[f]), hit))
    return out


def unreachable(motion: Motion, axes: str = "standard") -> list:
    """Symbols whose end pose does not read back as the symbol.

    Parameters
    ----------
    motion : Motion
        With ``events`` (as made by :func:`~synthetic.interpret.interpret`).
    axes : {"standard", "body"}
        The score's key.

    Returns
    -------
    list of (Symbol, (direction, level, bend))
        What the pose at each such event's end frame reads as (DESIGN.md
        thresholds; for a support whose foot does not support,
        ``("none", "", 0)``); empty when every symbol was reached.  See
        :func:`reach_report` for paths, holds and the limits to blame.
    """
    return [(u.symbol, u.got) for u in reach_report(motion, axes=axes) if u.kind == "end"]
