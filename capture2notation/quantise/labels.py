"""Per-frame Labanotation labels: direction, level and bend of every part.

Every gesture part of :data:`~capture2notation.notation.PART_SEGMENTS` is
classified with the shared thresholds of DESIGN.md
(:func:`~capture2notation.notation.directions.classify_indices`), in the body
frame (:func:`~capture2notation.body.body_frame`).  Supports follow DESIGN.md:
a foot supports when it is within 3 cm of the floor and slower than
0.2 m/s; its level is low when the knee bends more than 30° (plié), high when
the heel is raised (relevé), else middle.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace

import numpy as np

from ..atomic import write_text
from ..body import JOINTS, Body, body_frame, joint_index, key_frame
from ..errors import QuantiseError
from ..notation.directions import bend_angle, bend_degree, classify_indices
from ..notation.model import DIRECTIONS, LEVELS, PART_MIDDLE_JOINT, PART_SEGMENTS, SUPPORT_PARTS

__all__ = [
    "DIRECTION_NAMES",
    "LABEL_PARTS",
    "PLIE_DEG",
    "RELEVE_DEG",
    "SUPPORT_HEIGHT_M",
    "SUPPORT_SPEED_MS",
    "FrameLabels",
    "flat_foot_pitch",
    "foot_points",
    "label_frames",
    "support_frames",
    "with_supports",
    "write_labels_csv",
]

#: Direction names in the index order of ``classify_indices`` (8 = place).
DIRECTION_NAMES: tuple[str, ...] = tuple(DIRECTIONS)
PLACE = DIRECTION_NAMES.index("place")
MIDDLE = LEVELS.index("middle")
#: Parts labelled per frame: every gesture part, then the supports.
LABEL_PARTS: tuple[str, ...] = tuple(PART_SEGMENTS) + SUPPORT_PARTS

SUPPORT_HEIGHT_M = 0.03
SUPPORT_SPEED_MS = 0.2
PLIE_DEG = 30.0
#: The heel counts as raised when the foot (ankle → toe) points this much
#: further below horizontal than at rest.
RELEVE_DEG = 15.0

_SIDES = ("right", "left")


@dataclass(frozen=True)
class FrameLabels:
    """Labels of every part at every frame.

    Attributes
    ----------
    times : (T,) ndarray
        Seconds.
    parts : tuple of str
        :data:`LABEL_PARTS`.
    direction : (T, P) ndarray of int
        Index into :data:`DIRECTION_NAMES`; −1 where undefined (missing
        joints, or a support part whose feet do not support).
    level : (T, P) ndarray of int
        Index into ``LEVELS``; −1 where undefined.
    bend : (T, P) ndarray of int
        Bend degree 0–6 for whole arms and legs; −1 elsewhere or when missing.
    vectors : (T, P, 3) ndarray
        Unit body-frame vectors of gesture parts (right, forward, up); NaN for
        supports and missing joints.
    bend_deg : (T, P) ndarray
        Bend β in degrees for whole arms and legs, NaN elsewhere.
    supporting : (T, 2) ndarray of bool
        Right and left foot supporting.
    support_level : (T, 2) ndarray of int
        Level index of each foot's support, −1 when the foot does not support.
    """

    times: np.ndarray
    parts: tuple
    direction: np.ndarray
    level: np.ndarray
    bend: np.ndarray
    vectors: np.ndarray
    bend_deg: np.ndarray
    supporting: np.ndarray
    support_level: np.ndarray

    def index(self, part: str) -> int:
        """Column of `part`."""
        try:
            return self.parts.index(part)
        except ValueError:
            raise QuantiseError(f"no labels for part {part!r}; expected one of {' '.join(self.parts)}") from None


def _rest_foot_pitch_deg(body: Body) -> float:
    """Pitch of ankle → toe below horizontal at rest, degrees (proportional, so height-free)."""
    d = body.rest[joint_index("right_toe")] - body.rest[joint_index("right_ankle")]
    return float(np.degrees(np.arctan2(-d[2], np.hypot(d[0], d[1]))))


def flat_foot_pitch(joints: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """Pitch of each foot when flat on the floor, measured from the motion itself, degrees.

    A fitted foot seen from the front is pitched 10-20° further down than
    the body model's rest pose (its depth is barely observable), which
    read every standing frame of a capture as relevé.  A flat foot is the
    least pitched of a foot's contacts (a relevé only raises the heel), and
    every phrase starts standing flat (DESIGN.md), so the lower decile of
    the pitch over the frames in contact is the foot's own flat pitch.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    contact : (T, 2) ndarray of bool
        Right, left foot on the floor.

    Returns
    -------
    (2,) ndarray
        Right, left; the rest pitch of :class:`~capture2notation.body.Body`
        for a foot never in contact.
    """
    out = np.full(2, _rest_foot_pitch_deg(Body()))
    for k, side in enumerate(_SIDES):
        p = _foot_pitch_deg(joints, side)[np.asarray(contact)[:, k]]
        p = p[np.isfinite(p)]
        if p.size:
            out[k] = float(np.percentile(p, 10))
    return out


def _foot_pitch_deg(joints: np.ndarray, side: str) -> np.ndarray:
    """(T,) pitch of ankle → toe below horizontal, degrees."""
    d = joints[:, joint_index(f"{side}_toe")] - joints[:, joint_index(f"{side}_ankle")]
    return np.degrees(np.arctan2(-d[:, 2], np.hypot(d[:, 0], d[:, 1])))


def foot_points(joints: np.ndarray) -> tuple[list, list]:
    """Each foot's (right, left) lowest point and centre.

    The lowest point is the toe (flat or on demi-pointe); the ankle stands
    in for it when the toe is missing (``fmin`` skips NaN).

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.

    Returns
    -------
    low : list of two (T,) ndarray
        Height of the lowest point, metres.
    mid : list of two (T, 3) ndarray
        Midpoint of ankle and toe.
    """
    low, mid = [], []
    for side in _SIDES:
        ankle, toe = joints[:, joint_index(f"{side}_ankle")], joints[:, joint_index(f"{side}_toe")]
        low.append(np.fmin(toe[:, 2], ankle[:, 2]))
        mid.append(0.5 * (ankle + toe))
    return low, mid


def support_frames(
    joints: np.ndarray, fps: float, floor: float = 0.0, flat_pitch=None, contact=None
) -> tuple[np.ndarray, np.ndarray]:
    """Which feet support, and at which level, at every frame.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    fps : float
        Frames per second (for the foot speed).
    floor : float
        Floor height, metres.
    flat_pitch : (2,) array_like, optional
        Pitch (degrees) of the right and left foot standing flat, e.g. from
        :func:`flat_foot_pitch`; the body model's rest pitch by default.
        The heel is raised when a foot pitches :data:`RELEVE_DEG` beyond it.
    contact : (T, 2) array_like of bool, optional
        Right, left foot on the floor, decided elsewhere (measured motion:
        :func:`~capture2notation.quantise.contact.decode_contacts`); by
        default DESIGN.md's per-frame rule (within :data:`SUPPORT_HEIGHT_M`
        of the floor, slower than :data:`SUPPORT_SPEED_MS`).

    Returns
    -------
    supporting : (T, 2) ndarray of bool
        Right, left.
    level : (T, 2) ndarray of int
        Index into ``LEVELS`` (−1 where the foot does not support).
    """
    joints = np.asarray(joints, dtype=float)
    T = joints.shape[0]
    supporting = np.zeros((T, 2), bool)
    level = np.full((T, 2), -1, int)
    flat = np.full(2, _rest_foot_pitch_deg(Body())) if flat_pitch is None else np.asarray(flat_pitch, float)
    lows, mids = foot_points(joints)
    for k, side in enumerate(_SIDES):
        ankle = joints[:, joint_index(f"{side}_ankle")]
        low, mid = lows[k] - floor, mids[k]
        speed = np.full(T, np.nan)
        if T > 1:
            step = np.linalg.norm(np.diff(mid, axis=0), axis=-1) * fps
            # Central speed where possible: the slower of the two adjacent steps
            # so the first and last frames of a stance are not dropped.
            speed[:-1] = step
            speed[1:] = np.fmin(speed[1:], step)
            # Nothing follows the last frame: a foot that reaches the floor
            # there has landed (a movement arrives at its last frame).
            speed[-1] = 0.0
        else:
            speed[:] = 0.0
        sup = (
            (low < SUPPORT_HEIGHT_M) & (speed < SUPPORT_SPEED_MS)
            if contact is None
            else np.asarray(contact, bool)[:, k]
        )
        knee_bend = bend_angle(joints[:, joint_index(f"{side}_hip")], joints[:, joint_index(f"{side}_knee")], ankle)
        pitch = _foot_pitch_deg(joints, side)
        lev = np.full(T, MIDDLE)
        lev = np.where(pitch > flat[k] + RELEVE_DEG, LEVELS.index("high"), lev)
        lev = np.where(knee_bend > PLIE_DEG, LEVELS.index("low"), lev)
        supporting[:, k] = sup
        level[:, k] = np.where(sup, lev, -1)
    return supporting, level


#: Parts read in the body cross of axes under the body key (DESIGN.md, "Cross
#: of axes"): the arms and the head, as LabanotationSuite reads them; the
#: chest and the legs keep the standard cross (the chest's own tilt is what
#: its symbol writes; the legs are read from the hips).
BODY_KEY_PARTS = frozenset(
    ("right_arm", "left_arm", "right_upper_arm", "right_forearm", "left_upper_arm", "left_forearm", "head")
)


def label_frames(joints: np.ndarray, fps: float, floor: float = 0.0, axes: str = "standard") -> FrameLabels:
    """Label every part at every frame with the DESIGN.md thresholds.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joint positions, metres, z up (NaN where missing).
    fps : float
        Frames per second (> 0).
    floor : float
        Floor height in metres.
    axes : str
        ``"standard"``: every part in the standard cross (:func:`body_frame`,
        upright, turning with the hips); ``"body"``: the parts of
        :data:`BODY_KEY_PARTS` in the body cross (:func:`body_cross`, along
        the torso).

    Returns
    -------
    FrameLabels

    Notes
    -----
    Support parts: ``right_support`` / ``left_support`` are ``place`` at
    their foot's level while that foot supports; ``support`` is ``place``
    when both feet support at the same level.
    """
    joints = np.asarray(joints, dtype=float)
    if joints.ndim != 3 or joints.shape[1:] != (len(JOINTS), 3):
        raise QuantiseError(f"joints must have shape (T, {len(JOINTS)}, 3), got {joints.shape}")
    if not (np.isfinite(fps) and fps > 0):
        raise QuantiseError(f"fps must be a positive number, got {fps!r}")
    T = joints.shape[0]
    P = len(LABEL_PARTS)
    frame = body_frame(joints)
    cross = key_frame(joints, axes) if axes != "standard" else frame
    vectors = np.full((T, P, 3), np.nan)
    bend_deg = np.full((T, P), np.nan)
    for p, part in enumerate(PART_SEGMENTS):
        a, b = PART_SEGMENTS[part]
        v = joints[:, joint_index(b)] - joints[:, joint_index(a)]
        n = np.linalg.norm(v, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            v = np.where(n > 1e-12, v / n, np.nan)
        vectors[:, p] = np.einsum("tij,tj->ti", cross if part in BODY_KEY_PARTS else frame, v)
        if part in PART_MIDDLE_JOINT:
            m = PART_MIDDLE_JOINT[part]
            bend_deg[:, p] = bend_angle(joints[:, joint_index(a)], joints[:, joint_index(m)], joints[:, joint_index(b)])
    direction, level = classify_indices(vectors)
    bend = np.where(np.isnan(bend_deg), -1, bend_degree(bend_deg))
    supporting, sup_level = support_frames(joints, fps, floor)
    times = np.arange(T) / float(fps)
    labels = FrameLabels(
        times=times,
        parts=LABEL_PARTS,
        direction=direction.astype(int),
        level=level.astype(int),
        bend=bend.astype(int),
        vectors=vectors,
        bend_deg=bend_deg,
        supporting=supporting,
        support_level=sup_level,
    )
    return with_supports(labels, supporting, sup_level)


def with_supports(labels: FrameLabels, supporting: np.ndarray, level: np.ndarray) -> FrameLabels:
    """`labels` with other feet contacts (e.g. from smoothed joints) and their support columns.

    Parameters
    ----------
    labels : FrameLabels
    supporting : (T, 2) ndarray of bool
        Right, left foot supporting.
    level : (T, 2) ndarray of int
        Index into ``LEVELS`` of each foot's support, −1 where it does not support.

    Returns
    -------
    FrameLabels
        ``right_support`` / ``left_support`` are ``place`` at their foot's
        level while it supports; ``support`` is ``place`` when both feet
        support at the same level.
    """
    direction, lev = labels.direction.copy(), labels.level.copy()
    g = len(PART_SEGMENTS)
    for k, part in enumerate(("right_support", "left_support")):
        c = g + SUPPORT_PARTS.index(part)
        direction[:, c] = np.where(supporting[:, k], PLACE, -1)
        lev[:, c] = np.where(supporting[:, k], level[:, k], -1)
    both = supporting.all(axis=1) & (level[:, 0] == level[:, 1])
    c = g + SUPPORT_PARTS.index("support")
    direction[:, c] = np.where(both, PLACE, -1)
    lev[:, c] = np.where(both, level[:, 0], -1)
    return replace(
        labels,
        direction=direction,
        level=lev,
        supporting=np.asarray(supporting, bool),
        support_level=np.where(supporting, level, -1).astype(int),
    )


def labels_csv_text(labels: FrameLabels) -> str:
    """The ``labels.csv`` text: one row per frame and part.

    Columns ``frame, time, part, direction, level, bend``; undefined labels
    are empty cells, ``bend`` is empty for parts that carry none.
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("frame", "time", "part", "direction", "level", "bend"))
    T, P = labels.direction.shape
    dnames = np.array(DIRECTION_NAMES + ("",), dtype=object)
    lnames = np.array(LEVELS + ("",), dtype=object)
    # Index −1 picks the trailing empty name.
    d = dnames[labels.direction]
    lv = lnames[labels.level]
    for t in range(T):
        time = f"{labels.times[t]:.4f}"
        for p in range(P):
            b = labels.bend[t, p]
            w.writerow((t, time, labels.parts[p], d[t, p], lv[t, p], "" if b < 0 else int(b)))
    return buf.getvalue()


def write_labels_csv(labels: FrameLabels, path) -> None:
    """Atomically write :func:`labels_csv_text` to `path`."""
    write_text(path, labels_csv_text(labels))
