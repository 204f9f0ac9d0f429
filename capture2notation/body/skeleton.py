"""The canonical joint tree, its proportions and its joint limits.

Names are the contract (``../shared/DESIGN.md``): look joints up by name,
never by count.  World frame: right-handed, metres, z up, floor at z = 0; the
performer stands at the origin facing +y with their right on +x.

At rest every joint's local frame is aligned with the world axes, arms and legs
hang straight down, head and chest are upright.  A joint's local rotation turns
everything below it (its children's offsets).  Angles are Euler angles
``(rx, ry, rz)`` in radians, composed as ``R = Rz(rz) @ Ry(ry) @ Rx(rx)``
(see :mod:`capture2notation.body.kinematics`):

* ``rx`` > 0 swings a hanging limb forward (shoulder flexion, hip flexion,
  elbow flexion); knees flex with ``rx`` < 0;
* ``ry`` > 0 swings a hanging limb towards the performer's left (−x);
* ``rz`` twists about the vertical.

Segment lengths follow Drillis & Contini's proportions of body height, as
tabulated by Winter (Biomechanics and Motor Control of Human Movement, 2009,
Fig. 4.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ..errors import BodyModelError

__all__ = [
    "BLAZEPOSE_LANDMARKS",
    "BLAZEPOSE_TO_JOINT",
    "JOINTS",
    "JOINT_INDEX",
    "JOINT_TO_BLAZEPOSE",
    "LIMITS_DEG",
    "PARENT",
    "Body",
    "joint_index",
]

#: Joints in topological order (every parent before its children).
JOINTS: tuple[str, ...] = (
    "pelvis",
    "waist",
    "chest",
    "neck",
    "head",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "right_hand_tip",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "left_hand_tip",
    "right_hip",
    "right_knee",
    "right_ankle",
    "right_toe",
    "left_hip",
    "left_knee",
    "left_ankle",
    "left_toe",
)

#: Parent of each joint (``None`` for the root).
PARENT: MappingProxyType = MappingProxyType(
    {
        "pelvis": None,
        "waist": "pelvis",
        "chest": "waist",
        "neck": "chest",
        "head": "neck",
        "right_shoulder": "chest",
        "right_elbow": "right_shoulder",
        "right_wrist": "right_elbow",
        "right_hand_tip": "right_wrist",
        "left_shoulder": "chest",
        "left_elbow": "left_shoulder",
        "left_wrist": "left_elbow",
        "left_hand_tip": "left_wrist",
        "right_hip": "pelvis",
        "right_knee": "right_hip",
        "right_ankle": "right_knee",
        "right_toe": "right_ankle",
        "left_hip": "pelvis",
        "left_knee": "left_hip",
        "left_ankle": "left_knee",
        "left_toe": "left_ankle",
    }
)

JOINT_INDEX: MappingProxyType = MappingProxyType({n: i for i, n in enumerate(JOINTS)})


def joint_index(name: str) -> int:
    """Index of joint `name` in :data:`JOINTS`; raise a clear error if unknown."""
    try:
        return JOINT_INDEX[name]
    except KeyError:
        raise BodyModelError(f"unknown joint {name!r}; expected one of {', '.join(JOINTS)}") from None


#: The 33 BlazePose landmarks, in model output order.
BLAZEPOSE_LANDMARKS: tuple[str, ...] = (
    "nose",
    "left_eye_inner",
    "left_eye",
    "left_eye_outer",
    "right_eye_inner",
    "right_eye",
    "right_eye_outer",
    "left_ear",
    "right_ear",
    "mouth_left",
    "mouth_right",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_pinky",
    "right_pinky",
    "left_index",
    "right_index",
    "left_thumb",
    "right_thumb",
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
    "left_heel",
    "right_heel",
    "left_foot_index",
    "right_foot_index",
)

#: Landmarks that correspond one-to-one to a joint of the tree.
BLAZEPOSE_TO_JOINT: MappingProxyType = MappingProxyType(
    {
        11: "left_shoulder",
        12: "right_shoulder",
        13: "left_elbow",
        14: "right_elbow",
        15: "left_wrist",
        16: "right_wrist",
        19: "left_hand_tip",  # index finger tip
        20: "right_hand_tip",
        23: "left_hip",
        24: "right_hip",
        25: "left_knee",
        26: "right_knee",
        27: "left_ankle",
        28: "right_ankle",
        31: "left_toe",  # foot index
        32: "right_toe",
    }
)
JOINT_TO_BLAZEPOSE: MappingProxyType = MappingProxyType({j: i for i, j in BLAZEPOSE_TO_JOINT.items()})

#: Joint limits ("extremes", Cachola 1986 §3) in degrees, (min, max) per axis
#: (rx, ry, rz) for the *right* side and the trunk; the left side mirrors ry
#: and rz.  An axis with (0, 0) is locked.
LIMITS_DEG: MappingProxyType = MappingProxyType(
    {
        "pelvis": ((-180, 180), (-180, 180), (-180, 180)),
        # For upright segments rx < 0 bends forward (flexion), rx > 0 back.
        "waist": ((-60, 30), (-35, 35), (-40, 40)),
        "chest": ((-30, 20), (-20, 20), (-30, 30)),
        # The neck stands for the whole cervical spine and the head's nod:
        # it bows the head to the horizontal (DESIGN.md's head forward middle).
        "neck": ((-90, 60), (-45, 45), (-80, 80)),
        "head": ((0, 0), (0, 0), (0, 0)),
        # Shoulder flexion beyond 180 and a full circle of twist let the arm
        # pass through place high/low without a flip (Wolofsky ch. IV).
        "right_shoulder": ((-90, 200), (-200, 90), (-180, 180)),
        "right_elbow": ((0, 155), (0, 0), (0, 0)),
        "right_wrist": ((-70, 80), (-30, 30), (0, 0)),
        "right_hand_tip": ((0, 0), (0, 0), (0, 0)),
        # A dancer's hip: the leg reaches side middle (à la seconde, Figure 7's
        # phrase) and back middle (arabesque).
        "right_hip": ((-90, 135), (-95, 45), (-60, 60)),
        "right_knee": ((-155, 0), (0, 0), (0, 0)),
        "right_ankle": ((-50, 40), (-25, 25), (0, 0)),  # dorsiflexion 40: a deep plie
        "right_toe": ((0, 0), (0, 0), (0, 0)),
    }
)


def _mirror(name: str) -> str:
    if name.startswith("left_"):
        return "right_" + name[5:]
    if name.startswith("right_"):
        return "left_" + name[6:]
    return name


def _limits_array() -> np.ndarray:
    lim = np.zeros((len(JOINTS), 3, 2))
    for j, name in enumerate(JOINTS):
        if name.startswith("left_"):
            (ax, ay, az) = LIMITS_DEG[_mirror(name)]
            # Mirroring across the sagittal plane negates ry and rz.
            lim[j] = [ax, (-ay[1], -ay[0]), (-az[1], -az[0])]
        else:
            lim[j] = LIMITS_DEG[name]
    return np.deg2rad(lim)


# Rest positions as fractions of body height H (x right, y forward, z up).
# Drillis & Contini via Winter (2009): shoulder height 0.818 H, hip 0.530 H,
# knee 0.285 H, ankle 0.039 H, upper arm 0.186 H, forearm 0.146 H,
# hand 0.108 H, foot length 0.152 H, shoulder width 0.259 H.
_REST_FRACTIONS: dict[str, tuple[float, float, float]] = {
    "pelvis": (0.0, 0.0, 0.530),
    "waist": (0.0, 0.0, 0.630),
    "chest": (0.0, 0.0, 0.720),
    "neck": (0.0, 0.0, 0.818),
    "head": (0.0, 0.0, 1.000),
    "right_shoulder": (0.115, 0.0, 0.818),
    "right_elbow": (0.115, 0.0, 0.632),
    "right_wrist": (0.115, 0.0, 0.486),
    "right_hand_tip": (0.115, 0.0, 0.378),
    "right_hip": (0.055, 0.0, 0.530),
    "right_knee": (0.055, 0.0, 0.285),
    "right_ankle": (0.055, 0.0, 0.039),
    "right_toe": (0.055, 0.115, 0.006),
}


def _rest_positions(height: float) -> np.ndarray:
    pos = np.zeros((len(JOINTS), 3))
    for j, name in enumerate(JOINTS):
        if name.startswith("left_"):
            x, y, z = _REST_FRACTIONS[_mirror(name)]
            x = -x
        else:
            x, y, z = _REST_FRACTIONS[name]
        pos[j] = (x, y, z)
    return pos * height


@dataclass(frozen=True, eq=False)
class Body:
    """An articulated figure: the joint tree at a given size.

    Parameters
    ----------
    height : float
        Standing height in metres (top of head), default 1.70.
    limit_scale : float
        Multiplies every joint extreme (Cachola's ``SCALE EXTREMES``); a
        negative value mirrors the ranges.

    Attributes
    ----------
    rest : (J, 3) ndarray
        Joint positions at rest, metres, world frame.
    offsets : (J, 3) ndarray
        Offset of each joint from its parent at rest (zero for the root).
    parents : (J,) ndarray of int
        Parent index, -1 for the root.
    limits : (J, 3, 2) ndarray
        (min, max) of (rx, ry, rz) per joint, radians.
    """

    height: float = 1.70
    limit_scale: float = 1.0
    rest: np.ndarray = field(init=False, repr=False)
    offsets: np.ndarray = field(init=False, repr=False)
    parents: np.ndarray = field(init=False, repr=False)
    limits: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        if not (np.isfinite(self.height) and 0.3 <= self.height <= 3.0):
            raise BodyModelError(f"body height {self.height!r} m is outside the plausible range 0.3-3.0 m")
        rest = _rest_positions(float(self.height))
        parents = np.array([-1 if PARENT[n] is None else JOINT_INDEX[PARENT[n]] for n in JOINTS])
        offsets = rest - np.where(parents[:, None] >= 0, rest[parents], 0.0)
        offsets[0] = 0.0
        limits = _limits_array() * self.limit_scale
        limits.sort(axis=-1)  # a negative scale swaps min and max
        for name, value in (("rest", rest), ("offsets", offsets), ("parents", parents), ("limits", limits)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    def __eq__(self, other):
        if not isinstance(other, Body):
            return NotImplemented
        return (self.height, self.limit_scale) == (other.height, other.limit_scale)

    def __hash__(self):
        return hash((self.height, self.limit_scale))

    def segment_length(self, a: str, b: str) -> float:
        """Rest distance between joints `a` and `b`, metres."""
        return float(np.linalg.norm(self.rest[joint_index(b)] - self.rest[joint_index(a)]))

    def clip(self, angles: np.ndarray) -> np.ndarray:
        """Enforce the joint extremes.

        Parameters
        ----------
        angles : (..., J, 3) ndarray
            Euler angles, radians.

        Returns
        -------
        (..., J, 3) ndarray
            `angles` clipped into ``limits`` (a new array).
        """
        angles = np.asarray(angles, dtype=float)
        if angles.shape[-2:] != (len(JOINTS), 3):
            raise BodyModelError(f"angles must have shape (..., {len(JOINTS)}, 3), got {angles.shape}")
        return np.clip(angles, self.limits[..., 0], self.limits[..., 1])
