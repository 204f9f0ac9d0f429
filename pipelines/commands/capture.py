"""``c2n capture INPUT -o OUTDIR``: video or motion file → notation files."""

from __future__ import annotations

import json
import os
from pathlib import Path

import click

from .options import FPS, TEMPO_OR_NONE, Number, check_outdir

__all__ = ["capture"]

#: A floor height a recording can have, metres: a motion file's origin may
#: sit anywhere within a room-sized volume, never kilometres away.
FLOOR_HEIGHT = Number(-100.0, 100.0, "metres")


class FloorOrAuto(click.ParamType):
    """``--floor``: ``auto`` (found from the feet; None) or a height in :data:`FLOOR_HEIGHT`'s range."""

    name = "floor"

    def convert(self, value, param, ctx):
        if value is None or (isinstance(value, str) and value.strip().lower() == "auto"):
            return None
        try:
            return FLOOR_HEIGHT.convert(value, param, ctx)
        except click.BadParameter as exc:
            self.fail(f"{exc.message}; or 'auto' to find it from the feet", param, ctx)


#: ``--floor`` of a capture.
FLOOR = FloorOrAuto()


@click.command("capture")
@click.argument("input_paths", metavar="INPUT...", nargs=-1, required=True, type=click.Path(exists=True, path_type=str))
@click.option(
    "-o",
    "--output",
    "outdir",
    required=True,
    type=click.Path(file_okay=False, path_type=str),
    help="Folder for score.lab, score.json, laban_editor.json, benesh.json, labels.csv, "
    "staff.svg/png, capture.npz, effort.json and index.html.",
)
@click.option(
    "--backend",
    type=click.Choice(["blazepose", "markers"]),
    default="blazepose",
    show_default=True,
    help="Keypoints from a video: the BlazePose model or the renderer's colour markers.",
)
@click.option(
    "--tempo",
    type=TEMPO_OR_NONE,
    default=None,
    metavar="BPM|none",
    help="Beats per minute (default: estimated from the movements and a video's sound track); "
    "'none' writes time as it is: 60 bpm, one beat a second.",
)
@click.option("--fps-override", type=FPS, default=None, help="Frame rate to use instead of the input's.")
@click.option("--grid", default="1/4", show_default=True, help="Beat grid of starts and durations, e.g. 1/4 or 1/2.")
@click.option("--no-effort", is_flag=True, help="Skip the Laban Effort estimate (the slowest step).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the Effort posteriors.")
@click.option(
    "--workers",
    type=click.IntRange(1, 64),
    default=min(os.cpu_count() or 1, 4),
    show_default="this machine's cores, at most 4",
    help="Processes sampling the Effort posteriors (the results do not depend on it).",
)
@click.option(
    "--flip-test",
    is_flag=True,
    help="BlazePose also reads a mirrored copy of each crop (more accurate in side views; slower).",
)
@click.option(
    "--axes",
    type=click.Choice(["standard", "body"]),
    default="standard",
    show_default=True,
    help="Cross of axes limb directions are read in: 'standard' (vertical from gravity, front from the hips) "
    "or 'body' (arms and head along the torso, as LabanotationSuite reads Kinect captures).",
)
@click.option(
    "--calibration",
    type=click.Path(dir_okay=False, path_type=str),
    default=None,
    metavar="FILE",
    help="A calibration file (TOML, as written by c2n render's camera.toml) with the video's camera; "
    "by default the camera is estimated from the person.",
)
@click.option(
    "--floor",
    type=FLOOR,
    default="auto",
    metavar="auto|HEIGHT_M",
    help="The floor's height in metres, where you know it better than the capture: in a motion file's "
    "coordinates (z up, once read) or in a video's world (a calibration's floor is 0). "
    "Default 'auto': found from the feet (a motion file's tilt and drift too).",
)
@click.option(
    "--offsets",
    default=None,
    metavar="S,S,...|auto",
    help="Several clips: seconds each clip starts after the reference clock (one per clip), or 'auto' "
    "to find them from the keypoint motion; default the calibration's offset_s.",
)
def capture(
    input_paths,
    outdir,
    backend,
    tempo,
    fps_override,
    grid,
    no_effort,
    seed,
    workers,
    flip_test,
    axes,
    calibration,
    floor,
    offsets,
):
    """Turn INPUT (a video, image folder, keypoint track .npz from c2n keypoints, BVH, Kinect CSV or truth .npz)
    into notation files in OUTDIR.  Several video clips of calibrated cameras
    (--calibration naming each clip's camera) are triangulated into one capture."""
    from fractions import Fraction

    from capture2notation.errors import PipelineError
    from capture2notation.quantise.segment import SegmentParams
    from pipelines.capture import NO_TEMPO
    from pipelines.capture import capture as run
    from pipelines.capture_page import emotion_line

    try:
        step = Fraction(grid)
    except (ValueError, ZeroDivisionError):
        raise PipelineError(f"--grid {grid!r} must be a fraction of a beat such as 1/4") from None
    if not 0 < step <= 4:
        raise PipelineError(f"--grid {grid!r} must be a fraction of a beat in (0, 4]")
    check_outdir(outdir)
    tempo_value = tempo if tempo is None or tempo == NO_TEMPO else Fraction(tempo).limit_denominator(1000)
    if offsets is not None and len(input_paths) < 2:
        raise PipelineError("--offsets is for several clips (one per camera)")
    result = run(
        list(input_paths) if len(input_paths) > 1 else input_paths[0],
        outdir,
        backend=backend,
        tempo=tempo_value,
        fps_override=fps_override,
        progress=True,
        params=SegmentParams(grid=step),
        effort=not no_effort,
        seed=seed,
        workers=workers,
        flip_test=flip_test,
        axes=axes,
        calibration=calibration,
        floor=floor,
        **({"offsets": offsets} if offsets is not None else {}),
    )
    click.echo(
        f"{result.outdir}: {len(result.score.symbols)} symbols from {result.n_frames} frames "
        f"({result.kind}), tempo {result.score.tempo} bpm{result.tempo_text}"
    )
    if result.camera_estimate is not None:
        click.echo(f"  {result.camera_estimate.line()}")
    if "effort.json" in result.files:
        data = json.loads(Path(result.files["effort.json"]).read_text(encoding="utf-8"))
        click.echo(f"  emotion: {emotion_line(data)}")
    for note in result.skipped:
        click.echo(f"  not written: {note}")
    click.echo(f"  open {result.outdir / 'index.html'}")
