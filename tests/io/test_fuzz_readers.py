"""Property tests of the motion-file readers on generated bad input (issue 16).

Each reader (BVH, Kinect CSV, truth sidecar) is fed valid files with random
edits: tokens or fields replaced by extreme, non-finite or malformed values,
lines dropped or repeated, the bytes truncated or flipped.  The only outcomes
allowed are success, with output that keeps the readers' promises (shapes,
NaN exactly where confidence is 0, nothing infinite), or a
:class:`~capture2notation.errors.MotionFileError` whose message is one line
naming the file.  The default tier tries 200 inputs per reader; the slow tier
10,000 (``pytest -m slow tests/io/test_fuzz_readers.py``).
"""

from __future__ import annotations

import io
import logging
from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS
from capture2notation.errors import MotionFileError
from capture2notation.io.bvh import parse_bvh, read_bvh_points, read_own_bvh
from capture2notation.io.kinect import kinect_points, read_kinect_csv
from capture2notation.io.limits import MAX_FRAMES
from capture2notation.io.truth import TRUTH_FIELDS, read_truth

DEFAULT_EXAMPLES = 200
SLOW_EXAMPLES = 10_000

_NASTY = [
    "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e-300", "0", "-0", "-1", "1", "2.7", "6", "7",
    "1e9", "100000.5", "{", "}", "ROOT", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "MOTION", "Frames:",
    "Frame", "Time:", "HIERARCHY", "Xrotation", "Yposition", "", "\x00", "é", "0x10", "1_0", "--1",
]  # fmt: skip
_TOKEN = st.one_of(
    st.sampled_from(_NASTY),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**20), 10**20).map(str),
    st.text(max_size=6),
)


def _settings(n):
    return settings(
        max_examples=n,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )


#: Outcomes of the current property run: "ok" or "error".
OUTCOMES: Counter = Counter()


def _check_error(exc: MotionFileError, path) -> None:
    OUTCOMES["error"] += 1
    msg = str(exc)
    assert str(path) in msg or "joint map" in msg, msg
    assert "\n" not in msg, msg


# --- BVH --------------------------------------------------------------------------------------

_TREE = [  # (name, parent, offset in cm)
    ("Hips", None, (0, 0, 0)),
    ("Spine", "Hips", (0, 10, 0)),
    ("Neck", "Spine", (0, 40, 0)),
    ("Head", "Neck", (0, 10, 0)),
    ("LeftArm", "Spine", (18, 35, 0)),
    ("LeftForeArm", "LeftArm", (0, -28, 0)),
    ("RightArm", "Spine", (-18, 35, 0)),
    ("RightForeArm", "RightArm", (0, -28, 0)),
    ("LeftUpLeg", "Hips", (10, -5, 0)),
    ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
    ("LeftFoot", "LeftLeg", (0, -42, 0)),
    ("RightUpLeg", "Hips", (-10, -5, 0)),
    ("RightLeg", "RightUpLeg", (0, -42, 0)),
    ("RightFoot", "RightLeg", (0, -42, 0)),
]


def _bvh_lines(frames: int, rng: np.random.Generator) -> list[str]:
    children: dict = {}
    for name, parent, _ in _TREE:
        children.setdefault(parent, []).append(name)
    offsets = {name: off for name, _, off in _TREE}
    lines = ["HIERARCHY"]

    def emit(name, depth):
        ind = " " * depth
        lines.append(f"{ind}{'ROOT' if depth == 0 else 'JOINT'} {name}")
        lines.append(f"{ind}{{")
        lines.append(f"{ind} OFFSET {' '.join(str(v) for v in offsets[name])}")
        pos = "Xposition Yposition Zposition " if depth == 0 else ""
        lines.append(f"{ind} CHANNELS {6 if depth == 0 else 3} {pos}Zrotation Xrotation Yrotation")
        for c in children.get(name, []):
            emit(c, depth + 1)
        if name not in children:
            lines.extend([f"{ind} End Site", f"{ind} {{", f"{ind}  OFFSET 0 -5 0", f"{ind} }}"])
        lines.append(f"{ind}}}")

    emit("Hips", 0)
    n_ch = 6 + 3 * (len(_TREE) - 1)
    lines += ["MOTION", f"Frames: {frames}", "Frame Time: 0.04"]
    for _ in range(frames):
        row = rng.normal(0, 20, n_ch)
        row[:3] = [0, 95, 0]
        lines.append(" ".join(f"{v:.3f}" for v in row))
    return lines


_BVH_EDIT = st.one_of(
    st.tuples(st.just("replace"), st.integers(0, 10**6), _TOKEN),
    st.tuples(st.just("delete"), st.integers(0, 10**6), st.just("")),
    st.tuples(st.just("insert"), st.integers(0, 10**6), _TOKEN),
    st.tuples(st.just("dupline"), st.integers(0, 10**6), st.just("")),
    st.tuples(st.just("dropline"), st.integers(0, 10**6), st.just("")),
)


def _edit_bvh(lines: list[str], edits) -> list[str]:
    lines = list(lines)
    for op, i, tok in edits:
        if op in ("dupline", "dropline"):
            k = i % len(lines)
            lines[k : k + 1] = [lines[k]] * (2 if op == "dupline" else 0)
            if not lines:
                lines = [""]
            continue
        toks = [(li, t) for li, line in enumerate(lines) for t in range(len(line.split()))]
        if not toks:
            lines[0] = tok
            continue
        li, t = toks[i % len(toks)]
        words = lines[li].split()
        if op == "replace":
            words[t] = tok
        elif op == "delete":
            del words[t]
        else:
            words.insert(t, tok)
        lines[li] = " ".join(words)
    return lines


def bvh_property(tmp_path_factory):
    path = tmp_path_factory.mktemp("fuzz_bvh") / "f.bvh"

    @given(
        frames=st.integers(1, 5),
        seed=st.integers(0, 2**32 - 1),
        edits=st.lists(_BVH_EDIT, max_size=4),
        cut=st.none() | st.floats(0, 1),
        junk=st.none() | st.binary(max_size=8),
    )
    def prop(frames, seed, edits, cut, junk):
        data = "\n".join(_edit_bvh(_bvh_lines(frames, np.random.default_rng(seed)), edits)).encode("utf-8", "replace")
        if junk is not None:
            at = int(seed % (len(data) + 1))
            data = data[:at] + junk + data[at:]
        if cut is not None:
            data = data[: int(cut * len(data))]
        path.write_bytes(data)
        try:
            skel = parse_bvh(path)
            read_own_bvh(skel)
            points, conf, head, fps = read_bvh_points(skel, where=path)
        except MotionFileError as exc:
            _check_error(exc, path)
            return
        T = skel.motion.shape[0]
        assert 1 <= T <= MAX_FRAMES and 0.1 <= fps <= 1000.0
        assert points.shape == (T, len(JOINTS), 3) and conf.shape == (T, len(JOINTS))
        assert set(np.unique(conf)) <= {0.0, 1.0}
        assert np.array_equal(conf == 0, ~np.all(np.isfinite(points), axis=-1))
        assert not np.any(np.isinf(points)) and (head is None or not np.any(np.isinf(head)))
        OUTCOMES["ok"] += 1

    return prop


# --- Kinect CSV -------------------------------------------------------------------------------

_STAMP = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "1e15", "-1e15", "0", "1e300", "-0", "100000000", "31867373716"]),
    st.integers(-(10**16), 10**16).map(str),
)
_KINECT_EDIT = st.one_of(
    st.tuples(st.just("stamp"), st.integers(0, 100), st.integers(0, 0), _STAMP),
    st.tuples(st.just("field"), st.integers(0, 100), st.integers(1, 101), _TOKEN),
    st.tuples(st.just("state"), st.integers(0, 100), st.integers(0, 24), st.sampled_from(["0", "1", "2", "3", "-1", "2.5", "nan"])),
    st.tuples(st.just("dupline"), st.integers(0, 100), st.integers(0, 0), st.just("")),
    st.tuples(st.just("dropline"), st.integers(0, 100), st.integers(0, 0), st.just("")),
    st.tuples(st.just("truncrow"), st.integers(0, 100), st.integers(0, 101), st.just("")),
)  # fmt: skip


def _kinect_rows(rows: int, rng: np.random.Generator) -> list[list[str]]:
    out = []
    t = 10**8
    for _ in range(rows):
        t += int(rng.choice([333333, 333334, 666667]))
        cells = [str(t)]
        for _j in range(25):
            cells += [f"{v:.4f}" for v in rng.uniform(-1.0, 3.0, 3)] + [str(int(rng.integers(0, 3)))]
        out.append(cells)
    return out


def kinect_property(tmp_path_factory):
    path = tmp_path_factory.mktemp("fuzz_kinect") / "f.csv"

    @given(
        rows=st.integers(1, 6),
        seed=st.integers(0, 2**32 - 1),
        edits=st.lists(_KINECT_EDIT, max_size=4),
        junk=st.none() | st.binary(max_size=8),
    )
    def prop(rows, seed, edits, junk):
        table = _kinect_rows(rows, np.random.default_rng(seed))
        for op, r, f, tok in edits:
            if not table:
                break
            r %= len(table)
            if op == "stamp":
                table[r][0] = tok
            elif op == "field":
                table[r][f % len(table[r])] = tok
            elif op == "state" and len(table[r]) > 4 + 4 * f:
                table[r][4 + 4 * f] = tok
            elif op == "dupline":
                table.insert(r, list(table[r]))
            elif op == "dropline":
                del table[r]
            elif op == "truncrow":
                table[r] = table[r][: max(f, 1)]
        data = "\n".join(",".join(row) for row in table).encode("utf-8", "replace")
        if junk is not None:
            at = int(seed % (len(data) + 1))
            data = data[:at] + junk + data[at:]
        path.write_bytes(data)
        try:
            times, pos, conf, fps = read_kinect_csv(path)
        except MotionFileError as exc:
            _check_error(exc, path)
            return
        T = len(times)
        assert 1 <= T <= MAX_FRAMES and 0.1 <= fps <= 1000.0
        assert pos.shape == (T, 25, 3) and conf.shape == (T, 25)
        assert np.all(np.diff(times) > 0)
        assert np.array_equal(conf == 0, ~np.all(np.isfinite(pos), axis=-1))
        points, pconf, _head, _hc = kinect_points(pos, conf)
        assert not np.any(np.isinf(points)) and np.all((pconf >= 0) & (pconf <= 1))
        OUTCOMES["ok"] += 1

    return prop


# --- truth sidecar ----------------------------------------------------------------------------


def _truth_fields(T: int, rng: np.random.Generator) -> dict:
    J = len(JOINTS)
    return {
        "fps": np.asarray(25.0),
        "times": np.arange(T) / 25.0,
        "joint_names": np.array(JOINTS),
        "joints": rng.normal(size=(T, J, 3)),
        "angles": rng.normal(size=(T, J, 3)),
        "root": rng.normal(size=(T, 3)),
        "landmarks3d": rng.normal(size=(T, 33, 3)),
        "keypoints": rng.uniform(0, 640, size=(T, 33, 2)),
        "visibility": (rng.uniform(size=(T, 33)) > 0.3).astype(float),
        "K": np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]]),
        "R": np.eye(3),
        "t": np.array([0.0, -1.0, 4.0]),
        "image_size": np.array([640, 480]),
        "score": np.asarray('{"title": "x"}'),
        "effort": np.asarray("{}"),
        "view": np.asarray("front"),
        "style": np.asarray("mannequin"),
        "body_height": np.asarray(1.7),
    }


def _full(shape, kind, v):
    with np.errstate(over="ignore", invalid="ignore"):
        if kind in ("f8", "f4", "c16"):
            return np.full(shape, v).astype(kind)
        return np.full(shape, "x" if kind == "U3" else (None if kind == "O" else 1), dtype=kind)


_VALUE = st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -1.0, 1e300, 1e-300, 2.0, 0.5])
_ARRAY = st.builds(
    _full,
    st.lists(st.integers(0, 4), max_size=3).map(tuple),
    st.sampled_from(["f8", "f4", "i8", "u1", "?", "U3", "O", "c16"]),
    _VALUE,
)
_TRUTH_EDIT = st.one_of(
    st.tuples(st.just("drop"), st.sampled_from(list(TRUTH_FIELDS)), st.none()),
    st.tuples(st.just("add"), st.text(min_size=1, max_size=5).filter(lambda s: "/" not in s), _ARRAY),
    st.tuples(st.just("array"), st.sampled_from(list(TRUTH_FIELDS)), _ARRAY),
    st.tuples(st.just("value"), st.sampled_from(list(TRUTH_FIELDS)), _VALUE),
)


def truth_property(tmp_path_factory):
    path = tmp_path_factory.mktemp("fuzz_truth") / "truth.npz"

    @given(
        T=st.integers(0, 4),
        seed=st.integers(0, 2**32 - 1),
        edits=st.lists(_TRUTH_EDIT, max_size=3),
        compressed=st.booleans(),
        damage=st.none() | st.tuples(st.sampled_from(["cut", "flip"]), st.floats(0, 1)),
    )
    def prop(T, seed, edits, compressed, damage):
        fields = _truth_fields(T, np.random.default_rng(seed))
        for op, name, value in edits:
            if op == "drop":
                fields.pop(name, None)
            elif op in ("add", "array"):
                fields[name] = value
            elif name in fields and fields[name].dtype.kind == "f":
                arr = fields[name].copy()
                if arr.size:
                    with np.errstate(over="ignore", invalid="ignore"):
                        arr.flat[seed % arr.size] = value
                fields[name] = arr
        buf = io.BytesIO()
        (np.savez_compressed if compressed else np.savez)(buf, **fields)
        data = buf.getvalue()
        if damage is not None:
            at = int(damage[1] * (len(data) - 1))
            data = data[:at] if damage[0] == "cut" else data[:at] + bytes([data[at] ^ 0x5A]) + data[at + 1 :]
        path.write_bytes(data)
        try:
            tr = read_truth(path)
        except MotionFileError as exc:
            _check_error(exc, path)
            return
        n = tr.n_frames
        assert tr.joints.shape == (n, len(tr.joint_names), 3) and tr.visibility.shape == (n, 33)
        assert 0.1 <= tr.fps <= 1000.0 and np.all(np.isfinite(tr.times)) and np.all(np.diff(tr.times) >= 0)
        OUTCOMES["ok"] += 1

    return prop


# --- the tests --------------------------------------------------------------------------------

_PROPERTIES = {"bvh": bvh_property, "kinect": kinect_property, "truth": truth_property}


@pytest.fixture(autouse=True)
def _quiet_readers():
    # The readers log one warning per odd file; thousands of them are noise here.
    logging.getLogger("capture2notation.io").setLevel(logging.ERROR)
    yield
    logging.getLogger("capture2notation.io").setLevel(logging.NOTSET)


def _run(tmp_path_factory, reader: str, n: int) -> None:
    OUTCOMES.clear()
    _settings(n)(_PROPERTIES[reader](tmp_path_factory))()
    # Both outcomes must be exercised, or the generator tests nothing.
    total = sum(OUTCOMES.values())
    assert total >= min(n, 100) and min(OUTCOMES["ok"], OUTCOMES["error"]) >= 0.05 * total, OUTCOMES


@pytest.mark.parametrize("reader", list(_PROPERTIES))
def test_readers_accept_or_refuse_in_one_line(tmp_path_factory, reader):
    _run(tmp_path_factory, reader, DEFAULT_EXAMPLES)


@pytest.mark.slow
@pytest.mark.parametrize("reader", list(_PROPERTIES))
def test_readers_accept_or_refuse_in_one_line_10000_inputs(tmp_path_factory, reader):
    _run(tmp_path_factory, reader, SLOW_EXAMPLES)
