"""The truth sidecar: exact round trip, and errors that name the file and field."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.errors import MotionFileError
from capture2notation.io.truth import TRUTH_FIELDS, Truth, read_truth, write_truth


def _fields(T=5, J=21, seed=0):
    rng = np.random.default_rng(seed)
    return {
        "fps": 25.0,
        "times": np.arange(T) / 25.0,
        "joint_names": np.array([f"j{i}" for i in range(J)]),
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
        "score": '{"title": "x"}',
        "effort": '{"time": -2.0}',
        "view": "front",
        "style": "mannequin",
        "body_height": 1.7,
    }


@settings(max_examples=15, deadline=None)
@given(st.integers(1, 30), st.integers(1, 25), st.integers(0, 2**31 - 1))
def test_round_trip_is_exact(tmp_path_factory, T, J, seed):
    path = tmp_path_factory.mktemp("truth") / "truth.npz"
    f = _fields(T, J, seed)
    write_truth(path, **f)
    got = read_truth(path)
    assert isinstance(got, Truth)
    for name in TRUTH_FIELDS:
        value = getattr(got, name)
        if name == "joint_names":
            assert value == tuple(f[name])
        elif name in ("score", "effort", "view", "style"):
            assert value == f[name]
        else:
            np.testing.assert_array_equal(np.asarray(value, float), np.asarray(f[name], float))
    assert got.n_frames == T
    assert got.image_size == (640, 480)
    assert list(path.parent.iterdir()) == [path]  # no temporary file left behind


def test_arrays_read_back_are_read_only(tmp_path):
    write_truth(tmp_path / "truth.npz", **_fields())
    got = read_truth(tmp_path / "truth.npz")
    with pytest.raises(ValueError):
        got.joints[0, 0, 0] = 1.0


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda f: f.pop("keypoints"), ["keypoints"]),
        (lambda f: f.update(extra=1), ["extra"]),
        (lambda f: f.update(K=np.eye(4)), ["K", "(3, 3)"]),
        (lambda f: f.update(root=np.zeros((4, 3))), ["root", "T = 5"]),
        (lambda f: f.update(landmarks3d=np.zeros((5, 17, 3))), ["landmarks3d", "33"]),
        (lambda f: f.update(view=["front", "side"]), ["view"]),
        (lambda f: f.update(visibility=np.full((5, 33), 2.0)), ["visibility"]),
        (lambda f: f.update(fps=0.0), ["fps"]),
        (lambda f: f.update(score=3.0), ["score"]),
    ],
)
def test_bad_fields_name_file_and_field(tmp_path, change, words):
    f = _fields()
    change(f)
    path = tmp_path / "truth.npz"
    with pytest.raises(MotionFileError) as err:
        write_truth(path, **f)
    msg = str(err.value)
    assert str(path) in msg
    for w in words:
        assert w in msg
    assert not path.exists()


def test_reading_a_sidecar_with_a_missing_field_names_it(tmp_path):
    f = _fields()
    f.pop("visibility")
    path = tmp_path / "truth.npz"
    np.savez(path, **f)
    with pytest.raises(MotionFileError, match="visibility"):
        read_truth(path)


@pytest.mark.parametrize("content", [None, b"not a zip file"])
def test_unreadable_file(tmp_path, content):
    path = tmp_path / "truth.npz"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(MotionFileError, match=r"truth\.npz"):
        read_truth(path)


# --- bad input: one-line errors naming the field and the value (issue 16) -------------------------


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda f: f.update(fps=np.nan), ["fps is nan", "0.1-1000 Hz"]),
        (lambda f: f.update(fps=1e9), ["fps is 1000000000.0"]),
        (lambda f: f.update(body_height=np.inf), ["body_height is inf", "0.3-3 m"]),
        (lambda f: f.update(times=np.array([0.0, 0.04, np.nan, 0.12, 0.16])), ["times", "finite"]),
        (lambda f: f.update(times=np.array([0.0, 0.08, 0.04, 0.12, 0.16])), ["times", "increasing"]),
        (lambda f: f.update(K=np.full((3, 3), np.inf)), ["field K", "not finite"]),
        (lambda f: f.update(image_size=np.array([640.5, 480])), ["image_size", "whole pixels"]),
        (lambda f: f.update(image_size=np.array([0, 480])), ["image_size", "1-16384"]),
    ],
)
def test_implausible_values_name_the_field(tmp_path, change, words):
    f = _fields()
    change(f)
    path = tmp_path / "truth.npz"
    np.savez(path, **f)
    with pytest.raises(MotionFileError) as err:
        read_truth(path)
    assert str(path) in str(err.value)
    for w in words:
        assert w in str(err.value)


def test_a_member_declaring_a_huge_array_is_refused_from_its_header(tmp_path):
    """A .npy header claiming 10⁹ frames is refused before any data is read (the file is tiny)."""
    import io
    import zipfile

    path = tmp_path / "truth.npz"
    with zipfile.ZipFile(path, "w") as zf:
        for name, value in _fields().items():
            buf = io.BytesIO()
            if name == "joints":
                header = {"descr": "<f8", "fortran_order": False, "shape": (10**9, 21, 3)}
                np.lib.format.write_array_header_1_0(buf, header)
            else:
                np.save(buf, np.asarray(value))
            zf.writestr(f"{name}.npy", buf.getvalue())
    assert path.stat().st_size < 20_000
    with pytest.raises(MotionFileError, match=r"field joints has shape \(1000000000, 21, 3\)"):
        read_truth(path)


def test_object_arrays_are_refused_without_unpickling(tmp_path):
    f = _fields()
    f["joints"] = np.array([None] * 5, dtype=object)
    path = tmp_path / "truth.npz"
    np.savez(path, **f)
    with pytest.raises(MotionFileError, match="field joints has dtype object"):
        read_truth(path)
