"""``c2n render``: score → ``video.mp4`` (or PNG frames) + ``truth.npz`` + ``score.lab``."""

from __future__ import annotations

import re
from pathlib import Path

import click

from capture2notation.errors import PipelineError

from .options import FPS, check_outdir, score_format_or_fail

__all__ = ["check_choice", "parse_size", "render"]

_SIZE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


def parse_size(text: str, option: str = "--size") -> tuple[int, int]:
    """``"640x480"`` → ``(640, 480)``; a one-line :class:`PipelineError` otherwise."""
    m = _SIZE.match(text or "")
    if not m:
        raise PipelineError(f"{option} {text!r} must be WIDTHxHEIGHT in pixels, e.g. 640x480")
    w, h = int(m.group(1)), int(m.group(2))
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise PipelineError(f"{option} {text!r}: width and height must each be 16-8192 pixels")
    return w, h


def check_choice(value, option: str, choices) -> str | None:
    """`value` if it is one of `choices` (or None); a one-line :class:`PipelineError` otherwise."""
    if value is not None and value not in choices:
        raise PipelineError(f"{option} {value!r} is not one of {', '.join(choices)}")
    return value


def _fps(value: float) -> float:
    if not (value > 0 and value <= 1000):
        raise PipelineError(f"--fps {value!r} must be a frame rate in (0, 1000]")
    return value


@click.command("render")
@click.argument("score", type=click.Path(dir_okay=False, path_type=str))
@click.option(
    "-o",
    "--output",
    "outdir",
    required=True,
    type=click.Path(file_okay=False, path_type=str),
    help="Folder to write video.mp4, truth.npz, camera.toml and score.lab into.",
)
@click.option("--fps", type=FPS, default=25.0, show_default=True, help="Frames per second.")
@click.option("--size", default="640x480", show_default=True, help="Image WIDTHxHEIGHT in pixels.")
@click.option("--view", default="front", show_default=True, help="Camera: front, 45 or side.")
@click.option("--style", default="mannequin", show_default=True, help="Drawing: mannequin, stick or markers.")
@click.option("--emotion", default=None, help="Perform with an emotion preset: happy, sad, angry or afraid.")
@click.option("--png", is_flag=True, help="Write the frames as OUTDIR/frames/frame_NNNNNN.png instead of video.mp4.")
@click.option(
    "--audio",
    default=None,
    metavar="click|FILE",
    help="Give video.mp4 a sound track: 'click' (a click on every beat at the score's tempo, "
    "the first of each measure accented) or a music file's sound.",
)
def render(score, outdir, fps, size, view, style, emotion, png, audio):
    """Perform the notation in SCORE (.lab, .json, 1974 coded input) with the
    virtual dancer and render it with its ground truth."""
    from capture2notation.notation import EMOTIONS
    from capture2notation.notation.formats import read
    from synthetic.render import STYLES, VIEWS, render_score

    wh = parse_size(size)
    _fps(fps)
    check_outdir(outdir)
    score_format_or_fail(score)
    check_choice(view, "--view", list(VIEWS))
    check_choice(style, "--style", list(STYLES))
    check_choice(emotion, "--emotion", list(EMOTIONS))
    if audio is not None and png:
        raise PipelineError("--audio needs video.mp4: a folder of PNG frames (--png) has no sound track")
    if audio is not None and audio != "click" and not Path(audio).is_file():
        raise PipelineError(f"--audio {audio!r}: no such file; expected 'click' or a music file")
    parsed = read(score)
    video = "frames" if png else "video.mp4"
    out = render_score(
        parsed,
        outdir,
        fps=fps,
        size=wh,
        view=view,
        style=style,
        emotion=emotion,
        progress=True,
        video_name=video,
        audio=audio,
    )
    sound = "" if audio is None else (", with a click track" if audio == "click" else f", with the sound of {audio}")
    click.echo(
        f"{out}: {video}, truth.npz, camera.toml and score.lab written ({style}, {view} view, {wh[0]}x{wh[1]} at {fps:g} fps{sound})"
    )
