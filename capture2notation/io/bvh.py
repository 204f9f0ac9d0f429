"""BVH motion capture files: read any common skeleton, write ours.

Reading parses the hierarchy and the motion block, runs the file's own
forward kinematics (rotation channels compose in the order listed:
``Zrotation Xrotation Yrotation`` is ``Rz @ Rx @ Ry``), and maps joint names
onto :data:`~capture2notation.body.JOINTS` with :data:`NAME_TABLE` (CMU,
Mixamo / Rokoko with or without the ``mixamorig:`` prefix, the
"Chest / LeftCollar / LeftShoulder / LeftElbow" style of the bvh-python test
file, and our own names), optionally overridden by a user map.  End sites are
named ``<joint>_End`` so that e.g. ``Head_End`` (top of the head) and
``LeftWrist_End`` (hand tip) can be mapped too.

Positions are converted to our world frame: the up axis is detected from the
rest skeleton (BVH is usually y-up), the length unit is chosen among metres,
centimetres, millimetres, inches and CMU units so the figure is 1.2–2.2 m tall
(otherwise it is scaled to 1.70 m with a warning); see
:func:`capture2notation.fitting.motion.normalise_world` for floor and facing.

Writing produces our skeleton in a y-up file (as Blender, MotionBuilder and
Mixamo expect), centimetres by default, every joint with channels
``Yrotation Zrotation Xrotation`` so that the file's ``Ry Rz Rx`` is exactly
our ``Rz Ry Rx`` seen in y-up axes.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..body import JOINTS, Body
from ..errors import MotionFileError

__all__ = [
    "NAME_TABLE",
    "BvhSkeleton",
    "bvh_positions",
    "map_joints",
    "parse_bvh",
    "read_bvh_points",
    "read_own_bvh",
    "write_bvh",
    "write_motion_bvh",
]

log = logging.getLogger(__name__)

#: Candidate source names for each of our joints, in order of preference,
#: compared after :func:`canonical_name`.  Order matters where styles clash:
#: Mixamo's ``LeftShoulder`` is the collar bone (its shoulder is ``LeftArm``),
#: the bvh-python style's ``LeftShoulder`` is the shoulder.
_SIDED = {
    "shoulder": ["{s}arm", "{s}upperarm", "{s}shoulder", "{c}shoulder"],
    "elbow": ["{s}forearm", "{s}elbow", "{s}lowerarm", "{c}elbow"],
    "wrist": ["{s}hand", "{s}wrist", "{c}wrist", "{c}hand"],
    "hand_tip": [
        "{s}handmiddle3end",
        "{s}handmiddle4",
        "{s}handindex3end",
        "{s}handindex1",
        "{s}fingerbase",
        "{s}wristend",
        "{s}handend",
        "{s}handtip",
        "{s}handthumb1",
    ],
    "hip": ["{s}upleg", "{s}upperleg", "{s}thigh", "{s}hip", "{c}hip"],
    "knee": ["{s}leg", "{s}lowerleg", "{s}shin", "{s}knee", "{c}knee"],
    "ankle": ["{s}foot", "{s}ankle", "{c}ankle", "{c}foot"],
    "toe": ["{s}toebase", "{s}toe", "{s}toes", "{s}ankleend", "{s}footend", "{c}toe"],
}
NAME_TABLE: dict[str, list[str]] = {
    "pelvis": ["hips", "hip", "pelvis", "root"],
    "waist": ["spine", "lowerback", "abdomen", "chest", "torso", "spine0"],
    "chest": ["spine1", "chest2", "spine2", "upperchest", "chest", "spine3", "thorax"],
    "neck": ["neck", "neck1"],
    "head": ["headtopend", "headend", "headtop", "headsite"],
    **{
        f"{side}_{part}": [c.format(s=side, c=side[0]) for c in cands]
        for side in ("right", "left")
        for part, cands in _SIDED.items()
    },
}
#: Source joints approximating the centre of the head (used when no head top).
HEAD_CENTRE_NAMES = ("head", "head1")

_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254, "cmu": 0.0254 / 0.45}


def canonical_name(name: str) -> str:
    """Lower-case name without namespace prefix (``mixamorig:``) and separators."""
    name = name.rsplit(":", 1)[-1]
    name = re.sub(r"^(bip0?1|character\d*|def)[ _]", "", name, flags=re.I)
    return re.sub(r"[^a-z0-9]", "", name.lower())


@dataclass(frozen=True)
class BvhSkeleton:
    """A parsed BVH file.

    Attributes
    ----------
    names : list of str
        Joints and end sites (``<parent>_End``) in file order.
    parents : (N,) ndarray of int
        -1 for the root.
    offsets : (N, 3) ndarray
        File units, file axes.
    channels : list of list of str
        Channel names per joint (empty for end sites).
    motion : (T, C) ndarray
        Channel values, degrees for rotations.
    frame_time : float
        Seconds per frame.
    """

    names: list
    parents: np.ndarray
    offsets: np.ndarray
    channels: list
    motion: np.ndarray
    frame_time: float

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time


def parse_bvh(path) -> BvhSkeleton:
    """Parse a BVH file; errors name the file, line and what was expected."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise MotionFileError(f"{path}: cannot read BVH file: {exc.strerror}") from None
    lines = text.splitlines()
    tokens = [(tok, i + 1) for i, line in enumerate(lines) for tok in line.split()]
    pos = 0

    def take(expect=None):
        nonlocal pos
        if pos >= len(tokens):
            raise MotionFileError(f"{path}: unexpected end of file; expected {expect or 'more data'}")
        tok, ln = tokens[pos]
        if expect is not None and tok.upper() != expect.upper():
            raise MotionFileError(f"{path}:{ln}: expected {expect!r}, found {tok!r}")
        pos += 1
        return tok, ln

    def number(what):
        tok, ln = take()
        try:
            return float(tok)
        except ValueError:
            raise MotionFileError(f"{path}:{ln}: expected a number for {what}, found {tok!r}") from None

    take("HIERARCHY")
    names: list[str] = []
    parents: list[int] = []
    offsets: list = []
    channels: list = []
    stack: list[int] = []
    tok, ln = take("ROOT")
    kind = "ROOT"
    while True:
        if kind in ("ROOT", "JOINT"):
            name, _ = take()
        else:  # End Site
            take("Site")
            name = f"{names[stack[-1]]}_End"
        take("{")
        idx = len(names)
        names.append(name)
        parents.append(stack[-1] if stack else -1)
        take("OFFSET")
        offsets.append([number(f"OFFSET of {name}") for _ in range(3)])
        chans = []
        if kind != "End" and pos < len(tokens) and tokens[pos][0].upper() == "CHANNELS":
            take("CHANNELS")
            n = number(f"CHANNELS count of {name}")
            for _ in range(int(n)):
                c, cl = take()
                if c.lower() not in ("xposition", "yposition", "zposition", "xrotation", "yrotation", "zrotation"):
                    raise MotionFileError(f"{path}:{cl}: unknown channel {c!r} of joint {name}")
                chans.append(c.lower())
        channels.append(chans)
        stack.append(idx)
        # Children or closing braces.
        while True:
            tok, ln = take()
            up = tok.upper()
            if up == "}":
                stack.pop()
                if not stack:
                    break
                continue
            if up in ("JOINT", "END"):
                kind = "JOINT" if up == "JOINT" else "End"
                break
            if up == "ROOT":
                raise MotionFileError(f"{path}:{ln}: a second ROOT is not supported (one performer per file)")
            raise MotionFileError(f"{path}:{ln}: expected JOINT, End Site or '}}', found {tok!r}")
        if not stack:
            break
    take("MOTION")
    take("Frames:")
    n_frames = int(number("Frames"))
    take("Frame")
    take("Time:")
    frame_time = number("Frame Time")
    if not frame_time > 0:
        raise MotionFileError(f"{path}: Frame Time must be positive, got {frame_time}")
    n_ch = sum(len(c) for c in channels)
    rest = tokens[pos:]
    try:
        values = np.array([float(t) for t, _ in rest], dtype=float)
    except ValueError:
        bad = next((t, ln) for t, ln in rest if not _is_float(t))
        raise MotionFileError(f"{path}:{bad[1]}: expected a channel value, found {bad[0]!r}") from None
    if values.size < n_frames * n_ch:
        raise MotionFileError(
            f"{path}: motion block has {values.size} values, expected {n_frames} frames × {n_ch} channels = {n_frames * n_ch}"
        )
    if values.size > n_frames * n_ch:
        log.warning("%s: %d values after the %d declared frames ignored", path, values.size - n_frames * n_ch, n_frames)
    motion = values[: n_frames * n_ch].reshape(n_frames, n_ch)
    return BvhSkeleton(names, np.array(parents), np.array(offsets, float), channels, motion, frame_time)


def _is_float(t: str) -> bool:
    try:
        float(t)
        return True
    except ValueError:
        return False


def _axis_rotation(axis: str, deg: np.ndarray) -> np.ndarray:
    a = np.deg2rad(deg)
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(a.shape + (3, 3))
    i = "xyz".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    m[..., i, i] = 1.0
    m[..., j, j] = c
    m[..., k, k] = c
    m[..., k, j] = s
    m[..., j, k] = -s
    return m


def bvh_positions(skel: BvhSkeleton) -> np.ndarray:
    """World positions of every joint and end site, file units and axes, ``(T, N, 3)``."""
    T = skel.motion.shape[0]
    N = len(skel.names)
    pos = np.zeros((T, N, 3))
    glob = np.zeros((T, N, 3, 3))
    col = 0
    for i in range(N):
        p = skel.parents[i]
        local_t = np.broadcast_to(skel.offsets[i], (T, 3)).copy()
        rot = np.broadcast_to(np.eye(3), (T, 3, 3)).copy()
        for ch in skel.channels[i]:
            v = skel.motion[:, col]
            col += 1
            if ch.endswith("position"):
                local_t[:, "xyz".index(ch[0])] = v
            else:
                rot = rot @ _axis_rotation(ch[0], v)
        if p < 0:
            pos[:, i] = local_t
            glob[:, i] = rot
        else:
            pos[:, i] = pos[:, p] + np.einsum("tij,tj->ti", glob[:, p], local_t)
            glob[:, i] = glob[:, p] @ rot
    return pos


def _up_and_unit(pos: np.ndarray, pelvis: int, top: int) -> tuple[np.ndarray, float]:
    """Rotation from file axes to z-up, and metres per file unit.

    Parameters
    ----------
    pos : (T, N, 3) ndarray
        Animated positions, file units and axes (rest poses of some exporters
        are not upright, so the animation decides).
    pelvis, top : int
        Indices of the pelvis and of a point above it (head or neck).
    """
    up_vec = np.median(pos[:, top] - pos[:, pelvis], axis=0)
    up = int(np.argmax(np.abs(up_vec)))
    sign = 1.0 if up_vec[up] >= 0 else -1.0
    to_z = {
        0: np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0]]),  # x up -> z
        1: np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]),  # y up -> z
        2: np.eye(3),
    }[up].astype(float)
    if sign < 0:
        to_z = np.diag([1.0, -1.0, -1.0]) @ to_z
    extent = pos[..., up].max(axis=1) - pos[..., up].min(axis=1)
    height = float(np.percentile(extent, 95))
    unit = min(_UNITS.values(), key=lambda u: abs(np.log(max(height * u, 1e-9) / 1.7)))
    if not 1.2 <= height * unit <= 2.2:
        unit = 1.7 / height if height > 0 else 1.0
        log.warning("BVH figure is %.3g units tall: no known unit gives 1.2-2.2 m; scaled to 1.70 m", height)
    return to_z, unit


def map_joints(names, joint_map: dict | None = None) -> dict[str, int]:
    """Our joint name -> index of the source joint measuring it.

    Parameters
    ----------
    names : list of str
        Source joint (and end site) names.
    joint_map : dict, optional
        Source name -> our joint name; takes precedence over :data:`NAME_TABLE`.
        An unknown name on either side raises :class:`MotionFileError`.
    """
    out: dict[str, int] = {}
    used: set[int] = set()
    if set(JOINTS) <= set(names) and not joint_map:  # one of our own files
        return {j: names.index(j) for j in JOINTS}
    for src, ours in (joint_map or {}).items():
        if ours not in JOINTS and ours != "head_centre":
            raise MotionFileError(f"joint map: {ours!r} is not one of our joints ({', '.join(JOINTS)})")
        if src not in names:
            raise MotionFileError(f"joint map: source joint {src!r} is not in the file (it has {', '.join(names)})")
        out[ours] = names.index(src)
        used.add(names.index(src))
    canon = [canonical_name(n) for n in names]
    for ours, cands in NAME_TABLE.items():
        if ours in out:
            continue
        for c in cands:
            hits = [i for i, n in enumerate(canon) if n == c and i not in used]
            if hits:
                out[ours] = hits[0]
                used.add(hits[0])
                break
    if "head" not in out and "head_centre" not in out:
        hits = [i for i, n in enumerate(canon) if n in HEAD_CENTRE_NAMES and i not in used]
        if hits:
            out["head_centre"] = hits[0]
    return out


def _check_head_top(mapping: dict, names, pos: np.ndarray, joint_map) -> None:
    """Drop a head-top end site that does not point up from the head joint.

    Some exporters (Rokoko) leave end-site offsets along a bone's local x, so
    ``Head_End`` is beside the head rather than on top; the head joint is
    then used as the head centre.
    """
    if "head" not in mapping or (joint_map and "head" in joint_map.values()):
        return
    i = mapping["head"]
    if not names[i].endswith("_End"):
        return
    parent_name = names[i][: -len("_End")]
    if parent_name not in names:
        return
    v = np.median(pos[:, i] - pos[:, names.index(parent_name)], axis=0)
    if v[2] < 0.3 * np.linalg.norm(v):  # sideways, not a tilted head
        del mapping["head"]
        mapping["head_centre"] = names.index(parent_name)


def read_bvh_points(path, joint_map: dict | None = None, where=None):
    """Our joints' positions from a BVH file, metres, z up (not yet floored or turned).

    Parameters
    ----------
    path : str, Path or BvhSkeleton
        The file, or its parsed contents.
    joint_map : dict, optional
        Source joint name -> our joint name (see :func:`map_joints`).
    where : str or Path, optional
        File name for messages when `path` is already parsed.

    Returns
    -------
    points : (T, J, 3) ndarray
        NaN for joints the file does not have.
    confidence : (T, J) ndarray
        1 for mapped joints, 0 otherwise.
    head_centre : (T, 3) ndarray or None
        Head joint position when the file has no head top.
    fps : float
    """
    skel = path if isinstance(path, BvhSkeleton) else parse_bvh(path)
    path = where if isinstance(path, BvhSkeleton) else path
    pos = bvh_positions(skel)
    mapping = map_joints(skel.names, joint_map)
    missing = [j for j in ("pelvis", "right_hip", "left_hip", "right_shoulder", "left_shoulder") if j not in mapping]
    if missing:
        raise MotionFileError(
            f"{path}: cannot find joints for {', '.join(missing)} among {', '.join(skel.names)}; "
            "pass joint_map={source_name: our_name}"
        )
    top = mapping.get("head", mapping.get("head_centre", mapping.get("neck", mapping["right_shoulder"])))
    to_z, unit = _up_and_unit(pos, mapping["pelvis"], top)
    pos = pos @ to_z.T * unit
    _check_head_top(mapping, skel.names, pos, joint_map)
    T = pos.shape[0]
    points = np.full((T, len(JOINTS), 3), np.nan)
    conf = np.zeros((T, len(JOINTS)))
    for j, name in enumerate(JOINTS):
        if name in mapping:
            points[:, j] = pos[:, mapping[name]]
            conf[:, j] = 1.0
    head_centre = pos[:, mapping["head_centre"]] if "head_centre" in mapping else None
    return points, conf, head_centre, skel.fps


def read_own_bvh(skel: BvhSkeleton):
    """Angles of a file written by :func:`write_bvh` (our joint names and channels), else None.

    Returns
    -------
    angles : (T, J, 3) ndarray
        Radians, our convention.
    root : (T, 3) ndarray
        Metres, our world frame.
    offsets : (J, 3) ndarray
        Metres, our world axes.
    """
    if list(skel.names[:1]) != [JOINTS[0]] or not set(JOINTS) <= set(skel.names):
        return None
    want_root = ["xposition", "yposition", "zposition", "yrotation", "zrotation", "xrotation"]
    if any(
        skel.channels[i] != (want_root if i == 0 else want_root[3:]) for i, n in enumerate(skel.names) if n in JOINTS
    ):
        return None
    idx = [skel.names.index(j) for j in JOINTS]
    starts = np.cumsum([0] + [len(c) for c in skel.channels])[:-1]
    offsets_file = skel.offsets[idx]
    # Metres per unit from the thigh length (cm files are ~40 units, m files ~0.4).
    thigh = np.linalg.norm(offsets_file[JOINTS.index("right_knee")])
    unit = 0.01 if thigh > 5.0 else 1.0
    T = skel.motion.shape[0]
    ch = np.stack(
        [skel.motion[:, starts[i] + (3 if i == 0 else 0) : starts[i] + (6 if i == 0 else 3)] for i in idx], axis=1
    )
    ch = np.deg2rad(ch)  # (T, J, 3) = (rz, -ry, rx)
    angles = np.stack([ch[..., 2], -ch[..., 1], ch[..., 0]], axis=-1)
    root = skel.motion[:, starts[0] : starts[0] + 3] @ _Z_TO_Y * unit
    offsets = offsets_file @ _Z_TO_Y * unit
    offsets[0] = 0.0
    return angles.reshape(T, len(JOINTS), 3), root, offsets


# --------------------------------------------------------------------------- writing

# Our z-up world -> y-up file: (x, y, z) -> (x, z, -y).
_Z_TO_Y = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def write_bvh(
    path,
    angles: np.ndarray,
    root: np.ndarray,
    fps: float,
    offsets: np.ndarray | None = None,
    body: Body | None = None,
    unit: str = "cm",
) -> Path:
    """Write a motion of our skeleton as BVH (atomically).

    Parameters
    ----------
    path : str or Path
    angles : (T, J, 3) ndarray
        Local Euler angles ``(rx, ry, rz)``, radians (our convention).
    root : (T, 3) ndarray
        Pelvis position, metres, our world frame.
    fps : float
    offsets : (J, 3) ndarray, optional
        Per-clip offsets (e.g. ``FitResult.offsets``); default ``body.offsets``.
    body : Body, optional
        Default ``Body()``.
    unit : {"cm", "m"}
        Length unit of the file.

    Returns
    -------
    Path

    Notes
    -----
    The file is y-up.  Our rotation ``Rz(rz) Ry(ry) Rx(rx)`` about z-up axes
    equals ``Ry'(rz) Rz'(-ry) Rx'(rx)`` about the file's axes, hence every
    joint's channels are ``Yrotation Zrotation Xrotation`` with values
    ``(rz, -ry, rx)`` in degrees.  Frames with NaN are written as the rest
    pose at the last known root (BVH cannot mark missing data).
    """
    body = body or Body()
    angles = np.asarray(angles, float)
    root = np.asarray(root, float)
    J = len(JOINTS)
    if angles.ndim != 3 or angles.shape[1:] != (J, 3) or root.shape != (angles.shape[0], 3):
        raise MotionFileError(f"write_bvh needs angles (T, {J}, 3) and root (T, 3); got {angles.shape}, {root.shape}")
    if not (np.isfinite(fps) and fps > 0):
        raise MotionFileError(f"write_bvh: fps must be positive, got {fps!r}")
    if unit not in ("cm", "m"):
        raise MotionFileError(f"write_bvh: unit must be 'cm' or 'm', got {unit!r}")
    scale = 100.0 if unit == "cm" else 1.0
    offsets = body.offsets if offsets is None else np.asarray(offsets, float)
    off = offsets @ _Z_TO_Y.T * scale
    children = {j: [c for c in range(J) if body.parents[c] == j] for j in range(J)}
    lines = ["HIERARCHY"]

    def emit(j, depth):
        ind = "  " * depth
        kw = "ROOT" if j == 0 else "JOINT"
        lines.append(f"{ind}{kw} {JOINTS[j]}")
        lines.append(f"{ind}{{")
        o = np.zeros(3) if j == 0 else off[j]
        lines.append(f"{ind}  OFFSET {o[0]:.6f} {o[1]:.6f} {o[2]:.6f}")
        pos = "Xposition Yposition Zposition " if j == 0 else ""
        lines.append(f"{ind}  CHANNELS {6 if j == 0 else 3} {pos}Yrotation Zrotation Xrotation")
        if children[j]:
            for c in children[j]:
                emit(c, depth + 1)
        else:
            # A short end segment continuing the parent's direction, so the
            # leaf is a visible bone in Blender.
            d = off[j] / max(np.linalg.norm(off[j]), 1e-9) * 0.05 * scale
            lines.append(f"{ind}  End Site")
            lines.append(f"{ind}  {{")
            lines.append(f"{ind}    OFFSET {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}")
            lines.append(f"{ind}  }}")
        lines.append(f"{ind}}}")

    emit(0, 0)
    T = angles.shape[0]
    order = [0] + [c for c in _dfs(children, 0) if c != 0]
    ok = np.all(np.isfinite(angles), axis=(1, 2)) & np.all(np.isfinite(root), axis=1)
    ang = np.where(ok[:, None, None], angles, 0.0)
    rt = _hold(root, ok)
    ch = np.rad2deg(np.stack([ang[..., 2], -ang[..., 1], ang[..., 0]], axis=-1))[:, order]  # (T, J, 3)
    rpos = rt @ _Z_TO_Y.T * scale
    data = np.concatenate([rpos, ch.reshape(T, -1)], axis=1)
    lines += ["MOTION", f"Frames: {T}", f"Frame Time: {1.0 / fps:.8f}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in data]
    return write_text(path, "\n".join(lines) + "\n")


def write_motion_bvh(path, motion, unit: str = "cm") -> Path:
    """Write a :class:`~capture2notation.fitting.FitResult` (or ``MotionData``) as BVH.

    Uses its ``angles``, ``root``, ``fps`` and per-clip ``offsets``; see :func:`write_bvh`.
    """
    return write_bvh(path, motion.angles, motion.root, motion.fps, offsets=motion.offsets, unit=unit)


def _dfs(children, j):
    out = [j]
    for c in children[j]:
        out += _dfs(children, c)
    return out


def _hold(root: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Root with missing frames holding the last (or first) known position."""
    out = root.copy()
    if not ok.any():
        return np.zeros_like(root)
    idx = np.where(ok, np.arange(len(ok)), 0)
    np.maximum.accumulate(idx, out=idx)
    first = int(np.argmax(ok))
    idx[:first] = first
    return out[idx]
