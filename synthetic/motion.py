"""Motion: joint angles over time, key framing and Cachola's motion algebra.

A :class:`Motion` is the virtual dancer's animation: per frame, the local
Euler angles of every joint of :data:`capture2notation.body.JOINTS` and the
pelvis position.  Its extremes are always those of its :class:`Body`: the
constructor clips the angles (Cachola 1986 §3, "a joint enforces its
limits whatever the motion asks").

The motion algebra of Cachola ch. 4:

* ``a + b`` — concatenation (``b`` starts where ``a`` ends: its root is
  translated horizontally so that its first frame stands on ``a``'s last);
* ``k * a`` — repetition (``a + a + … + a``);
* :meth:`Motion.strip` — keep a subset of joints; the others become absent
  (NaN angles, so their positions are NaN too);
* :func:`synchronize` — merge motions animating disjoint joint sets;
* :meth:`Motion.scale_frames` — temporal stretch, a negative factor reverses;
* :meth:`Motion.scale_extremes` — scale every angle about the neutral pose.

:func:`keyframed` builds a motion from per-joint key frames (frame, angles,
interpolation), Cachola's explicit ``STARTMOTION … ENDMOTION`` definition.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import reduce

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from capture2notation.body import (
    JOINTS,
    Body,
    euler_to_matrix,
    forward_kinematics,
    joint_index,
    matrix_to_euler,
    rotation_front,
)
from capture2notation.errors import SyntheticError

from .interpolate import easing

__all__ = ["Keyframe", "Motion", "euler_near", "keyframed", "synchronize"]

_J = len(JOINTS)


@dataclass(frozen=True, eq=False)
class Motion:
    """Joint angles and root position over time.

    Parameters
    ----------
    fps : float
        Frames per second (> 0).
    angles : (T, J, 3) ndarray
        Local Euler angles ``(rx, ry, rz)`` per joint, radians; clipped to the
        body's extremes on construction.  NaN marks a joint that this motion
        does not animate (see :meth:`strip`).
    root : (T, 3) ndarray
        Pelvis position, metres (NaN when the pelvis is absent).
    body : Body
        The figure animated; default ``Body()``.
    events : tuple of (Symbol, int, int)
        Optional timing of the notation symbols this motion performs:
        ``(symbol, start_frame, end_frame)``; the movement of ``symbol``
        begins at ``start_frame`` and arrives at ``end_frame``.
    """

    fps: float
    angles: np.ndarray
    root: np.ndarray
    body: Body = field(default_factory=Body)
    events: tuple = ()

    def __post_init__(self):
        fps = float(self.fps)
        if not (np.isfinite(fps) and fps > 0):
            raise SyntheticError(f"motion fps must be a positive number, got {self.fps!r}")
        angles = np.asarray(self.angles, dtype=float)
        if angles.ndim != 3 or angles.shape[1:] != (_J, 3) or angles.shape[0] < 1:
            raise SyntheticError(f"motion angles must have shape (T>=1, {_J}, 3), got {angles.shape}")
        root = np.asarray(self.root, dtype=float)
        if root.shape != (angles.shape[0], 3):
            raise SyntheticError(
                f"motion root must have shape ({angles.shape[0]}, 3) to match the angles, got {root.shape}"
            )
        angles = self.body.clip(angles)
        angles.setflags(write=False)
        root = root.copy()
        root.setflags(write=False)
        object.__setattr__(self, "fps", fps)
        object.__setattr__(self, "angles", angles)
        object.__setattr__(self, "root", root)
        object.__setattr__(self, "events", tuple(self.events))

    # -- views ---------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.angles.shape[0])

    @property
    def times(self) -> np.ndarray:
        """(T,) ndarray: time of each frame in seconds, starting at 0."""
        return np.arange(self.n_frames) / self.fps

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.n_frames - 1) / self.fps

    @property
    def present(self) -> np.ndarray:
        """(J,) bool: joints this motion animates (not NaN in every frame)."""
        return ~np.all(np.isnan(self.angles), axis=(0, 2))

    @property
    def front(self) -> np.ndarray:
        """(T,) front: degrees clockwise seen from above from the room's +y, unwrapped.

        The pelvis's facing (DESIGN.md, "Facing and turns"): a right turn of
        a half ends at +180, two right pirouettes at +720.  NaN where the
        pelvis is absent.
        """
        out = rotation_front(euler_to_matrix(np.nan_to_num(self.angles[:, 0])))
        out[np.isnan(self.angles[:, 0]).any(axis=-1)] = np.nan
        return out

    def joints(self) -> np.ndarray:
        """World joint positions, (T, J, 3) metres (NaN below absent joints)."""
        return forward_kinematics(self.angles, self.root, self.body)

    def allclose(self, other: Motion, atol: float = 1e-9) -> bool:
        """Same fps, body, frame count, and equal angles/root (NaN equal NaN)."""
        return (
            isinstance(other, Motion)
            and self.fps == other.fps
            and self.body == other.body
            and self.n_frames == other.n_frames
            and np.allclose(self.angles, other.angles, atol=atol, rtol=0, equal_nan=True)
            and np.allclose(self.root, other.root, atol=atol, rtol=0, equal_nan=True)
        )

    # -- algebra -------------------------------------------------------------
    def __add__(self, other: Motion) -> Motion:
        if not isinstance(other, Motion):
            return NotImplemented
        if other.fps != self.fps or other.body != self.body:
            raise SyntheticError(
                f"cannot concatenate motions at {self.fps} and {other.fps} fps / different bodies; "
                "resample with scale_frames first"
            )
        shift = np.zeros(3)
        if np.all(np.isfinite(self.root[-1, :2])) and np.all(np.isfinite(other.root[0, :2])):
            shift[:2] = self.root[-1, :2] - other.root[0, :2]
        n = self.n_frames
        events = self.events + tuple((s, a + n, b + n) for s, a, b in other.events)
        return Motion(
            self.fps,
            np.concatenate([self.angles, other.angles]),
            np.concatenate([self.root, other.root + shift]),
            self.body,
            events,
        )

    def __mul__(self, k: int) -> Motion:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            return NotImplemented
        if k < 1:
            raise SyntheticError(f"repetition factor must be a positive integer, got {k}")
        return reduce(lambda a, b: a + b, [self] * int(k))

    __rmul__ = __mul__

    def strip(self, joints: Iterable[str]) -> Motion:
        """Partial motion animating only `joints` (Cachola's STRIP).

        Parameters
        ----------
        joints : iterable of str
            Joint names to keep; the others get NaN angles.  The root
            position is kept only with ``"pelvis"``.
        """
        keep = np.zeros(_J, bool)
        for name in joints:
            keep[joint_index(name)] = True
        angles = np.where(keep[None, :, None], self.angles, np.nan)
        root = self.root if keep[0] else np.full_like(self.root, np.nan)
        return Motion(self.fps, angles, root, self.body, ())

    def scale_frames(self, k: float) -> Motion:
        """Temporal stretch by `k` (Cachola's SCALE FRAMES).

        The motion keeps its first and last poses; ``(T − 1)·|k|`` intervals
        replace ``T − 1``.  In-between poses are interpolated by spherical
        linear interpolation of each joint's rotation (so Euler wrap-arounds
        cannot produce spurious spins) and linearly for the root.  A negative
        `k` also reverses time.  Frames falling on original frames are copied
        exactly, so ``scale_frames(-1)`` twice gives back the motion.

        Events are rescaled for ``k > 0`` and dropped for ``k < 0`` (a
        reversed movement is no longer its symbol).
        """
        k = float(k)
        if not np.isfinite(k) or k == 0:
            raise SyntheticError(f"scale_frames factor must be finite and non-zero, got {k}")
        T = self.n_frames
        n_new = max(int(round((T - 1) * abs(k))), 0) + 1
        u = np.linspace(0.0, T - 1, n_new) if n_new > 1 else np.zeros(1)
        if k < 0:
            u = u[::-1]
        angles, root = _resample(self.angles, self.root, u, self.body)
        events = ()
        if k > 0 and T > 1:
            f = (n_new - 1) / (T - 1)
            events = tuple((s, int(round(a * f)), int(round(b * f))) for s, a, b in self.events)
        return Motion(self.fps, angles, root, self.body, events)

    def scale_extremes(self, k: float) -> Motion:
        """Scale every joint angle by `k` about the neutral pose (SCALE EXTREMES).

        The result is clipped to the body's extremes like any motion; the
        root is unchanged.
        """
        k = float(k)
        if not np.isfinite(k):
            raise SyntheticError(f"scale_extremes factor must be finite, got {k}")
        return Motion(self.fps, self.angles * k, self.root, self.body, ())

    @classmethod
    def rest(cls, n_frames: int = 1, fps: float = 25.0, body: Body | None = None) -> Motion:
        """The rest pose held for `n_frames` frames."""
        body = body or Body()
        if n_frames < 1:
            raise SyntheticError(f"n_frames must be >= 1, got {n_frames}")
        return cls(fps, np.zeros((n_frames, _J, 3)), np.tile(body.rest[0], (n_frames, 1)), body)


def synchronize(*motions: Motion) -> Motion:
    """Merge partial motions on disjoint joint sets (Cachola's SYNCHRONIZE).

    Motions shorter than the longest hold their last frame (Cachola: "the
    model remains frozen at its last specified orientation").  The root
    comes from the motion that animates the pelvis (NaN if none does).

    Raises
    ------
    SyntheticError
        If two motions animate the same joint, or fps / bodies differ.
    """
    if not motions:
        raise SyntheticError("synchronize needs at least one motion")
    first = motions[0]
    T = max(m.n_frames for m in motions)
    angles = np.full((T, _J, 3), np.nan)
    root = np.full((T, 3), np.nan)
    owner = np.full(_J, -1)
    events: list = []
    for i, m in enumerate(motions):
        if m.fps != first.fps or m.body != first.body:
            raise SyntheticError(
                f"synchronize: motion {i} has fps {m.fps} / body {m.body}, expected {first.fps} / {first.body}"
            )
        clash = m.present & (owner >= 0)
        if np.any(clash):
            j = int(np.flatnonzero(clash)[0])
            raise SyntheticError(
                f"synchronize: joint {JOINTS[j]!r} is animated by both motion {owner[j]} and motion {i}; "
                "strip one of them first"
            )
        owner[m.present] = i
        pad = T - m.n_frames
        a = np.concatenate([m.angles, np.repeat(m.angles[-1:], pad, 0)])
        angles[:, m.present] = a[:, m.present]
        if m.present[0]:
            root = np.concatenate([m.root, np.repeat(m.root[-1:], pad, 0)])
        events.extend(m.events)
    return Motion(first.fps, angles, root, first.body, tuple(events))


@dataclass(frozen=True)
class Keyframe:
    """One key of a joint (Cachola's ``FRAME … POSITION … INTERPOLATE``).

    Parameters
    ----------
    frame : int
        Frame at which the joint reaches `angles` (>= 0).
    angles : (3,) array_like
        ``(rx, ry, rz)`` radians.
    interpolation : str, Effort or callable
        How the joint travels from the previous key to this one (see
        :func:`synthetic.interpolate.easing`).
    """

    frame: int
    angles: tuple
    interpolation: object = "linear"


def keyframed(
    keys: Mapping[str, Sequence[Keyframe]],
    n_frames: int | None = None,
    fps: float = 25.0,
    body: Body | None = None,
    root: np.ndarray | None = None,
) -> Motion:
    """A motion from per-joint key frames.

    Every joint starts at its neutral pose (0, 0, 0) unless it has a key at
    frame 0, travels from key to key with each key's interpolation, and
    holds after its last key.  Joints without keys stay neutral.

    Parameters
    ----------
    keys : mapping joint name -> sequence of Keyframe
        Keys in increasing frame order.
    n_frames : int, optional
        Length; default one past the last key.
    fps : float
    body : Body, optional
    root : (T, 3) or (3,) ndarray, optional
        Pelvis position; default the rest position held.

    Returns
    -------
    Motion
    """
    body = body or Body()
    last = max((k.frame for ks in keys.values() for k in ks), default=0)
    T = int(n_frames) if n_frames is not None else last + 1
    if T < 1:
        raise SyntheticError(f"n_frames must be >= 1, got {T}")
    angles = np.zeros((T, _J, 3))
    frames = np.arange(T)
    for name, ks in keys.items():
        j = joint_index(name)
        prev_f, prev_a = 0, np.zeros(3)
        for i, k in enumerate(ks):
            f = int(k.frame)
            a = np.asarray(k.angles, dtype=float)
            if a.shape != (3,) or not np.all(np.isfinite(a)):
                raise SyntheticError(
                    f"keyframe {i} of joint {name!r}: angles must be 3 finite numbers, got {k.angles!r}"
                )
            if f < prev_f or (i > 0 and f == prev_f) or f >= T:
                raise SyntheticError(
                    f"keyframe {i} of joint {name!r} at frame {f}: frames must increase and lie in [0, {T - 1}]"
                )
            if f > prev_f:
                sel = (frames > prev_f) & (frames <= f)
                s = easing(k.interpolation)((frames[sel] - prev_f) / (f - prev_f))
                angles[sel, j] = prev_a + np.asarray(s)[:, None] * (a - prev_a)
            else:
                angles[0, j] = a
            prev_f, prev_a = f, a
        angles[frames > prev_f, j] = prev_a
    if root is None:
        root = np.tile(body.rest[0], (T, 1))
    root = np.broadcast_to(np.asarray(root, dtype=float), (T, 3))
    return Motion(fps, angles, root, body)


def euler_near(m: np.ndarray, ref: np.ndarray, limits: np.ndarray | None = None) -> np.ndarray:
    """Euler angles of rotations `m`, choosing the representation nearest `ref`.

    A rotation has two Euler triples, ``(rx, ry, rz)`` and
    ``(rx + π, π − ry, rz + π)``, each defined modulo 2π per angle.  Among
    them this picks the one inside `limits` (when given) closest to `ref`,
    so that angle tracks stay continuous and inside the extremes.

    Parameters
    ----------
    m : (..., 3, 3) ndarray
        Rotation matrices.
    ref : (..., 3) ndarray
        Reference angles, radians (broadcast against ``m[..., 0]``).
    limits : (..., 3, 2) ndarray, optional
        (min, max) per angle.

    Returns
    -------
    (..., 3) ndarray
    """
    e = matrix_to_euler(m)
    alt = np.stack([e[..., 0] + np.pi, np.pi - e[..., 1], e[..., 2] + np.pi], axis=-1)
    ref = np.broadcast_to(np.asarray(ref, dtype=float), e.shape)
    cands = []
    for c in (e, alt):
        c = ref + (np.mod(c - ref + np.pi, 2 * np.pi) - np.pi)
        cost = np.sum((c - ref) ** 2, axis=-1)
        if limits is not None:
            lo, hi = limits[..., 0], limits[..., 1]
            excess = np.maximum(lo - c, 0) + np.maximum(c - hi, 0)
            # Leaving the extremes costs far more than any in-range distance;
            # a wrap by 2π may bring an angle back inside, so try it too.
            for shift in (-2 * np.pi, 2 * np.pi):
                c2 = np.where(excess > 1e-9, c + shift, c)
                ex2 = np.maximum(lo - c2, 0) + np.maximum(c2 - hi, 0)
                better = ex2 < excess
                c = np.where(better, c2, c)
                excess = np.where(better, ex2, excess)
            cost = np.sum((c - ref) ** 2, axis=-1) + 1e3 * np.sum(excess, axis=-1)
        cands.append((c, cost))
    (c0, k0), (c1, k1) = cands
    return np.where((k1 < k0)[..., None], c1, c0)


def _resample(angles: np.ndarray, root: np.ndarray, u: np.ndarray, body: Body):
    """Angles and root at fractional frame positions `u` (exact on integers)."""
    T = angles.shape[0]
    i0 = np.clip(np.floor(u).astype(int), 0, T - 1)
    frac = u - i0
    i1 = np.minimum(i0 + 1, T - 1)
    exact = frac < 1e-12
    out = angles[i0].copy()
    r = root[i0] * (1 - frac[:, None]) + root[i1] * frac[:, None]
    r[exact] = root[i0[exact]]
    if np.all(exact) or T == 1:
        return out, r
    present = ~np.all(np.isnan(angles), axis=(0, 2))
    mats = euler_to_matrix(np.nan_to_num(angles))  # (T, J, 3, 3)
    idx = np.flatnonzero(~exact)
    for j in np.flatnonzero(present):
        slerp = Slerp(np.arange(T, dtype=float), Rotation.from_matrix(mats[:, j]))
        m = slerp(u[idx]).as_matrix()
        ref = angles[i0[idx], j] * (1 - frac[idx, None]) + angles[i1[idx], j] * frac[idx, None]
        out[idx, j] = euler_near(m, ref, body.limits[j])
    return out, r
