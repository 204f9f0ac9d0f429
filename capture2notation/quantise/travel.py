"""Travel relative to the front: the motion with its turns taken out.

Steps are written relative to the current front (DESIGN.md, "Facing and
turns"), and a turning foot is still a supporting foot: it spins on the spot
(one foot) or slides round the feet's midpoint (two feet).  Both are read
from the **unturned** motion: every frame rotated about the vertical by
minus the front turned so far, and shifted so that whatever the dancer
pivots on (the centres of the feet on the floor, else the pelvis in the
air) stays where it is from frame to frame.  Outside turns the rotation and
the shift are constant, so a step or a travel keeps its path relative to
the front it starts from; inside a turn the pivot keeps its place, so a
pirouette's supporting foot stands still and a two-foot turn's feet stay
put.  It is the inverse of the virtual dancer's placing of its plan
(``synthetic/turning.py``): the truth's unturned motion is the plan, up to
one rigid motion.

Everything else the quantiser reads (limb directions in the body frame or
the body cross, knee bends, foot pitch and height) is unchanged by a
rotation about the vertical.
"""

from __future__ import annotations

import numpy as np

from ..body import joint_index
from .labels import foot_points

__all__ = ["unturn"]


def _rot(theta: np.ndarray) -> np.ndarray:
    """(n, 2, 2) counter-clockwise rotations by `theta` radians."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def unturn(joints: np.ndarray, turned_deg: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """The motion with its turns undone about their pivots.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    turned_deg : (T,) ndarray
        The front turned so far at each frame, degrees clockwise (constant
        outside turns; NaN counts as no change).
    contact : (T, 2) ndarray of bool
        Right, left foot on the floor (the pivot's feet).

    Returns
    -------
    (T, J, 3) ndarray
        ``R(θ_t) x + c_t`` per frame with θ_t the front turned (clockwise, so
        the rotation undoing it is counter-clockwise by θ_t) and ``c_t``
        chosen so that the pivot's unturned position changes only as the
        pivot itself moves; in the air the pelvis's unturned path is its
        room path turned by the front it took off with (DESIGN.md: it flies
        straight while the body turns about it).
    """
    joints = np.asarray(joints, float)
    T = joints.shape[0]
    theta = np.radians(np.nan_to_num(np.asarray(turned_deg, float) - float(np.nan_to_num(turned_deg[0]))))
    # A clockwise front is a negative rotation about z; undoing it is +θ.
    R = _rot(theta)
    _, mids = foot_points(joints)
    centres = np.stack(mids, axis=1)[:, :, :2]  # (T, 2, 2)
    pelvis = joints[:, joint_index("pelvis"), :2]
    c = np.asarray(contact, bool) & np.isfinite(centres).all(axis=-1)
    n = c.sum(axis=1)
    with np.errstate(invalid="ignore"):
        feet = np.nansum(np.where(c[..., None], centres, 0.0), axis=1) / np.maximum(n, 1)[:, None]
    pivot = np.where((n > 0)[:, None], feet, pelvis)
    pivot = np.where(np.isfinite(pivot), pivot, 0.0)
    shift = np.zeros((T, 2))
    take_off = R[0]  # the rotation undoing the front the body last stood with
    for t in range(1, T):
        if n[t] == 0 and np.all(np.isfinite(pelvis[t - 1 : t + 1])):
            # In the air the pelvis flies straight along the front it took
            # off with while the body turns about it: its unturned path is
            # its room path turned by the take-off front only.
            shift[t] = (
                R[t - 1] @ pelvis[t - 1] + shift[t - 1] + take_off @ (pelvis[t] - pelvis[t - 1]) - R[t] @ pelvis[t]
            )
            continue
        take_off = R[t]
        if theta[t] == theta[t - 1]:
            shift[t] = shift[t - 1]
            continue
        # R_t p + c_t = R_{t-1} p + c_{t-1}: the pivot does not jump.
        shift[t] = shift[t - 1] + (R[t - 1] - R[t]) @ pivot[t]
    out = joints.copy()
    out[..., :2] = np.einsum("tij,tkj->tki", R, joints[..., :2]) + shift[:, None, :]
    return out
