"""The same performance from several cameras, and each camera's calibration clip.

``render_views(score, outdir, ["front", "45"])`` writes ``OUTDIR/NAME/``
for each view (``video.mp4``, ``truth.npz``, ``camera.toml``: a complete
one-camera render each, so every single-view tool reads it), the renderer's
true cameras together in ``OUTDIR/cameras.toml`` (for experiments, passed
explicitly; a capture never reads it on its own), ``OUTDIR/score.lab`` and,
with ``calibration_clip``, ``OUTDIR/calibration/NAME.mp4``: the ChArUco board
of :mod:`.board_clip` moved through the space, one clip per camera, all
synchronised, for ``c2n calibrate``.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from capture2notation.body import Body
from capture2notation.errors import SyntheticError
from capture2notation.io.calibration import Calibration, CameraCalibration, write_calibration

from .board_clip import BOARD, FLOOR_MARGIN, board_path, floor_origin, render_board_clip
from .camera import VIEWS, Camera
from .job import perform_score, render_motion

__all__ = ["CAMERAS_FILE", "calibrate_command", "render_views"]

#: Every true camera of a multi-view render, beside the view folders.
CAMERAS_FILE = "cameras.toml"


def calibrate_command(outdir, views) -> str:
    """The ``c2n calibrate`` line for the calibration clips of a multi-view render."""
    cams = [Camera.for_view(v) for v in views]
    x, y, yaw = floor_origin(cams)
    clips = " ".join(str(Path(outdir) / "calibration" / f"{v}.mp4") for v in views)
    b = BOARD
    return (
        f"c2n calibrate {clips} -o cameras.toml --board {b.squares[0]}x{b.squares[1]} --square {b.square:g} "
        f"--marker {b.marker:g} --dict {b.dictionary} --floor standing --origin {x:g},{y:g},{yaw:.6g} "
        f"--margin {FLOOR_MARGIN * b.square:g}"
    )


def render_views(
    score,
    outdir,
    views,
    *,
    fps: float = 25.0,
    size=(640, 480),
    style: str = "mannequin",
    emotion: str | None = None,
    calibration_clip: bool = False,
    seed: int = 0,
    progress: bool = True,
) -> Path:
    """Perform `score` once and render it from every view in `views`.

    Parameters
    ----------
    score : capture2notation.notation.Score
    outdir : str or Path
    views : sequence of str
        Names from :data:`.camera.VIEWS`, at least two, no repeats.
    fps, size, style, emotion, progress
        As :func:`.job.render_score`.
    calibration_clip : bool
        Also write ``OUTDIR/calibration/NAME.mp4`` for each view.
    seed : int
        Seeds the board's path and the clips' noise.

    Returns
    -------
    Path
        The output folder.
    """
    from capture2notation.notation.formats import dumps, write

    views = list(views)
    if len(views) < 2 or len(set(views)) != len(views):
        raise SyntheticError(f"views {','.join(views)} must be two or more different names")
    for v in views:
        if v not in VIEWS:
            raise SyntheticError(f"unknown view {v!r}; expected some of {', '.join(VIEWS)}")
    body = Body()
    score, motion = perform_score(score, fps, body, style, emotion)
    outdir = Path(outdir)
    cameras = [Camera.for_view(v, size, body.height) for v in views]
    for v, cam in zip(views, cameras):
        render_motion(
            motion,
            outdir / v,
            view=v,
            style=style,
            score_json=dumps(score, "json"),
            effort_json=json.dumps(asdict(score.resolved_effort())),
            progress=progress,
            camera=cam,
        )
    truth = [
        CameraCalibration(v, tuple(int(s) for s in c.size), np.asarray(c.K), np.zeros(5), c.R, c.t)
        for v, c in zip(views, cameras)
    ]
    write_calibration(Calibration.of(truth, BOARD), outdir / CAMERAS_FILE, comment="the renderer's true cameras")
    write(score, outdir / "score.lab")
    if calibration_clip:
        rng = np.random.default_rng(seed)
        path = board_path(cameras, rng)
        for v, cam in zip(views, cameras):
            render_board_clip(cam, path, outdir / "calibration" / f"{v}.mp4", fps, rng)
    return outdir
