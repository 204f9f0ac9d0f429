"""Rotation helpers of the virtual dancer, vectorised over leading axes.

All matrices are ``(..., 3, 3)`` rotations acting on column vectors; frames
are the body frame of DESIGN.md (x right, y forward, z up).  A limb frame's
−z axis is the limb's direction (limbs hang along −z at rest).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "Z",
    "axis_angle",
    "cross",
    "great_circle_frames",
    "rot_between",
    "rot_x",
    "slerp_dirs",
    "slerp_frames",
    "unit",
]

#: World / body-frame up.
Z = np.array([0.0, 0.0, 1.0])
_Z = Z


def unit(v):
    """Unit vectors along the last axis of `v` (..., 3)."""
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def rot_x(theta):
    """Rotation matrices (..., 3, 3) about x by `theta` (...) radians."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    m = np.zeros(theta.shape + (3, 3))
    m[..., 0, 0] = 1.0
    m[..., 1, 1], m[..., 1, 2] = c, -s
    m[..., 2, 1], m[..., 2, 2] = s, c
    return m


def cross(a, b):
    """Cross product of (..., 3) arrays (broadcast; faster than ``np.cross`` on small stacks)."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def axis_angle(axis, angle):
    """Rotation matrices (Rodrigues) about `axis` (..., 3) by `angle` (...) radians."""
    k = unit(axis)
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


def rot_between(a, b, fallback_axis):
    """Minimal rotation taking unit `a` to unit `b`; half turns about `fallback_axis`."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    v = cross(a, b)
    c = np.sum(a * b, axis=-1)
    n = np.linalg.norm(v, axis=-1)
    angle = np.arctan2(n, c)
    fb = np.broadcast_to(np.asarray(fallback_axis, float), a.shape)
    fb = fb - np.sum(fb * a, -1, keepdims=True) * a
    axis = np.where((n > 1e-9)[..., None], v, fb)
    return axis_angle(axis, angle)


def slerp_frames(Pa, Pb, s, prefer=None):
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


def great_circle_frames(Pa, Pb, s, prefer):
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
    G = axis_angle(n, theta)
    tw = (G @ Pa).T @ Pb  # a turn about the limb's own axis
    psi = np.arctan2(tw[1, 0], tw[0, 0])
    s = np.asarray(s, float)
    return (
        axis_angle(np.broadcast_to(n, s.shape + (3,)), s * theta)
        @ Pa
        @ axis_angle(np.broadcast_to(_Z, s.shape + (3,)), s * psi)
    )


def slerp_dirs(da, db, s):
    """Unit vectors (n, 3) along the great circle from `da` to `db` at progress `s` (n,).

    Opposite ends go through +x (an arbitrary but fixed choice).
    """
    n = np.cross(da, db)
    if np.linalg.norm(n) < 1e-9:
        n = np.cross(da, [1.0, 0.0, 0.0]) if abs(da[0]) < 0.9 else np.cross(da, [0.0, 1.0, 0.0])
    theta = np.arctan2(np.linalg.norm(np.cross(da, db)), da @ db)
    return axis_angle(np.broadcast_to(n, np.shape(s) + (3,)), np.asarray(s) * theta) @ da
