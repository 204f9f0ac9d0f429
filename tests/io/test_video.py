"""Video reading (files, image folders, damaged files) and the atomic writer."""

from __future__ import annotations

import types
import warnings

import cv2
import numpy as np
import pytest

from capture2notation.errors import VideoError
from capture2notation.io.video import VideoWriter, iter_frames, probe


def _frame(i, w=64, h=48):
    """A frame whose mean brightness encodes its index (survives compression)."""
    img = np.full((h, w, 3), 20 + 10 * (i % 20), np.uint8)
    cv2.putText(img, str(i), (5, 30), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (255, 255, 255), 2)
    return img


def _write(path, n, fps=12.5, size=(64, 48)):
    with VideoWriter(path, fps, size) as w:
        for i in range(n):
            w.write(_frame(i, *size))
    return path


@pytest.mark.parametrize("ext", [".avi", ".mp4"])
def test_round_trip_frames_fps_and_times(tmp_path, ext):
    path = _write(tmp_path / f"v{ext}", 10)
    info = probe(path)
    assert info.fps == pytest.approx(12.5, rel=1e-3)
    assert info.image_size == (64, 48) and info.frame_count == 10
    frames = list(iter_frames(path))
    assert [f.index for f in frames] == list(range(10))
    np.testing.assert_allclose([f.time for f in frames], np.arange(10) / 12.5, atol=1e-3)
    brightness = [f.image[40:, 40:].mean() for f in frames]
    np.testing.assert_allclose(brightness, 20 + 10 * np.arange(10), atol=6)


def test_streaming_is_lazy_and_ranges_work(tmp_path):
    path = _write(tmp_path / "v.avi", 8)
    it = iter_frames(path, start=2, stop=5)
    assert isinstance(it, types.GeneratorType)
    frames = list(it)
    assert [f.index for f in frames] == [2, 3, 4]
    np.testing.assert_allclose([f.time for f in frames], np.array([2, 3, 4]) / 12.5, atol=1e-3)
    with pytest.raises(VideoError, match="bad frame range"):
        list(iter_frames(path, start=3, stop=1))


def test_image_folder_with_given_fps(tmp_path):
    for i in range(4):
        cv2.imwrite(str(tmp_path / f"img_{i:03d}.png"), _frame(i))
    (tmp_path / "notes.txt").write_text("not an image")
    frames = list(iter_frames(tmp_path, fps=10))
    assert len(frames) == 4 and frames[3].time == pytest.approx(0.3)
    assert frames[2].image[40:, 40:].mean() == pytest.approx(40, abs=1)
    assert probe(tmp_path).fps == 30.0  # documented default for folders


def test_image_folder_stops_at_a_bad_image(tmp_path):
    for i in range(3):
        cv2.imwrite(str(tmp_path / f"{i}.png"), _frame(i))
    (tmp_path / "3.png").write_bytes(b"broken")
    cv2.imwrite(str(tmp_path / "4.png"), _frame(4))
    with pytest.warns(RuntimeWarning, match=r"frame 3 .*3\.png"):
        frames = list(iter_frames(tmp_path))
    assert len(frames) == 3


def test_truncated_file_gives_frames_read_and_warns(tmp_path):
    path = _write(tmp_path / "v.avi", 30)
    data = path.read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) // 2])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = list(iter_frames(cut))
    assert 0 < len(frames) < 30
    msgs = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert any(f"frame {len(frames)} " in m for m in msgs), msgs


def test_unreadable_inputs_raise(tmp_path):
    with pytest.raises(VideoError, match="no such"):
        probe(tmp_path / "missing.mp4")
    junk = tmp_path / "junk.mp4"
    junk.write_bytes(b"\x00" * 1000)
    with pytest.raises(VideoError, match=r"junk\.mp4"):
        list(iter_frames(junk))
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(VideoError, match=r"no .*png"):
        probe(empty)


def test_writer_is_atomic_and_checks_sizes(tmp_path):
    out = tmp_path / "o.avi"
    with pytest.raises(VideoError, match="frame 1 has size 32x48"), VideoWriter(out, 10, (64, 48)) as w:
        w.write(_frame(0))
        w.write(_frame(1, 32, 48))
    assert list(tmp_path.iterdir()) == []  # nothing half-written left behind
    with pytest.raises(VideoError, match="extension"), VideoWriter(tmp_path / "o.gif", 10, (64, 48)):
        pass
