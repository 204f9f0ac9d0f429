"""Reference motions with known Effort, for tests and calibration.

The smallest dancer: the body stands at rest and one
straight arm (or leg) swings between symbol directions, its direction
slerped with the logistic progress ``s(τ)`` and its distance from the bound
joint modulated by Space (eq. 5.5).  It is exact by construction, so it tests
the estimator alone; ``synthetic.interpret`` is the full dancer.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from capture2notation.body import Body, joint_index
from capture2notation.errors import SyntheticError
from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.effort import progress, space_radius
from capture2notation.notation.model import PART_SEGMENTS, SUPPORT_PARTS, Effort, Score, Symbol

__all__ = ["arc_motion", "random_arm_score"]

#: Targets for random arm symbols (direction, level), all different vectors.
_TARGETS = (
    ("forward", "middle"),
    ("right", "middle"),
    ("forward", "high"),
    ("right", "high"),
    ("right_forward", "middle"),
    ("forward", "low"),
    ("right", "low"),
    ("place", "high"),
    ("right_back", "middle"),
    ("right_forward", "high"),
)


def _slerp(u0, u1, s):
    """Great-circle interpolation of unit vectors; s (N,) → (N, 3)."""
    om = np.arccos(np.clip(np.dot(u0, u1), -1.0, 1.0))
    if om < 1e-9:
        return np.repeat(u0[None], s.size, axis=0)
    return (np.sin((1 - s) * om)[:, None] * u0 + np.sin(s * om)[:, None] * u1) / np.sin(om)


def random_arm_score(rng: np.random.Generator, n_moves: int, tempo=60, part: str = "right_arm", effort=None) -> Score:
    """A score of `n_moves` consecutive 1–2 beat symbols of `part`.

    Each target differs from the previous one by 30°–150°, so the swing is
    well defined; left limbs move to the mirror images of the right's targets.
    """
    rng = np.random.default_rng(rng)
    left = part.startswith("left")
    syms, prev, beat = [], ("place", "low"), Fraction(0)
    for _ in range(n_moves):
        u = canonical_vector(*prev)
        choices = [t for t in _TARGETS if 0.5 * np.sqrt(3) > np.dot(u, canonical_vector(*t)) > -0.5 * np.sqrt(3)]
        prev = choices[int(rng.integers(len(choices)))]
        dur = Fraction(int(rng.integers(1, 3)))
        # left limbs take the mirror image (right <-> left) of the targets
        direction = prev[0].replace("right", "left") if left else prev[0]
        syms.append(Symbol(beat, dur, part, direction, prev[1]))
        beat += dur
    return Score(symbols=tuple(syms), tempo=Fraction(tempo), effort=effort)


def arc_motion(
    score: Score, fps: float = 25.0, effort: Effort | None = None, body: Body | None = None, snap: bool = True
) -> np.ndarray:
    """Joint positions (T, J, 3) of `score` with the given Effort.

    Only whole arms and legs move (their bound joint fixed, limb straight);
    the rest of the body stands at rest and support symbols are ignored.  Frame ``i`` is at ``i / fps`` s.

    Parameters
    ----------
    score : Score
    fps : float
    effort : Effort, optional
        Default: the score's resolved Effort.
    body : Body, optional
    snap : bool
        Start and end each movement on the frame nearest its beat (round half
        up), as ``synthetic.interpret`` does; otherwise on the exact time.
    """
    body = body or Body()
    effort = effort or score.resolved_effort()
    n = int(np.floor(score.seconds(score.duration) * fps)) + 2
    t = np.arange(n) / fps
    joints = np.repeat(body.rest[None], n, axis=0)
    for part in sorted({s.part for s in score.symbols} - set(SUPPORT_PARTS)):
        if part not in ("right_arm", "left_arm", "right_leg", "left_leg"):
            raise SyntheticError(f"arc_motion moves whole arms and legs only, not {part}")
        bound, free = (joint_index(j) for j in PART_SEGMENTS[part])
        mid = joint_index(PART_SEGMENTS[part][1].replace("wrist", "elbow").replace("ankle", "knee"))
        length = float(np.linalg.norm(body.rest[free] - body.rest[bound]))
        # body frame at rest is (right, forward, up) = world (x, y, z)
        u_prev = np.array([0.0, 0.0, -1.0])
        u = np.repeat(u_prev[None], n, axis=0)
        r = np.full(n, length)
        for sym in score.for_part(part):
            t0, t1 = score.seconds(sym.start), score.seconds(sym.end)
            if snap:
                t0, t1 = (np.floor(x * fps + 0.5 + 1e-9) / fps for x in (t0, t1))
            u_next = canonical_vector(sym.direction, sym.level)
            inside = (t >= t0 - 1e-9) & (t < t1 - 1e-9)
            tau = (t[inside] - t0) / (t1 - t0)
            u[inside] = _slerp(u_prev, u_next, progress(tau, effort.time, effort.weight))
            r[inside] = space_radius(length, effort.space, tau)
            u[t >= t1 - 1e-9] = u_next
            r[t >= t1 - 1e-9] = length
            u_prev = u_next
        joints[:, free] = joints[:, bound] + r[:, None] * u
        # elbow/knee on the line (its distance changes with the bend Space implies)
        joints[:, mid] = joints[:, bound] + 0.5 * r[:, None] * u
    return joints
