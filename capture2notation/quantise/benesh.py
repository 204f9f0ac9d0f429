"""Benesh key poses (Neagle 2005 §4.3–4.4; DESIGN.md "Benesh key poses").

At each key frame the four extremities (hands = wrists, feet = ankles) are
placed on the frontal plane against a five-line stave drawn from the
dancer's own proportions: floor (0), knee (1), hip (2), shoulder (3), top of
head (4).  Height is ``line + fraction`` (linear between lines; above the
head the head–shoulder spacing continues, so a wrist raised straight up
reads about 4.8; Neagle's Figure 4.6 writes 5.5 for the raised hand).  Width is the signed fraction (+ to the
performer's right, as the stave is read from behind) of the limb's maximal
reach — half the shoulder or hip width plus the straight limb — measured
from the body's centre line.  Depth is front / level / behind the body
plane.  Elbows and knees are recorded when their bend degree differs from
the default (straight, the starting pose of DESIGN.md; pass
``default_bend={"elbow": 1}`` for ballet's rounded arms).  Head and body
carry tilt (sideways, + to the right), turn (+ to the right, clockwise seen
from above) and bend (+ forward), in degrees.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from fractions import Fraction

import numpy as np

from ..atomic import write_text
from ..body import Body, body_frame, front_of, global_rotations, joint_index
from ..errors import QuantiseError
from ..notation.directions import bend_angle, bend_degree

__all__ = [
    "DEPTHS",
    "STAVE_LINES",
    "BeneshPose",
    "Extremity",
    "Orientation",
    "Stave",
    "benesh_json",
    "benesh_key_poses",
    "estimate_stave",
    "write_benesh",
]

#: Stave lines, bottom to top.
STAVE_LINES: tuple[str, ...] = ("floor", "knee", "hip", "shoulder", "head_top")
DEPTHS: tuple[str, ...] = ("front", "level", "behind")
#: An extremity within this fraction of its limb's reach of the body plane is level.
DEPTH_TOLERANCE = 0.2
_EXTREMITIES = {
    "right_hand": ("right_shoulder", "right_elbow", "right_wrist"),
    "left_hand": ("left_shoulder", "left_elbow", "left_wrist"),
    "right_foot": ("right_hip", "right_knee", "right_ankle"),
    "left_foot": ("left_hip", "left_knee", "left_ankle"),
}


@dataclass(frozen=True)
class Stave:
    """Heights of the five stave lines and the extremities' reaches.

    Attributes
    ----------
    lines : tuple of float
        Heights above the floor of floor, knee, hip, shoulder, top of head, metres.
    reach : tuple of (str, float)
        Maximal horizontal reach from the centre line per extremity, metres.
    floor : float
        Floor height in world z, metres.
    """

    lines: tuple
    reach: tuple
    floor: float = 0.0

    def reach_of(self, name: str) -> float:
        return dict(self.reach)[name]


@dataclass(frozen=True)
class Extremity:
    """An extremity on the stave: ``height`` (line + fraction), ``width`` (signed fraction of reach), ``depth``."""

    height: float
    width: float
    depth: str


@dataclass(frozen=True)
class Orientation:
    """Tilt, turn and bend of the head or the body, degrees (NaN when unobservable)."""

    tilt: float
    turn: float
    bend: float


@dataclass(frozen=True)
class BeneshPose:
    """One key pose.

    Attributes
    ----------
    frame : int
    time : float
        Seconds.
    beat : Fraction or None
        Position on the beat grid, when the tempo is known.
    extremities : tuple of (str, Extremity)
        ``right_hand``, ``left_hand``, ``right_foot``, ``left_foot``.
    bends : tuple of (str, int)
        Elbows / knees whose bend degree differs from the default.
    head, body : Orientation
    facing : float
        The front at the pose: degrees clockwise seen from above from the
        room's +y, unwrapped through the whole motion (DESIGN.md, "Facing
        and turns"); NaN when the hips are not seen.
    """

    frame: int
    time: float
    beat: Fraction | None
    extremities: tuple
    bends: tuple
    head: Orientation
    body: Orientation = field(default_factory=lambda: Orientation(np.nan, np.nan, np.nan))
    facing: float = float("nan")


def _median_length(joints: np.ndarray, a: str, b: str) -> float:
    d = np.linalg.norm(joints[:, joint_index(b)] - joints[:, joint_index(a)], axis=-1)
    d = d[np.isfinite(d)]
    if d.size == 0:
        raise QuantiseError(f"no frame has both {a} and {b}: cannot size the Benesh stave")
    return float(np.median(d))


def estimate_stave(joints: np.ndarray, floor: float = 0.0) -> Stave:
    """Stave lines from the dancer's proportions.

    The body height is estimated from the median leg length (hip → knee →
    ankle, robust to pliés and gestures) and the lines are those of
    :class:`~capture2notation.body.Body` at that height, so they belong to the
    dancer standing upright, not to the pose of any one frame.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
    floor : float

    Returns
    -------
    Stave
    """
    joints = np.asarray(joints, dtype=float)
    ref = Body()
    leg = _median_length(joints, "right_hip", "right_knee") + _median_length(joints, "right_knee", "right_ankle")
    ref_leg = ref.segment_length("right_hip", "right_knee") + ref.segment_length("right_knee", "right_ankle")
    height = float(np.clip(ref.height * leg / ref_leg, 0.3, 3.0))
    body = Body(height)
    z = body.rest[:, 2]
    lines = (0.0, z[joint_index("right_knee")], z[joint_index("right_hip")], z[joint_index("right_shoulder")], height)
    reach = []
    for name, (a, m, b) in _EXTREMITIES.items():
        half = 0.5 * _median_length(
            joints, a, a.replace("right", "left") if "right" in a else a.replace("left", "right")
        )
        reach.append((name, half + _median_length(joints, a, m) + _median_length(joints, m, b)))
    return Stave(lines=tuple(float(v) for v in lines), reach=tuple(reach), floor=float(floor))


def _piecewise(z: np.ndarray, ext: np.ndarray) -> np.ndarray:
    """Line + fraction of heights `z` above the floor, `ext` the lines plus one extrapolated line."""
    k = np.clip(np.searchsorted(ext, z, side="right") - 1, 0, ext.size - 2)
    frac = (z - ext[k]) / (ext[k + 1] - ext[k])
    # The last interval extends upward, so heights above the head read beyond 4.
    return np.where(z < 0, z / ext[1], k + frac)


def _orientation(v: np.ndarray, turn: float) -> Orientation:
    """Tilt and bend of a body-frame up-pointing vector (right, forward, up)."""
    r, f, u = v
    return Orientation(
        tilt=float(np.degrees(np.arctan2(r, u))),
        turn=float(turn),
        bend=float(np.degrees(np.arctan2(f, u))),
    )


def _signed_turn(h: np.ndarray, s: np.ndarray) -> float:
    """Clockwise (seen from above) angle from horizontal vector h to s, degrees."""
    cross = h[0] * s[1] - h[1] * s[0]
    return float(-np.degrees(np.arctan2(cross, h[0] * s[0] + h[1] * s[1])))


def benesh_key_poses(
    joints: np.ndarray,
    frames,
    fps: float,
    tempo=None,
    grid: Fraction = Fraction(1, 4),
    angles: np.ndarray | None = None,
    floor: float = 0.0,
    default_bend: dict | None = None,
    stave: Stave | None = None,
) -> tuple[Stave, list[BeneshPose]]:
    """Benesh key poses at the given frames.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World joints, metres, z up.
    frames : sequence of int
        Key frames (e.g. :attr:`Segmentation.key_frames`).
    fps : float
    tempo : number, optional
        Beats per minute; gives each pose a beat on `grid`.
    grid : Fraction
    angles : (T, J, 3) ndarray, optional
        Joint angles; needed for the head's turn (NaN without them).
    floor : float
    default_bend : dict, optional
        Default bend degree of ``"elbow"`` and ``"knee"`` (0 and 0).
    stave : Stave, optional
        Precomputed :func:`estimate_stave`.

    Returns
    -------
    stave : Stave
    poses : list of BeneshPose
    """
    from .tempo import snap

    joints = np.asarray(joints, dtype=float)
    T = joints.shape[0]
    frames = [int(f) for f in frames]
    for f in frames:
        if not 0 <= f < T:
            raise QuantiseError(f"key frame {f} is outside the motion's frames 0..{T - 1}")
    defaults = {"elbow": 0, "knee": 0, **(default_bend or {})}
    stave = stave or estimate_stave(joints, floor)
    lines = np.asarray(stave.lines)
    J = joints[frames]
    frame = body_frame(J)  # (K, 3, 3) rows right, forward, up
    # The front over the whole motion, so it unwraps through every turn.
    facing = front_of(body_frame(joints)[:, 1])[frames] if frames else np.zeros(0)
    mid_hip = 0.5 * (J[:, joint_index("right_hip")] + J[:, joint_index("left_hip")])
    mid_sh = 0.5 * (J[:, joint_index("right_shoulder")] + J[:, joint_index("left_shoulder")])
    head_turn = np.full(len(frames), np.nan)
    if angles is not None:
        g = global_rotations(np.asarray(angles, dtype=float)[frames])
        fwd = g[:, joint_index("neck")] @ np.array([0.0, 1.0, 0.0])
        pel = g[:, joint_index("pelvis")] @ np.array([0.0, 1.0, 0.0])
        head_turn = np.array([_signed_turn(p[:2], h[:2]) for p, h in zip(pel, fwd)])
    poses = []
    for i, f in enumerate(frames):
        R = frame[i]
        ext = []
        for name, (_a, _m, b) in _EXTREMITIES.items():
            p = J[i, joint_index(b)]
            centre = mid_sh[i] if name.endswith("hand") else mid_hip[i]
            reach = stave.reach_of(name)
            rel = R @ (p - centre)
            height = float(_piecewise(np.array([p[2] - stave.floor]), np.r_[lines, 2 * lines[-1] - lines[-2]])[0])
            width = float(rel[0] / reach)
            depth = (
                "front"
                if rel[1] > DEPTH_TOLERANCE * reach
                else "behind"
                if rel[1] < -DEPTH_TOLERANCE * reach
                else "level"
            )
            ext.append((name, Extremity(round(height, 3), round(width, 3), depth)))
        bends = []
        for side in ("right", "left"):
            for mid, (a, b) in (("elbow", ("shoulder", "wrist")), ("knee", ("hip", "ankle"))):
                beta = bend_angle(
                    J[i, joint_index(f"{side}_{a}")],
                    J[i, joint_index(f"{side}_{mid}")],
                    J[i, joint_index(f"{side}_{b}")],
                )
                k = int(bend_degree(beta))
                if k >= 0 and k != defaults[mid]:
                    bends.append((f"{side}_{mid}", k))
        head_v = R @ (J[i, joint_index("head")] - J[i, joint_index("neck")])
        chest_v = R @ (J[i, joint_index("neck")] - J[i, joint_index("waist")])
        sh = J[i, joint_index("right_shoulder")] - J[i, joint_index("left_shoulder")]
        hp = J[i, joint_index("right_hip")] - J[i, joint_index("left_hip")]
        poses.append(
            BeneshPose(
                frame=f,
                time=f / float(fps),
                beat=None if tempo is None else snap(f / float(fps), tempo, grid),
                extremities=tuple(ext),
                bends=tuple(bends),
                head=_orientation(head_v, head_turn[i]),
                body=_orientation(chest_v, _signed_turn(hp[:2], sh[:2])),
                facing=float(facing[i]),
            )
        )
    return stave, poses


def _num(x):
    if isinstance(x, Fraction):
        return str(x)
    if isinstance(x, float):
        return None if not np.isfinite(x) else round(x, 2)
    return x


def benesh_json(stave: Stave, poses: list[BeneshPose], tempo=None) -> str:
    """The ``benesh.json`` text: the stave and every key pose."""
    doc = {
        "stave": {
            "lines": dict(zip(STAVE_LINES, (round(v, 4) for v in stave.lines))),
            "reach": {k: round(v, 4) for k, v in stave.reach},
            "floor": stave.floor,
            "units": "metres above the floor; height = line + fraction, width = fraction of reach (+ right)",
        },
        "tempo": None if tempo is None else str(Fraction(tempo)),
        "facing_units": "degrees clockwise seen from above from the room's +y, unwrapped through turns",
        "poses": [
            {
                "frame": p.frame,
                "time": round(p.time, 4),
                "beat": _num(p.beat),
                "extremities": {k: asdict(e) for k, e in p.extremities},
                "bends": dict(p.bends),
                "head": {k: _num(v) for k, v in asdict(p.head).items()},
                "body": {k: _num(v) for k, v in asdict(p.body).items()},
                "facing": _num(p.facing),
            }
            for p in poses
        ],
    }
    return json.dumps(doc, indent=1)


def write_benesh(path, stave: Stave, poses: list[BeneshPose], tempo=None) -> None:
    """Atomically write :func:`benesh_json` to `path`."""
    write_text(path, benesh_json(stave, poses, tempo))
