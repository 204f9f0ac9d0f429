"""Closed-form inverse kinematics from 3D segment directions: the solver's starting pose.

Gauss–Newton on Euler angles only finds the nearest minimum; a raised arm
started from the rest pose can settle in a mirror pose that projects the same.
So every frame starts from the pose computed directly from measured 3D
directions (world landmarks of the keypoint model, or mocap joints):

* pelvis: x along right hip − left hip, z as close to world up as possible;
* waist and chest: share equally the bend that takes the pelvis's up to the
  pelvis → neck direction; the chest takes the twist of the shoulder line;
* shoulder / hip: the frame whose −z is the upper arm / thigh and whose
  forward (+y) lies in the plane of the bend, towards the forearm (elbow
  flexion swings forward) or away from the shin (knee flexion swings back);
  with a straight limb, the forward axis follows the shortest swing from rest;
* elbow / knee: the angle between the two segments.

Wrists, ankles, neck and head start at rest.  Each Euler triple is the one of
the two equivalent triples nearer to the joint's limits, then clipped.  A
shoulder then follows on from frame to frame (:func:`_continuous`): a straight
arm carries its twist on, and each frame keeps the triple nearer the last.
"""

from __future__ import annotations

import math

import numpy as np

from ..body import JOINTS, euler_to_matrix, joint_index, matrix_to_euler
from .model import PoseModel

__all__ = ["initial_angles"]

_J = len(JOINTS)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / n


def _swing(u: np.ndarray) -> np.ndarray:
    """Shortest rotation taking −z onto unit vectors `u` (..., 3) -> (..., 3, 3)."""
    a = np.array([0.0, 0.0, -1.0])
    axis = np.cross(a, u)
    s = np.linalg.norm(axis, axis=-1)
    c = np.clip(np.sum(a * u, axis=-1), -1.0, 1.0)
    # Antiparallel (straight up): turn through the front, about x.
    axis = np.where((s < 1e-9)[..., None], np.array([1.0, 0.0, 0.0]), axis / np.maximum(s, 1e-12)[..., None])
    ang = np.arctan2(s, c)
    return _rodrigues(axis, ang)


def _rodrigues(axis: np.ndarray, ang: np.ndarray) -> np.ndarray:
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    c, s = np.cos(ang), np.sin(ang)
    C = 1 - c
    return np.stack(
        [
            np.stack([c + x * x * C, x * y * C - z * s, x * z * C + y * s], -1),
            np.stack([y * x * C + z * s, c + y * y * C, y * z * C - x * s], -1),
            np.stack([z * x * C - y * s, z * y * C + x * s, c + z * z * C], -1),
        ],
        -2,
    )


def _euler_in_limits(R: np.ndarray, lim: np.ndarray) -> np.ndarray:
    """Euler angles of `R` (..., 3, 3): the equivalent triple nearer the limits (3, 2), clipped."""
    e1 = matrix_to_euler(R)
    e2 = np.stack([e1[..., 0] + np.pi, np.pi - e1[..., 1], e1[..., 2] + np.pi], -1)
    e2 = np.angle(np.exp(1j * e2))  # wrap to (-pi, pi]
    # Also try each angle shifted by a full turn (limits may exceed +-180 deg).
    cands = [_shifted_into(e, lim) for e in (e1, e2)]
    viol = [np.sum(np.maximum(lim[:, 0] - c, 0) + np.maximum(c - lim[:, 1], 0), axis=-1) for c in cands]
    best = np.where((viol[0] <= viol[1])[..., None], cands[0], cands[1])
    return np.clip(best, lim[:, 0], lim[:, 1])


def initial_angles(points: np.ndarray, model: PoseModel) -> np.ndarray:
    """Starting angles from 3D joint positions (any origin), world axes.

    Parameters
    ----------
    points : (T, J, 3) ndarray
        Measured positions of our joints, z up; NaN where unknown (those
        parts start at rest).
    model : PoseModel
        Supplies the limits.

    Returns
    -------
    (T, J, 3) ndarray
        Euler angles, radians, within the limits.
    """
    P = np.asarray(points, float)
    T = P.shape[0]
    lim = model.body.limits
    ang = np.zeros((T, _J, 3))
    eye = np.broadcast_to(np.eye(3), (T, 3, 3))

    def seg(a, b):
        return _unit(P[:, joint_index(b)] - P[:, joint_index(a)])

    # Pelvis.
    x = seg("left_hip", "right_hip")
    xs = seg("left_shoulder", "right_shoulder")
    x = np.where(np.isfinite(x), x, xs)
    up = np.array([0.0, 0.0, 1.0])
    y = _unit(np.cross(up, x))
    z = np.cross(x, y)
    G = np.stack([x, y, z], axis=-1)
    ok = np.all(np.isfinite(G), axis=(1, 2))
    G = np.where(ok[:, None, None], G, eye)
    ang[:, 0] = np.where(ok[:, None], matrix_to_euler(G), 0.0)

    # Waist and chest: half the bend each; the chest takes the twist.
    d = seg("pelvis", "neck")
    d_loc = np.einsum("tji,tj->ti", G, d)
    ok = np.all(np.isfinite(d_loc), axis=1)
    d_loc = np.where(ok[:, None], d_loc, up)
    axis = np.cross(up, d_loc)
    s = np.linalg.norm(axis, axis=1)
    axis = np.where((s > 1e-9)[:, None], axis / np.maximum(s, 1e-12)[:, None], np.array([1.0, 0.0, 0.0]))
    theta = np.arctan2(s, d_loc[:, 2])
    half = _rodrigues(axis, theta / 2)
    G_mid = G @ half @ half
    s_loc = np.einsum("tji,tj->ti", G_mid, xs)
    phi = np.where(np.all(np.isfinite(s_loc), axis=1), np.arctan2(s_loc[:, 1], s_loc[:, 0]), 0.0)
    twist = _rodrigues(np.broadcast_to(up, (T, 3)), phi)
    w, c = joint_index("waist"), joint_index("chest")
    ang[:, w] = _euler_in_limits(half, lim[w])
    ang[:, c] = _euler_in_limits(half @ twist, lim[c])
    G_chest = G @ euler_to_matrix(ang[:, w]) @ euler_to_matrix(ang[:, c])
    G_pelvis = euler_to_matrix(ang[:, 0])

    for side in ("right", "left"):
        _limb(ang, P, G_chest, f"{side}_shoulder", f"{side}_elbow", f"{side}_wrist", +1.0, lim, continuous=True)
        # Legs keep the per-frame choice: carrying a straight leg's twist on
        # (its turn-out, which the feet show) put the fidelity study's
        # leg phrase in its failure mode (a leg fitted 10° off) in 53 of its
        # captures instead of 23.
        _limb(ang, P, G_pelvis, f"{side}_hip", f"{side}_knee", f"{side}_ankle", -1.0, lim, continuous=False)
    return ang


def _limb(ang, P, G_parent, root, mid, end, sign, lim, continuous: bool):
    """Set the root joint's 3 angles and the middle joint's flexion from two segment directions.

    With `continuous`, the root's angles follow on from frame to frame
    (:func:`_continuous`).
    """
    r, m, e = joint_index(root), joint_index(mid), joint_index(end)
    u = _unit(P[:, m] - P[:, r])
    f = _unit(P[:, e] - P[:, m])
    u_l = np.einsum("tji,tj->ti", G_parent, u)
    f_l = np.einsum("tji,tj->ti", G_parent, f)
    ok_u = np.all(np.isfinite(u_l), axis=1)
    if not ok_u.any():
        return
    u_l = np.where(ok_u[:, None], u_l, np.array([0.0, 0.0, -1.0]))
    swing = _swing(u_l)
    y_rest = swing[..., :, 1]  # forward axis after the shortest swing
    perp = f_l - np.sum(f_l * u_l, axis=1, keepdims=True) * u_l
    sin_b = np.linalg.norm(perp, axis=1)
    bent = np.isfinite(sin_b) & (sin_b > 0.2)
    y_bend = sign * perp / np.maximum(sin_b, 1e-12)[:, None]
    z_ax = -u_l
    # The bend's plane fixes the root joint's twist; where that twist is
    # beyond the limits (a noisy, slight bend of a raised leg), clipping each
    # Euler angle on its own can swing the segment far from `u` (a thigh
    # raised forward ended up back).  So the untwisted frames are candidates
    # too — the shortest swing, and the two (rx, ry) pairs with rz = 0, which
    # reach a leg raised high forward and a little aside — and the bend's
    # frame is kept unless another points the segment clearly closer to `u`
    # after clipping.
    euler = [
        _euler_in_limits(np.stack([np.cross(y_ax, z_ax), y_ax, z_ax], axis=-1), lim[r])
        for y_ax in (np.where(bent[:, None], y_bend, y_rest), y_rest)
    ]
    rx = np.arcsin(np.clip(u_l[:, 1], -1.0, 1.0))
    for rx_k in (rx, np.pi - rx):
        c = np.cos(rx_k)
        ry_k = np.arctan2(-u_l[:, 0] * np.sign(c), -u_l[:, 2] * np.sign(c))
        e = np.stack([np.angle(np.exp(1j * rx_k)), ry_k, np.zeros_like(rx_k)], axis=-1)
        euler.append(np.clip(e, lim[r, :, 0], lim[r, :, 1]))
    euler = np.stack(euler)  # (4, T, 3)
    cos = np.sum(-euler_to_matrix(euler)[..., :, 2] * u_l, axis=-1)  # (4, T)
    pick = np.where(cos[0] >= cos.max(axis=0) - 0.02, 0, np.argmax(cos, axis=0))
    chosen = euler[pick, np.arange(len(pick))]
    if continuous:
        chosen = _continuous(chosen, u_l, ok_u & ~bent, cos.max(axis=0), lim[r])
    ang[:, r] = np.where(ok_u[:, None], chosen, 0.0)
    beta = np.arccos(np.clip(np.sum(u_l * f_l, axis=1), -1, 1))
    flex = np.where(np.isfinite(beta) & ok_u, sign * beta, 0.0)
    ang[:, m, 0] = np.clip(flex, lim[m, 0, 0], lim[m, 0, 1])


def _continuous(
    chosen: np.ndarray, u: np.ndarray, free: np.ndarray, best_cos: np.ndarray, lim: np.ndarray
) -> np.ndarray:
    """Root-joint angles that follow on from frame to frame.

    Chosen frame by frame, a straight limb's start jumped between twists and
    between the two Euler triples of one rotation as it straightened or
    passed the side (rz −100° → 175°, rx to its 200° limit), and the
    smoothed solve between two branches pointed an arm 15–35° off for a
    beat.  So where the limb is straight (`free`: its twist is not seen), the
    last frame's rotation is carried on by the shortest swing onto this
    frame's direction; and in every frame the Euler triple nearer the last
    frame's is kept.  (The frame loop works on Python floats: numpy's
    per-call cost on 3-vectors made it a fifth of the whole fit.)

    Parameters
    ----------
    chosen : (T, 3) ndarray
        Per-frame choice (Euler angles, radians, within the limits).
    u : (T, 3) ndarray
        Segment direction in the parent's frame (unit).
    free : (T,) ndarray of bool
        Frames whose twist may be carried on (straight limb, direction known).
    best_cos : (T,) ndarray
        Cosine to `u` of the best per-frame candidate: a candidate that the
        limits keep further than 0.02 below it is not used.
    lim : (3, 2) ndarray
        The joint's limits, radians.
    """
    other = _other_triples(chosen, lim)
    ok_chosen = np.sum(-euler_to_matrix(chosen)[..., :, 2] * u, axis=-1) >= best_cos - 0.02
    ok_other = np.sum(-euler_to_matrix(other)[..., :, 2] * u, axis=-1) >= best_cos - 0.02
    lim_l = lim.tolist()
    out = chosen.copy()
    last = None
    for t in np.flatnonzero(np.all(np.isfinite(u), axis=1)):
        cands = []
        if free[t] and last is not None:
            ut = u[t].tolist()
            carried = _euler_in_limits_1(_swing_from(_rotation_1(last), ut), lim_l)
            for c in (carried, _other_triple_1(carried, lim_l)):
                if _axis_cos(c, ut) >= best_cos[t] - 0.02:
                    cands.append(c)
        if not cands:
            cands = [c.tolist() for c, ok in ((chosen[t], ok_chosen[t]), (other[t], ok_other[t])) if ok]
            cands = cands or [chosen[t].tolist()]
        if last is not None:
            cands.sort(key=lambda c: sum(abs(x - y) for x, y in zip(c, last)))
        last = cands[0]
        out[t] = last
    return out


def _other_triples(euler: np.ndarray, lim: np.ndarray) -> np.ndarray:
    """The other Euler triple of each rotation (..., 3), shifted by full turns into `lim` (3, 2) where it fits, clipped."""
    o = np.angle(np.exp(1j * np.stack([euler[..., 0] + np.pi, np.pi - euler[..., 1], euler[..., 2] + np.pi], -1)))
    return np.clip(_shifted_into(o, lim), lim[:, 0], lim[:, 1])


def _shifted_into(e: np.ndarray, lim: np.ndarray) -> np.ndarray:
    """Euler angles (..., 3) each shifted by a full turn where that brings it within `lim` (3, 2)."""
    return np.where(e < lim[:, 0], e + 2 * np.pi, np.where(e > lim[:, 1], e - 2 * np.pi, e))


# -- one rotation at a time, on Python floats (for the frame loop above) ------


def _rotation_1(e) -> list:
    """``Rz @ Ry @ Rx`` of one triple, as rows (see :func:`~capture2notation.body.euler_to_matrix`)."""
    cx, cy, cz = math.cos(e[0]), math.cos(e[1]), math.cos(e[2])
    sx, sy, sz = math.sin(e[0]), math.sin(e[1]), math.sin(e[2])
    return [
        [cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
        [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
        [-sy, cy * sx, cy * cx],
    ]


def _axis_cos(e, u) -> float:
    """Cosine between the segment direction (−z column) of triple `e` and `u`."""
    R = _rotation_1(e)
    return -(R[0][2] * u[0] + R[1][2] * u[1] + R[2][2] * u[2])


def _swing_from(R: list, u) -> list:
    """`R` turned by the shortest rotation that takes its −z column onto unit `u`."""
    a = [-R[0][2], -R[1][2], -R[2][2]]
    axis = [a[1] * u[2] - a[2] * u[1], a[2] * u[0] - a[0] * u[2], a[0] * u[1] - a[1] * u[0]]
    s = math.sqrt(sum(x * x for x in axis))
    dot = a[0] * u[0] + a[1] * u[1] + a[2] * u[2]
    if s <= 1e-9:
        if dot > 0:
            return R
        # Opposite: half a turn about any axis across the segment.
        axis = [0.0, -a[2], a[1]] if abs(a[0]) < 0.9 else [a[2], 0.0, -a[0]]
        s = math.sqrt(sum(x * x for x in axis))
    x, y, z = (v / s for v in axis)
    ang = math.atan2(math.sqrt(max(0.0, 1.0 - dot * dot)), dot)
    c, sn = math.cos(ang), math.sin(ang)
    C = 1 - c
    K = [
        [c + x * x * C, x * y * C - z * sn, x * z * C + y * sn],
        [y * x * C + z * sn, c + y * y * C, y * z * C - x * sn],
        [z * x * C - y * sn, z * y * C + x * sn, c + z * z * C],
    ]
    return [[sum(K[i][k] * R[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def _euler_in_limits_1(R: list, lim: list) -> list:
    """:func:`_euler_in_limits` of one rotation (rows `R`, limits as nested lists)."""
    ry = math.asin(max(-1.0, min(1.0, -R[2][0])))
    if abs(R[2][0]) > 1 - 1e-9:  # gimbal lock: all the turn in rx (as matrix_to_euler)
        e1 = [math.atan2(-R[1][2], R[1][1]), ry, 0.0]
    else:
        e1 = [math.atan2(R[2][1], R[2][2]), ry, math.atan2(R[1][0], R[0][0])]
    best, worst = None, math.inf
    for e in (e1, _other_triple_1(e1, None)):
        e = _into_1(e, lim)
        viol = sum(max(lo - v, 0.0) + max(v - hi, 0.0) for v, (lo, hi) in zip(e, lim))
        if viol < worst:
            best, worst = e, viol
    return [min(max(v, lo), hi) for v, (lo, hi) in zip(best, lim)]


def _other_triple_1(e, lim) -> list:
    """The other triple of rotation `e`, wrapped to (−π, π], then (with `lim`) shifted into the limits and clipped."""
    o = [math.remainder(v, 2 * math.pi) for v in (e[0] + math.pi, math.pi - e[1], e[2] + math.pi)]
    if lim is None:
        return o
    return [min(max(v, lo), hi) for v, (lo, hi) in zip(_into_1(o, lim), lim)]


def _into_1(e, lim) -> list:
    """:func:`_shifted_into` of one triple."""
    return [v + 2 * math.pi if v < lo else v - 2 * math.pi if v > hi else v for v, (lo, hi) in zip(e, lim)]
