"""``c2n calibrate``: clips of a ChArUco board, one per camera → ``cameras.toml``."""

from __future__ import annotations

import re

import click

from capture2notation.errors import CalibrationError

from .options import check_output_file

__all__ = ["calibrate", "parse_board", "parse_origin"]

_BOARD = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


def parse_board(text: str) -> tuple[int, int]:
    """``"7x5"`` → ``(7, 5)`` (columns, rows); a one-line error otherwise."""
    m = _BOARD.match(text or "")
    if not m or min(int(m.group(1)), int(m.group(2))) < 2 or max(int(m.group(1)), int(m.group(2))) > 64:
        raise CalibrationError(f"--board {text!r} must be COLUMNSxROWS squares, each 2-64, e.g. 7x5")
    return int(m.group(1)), int(m.group(2))


def parse_origin(text: str) -> tuple[float, float, float]:
    """``"X,Y,YAW"`` (metres, metres, degrees) → floats; a one-line error otherwise."""
    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != 3 or not all(abs(v) < 1e4 for v in vals):
        raise CalibrationError(f"--origin {text!r} must be X,Y,YAW: metres, metres, degrees")
    return vals  # type: ignore[return-value]


@click.command("calibrate")
@click.argument("videos", nargs=-1, required=True, type=click.Path(exists=True, path_type=str))
@click.option(
    "-o", "--output", required=True, type=click.Path(dir_okay=False), help="Calibration file to write (.toml)."
)
@click.option("--board", "board_size", default="7x5", show_default=True, help="ChArUco squares COLUMNSxROWS.")
@click.option("--square", type=float, default=0.04, show_default=True, help="Square side, metres.")
@click.option("--marker", type=float, default=0.03, show_default=True, help="Marker side, metres.")
@click.option("--dict", "dictionary", default="DICT_4X4_250", show_default=True, help="OpenCV ArUco dictionary.")
@click.option(
    "--floor",
    type=click.Choice(["standing", "lying"]),
    default="standing",
    show_default=True,
    help="How the board is at the clips' start, fixing the world: upright on its lower edge on the floor, "
    "or lying face up on it.",
)
@click.option(
    "--origin",
    default="0,0,0",
    show_default=True,
    help="X,Y,YAW of that board: the floor point below its centre (metres) and the turn of its face "
    "from +y, degrees anticlockwise (lying: its centre, and its columns' angle from +x).",
)
@click.option(
    "--margin", type=float, default=0.0, show_default=True, help="Standing board: its border below the squares, metres."
)
@click.option("--step", type=click.IntRange(1, 100), default=1, show_default=True, help="Use every STEP-th frame.")
def calibrate(videos, output, board_size, square, marker, dictionary, floor, origin, margin, step):
    """Calibrate two or more cameras from their synchronised clips of a moving ChArUco board.

    A camera is named by its clip's file stem, or its folder for
    .../NAME/video.mp4.  The clips start with the board still on the floor
    (see --floor), then the board moves through the space, tilted, near and far.
    """
    from capture2notation.calibrate import calibrate_videos
    from capture2notation.io.calibration import Board, write_calibration

    check_output_file(output)
    board = Board(parse_board(board_size), square, marker, dictionary)
    where = parse_origin(origin)
    if not (0.0 <= margin < 1.0):
        raise CalibrationError(f"--margin {margin!r} must be metres in [0, 1)")
    result = calibrate_videos(videos, board, where, floor, margin, step)
    for name, rms in result.rms_px.items():
        cam = result.calibration[name]
        x, y, z = cam.centre
        click.echo(
            f"{name}: reprojection RMS {rms:.3f} px over {result.views[name]} board views; "
            f"f = {cam.K[0, 0]:.1f} px, centre ({x:.3f}, {y:.3f}, {z:.3f}) m"
        )
    comment = f"c2n calibrate: {result.shared_views} board views shared by two or more cameras"
    write_calibration(result.calibration, output, comment=comment)
    click.echo(f"{output}: {len(result.rms_px)} cameras written")
