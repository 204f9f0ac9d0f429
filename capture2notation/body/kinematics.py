"""Forward kinematics, vectorised over frames.

Conventions are those of :mod:`capture2notation.body.skeleton`: local Euler
angles ``(rx, ry, rz)`` composed as ``R = Rz @ Ry @ Rx``; at rest every local
frame is the world frame.
"""

from __future__ import annotations

import numpy as np

from ..errors import BodyModelError
from .skeleton import JOINTS, Body

__all__ = ["euler_to_matrix", "forward_kinematics", "global_rotations", "matrix_to_euler"]


def euler_to_matrix(angles: np.ndarray) -> np.ndarray:
    """Rotation matrices from Euler angles.

    Parameters
    ----------
    angles : (..., 3) ndarray
        ``(rx, ry, rz)`` in radians.

    Returns
    -------
    (..., 3, 3) ndarray
        ``Rz(rz) @ Ry(ry) @ Rx(rx)``.
    """
    a = np.asarray(angles, dtype=float)
    m = np.empty(a.shape[:-1] + (3, 3))
    _fill_rotation(m, a[..., 0], a[..., 1], a[..., 2], lambda m, i, k: m[..., i, k])
    return m


def _fill_rotation(m, rx, ry, rz, entry):
    """Write the entries of ``Rz @ Ry @ Rx`` into `m`; ``entry(m, i, k)`` is the (i, k) view."""
    cx, cy, cz = np.cos(rx), np.cos(ry), np.cos(rz)
    sx, sy, sz = np.sin(rx), np.sin(ry), np.sin(rz)
    entry(m, 0, 0)[...] = cz * cy
    entry(m, 0, 1)[...] = cz * sy * sx - sz * cx
    entry(m, 0, 2)[...] = cz * sy * cx + sz * sx
    entry(m, 1, 0)[...] = sz * cy
    entry(m, 1, 1)[...] = sz * sy * sx + cz * cx
    entry(m, 1, 2)[...] = sz * sy * cx - cz * sx
    entry(m, 2, 0)[...] = -sy
    entry(m, 2, 1)[...] = cy * sx
    entry(m, 2, 2)[...] = cy * cx


def matrix_to_euler(m: np.ndarray) -> np.ndarray:
    """Inverse of :func:`euler_to_matrix` with ``ry`` in [−π/2, π/2].

    Parameters
    ----------
    m : (..., 3, 3) ndarray
        Rotation matrices.

    Returns
    -------
    (..., 3) ndarray
        ``(rx, ry, rz)`` in radians.
    """
    m = np.asarray(m, dtype=float)
    ry = np.arcsin(np.clip(-m[..., 2, 0], -1.0, 1.0))
    rx = np.arctan2(m[..., 2, 1], m[..., 2, 2])
    rz = np.arctan2(m[..., 1, 0], m[..., 0, 0])
    # At gimbal lock (|ry| = 90 deg) rx and rz are coupled; put it all in rx.
    lock = np.abs(m[..., 2, 0]) > 1 - 1e-9
    if np.any(lock):
        rz = np.where(lock, 0.0, rz)
        rx = np.where(lock, np.arctan2(-m[..., 1, 2], m[..., 1, 1]), rx)
    return np.stack([rx, ry, rz], axis=-1)


def _global_soa(angles: np.ndarray, body: Body) -> np.ndarray:
    """World rotations laid out (J, 3, 3, T): frames last, so that composing
    along the tree is elementwise arithmetic on long contiguous rows (far
    faster than stacks of tiny 3×3 matrix products)."""
    a = angles.transpose(1, 2, 0)  # (J, 3, T)
    local = np.empty((a.shape[0], 3, 3, a.shape[2]))
    _fill_rotation(local, a[:, 0], a[:, 1], a[:, 2], lambda m, i, k: m[:, i, k])
    glob = np.empty_like(local)
    for j, p in enumerate(body.parents):
        if p < 0:
            glob[j] = local[j]
        else:
            g, l = glob[p], local[j]
            glob[j] = g[:, 0, None, :] * l[0] + g[:, 1, None, :] * l[1] + g[:, 2, None, :] * l[2]
    return glob


def global_rotations(angles: np.ndarray, body: Body | None = None) -> np.ndarray:
    """World orientation of every joint's local frame.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Local Euler angles, radians.
    body : Body, optional
        Only its tree is used; default ``Body()``.

    Returns
    -------
    (T, J, 3, 3) ndarray
    """
    body = body or Body()
    return np.ascontiguousarray(np.moveaxis(_global_soa(_check(angles), body), -1, 0))


def forward_kinematics(
    angles: np.ndarray,
    root_position: np.ndarray | None = None,
    body: Body | None = None,
) -> np.ndarray:
    """Joint positions for every frame in one call.

    Parameters
    ----------
    angles : (T, J, 3) ndarray
        Local Euler angles per joint, radians (not clipped here: call
        :meth:`Body.clip` to enforce the extremes).
    root_position : (T, 3) ndarray, optional
        Pelvis position in metres; default the rest pelvis position.
    body : Body, optional
        Default ``Body()`` (1.70 m).

    Returns
    -------
    (T, J, 3) ndarray
        World positions, metres.
    """
    body = body or Body()
    angles = _check(angles)
    T = angles.shape[0]
    if root_position is None:
        root_position = np.broadcast_to(body.rest[0], (T, 3))
    root_position = np.asarray(root_position, dtype=float)
    if root_position.shape != (T, 3):
        raise BodyModelError(f"root_position must have shape ({T}, 3) to match angles, got {root_position.shape}")
    glob = _global_soa(angles, body)  # (J, 3, 3, T)
    pos = np.empty((len(JOINTS), 3, T))
    pos[0] = root_position.T
    offsets = body.offsets
    for j in range(1, len(JOINTS)):
        g, o = glob[body.parents[j]], offsets[j]
        pos[j] = pos[body.parents[j]] + g[:, 0] * o[0] + g[:, 1] * o[1] + g[:, 2] * o[2]
    return np.ascontiguousarray(pos.transpose(2, 0, 1))


def _check(angles: np.ndarray) -> np.ndarray:
    angles = np.asarray(angles, dtype=float)
    if angles.ndim != 3 or angles.shape[1:] != (len(JOINTS), 3):
        raise BodyModelError(f"angles must have shape (T, {len(JOINTS)}, 3), got {angles.shape}")
    return angles
