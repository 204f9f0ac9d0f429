"""``c2n keypoints``: video → keypoint track (``.npz``), optionally an overlay video."""

from __future__ import annotations

import click

from capture2notation.keypoints import BACKENDS, extract

from .options import FPS, check_output_file


@click.command("keypoints")
@click.argument("video", type=click.Path(exists=True, path_type=str))
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Track file to write (.npz).")
@click.option("--backend", type=click.Choice(BACKENDS), default="blazepose", show_default=True)
@click.option(
    "--overlay",
    type=click.Path(dir_okay=False),
    default=None,
    help="Also write the video with the skeleton drawn (.mp4/.avi).",
)
@click.option(
    "--model",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="ONNX pose model (default: $C2N_POSE_MODEL or the cache).",
)
@click.option("--fps", type=FPS, default=None, help="Frame rate of an image folder (default 30).")
@click.option("--threads", type=click.IntRange(1, 256), default=2, show_default=True, help="onnxruntime threads.")
@click.option("--no-smooth", is_flag=True, help="Disable the one-euro temporal filter.")
@click.option(
    "--markers",
    "markers_file",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="JSON marker colours for --backend markers (default: the renderer's).",
)
@click.option(
    "--flip-test",
    is_flag=True,
    help="Also read a mirrored copy of each crop and keep the reading facing the right way "
    "(more accurate in side views and folded arms; about half the speed).",
)
def keypoints(video, output, backend, overlay, model, fps, threads, no_smooth, markers_file, flip_test):
    """Extract 33 BlazePose keypoints per frame from VIDEO (file or image folder)."""
    check_output_file(output)
    if overlay:
        check_output_file(overlay, "--overlay")
    markers = None
    if markers_file:
        from capture2notation.keypoints.markers import read_marker_specs

        markers = read_marker_specs(markers_file)
    track = extract(
        video,
        backend,
        model=model,
        fps=fps,
        threads=threads,
        smooth=not no_smooth,
        markers=markers,
        progress=True,
        flip_test=flip_test,
    )
    track.save(output)
    seen = float((track.presence > 0).mean()) if len(track) else 0.0
    click.echo(f"{output}: {len(track)} frames at {track.fps:g} fps, person found in {100 * seen:.0f}% of frames")
    if overlay:
        from capture2notation.keypoints.overlay import write_overlay

        write_overlay(video, track, overlay, fps=fps)
        click.echo(f"{overlay}: overlay written")
