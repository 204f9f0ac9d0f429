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
import os
import re
from collections import deque
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..body import JOINTS, Body
from ..errors import MotionFileError
from .limits import MAX_ABS_ANGLE_DEG, MAX_ABS_FILE_LENGTH, MAX_FRAMES, MAX_JOINTS, MIN_FPS, check_duration

__all__ = [
    "CHANNEL_NAMES",
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


#: The six channel names a BVH joint may list (compared lower-case).
CHANNEL_NAMES = ("xposition", "yposition", "zposition", "xrotation", "yrotation", "zrotation")
#: Values of a motion block allocated without first checking that the file
#: is long enough to hold them (8 MB); smaller blocks are counted as read,
#: which gives the exact count in the message.
_SMALL_BLOCK = 1 << 20
_INTEGER = re.compile(r"^\+?[0-9]+$")


class _Tokens:
    """Whitespace tokens of a BVH hierarchy with their line numbers, read line by line."""

    def __init__(self, fh, path: Path):
        self.fh = fh
        self.path = path
        self.line_no = 0
        self.buf: deque = deque()

    def _fill(self) -> bool:
        while not self.buf:
            raw = self.fh.readline()
            if not raw:
                return False
            self.line_no += 1
            self.buf.extend((t, self.line_no) for t in raw.decode("utf-8", errors="replace").split())
        return True

    def peek(self) -> str | None:
        return self.buf[0][0] if self._fill() else None

    def take(self, expect: str | None = None, what: str | None = None) -> tuple[str, int]:
        """The next token; it must be `expect` (case-insensitive) when given; `what` names it at end of file."""
        if not self._fill():
            raise MotionFileError(
                f"{self.path}: unexpected end of file; expected {what or (repr(expect) if expect else 'more data')}"
            )
        tok, ln = self.buf.popleft()
        if expect is not None and tok.upper() != expect.upper():
            raise MotionFileError(f"{self.path}:{ln}: expected {expect!r}, found {tok!r}")
        return tok, ln

    def number(self, what: str, bound: float) -> float:
        tok, ln = self.take()
        try:
            value = float(tok)
        except ValueError:
            raise MotionFileError(f"{self.path}:{ln}: expected a number for {what}, found {tok!r}") from None
        if not abs(value) <= bound:
            raise MotionFileError(f"{self.path}:{ln}: {what} is {tok}; expected a finite number within ±{bound:g}")
        return value

    def integer(self, what: str, low: int, high: int) -> int:
        tok, ln = self.take()
        if not _INTEGER.match(tok) or not low <= int(tok) <= high:
            raise MotionFileError(f"{self.path}:{ln}: {what} is {tok!r}; expected a whole number from {low} to {high}")
        return int(tok)


def parse_bvh(path) -> BvhSkeleton:
    """Parse a BVH file; errors name the file, line and what was expected.

    The file is streamed: the motion block goes straight into one array of
    the declared size, which must fit in what is left of the file (at least
    two bytes per value), so a header cannot make the reader allocate more
    than a few times the file's own size.  Frame counts, rates, offsets and
    channel counts are checked against :mod:`capture2notation.io.limits`.

    Channel values that are not finite numbers, or beyond
    :data:`~capture2notation.io.limits.MAX_ABS_FILE_LENGTH` (positions) or
    :data:`~capture2notation.io.limits.MAX_ABS_ANGLE_DEG` (rotations), are
    read as NaN, so the joint they move and everything below it are missing
    in that frame (NaN with zero confidence downstream), and one warning
    names the first of them: exporters write ``nan`` for a lost marker, and
    the other frames and joints remain good measurements.

    Raises
    ------
    MotionFileError
        Unreadable file, syntax error, or a header value outside the limits.
    """
    path = Path(path)
    try:
        fh = open(path, "rb")  # noqa: SIM115 - closed below; binary for exact positions
    except OSError as exc:
        raise MotionFileError(f"{path}: cannot read BVH file: {exc.strerror}") from None
    with fh:
        try:
            size = os.fstat(fh.fileno()).st_size
            return _parse(_Tokens(fh, path), size)
        except OSError as exc:
            raise MotionFileError(f"{path}: cannot read BVH file: {exc.strerror}") from None


def _parse(tk: _Tokens, size: int) -> BvhSkeleton:
    path = tk.path
    tk.take("HIERARCHY")
    names: list[str] = []
    parents: list[int] = []
    offsets: list = []
    channels: list = []
    stack: list[int] = []
    tk.take("ROOT")
    kind = "ROOT"
    while True:
        if kind in ("ROOT", "JOINT"):
            name, _ = tk.take(what=f"a name after {kind}")
        else:  # End Site
            tk.take("Site")
            name = f"{names[stack[-1]]}_End"
        _, ln = tk.take("{")
        if len(names) >= MAX_JOINTS:
            raise MotionFileError(f"{path}:{ln}: more than {MAX_JOINTS} joints; not one performer's skeleton")
        idx = len(names)
        names.append(name)
        parents.append(stack[-1] if stack else -1)
        tk.take("OFFSET")
        offsets.append([tk.number(f"OFFSET of {name}", MAX_ABS_FILE_LENGTH) for _ in range(3)])
        chans: list[str] = []
        if kind != "End" and (tk.peek() or "").upper() == "CHANNELS":
            tk.take("CHANNELS")
            n = tk.integer(f"CHANNELS count of {name}", 0, len(CHANNEL_NAMES))
            for _ in range(n):
                c, cl = tk.take(what=f"{n} channel names for {name}")
                if c.lower() not in CHANNEL_NAMES:
                    raise MotionFileError(
                        f"{path}:{cl}: unknown channel {c!r} of joint {name}; expected {n} of "
                        "Xposition Yposition Zposition Xrotation Yrotation Zrotation"
                    )
                if c.lower() in chans:
                    raise MotionFileError(f"{path}:{cl}: channel {c!r} of joint {name} is listed twice")
                chans.append(c.lower())
        channels.append(chans)
        stack.append(idx)
        # Children or closing braces.
        while True:
            tok, ln = tk.take(what="JOINT, End Site or '}'")
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
    tk.take("MOTION")
    tk.take("Frames:")
    n_frames = tk.integer("Frames", 1, MAX_FRAMES)
    tk.take("Frame")
    _, ln = tk.take("Time:")
    frame_time = tk.number("Frame Time", 1.0 / MIN_FPS)
    problem = check_duration(n_frames, 1.0 / frame_time) if frame_time > 0 else "it is not positive"
    if problem is not None:
        raise MotionFileError(f"{path}:{ln}: Frame Time {frame_time:g} s with {n_frames} frames: {problem}")
    motion = _read_motion_block(tk, size, n_frames, channels, names)
    return BvhSkeleton(names, np.array(parents), np.array(offsets, float), channels, motion, frame_time)


def _read_motion_block(tk: _Tokens, size: int, n_frames: int, channels: list, names: list) -> np.ndarray:
    """The (T, C) channel values after ``Frame Time``, bad values as NaN (see :func:`parse_bvh`)."""
    path = tk.path
    n_ch = sum(len(c) for c in channels)
    total = n_frames * n_ch
    left = size - tk.fh.tell() + sum(len(t) + 1 for t, _ in tk.buf)
    if total > _SMALL_BLOCK and total > (left + 1) // 2:
        raise MotionFileError(
            f"{path}: Frames: {n_frames} × {n_ch} channels declares {total} values, "
            f"but only {max(left, 0)} bytes follow (at least 2 per value)"
        )
    bound = np.array(
        [MAX_ABS_FILE_LENGTH if c.endswith("position") else MAX_ABS_ANGLE_DEG for ch in channels for c in ch]
    )
    flat = np.empty(total)
    k = extra = 0
    first_bad = None

    def lines():
        while tk.buf:  # values left on the Frame Time line
            tok, ln = tk.buf.popleft()
            yield ln, [tok]
        for raw in tk.fh:
            tk.line_no += 1
            yield tk.line_no, raw.decode("utf-8", errors="replace").split()

    for ln, toks in lines():
        if not toks:
            continue
        take = min(len(toks), total - k)
        extra += len(toks) - take
        if take == 0:
            continue
        try:
            vals = np.array(toks[:take], dtype=float)
        except ValueError:
            bad = next(t for t in toks[:take] if not _is_float(t))
            raise MotionFileError(f"{path}:{ln}: expected a channel value, found {bad!r}") from None
        if first_bad is None:
            col = (k + np.arange(take)) % n_ch
            off = ~(np.abs(vals) <= bound[col])
            if off.any():
                i = int(np.argmax(off))
                first_bad = (ln, int(col[i]), toks[i])
        flat[k : k + take] = vals
        k += take
    if k < total:
        raise MotionFileError(
            f"{path}: motion block has {k} values, expected {n_frames} frames × {n_ch} channels = {total}"
        )
    if extra:
        log.warning("%s: %d values after the %d declared frames ignored", path, extra, n_frames)
    motion = flat.reshape(n_frames, n_ch)
    if first_bad is not None:
        bad = ~(np.abs(motion) <= bound)
        motion[bad] = np.nan
        ln, at, tok = first_bad
        owner = [(n, c) for n, ch in zip(names, channels) for c in ch][at]
        log.warning(
            "%s:%d: %s %s is %s: %d channel values are not finite or out of range; what they move is "
            "missing (NaN, confidence 0) in %d of %d frames",
            path,
            ln,
            owner[0],
            owner[1].capitalize(),
            tok,
            int(bad.sum()),
            int(bad.any(axis=1).sum()),
            n_frames,
        )
    return motion


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


#: Frames per forward-kinematics chunk: the per-joint rotations of a chunk
#: (N, chunk, 3, 3) stay a few MB however long the file is.
_FK_CHUNK = 4096


def bvh_positions(skel: BvhSkeleton) -> np.ndarray:
    """World positions of every joint and end site, file units and axes, ``(T, N, 3)``.

    NaN channel values make the joint they move, and every joint below it, NaN.
    """
    T = skel.motion.shape[0]
    pos = np.empty((T, len(skel.names), 3))
    for a in range(0, T, _FK_CHUNK):
        pos[a : a + _FK_CHUNK] = _positions(skel, skel.motion[a : a + _FK_CHUNK])
    return pos


def _positions(skel: BvhSkeleton, motion: np.ndarray) -> np.ndarray:
    T = motion.shape[0]
    N = len(skel.names)
    pos = np.zeros((T, N, 3))
    glob = np.zeros((T, N, 3, 3))
    col = 0
    for i in range(N):
        p = skel.parents[i]
        local_t = np.broadcast_to(skel.offsets[i], (T, 3)).copy()
        rot = np.broadcast_to(np.eye(3), (T, 3, 3)).copy()
        for ch in skel.channels[i]:
            v = motion[:, col]
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


def _up_and_unit(pos: np.ndarray, pelvis: int, top: int, where="BVH file") -> tuple[np.ndarray, float]:
    """Rotation from file axes to z-up, and metres per file unit.

    Parameters
    ----------
    pos : (T, N, 3) ndarray
        Animated positions, file units and axes (rest poses of some exporters
        are not upright, so the animation decides).
    pelvis, top : int
        Indices of the pelvis and of a point above it (head or neck).
    """
    seen = np.all(np.isfinite(pos[:, [pelvis, top]]), axis=(1, 2))
    if not seen.any():
        raise MotionFileError(
            f"{where}: no frame has both the pelvis and the head or neck: cannot tell which axis is up"
        )
    up_vec = np.median(pos[seen, top] - pos[seen, pelvis], axis=0)
    up = int(np.argmax(np.abs(up_vec)))
    sign = 1.0 if up_vec[up] >= 0 else -1.0
    to_z = {
        0: np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0]]),  # x up -> z
        1: np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]),  # y up -> z
        2: np.eye(3),
    }[up].astype(float)
    if sign < 0:
        to_z = np.diag([1.0, -1.0, -1.0]) @ to_z
    extent = np.nanmax(pos[seen, :, up], axis=1) - np.nanmin(pos[seen, :, up], axis=1)
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
    to_z, unit = _up_and_unit(pos, mapping["pelvis"], top, path)
    pos = pos @ to_z.T * unit
    _check_head_top(mapping, skel.names, pos, joint_map)
    T = pos.shape[0]
    points = np.full((T, len(JOINTS), 3), np.nan)
    conf = np.zeros((T, len(JOINTS)))
    for j, name in enumerate(JOINTS):
        if name in mapping:
            points[:, j] = pos[:, mapping[name]]
            conf[:, j] = np.all(np.isfinite(points[:, j]), axis=-1)
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
