"""``c2n models``: fetch, locate and check the BlazePose ONNX model."""

from __future__ import annotations

import click

from capture2notation.keypoints import model as pose_model


@click.group("models")
def models():
    """Manage the pose model (downloaded from the package index, converted to ONNX)."""


@models.command("fetch")
@click.option(
    "--wheel",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help=f"Use this mediapipe-{pose_model.MEDIAPIPE_VERSION} wheel instead of downloading it.",
)
@click.option("--force", is_flag=True, help="Rebuild even if a valid cached model exists.")
def fetch(wheel, force):
    """Download mediapipe's BlazePose model with pip, convert it to ONNX, verify and cache it."""
    path = pose_model.fetch_model(wheel=wheel, force=force)
    click.echo(str(path))


@models.command("path")
def path():
    """Print the pose model that would be used (without fetching)."""
    click.echo(str(pose_model.resolve_model(fetch=False)))


@models.command("verify")
@click.option("--model", type=click.Path(exists=True, dir_okay=False), default=None)
def verify(model):
    """Check the pose model loads and has the expected inputs and outputs."""
    p = pose_model.resolve_model(model, fetch=False)
    pose_model.verify_onnx(p)
    click.echo(f"{p}: ok (sha256 {pose_model.sha256_file(p)})")
