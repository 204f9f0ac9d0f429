"""Head and chest: rigid segments whose direction is notated in the body frame.

The chest (waist → neck) is shared by the waist and chest joints; the head
(neck → head top) is turned by the neck.  Both directions are measured in
the body frame of DESIGN.md (world up, the hips' right), as the quantiser
reads them, so the neck compensates a tilted chest to keep the head where
its symbol (or its last symbol) puts it.

Where that convention meets the neck's extremes — an upright head held over
a chest bowed further than the neck bends back (60°), a head tilted 45°
sideways over a chest tilted the other way — the neck stops at its extreme
and the head is carried along by the chest, which is what a notator expects
of a tilting chest (the parts it carries go with it unless notated
otherwise); :mod:`synthetic.reach` reports the broken hold.  A chest target
beyond the waist's and chest's extremes (e.g. ``chest back middle``: the
spine arches 50° at most) is approached to the nearest reachable direction
all the way to the symbol's end (:func:`chest_reach`), not reached early.
"""

from __future__ import annotations

import numpy as np

from capture2notation.body import Body, euler_to_matrix, joint_index, matrix_to_euler
from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.effort import progress

from .rotations import Z as _Z
from .rotations import axis_angle, cross, slerp_dirs, unit

__all__ = ["chest_reach", "direction_track", "trunk_angles"]


def direction_track(symbols, part, frame, T, eff, reach=None):
    """(T,3) body-frame direction of a rigid segment (head, chest); rest = up.

    Parameters
    ----------
    symbols : sequence of Symbol
    part : str
    frame : callable
        Beat → frame index.
    T : int
        Number of frames.
    eff : Effort
    reach : callable, optional
        Maps a symbol's canonical vector (3,) to the nearest direction the
        extremes allow, so a target beyond them is approached all the way to
        the symbol's end instead of being reached early and held.
    """
    d = np.tile(_Z, (T, 1))
    syms = [x for x in symbols if x.part == part]
    if not syms:
        return d
    targets = np.array([canonical_vector(s.direction, s.level) for s in syms])
    if reach is not None:
        targets = reach(targets)
    for s, db in zip(syms, targets):
        f0, f1 = frame(s.start), frame(s.end)
        da = d[min(f0, T - 1)].copy()
        n = np.arange(f0 + 1, f1 + 1)
        d[n] = slerp_dirs(da, db, progress((n - f0) / max(f1 - f0, 1), eff.time, eff.weight))
        d[f1 + 1 :] = db
    return d


def chest_reach(body: Body):
    """The `reach` of :func:`direction_track` for the chest (waist → neck).

    Returns
    -------
    callable
        (N, 3) target directions → (N, 3) unit directions of waist → neck
        in the poses :func:`trunk_angles` gives for them (the targets
        themselves where the waist and chest can reach them).
    """
    o1, o2 = body.offsets[joint_index("chest")], body.offsets[joint_index("neck")]

    def reach(d):
        d = np.asarray(d, float)
        ew, ec = trunk_angles(d, body)
        Rw = euler_to_matrix(ew)
        v = Rw @ o1 + (Rw @ euler_to_matrix(ec)) @ o2
        v = unit(v)
        same = np.all(np.abs(v - d) < 1e-6, axis=-1)
        return np.where(same[:, None], d, v)

    return reach


def trunk_angles(d, body: Body):
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
    axis = cross(_Z, uniq)
    # Straight down has no tilt axis: bow forward (a turn about −x).
    axis[np.linalg.norm(axis, axis=-1) < 1e-9] = [-1.0, 0.0, 0.0]
    axis = unit(axis)
    target = np.arccos(np.clip(uniq[:, 2], -1, 1))

    def pose(phi):
        # The trunk's extremes lie within the principal Euler ranges.
        w = np.clip(matrix_to_euler(axis_angle(axis, phi * 2 / 3)), lw[:, 0], lw[:, 1])
        c = np.clip(matrix_to_euler(axis_angle(axis, phi / 3)), lc[:, 0], lc[:, 1])
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
