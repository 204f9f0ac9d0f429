from pathlib import Path

import pytest

from capture2notation.atomic import atomic_path, write_text


def test_write_text_replaces_whole_file(tmp_path):
    p = tmp_path / "sub" / "out.txt"
    write_text(p, "first")
    write_text(p, "second")
    assert p.read_text() == "second"
    assert [f.name for f in p.parent.iterdir()] == ["out.txt"]


def test_failed_write_leaves_no_file_and_no_temp(tmp_path):
    p = tmp_path / "out.json"
    with pytest.raises(RuntimeError), atomic_path(p) as tmp:
        Path(tmp).write_text("half")
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_previous_version(tmp_path):
    p = tmp_path / "out.txt"
    write_text(p, "good")
    with pytest.raises(ValueError), atomic_path(p) as tmp:
        Path(tmp).write_text("bad")
        raise ValueError
    assert p.read_text() == "good"


def test_temp_file_keeps_suffix_for_writers_that_need_it(tmp_path):
    with atomic_path(tmp_path / "video.mp4") as tmp:
        assert tmp.suffix == ".mp4"
        assert tmp.parent == tmp_path
        tmp.write_bytes(b"x")


def test_written_files_get_the_umask_mode_not_mkstemps_0600(tmp_path):
    import os

    mask = os.umask(0o022)
    os.umask(mask)
    p = write_text(tmp_path / "out.txt", "x")
    assert p.stat().st_mode & 0o777 == 0o666 & ~mask
