"""``c2n calibrate`` on bad input: one line, exit 2, naming the file or option."""

from __future__ import annotations

import numpy as np
from click.testing import CliRunner

from capture2notation.io.video import VideoWriter
from pipelines.cli import main


def _blank_clip(path, n=5):
    with VideoWriter(path, 25.0, (64, 48)) as w:
        for _ in range(n):
            w.write(np.full((48, 64, 3), 200, np.uint8))
    return path


def test_a_clip_without_the_board_is_named(tmp_path):
    a = _blank_clip(tmp_path / "left.mp4")
    b = _blank_clip(tmp_path / "right.mp4")
    r = CliRunner().invoke(main, ["calibrate", str(a), str(b), "-o", str(tmp_path / "c.toml")])
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and "left.mp4: the ChArUco board (7x5" in lines[0] and "none of its 5 frames" in lines[0]
    assert not (tmp_path / "c.toml").exists()


def test_bad_board_options_are_one_line_errors(tmp_path):
    a = _blank_clip(tmp_path / "a.mp4")
    runner = CliRunner()
    for args, expected in (
        (["--board", "7by5"], "--board '7by5'"),
        (["--dict", "DICT_NOPE"], "DICT_NOPE"),
        (["--marker", "0.05"], "marker"),
        (["--origin", "1,2"], "--origin '1,2'"),
    ):
        r = runner.invoke(main, ["calibrate", str(a), str(a), "-o", str(tmp_path / "c.toml"), *args])
        assert r.exit_code == 2, r.output
        assert len(r.output.strip().splitlines()) == 1 and expected in r.output
