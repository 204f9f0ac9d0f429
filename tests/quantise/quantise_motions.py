"""Motions built directly with forward kinematics, for the quantiser's tests.

These do not depend on the virtual dancer: a movement eases one joint's
Euler angles from their current values to a target with the Effort logistic,
exactly as a notation symbol would (start at its start beat, arrive at its
end, each beat at its nearest frame as the renderer times them).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from capture2notation.body import JOINTS, forward_kinematics, joint_index
from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.effort import progress


def arm_angles(direction: str, level: str) -> np.ndarray:
    """Shoulder Euler angles pointing a straight, hanging arm along a symbol's canonical vector.

    Body-frame components (right, forward, up) equal world (x, y, z) for the
    performer standing at the origin facing +y.
    """
    v = canonical_vector(direction, level)
    rot, _ = Rotation.align_vectors([v], [[0.0, 0.0, -1.0]])
    m = rot.as_matrix()
    from capture2notation.body import matrix_to_euler

    return matrix_to_euler(m)


def build_motion(moves, tempo, fps=25.0, beats=None, b=-3.0, x0=0.45):
    """Joints of a motion made of joint-angle movements.

    Parameters
    ----------
    moves : list of (start, duration, joint, angles (3,))
        Start and duration in beats; each eases `joint` to `angles` (radians).
    tempo : float
        Beats per minute.
    beats : number, optional
        Length of the motion in beats (default: last arrival + 1).

    Returns
    -------
    joints : (T, J, 3) ndarray
    angles : (T, J, 3) ndarray
    """
    spb = 60.0 / tempo
    end = max(float(s + d) for s, d, _, _ in moves) + 1 if beats is None else float(beats)
    T = int(round(end * spb * fps)) + 1
    t = np.arange(T) / fps
    angles = np.zeros((T, len(JOINTS), 3))
    current = {}
    for s, d, joint, target in sorted(moves, key=lambda m: m[0]):
        j = joint_index(joint)
        cur = current.get(j, np.zeros(3))
        # Like the virtual dancer, a beat happens at its nearest frame.
        t0, t1 = (np.floor(float(x) * spb * fps + 0.5) / fps for x in (s, s + d))
        p = progress((t - t0) / (t1 - t0), b, x0)
        m = t >= t0
        angles[m, j] = cur + (np.asarray(target, float) - cur) * p[m, None]
        current[j] = np.asarray(target, float)
    return forward_kinematics(angles), angles
