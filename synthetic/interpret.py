"""Interpreter: a notation :class:`Score` → a :class:`Motion` of the virtual dancer.

Semantics (``../shared/DESIGN.md``; Wolofsky 1974 ch. IV; Neagle 2005 ch. 5):

* Every gesture symbol sets the target direction of its segment — the
  canonical vector of (direction, level) in the body frame — and, for whole
  arms and legs, the bend of the elbow / knee (β = 30°·bend).  The movement
  begins at the symbol's start frame and arrives at its end frame
  (``seconds = beats × 60 / tempo``, frame = round(seconds × fps)); progress
  along the path is the Effort logistic ``s(τ)`` (time b, weight x0), Space
  modulating the reach mid-movement (:mod:`synthetic.limbs`).
* Head and chest directions are in the body frame (DESIGN.md: world up and
  the hips' right — Labanotation's standard cross of axes), not relative to
  the chest: the neck compensates a tilted chest (:mod:`synthetic.trunk`).
* Supports place the feet and carry the weight (:mod:`synthetic.supports`);
  a step or a landing foot touches down on the symbol's end frame and the
  weight arrives with it, so supports arrive at the end like gestures.
* Turns (``turn right|left amount=F``) change the front with the Effort
  progress over their span, pivoting about the supporting foot or feet, or
  about the pelvis in the air (:mod:`synthetic.turning`); every direction
  — limbs and steps — is relative to the current front.  Flight
  (``support air``) is a ballistic pelvis between take-off and touchdown,
  landing into the level of the support symbol that starts where it ends
  (:mod:`synthetic.flight`).
* The score's key: with ``axes: body``, arm and head directions are read in
  the body cross of axes (the plane of the shoulders and the mid-spine,
  :func:`capture2notation.body.body_cross`), so they tilt with the torso;
  chest and legs keep the standard cross (the torso cannot be read against
  itself, and the body cross of LabanotationSuite is the arms').
* Unnotated parts hold.  The start pose is standing on both feet, arms and
  legs hanging straight, head and chest upright.
* Joint extremes: a whole limb's free twist keeps its bound joint inside
  them (:meth:`synthetic.limbs.Limb.fit_twist`); a path that still leaves
  them, or whose end is beyond them, moves linearly in joint angles instead
  of stopping short and jumping (:mod:`synthetic.extremes`).  What cannot be
  reached — an end pose, a path, a hold (e.g. an upright head over a chest
  bowed further than the neck can bend back: the head is carried, as a
  notator expects of a tilting chest), a support — is performed as far as
  the extremes allow and reported with an :class:`UnreachableWarning`
  naming the symbol and the extreme (:mod:`synthetic.reach`).

The stages, one module each: :mod:`synthetic.rotations` (rotation helpers),
:mod:`synthetic.limbs` (arms and legs), :mod:`synthetic.trunk` (head and
chest), :mod:`synthetic.supports` (feet, weight, legs),
:mod:`synthetic.extremes` (paths within the joint limits),
:mod:`synthetic.reach` (what cannot be reached).

Timing is returned on the motion: ``Motion.events`` holds
``(symbol, start_frame, end_frame)`` for every symbol of the score.
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np

from capture2notation.body import Body, body_cross, euler_to_matrix, forward_kinematics, joint_index
from capture2notation.errors import SyntheticError
from capture2notation.notation.model import Effort, Score

from .extremes import continuous_at_lock, keep_paths_within
from .limbs import Limb, apply_move, group_moves
from .motion import Motion, euler_near
from .reach import UnreachableWarning, reach_report, unreachable
from .rotations import Z as _Z
from .rotations import rot_between
from .supports import PLIE_BEND_DEG, RELEVE_DEG, STEP_LENGTH, Support, leg_tracks
from .trunk import chest_reach, direction_track, trunk_angles
from .turning import front_track, place_in_room, turn_spans

__all__ = ["PLIE_BEND_DEG", "RELEVE_DEG", "STEP_LENGTH", "UnreachableWarning", "beat_frame", "interpret", "unreachable"]


def beat_frame(beat, tempo, fps: float) -> int:
    """Frame index of a beat: round half up of ``beat × 60 / tempo × fps``."""
    x = float(Fraction(beat) * 60 / Fraction(tempo)) * fps
    return int(np.floor(x + 0.5 + 1e-9))


def _key_to_pelvis(angles: np.ndarray, body: Body) -> np.ndarray:
    """(T, 3, 3) body cross of axes in the pelvis frame (columns right, forward, up).

    From the trunk's angles alone (the shoulders hang from the chest, the
    waist from the pelvis), as :func:`capture2notation.body.body_cross`
    reads it from the joints.
    """
    trunk = np.zeros_like(angles)
    for name in ("waist", "chest"):
        trunk[:, joint_index(name)] = angles[:, joint_index(name)]
    J = forward_kinematics(trunk, np.zeros((len(angles), 3)), body)
    return body_cross(J).transpose(0, 2, 1)


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
    ew, ec = trunk_angles(direction_track(symbols, "chest", frame, T, eff, chest_reach(body)), body)
    angles[:, joint_index("waist")] = ew
    angles[:, joint_index("chest")] = ec
    Rchest = euler_to_matrix(ew) @ euler_to_matrix(ec)
    RchestT = Rchest.transpose(0, 2, 1)
    # Arms and head are read in the score's key: the body cross turns their
    # directions with the torso (key → pelvis frame), the standard one not.
    key = _key_to_pelvis(angles, body) if score.axes == "body" else np.tile(np.eye(3), (T, 1, 1))
    head_d = direction_track(symbols, "head", frame, T, eff)
    ineck = joint_index("neck")
    head_R = RchestT @ key @ rot_between(_Z, head_d, [1.0, 0.0, 0.0])
    angles[:, ineck] = euler_near(head_R, 0.0, body.limits[ineck])
    RchestT = RchestT @ key  # arms: key frame → chest-local

    for name in ("right_arm", "left_arm"):
        limb = Limb(name, body)
        Q, beta = np.tile(np.eye(3), (T, 1, 1)), np.zeros(T)
        for f0, f1, syms in group_moves(limb, symbols, frame, T):
            apply_move(limb, Q, beta, f0, f1, syms, eff, T, parent=RchestT)
        if not any(s.part in (limb.upper, limb.lower) for s in symbols):
            # A held whole arm keeps its direction while the chest moves,
            # twisting about itself where the shoulder's extremes need it.
            Q = limb.fit_twist(limb.whole_frame(Q, beta), beta, RchestT)
        ja, jm, _ = limb.joints
        angles[:, ja] = euler_near(RchestT @ Q, 0.0, body.limits[ja])
        angles[:, jm, 0] = limb.middle_angle(beta)

    sup = Support(score, frame, T, eff, body, fps)
    for name, (Q, beta, ankle) in leg_tracks(sup, symbols, frame, T, eff).items():
        limb = sup.limbs[name.split("_")[0]]
        ja, jm, jb = limb.joints
        angles[:, ja] = euler_near(Q, 0.0, body.limits[ja])  # in the pelvis's (plan) frame
        angles[:, jm, 0] = limb.middle_angle(beta)
        angles[:, jb] = ankle
    # Turns: the plan is placed in the room by the pelvis's yaw (rz = −front).
    front = front_track(symbols, frame, T, eff)
    turns = [(f0, f1, sup.pivot(s)) for s, f0, f1 in turn_spans(symbols, frame)]
    root = place_in_room(sup.root, front, turns)
    angles[:, 0] = 0.0
    angles[:, 0, 2] = np.mod(-front + np.pi, 2 * np.pi) - np.pi

    events = tuple((s, frame(s.start), frame(s.end)) for s in symbols)
    # Legs were kept within their extremes before the floor was enforced.
    keep_paths_within(angles, body, [e for e in events if not e[0].part.endswith(("leg", "thigh", "shin"))], eff)
    continuous_at_lock(angles, body)
    motion = Motion(fps, angles, root, body, events)  # enforces the extremes
    for u in reach_report(motion, angles, axes=score.axes):
        warnings.warn(u.message(), UnreachableWarning, stacklevel=2)
    return motion
