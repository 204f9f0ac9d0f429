"""``c2n effort CAPTURE_DIR``: recompute ``effort.json`` and its plots.

Reads ``CAPTURE_DIR/capture.npz`` (fitted joints, confidence, fps, times)
and ``CAPTURE_DIR/score.lab`` (the movements), estimates Laban Effort
(:func:`capture2notation.effort.estimate_effort`) and writes ``effort.json``,
``effort_progress.png`` and ``effort_pooled.png`` beside them.
"""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from capture2notation.body import JOINTS
from capture2notation.effort import estimate_effort, write_effort
from capture2notation.errors import PipelineError

__all__ = ["effort", "load_capture", "run_effort"]

CAPTURE_NPZ = "capture.npz"
SCORE_LAB = "score.lab"


def load_capture(path) -> dict:
    """Joints, confidence, fps, times and joint names from a ``capture.npz``.

    Also whether the capture was fitted to keypoints (``fitted``: its
    ``input_kind``; a file without one is fitted when it holds keypoints).
    Tolerant of optional keys: ``confidence`` defaults to 1 where the joint
    is finite (0 where NaN), ``times`` to ``arange(T) / fps``, ``fps`` to
    the median frame interval of ``times``, ``joint_names`` to the canonical
    :data:`~capture2notation.body.JOINTS`.

    Raises
    ------
    PipelineError
        Missing file, missing ``joints``, or inconsistent shapes (named).
    """
    path = Path(path)
    if not path.is_file():
        raise PipelineError(f"{path}: capture file not found (run c2n capture first)")
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise PipelineError(f"{path}: not a readable .npz file ({exc})") from None
    if "joints" not in data:
        raise PipelineError(f"{path}: no 'joints' array (T, J, 3); keys are {sorted(data)}")
    joints = np.asarray(data["joints"], dtype=float)
    if joints.ndim != 3 or joints.shape[2] != 3:
        raise PipelineError(f"{path}: 'joints' must be (T, J, 3), got {joints.shape}")
    t_count = joints.shape[0]
    finite = np.all(np.isfinite(joints), axis=2)
    conf = data.get("confidence")
    conf = finite.astype(float) if conf is None else np.where(finite, np.asarray(conf, dtype=float), 0.0)
    if conf.shape != joints.shape[:2]:
        raise PipelineError(f"{path}: 'confidence' must be (T, J) = {joints.shape[:2]}, got {conf.shape}")
    times = data.get("times")
    fps = data.get("fps")
    if fps is None and (times is None or len(times) < 2):
        raise PipelineError(f"{path}: neither 'fps' nor at least two 'times' to date the frames")
    if fps is None:
        fps = 1.0 / float(np.median(np.diff(times)))
    fps = float(np.asarray(fps))
    times = np.arange(t_count) / fps if times is None else np.asarray(times, dtype=float)
    if times.shape != (t_count,):
        raise PipelineError(f"{path}: 'times' must have T = {t_count} entries, got {times.shape}")
    names = tuple(str(n) for n in data["joint_names"]) if "joint_names" in data else JOINTS
    if "input_kind" in data:
        from pipelines.capture_input import is_fitted

        fitted = is_fitted(str(data["input_kind"]))
    else:
        # Written before the kind was recorded: a video's capture holds its keypoints.
        fitted = "keypoints" in data and bool(np.isfinite(np.asarray(data["keypoints"], dtype=float)).any())
    return {"joints": joints, "confidence": conf, "fps": fps, "times": times, "joint_names": names, "fitted": fitted}


def run_effort(capture_dir, seed: int = 0, workers: int = 2, plots: bool = True):
    """Estimate and write Effort for one capture folder; returns (result, paths)."""
    from capture2notation.notation import read
    from pipelines.capture import effort_sampler_options

    capture_dir = Path(capture_dir)
    cap = load_capture(capture_dir / CAPTURE_NPZ)
    score_path = capture_dir / SCORE_LAB
    if not score_path.is_file():
        raise PipelineError(f"{score_path}: score not found (the movements' timing comes from it)")
    score = read(score_path)
    result = estimate_effort(
        cap["joints"],
        cap["confidence"],
        cap["fps"],
        score,
        rng=np.random.default_rng(seed),
        times=cap["times"],
        joint_names=cap["joint_names"],
        workers=workers,
        sampler_kw=effort_sampler_options(cap["fitted"]),
    )
    paths = write_effort(result, capture_dir, plots=plots, rng=seed)
    return result, paths


@click.command("effort")
@click.argument("capture_dir", type=click.Path(exists=True, file_okay=False, path_type=str))
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the emcee runs.")
@click.option(
    "--workers", type=click.IntRange(1, 256), default=2, show_default=True, help="Processes for the posteriors."
)
@click.option("--no-plots", is_flag=True, help="Write effort.json only.")
def effort(capture_dir, seed, workers, no_plots):
    """Recompute effort.json (and plots) from CAPTURE_DIR/capture.npz and score.lab."""
    result, paths = run_effort(capture_dir, seed=seed, workers=workers, plots=not no_plots)
    n_conv = sum(m.posterior.converged for m in result.movements)
    click.echo(
        f"{paths['json']}: {len(result.movements)} movements ({n_conv} converged), {len(result.skipped)} skipped"
    )
    click.echo(f"emotion: {result.emotion_text}")
