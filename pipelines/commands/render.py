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


#: Camera settings ``c2n render`` accepts: (option, low, high, unit) — the
#: phones people film dance with, on a tripod or a table (issue 13).
CAMERA_RANGES = {
    "camera_height": ("--camera-height", 0.4, 2.0, "m"),
    "pitch": ("--pitch", -20.0, 20.0, "°"),
    "roll": ("--roll", -10.0, 10.0, "°"),
    "hfov": ("--hfov", 50.0, 80.0, "°"),
}


def _phone_camera(view, size, camera_height, pitch, roll, hfov):
    """The render camera for the camera options (None: the view's preset)."""
    given = {"camera_height": camera_height, "pitch": pitch, "roll": roll, "hfov": hfov}
    if all(v is None for v in given.values()):
        return None
    for key, value in given.items():
        option, lo, hi, unit = CAMERA_RANGES[key]
        if value is not None and not (lo <= value <= hi):
            raise PipelineError(f"{option} {value:g} must be in [{lo:g}, {hi:g}] {unit}")
    from capture2notation.errors import SyntheticError
    from synthetic.render.camera import Camera

    try:
        return Camera.phone(
            view, size, height=camera_height, pitch_deg=pitch or 0.0, roll_deg=roll or 0.0, hfov_deg=hfov
        )
    except SyntheticError as exc:
        raise PipelineError(f"--camera-height/--pitch/--hfov: {exc}") from None


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
@click.option("--view", default="front", show_default=True, help="Camera: front, 45, side or -45.")
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
@click.option("--camera-height", type=float, default=None, help="Camera height above the floor, metres (0.4-2).")
@click.option("--pitch", type=float, default=None, help="Camera pitch, degrees, positive looks up (-20..20).")
@click.option("--roll", type=float, default=None, help="Camera roll about its axis, degrees (-10..10).")
@click.option("--hfov", type=float, default=None, help="Horizontal field of view, degrees (50-80).")
@click.option(
    "--views",
    default=None,
    help="Several cameras, e.g. front,45: OUTDIR/NAME/video.mp4 each, their true cameras in OUTDIR/cameras.toml.",
)
@click.option(
    "--calibration-clip",
    is_flag=True,
    help="With --views: also a clip per camera of a ChArUco board moved through the space, OUTDIR/calibration/NAME.mp4.",
)
@click.option(
    "--seed", type=click.IntRange(0, 2**32 - 1), default=0, show_default=True, help="Seed of the board's path."
)
def render(
    score,
    outdir,
    fps,
    size,
    view,
    style,
    emotion,
    png,
    audio,
    camera_height,
    pitch,
    roll,
    hfov,
    views,
    calibration_clip,
    seed,
):
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
    if views is not None:
        _render_views(score, outdir, views, fps, wh, style, emotion, png, audio, calibration_clip, seed, view)
        return
    if calibration_clip:
        raise PipelineError("--calibration-clip needs --views (two or more cameras to calibrate)")
    camera = _phone_camera(view, wh, camera_height, pitch, roll, hfov)
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
        camera=camera,
    )
    sound = "" if audio is None else (", with a click track" if audio == "click" else f", with the sound of {audio}")
    click.echo(
        f"{out}: {video}, truth.npz, camera.toml and score.lab written ({style}, {view} view, {wh[0]}x{wh[1]} at {fps:g} fps{sound})"
    )


def _render_views(score, outdir, views, fps, wh, style, emotion, png, audio, calibration_clip, seed, view):
    from capture2notation.notation.formats import read
    from synthetic.render import VIEWS
    from synthetic.render.multiview import calibrate_command, render_views

    names = [v.strip() for v in views.split(",") if v.strip()]
    for v in names:
        check_choice(v, "--views", list(VIEWS))
    if len(names) < 2 or len(set(names)) != len(names):
        raise PipelineError(f"--views {views!r} must name two or more different cameras, e.g. front,45")
    ctx = click.get_current_context()
    if ctx.get_parameter_source("view") != click.core.ParameterSource.DEFAULT:
        raise PipelineError(f"--view {view!r} and --views {views!r}: give one of them")
    fixed = ("camera_height", "pitch", "roll", "hfov")
    if any(ctx.params.get(k) is not None for k in fixed) or png or audio is not None:
        raise PipelineError(
            "--views renders the preset cameras as mp4: drop --camera-height/--pitch/--roll/--hfov/--png/--audio"
        )
    out = render_views(
        read(score),
        outdir,
        names,
        fps=fps,
        size=wh,
        style=style,
        emotion=emotion,
        calibration_clip=calibration_clip,
        seed=seed,
    )
    click.echo(
        f"{out}: {', '.join(f'{v}/video.mp4' for v in names)}, cameras.toml and score.lab written ({style}, {wh[0]}x{wh[1]} at {fps:g} fps)"
    )
    if calibration_clip:
        click.echo(f"{out}/calibration: a board clip per camera; calibrate them with")
        click.echo("  " + calibrate_command(out, names))
