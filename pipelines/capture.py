"""The capture job: video or motion file → notation files a notator can use.

INPUT is a video file or image folder (keypoints → 3D fit), a keypoint
track saved by ``c2n keypoints`` (the same fit, without running the pose
model again), or a motion file
(BVH, Kinect v2 CSV, truth sidecar ``.npz``) read directly.  The motion is
then quantised (:mod:`capture2notation.quantise`) and every output is
written atomically into OUTDIR:

==================  ==========================================================
``score.lab``       the score, our text format
``score.json``      the same, JSON
``laban_editor.json``  LabanotationSuite's LabanEditor score
``benesh.json``     Benesh key poses at every key frame
``labels.csv``      per-frame labels of every part
``staff.svg/.png``  the Labanotation staff (a long one continues on
                    ``staff-2.png``, … pages)
``capture.npz``     the input's kind (``input_kind``), keypoints (video
                    input), fitted joints (T, J, 3), angles,
                    confidence (T, J), fps, times; for video the camera
                    estimate with its uncertainty (``camera_estimate``,
                    JSON) and which camera the fit used (``camera_source``)
``effort.json``     Laban Effort with uncertainty (and its plots)
``overlay.mp4``     the video with the keypoints drawn (video input)
``index.html``      the staff beside the overlay video, with a playhead
                    (:mod:`pipelines.capture_page`)
==================  ==========================================================

The tempo is given (``tempo=``), ``"none"`` (60 bpm: one beat a second),
or estimated from the movements and, for a video with a sound track, its
beat (:mod:`capture2notation.quantise.beats`, the optional ``audio`` extra);
the page and the command line say which, and how sure.

A capture reads only its input and the options given (DESIGN.md, "What a
capture may know"): a known camera comes from ``calibration=``
(``--calibration cameras.toml``; ``c2n render`` writes its true camera as
``camera.toml`` for experiments), otherwise the fitting stage estimates the
camera from the person.  Files lying beside the input are never read.
"""

from __future__ import annotations

import concurrent.futures
import json
import logging
import os
import shutil
import tempfile
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation.atomic import atomic_path, write_text
from capture2notation.body import JOINTS
from capture2notation.errors import C2NError, PipelineError, QuantiseError
from capture2notation.fitting.motion import joints_for_labels
from capture2notation.fitting.result import labelled_confidence
from capture2notation.notation.model import Score
from capture2notation.quantise.benesh import benesh_key_poses, write_benesh
from capture2notation.quantise.confidence import score_confidence
from capture2notation.quantise.labels import write_labels_csv
from capture2notation.quantise.segment import (
    Segmentation,
    SegmentParams,
    segment_motion,
)
from pipelines.capture_input import FITTED_KINDS, feet_seen, input_kind, is_fitted, load_motion
from pipelines.capture_page import index_html

__all__ = [
    "NO_TEMPO",
    "CaptureResult",
    "capture",
    "notate",
    "tempo_note",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class CaptureResult:
    """What :func:`capture` produced.

    Attributes
    ----------
    outdir : Path
    kind : str
        ``"video"``, ``"keypoints"``, ``"bvh"``, ``"kinect"``, ``"truth"`` or ``"multiview"``.
    score : Score
    segmentation : Segmentation
    motion : FitResult
        Fitted (video) or read (motion file) joints, angles, confidence.
    track : KeypointTrack or None
        Keypoints (video input only).
    files : dict of str to Path
        Every file written, by name.
    seconds : dict of str to float
        Wall-clock time of each stage.
    skipped : tuple of str
        Outputs not written, with the reason.
    tempo_text : str
        How the tempo was set, after "tempo N bpm" (:func:`tempo_note`).
    camera_estimate : CameraEstimate or None
        The camera estimated from the person (video input; None when the
        feet and body were not seen in enough frames).
    camera_source : str
        ``"estimated"`` or ``"calibration FILE"``: the camera the fit used.
    """

    outdir: Path
    kind: str
    score: Score
    segmentation: Segmentation
    motion: object
    track: object | None
    files: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)
    skipped: tuple = ()
    tempo_text: str = ""
    camera_estimate: object | None = None
    camera_source: str = ""

    @property
    def n_frames(self) -> int:
        return int(np.asarray(self.motion.joints).shape[0])


#: ``tempo=`` (``--tempo``) value that writes time as it is: one beat a second.
NO_TEMPO = "none"
#: The tempo written for :data:`NO_TEMPO` and when no beat is found, bpm: one beat a second.
SECONDS_TEMPO = 60


def _check_options(backend: str, tempo, fps_override) -> None:
    if backend not in ("blazepose", "markers"):
        raise PipelineError(f"--backend {backend!r} is not one of blazepose, markers")
    if isinstance(tempo, str):
        if tempo != NO_TEMPO:
            raise PipelineError(f"--tempo {tempo!r} must be beats per minute in (0, 400] or {NO_TEMPO!r}")
    elif tempo is not None and not (np.isfinite(float(tempo)) and 0 < float(tempo) <= 400):
        raise PipelineError(f"--tempo {tempo!r} must be beats per minute in (0, 400]")
    if fps_override is not None and not (np.isfinite(float(fps_override)) and 0 < float(fps_override) <= 1000):
        raise PipelineError(f"--fps-override {fps_override!r} must be a frame rate in (0, 1000]")


def capture(
    input_path,
    outdir,
    backend: str = "blazepose",
    tempo=None,
    fps_override=None,
    progress: bool = True,
    *,
    meter: int = 4,
    params: SegmentParams | None = None,
    effort: bool = True,
    seed: int = 0,
    overlay: bool = True,
    flip_test: bool = False,
    axes: str = "standard",
    calibration=None,
    floor: float | None = None,
    offsets=None,
    workers: int = 1,
    threads: int = 2,
) -> CaptureResult:
    """Capture notation from a video or motion file, or from clips of several calibrated cameras.

    Parameters
    ----------
    input_path : str or Path, or list of them
        Video file, image folder, ``.bvh``, Kinect ``.csv`` or truth ``.npz``;
        a list of two or more clips of calibrated cameras is a multi-camera
        capture (:func:`pipelines.capture_multi.capture_multi`).
    outdir : str or Path
        Created if missing; see the module docstring for its files.
    backend : {"blazepose", "markers"}
        Keypoint backend for video input.
    tempo : float or "none", optional
        Beats per minute; estimated when omitted (from the movements, and
        from the sound track's beats when a video has one); ``"none"``
        writes time as it is: 60 bpm, one beat a second.
    fps_override : float, optional
        Frame rate to use instead of the file's.
    progress : bool
        Progress bar over frames (stderr).
    meter : int
        Beats per measure of the written score.
    params : SegmentParams, optional
        Segmentation tuning (beat grid, smoothing, thresholds).
    effort : bool
        Estimate Laban Effort (``effort.json``); the slowest step.
    seed : int
        Seed of the Effort posteriors.
    workers : int
        Processes sampling the Effort posteriors (the results do not
        depend on it).
    threads : int
        The pose model's onnxruntime threads (1 where several captures run
        side by side on few cores).
    overlay : bool
        Write ``overlay.mp4`` for video input.
    flip_test : bool
        BlazePose also reads a mirrored copy of each crop (see
        :class:`capture2notation.keypoints.BlazePose`): more accurate, slower.
    axes : {"standard", "body"}
        The score's key (DESIGN.md, "Cross of axes").
    calibration : str or Path, optional
        Calibration file with the video's camera (see :func:`load_motion`),
        or every clip's camera.
    floor : float, optional
        The floor's height, metres, where the user knows it better than the
        capture: in a motion file's own coordinates once read (z up), or in
        a video's world (the calibration's, whose floor is z = 0, or the
        fit's own).  Found from the feet by default.
    offsets : "auto" or list of float, optional
        Several clips: their start offsets, seconds (see :func:`~pipelines.capture_multi.capture_multi`).

    Returns
    -------
    CaptureResult
    """
    if isinstance(input_path, (list, tuple)):
        if len(input_path) == 1:
            input_path = input_path[0]
        else:
            if calibration is None:
                raise PipelineError(f"{input_path[0]}: several clips need --calibration FILE with every clip's camera")
            from .capture_multi import load_views

            _check_options(backend, tempo, fps_override)
            for v in input_path:
                input_kind(v)  # a missing file or an unknown type, named
            motion, seconds, views, source = load_views(
                input_path, calibration, backend, fps_override, progress, offsets=offsets, overlay=overlay,
                flip_test=flip_test,
            )  # fmt: skip
            try:
                return notate(
                    motion, None, seconds, input_path=Path(input_path[0]), outdir=outdir, kind="multiview",
                    tempo=tempo, meter=meter, params=params, effort=effort, seed=seed, overlay=overlay, axes=axes,
                    camera=(None, source), extra_outputs=views, workers=workers,
                )  # fmt: skip
            finally:
                views.close()
    elif offsets is not None:
        raise PipelineError("--offsets is for several clips (one per camera)")
    _check_options(backend, tempo, fps_override)
    kind = input_kind(input_path)
    outdir = Path(outdir)
    motion, track, estimate, seconds = load_motion(
        input_path, kind, backend, fps_override, progress, flip_test, calibration=calibration, floor=floor,
        threads=threads, seed=seed,
    )  # fmt: skip
    camera_source = ""
    if track is not None:
        camera_source = "estimated" if calibration is None else f"calibration {calibration}"
        log.info("capture: %s", estimate.line() if estimate is not None else "camera not estimated (feet unseen)")
    return notate(
        motion,
        track,
        seconds,
        input_path=input_path,
        outdir=outdir,
        kind=kind,
        tempo=tempo,
        meter=meter,
        params=params,
        effort=effort,
        seed=seed,
        overlay=overlay,
        axes=axes,
        camera=(estimate, camera_source),
        workers=workers,
        line_of_sight=_line_of_sight(kind, calibration, input_path, track),
    )


def _line_of_sight(kind: str, calibration, path, track) -> np.ndarray | None:
    """A single camera's viewing axis in the fit's world, or None (motion files)."""
    if kind not in FITTED_KINDS:
        return None
    if calibration is None:
        # The fit's world has the camera on +y looking along -y (fitting.camera.Camera.default).
        return np.array([0.0, 1.0, 0.0])
    from capture2notation.fitting import Camera
    from capture2notation.io.calibration import read_calibration

    camera = Camera.from_calibration(read_calibration(calibration), path, track.image_size, undistorted=True)
    return np.asarray(camera.R, dtype=float)[2]


def notate(
    motion,
    track,
    seconds: dict,
    *,
    input_path,
    outdir,
    kind: str,
    tempo=None,
    meter: int = 4,
    params: SegmentParams | None = None,
    effort: bool = True,
    seed: int = 0,
    overlay: bool = True,
    axes: str = "standard",
    camera=(None, ""),
    extra_outputs=None,
    workers: int = 1,
    line_of_sight=None,
) -> CaptureResult:
    """Quantise fitted joints and write every output of a capture (after :func:`load_motion`).

    Parameters
    ----------
    motion : FitResult
    track : KeypointTrack or None
    seconds : dict
        Stage timings so far (updated).
    input_path : str or Path
        The input named in the outputs; for video kinds, the clip whose sound gives the tempo.
    kind : str
        ``"video"``, ``"multiview"`` or a motion-file kind (:func:`input_kind`).
    camera : (CameraEstimate or None, str)
        The camera estimate and the camera the fit used.
    extra_outputs : callable, optional
        ``extra_outputs(stage) -> dict`` of further files written into the
        staging folder (a multi-view capture's overlays).
    line_of_sight : (3,) ndarray, optional
        A single camera's viewing axis in the fit's world (symbol
        confidence: depth is measured worst along it); None otherwise.
    Other parameters are :func:`capture`'s.
    """
    outdir = Path(outdir)
    estimate, camera_source = camera
    # The body key is LabanotationSuite's reading of a Kinect's own arm
    # positions; the standard key keeps the fit throughout.
    measured_arms = kind not in FITTED_KINDS and axes == "body"
    joints = joints_for_labels(motion) if measured_arms else np.asarray(motion.joints, dtype=float)
    fps = float(motion.fps)
    if not np.isfinite(joints).any():
        raise PipelineError(f"{input_path}: no frame could be measured (no person found?)")

    evidence, sound = None, ""
    if kind in ("video", "multiview") and tempo is None:
        t0 = time.perf_counter()
        evidence, sound = _sound_evidence(input_path, fps)
        seconds["sound"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    seen = feet_seen(motion)
    title = Path(input_path).stem if Path(input_path).is_file() else Path(input_path).name
    given = Fraction(SECONDS_TEMPO) if tempo == NO_TEMPO else tempo
    # The same reading with the tempo given or, where none can be found, one beat a second.
    common = dict(meter=meter, params=params, title=title, axes=axes, feet_seen=seen, line_of_sight=line_of_sight)
    try:
        seg = segment_motion(joints, fps, tempo=given, tempo_evidence=evidence, **common)
    except QuantiseError as exc:
        if tempo is not None:
            raise
        # Too few movements for a beat: time as it is, one beat a second, and say so.
        log.warning("capture: no beat found (%s): writing %d bpm, one beat a second", exc, SECONDS_TEMPO)
        seg = segment_motion(joints, fps, tempo=Fraction(SECONDS_TEMPO), **common)
        seg = replace(seg, tempo_source="no beat")
    if tempo == NO_TEMPO:
        seg = replace(seg, tempo_source=NO_TEMPO)
    # A symbol rests on its joints measured and under their own labels.
    conf, readings = labelled_confidence(motion), getattr(motion, "front_readings", None)
    seg = replace(seg, score=score_confidence(seg.score, joints, fps, conf, line_of_sight, readings))
    seconds["quantise"] = time.perf_counter() - t0
    how = tempo_note(seg, sound)
    log.info("capture: tempo %s bpm%s", seg.tempo, how)
    # Exit order: an error stops the overlay, whose thread is then joined
    # before the staging folder is moved or removed.
    with (
        _staging(outdir) as stage,
        concurrent.futures.ThreadPoolExecutor(max_workers=1) as side,
        _stopped_on_error() as stop,
    ):
        # The overlay (decode, draw, encode; OpenCV releases the GIL) is
        # written beside the notation files and Effort, not after them.
        drawing = None
        if kind == "video" and overlay and track is not None:
            from capture2notation.keypoints.overlay import write_overlay

            drawing = side.submit(write_overlay, input_path, track, stage / "overlay.mp4", fps=track.fps, stop=stop)
        t0 = time.perf_counter()
        files, skipped = _write_outputs(stage, seg, motion, track, kind, (estimate, camera_source))
        seconds["outputs"] = time.perf_counter() - t0
        if extra_outputs is not None:
            files.update(extra_outputs(stage))
        if effort:
            t0 = time.perf_counter()
            try:
                files.update(_write_effort(stage, seg.score, motion, seed, workers, fitted=is_fitted(kind)))
            except C2NError as exc:
                # Effort is an addition to the notation: report, keep the rest.
                skipped.append(f"effort.json: {exc}")
                log.warning("capture: effort not estimated: %s", exc)
            seconds["effort"] = time.perf_counter() - t0
        if drawing is not None:
            t0 = time.perf_counter()
            files["overlay.mp4"] = drawing.result()
            seconds["overlay (after the rest)"] = time.perf_counter() - t0
        staged = CaptureResult(
            outdir, kind, seg.score, seg, motion, track, files, seconds, tuple(skipped), how, estimate, camera_source
        )
        files["index.html"] = write_text(stage / "index.html", index_html(staged))
        files = {name: outdir / Path(p).relative_to(stage) for name, p in files.items()}
    return replace(staged, files=files)


@contextmanager
def _stopped_on_error():
    """A ``threading.Event`` set if the block raises (an error or Ctrl-C): background work watching it gives up."""
    stop = threading.Event()
    try:
        yield stop
    except BaseException:
        stop.set()
        raise


@contextmanager
def _staging(outdir: Path):
    """A hidden folder beside `outdir` to write into; its files move into `outdir` only on success.

    A capture that fails part-way leaves neither an empty `outdir` nor a mix
    of new and old files in an existing one.
    """
    anchor = outdir.absolute().parent
    while not anchor.exists():
        anchor = anchor.parent
    try:
        stage = Path(tempfile.mkdtemp(dir=anchor, prefix=f".{outdir.name}.partial-"))
    except OSError as exc:
        raise PipelineError(f"{outdir}: cannot write in {anchor} ({exc.strerror})") from None
    try:
        yield stage
        outdir.mkdir(parents=True, exist_ok=True)
        for src in sorted(stage.rglob("*")):
            dst = outdir / src.relative_to(stage)
            if src.is_dir():
                dst.mkdir(exist_ok=True)
            else:
                os.replace(src, dst)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _write_outputs(outdir: Path, seg: Segmentation, motion, track, kind: str, camera=(None, "")):
    """The notation files, the staff and ``capture.npz`` (the overlay is written beside them)."""
    from capture2notation.notation import write
    from capture2notation.notation.formats.laban_editor import write_laban_editor
    from capture2notation.notation.staff import render_staff

    files: dict = {}
    skipped: list = []
    score = seg.score
    files["score.lab"] = write(score, outdir / "score.lab")
    files["score.json"] = write(score, outdir / "score.json")
    files["laban_editor.json"] = write_laban_editor(score, outdir / "laban_editor.json")
    angles = getattr(motion, "angles", None)
    stave, poses = benesh_key_poses(motion.joints, seg.key_frames, motion.fps, tempo=score.tempo, angles=angles)
    write_benesh(outdir / "benesh.json", stave, poses, tempo=score.tempo)
    files["benesh.json"] = outdir / "benesh.json"
    write_labels_csv(seg.labels, outdir / "labels.csv")
    files["labels.csv"] = outdir / "labels.csv"
    files["staff.svg"] = render_staff(score, outdir / "staff.svg", outdir / "staff.png")
    # a long staff continues on further PNG pages: staff-2.png, ...
    for page in sorted(outdir.glob("staff*.png")):
        files[page.name] = page
    files["capture.npz"] = _write_npz(outdir / "capture.npz", motion, track, *camera, input_kind=kind)
    if kind not in ("video", "multiview"):
        skipped.append(f"overlay.mp4: no video ({kind} input)")
    return files, skipped


def _write_npz(path: Path, motion, track, estimate=None, camera_source: str = "", input_kind: str = "") -> Path:
    T = np.asarray(motion.joints).shape[0]
    arrays = {
        "input_kind": np.asarray(input_kind),
        "fps": np.asarray(float(motion.fps)),
        "times": np.asarray(motion.times, float),
        "joint_names": np.asarray(JOINTS),
        "joints": np.asarray(motion.joints, float),
        "angles": np.asarray(motion.angles, float),
        "root": np.asarray(motion.root, float),
        "confidence": np.asarray(labelled_confidence(motion), float),
    }
    if track is not None:
        arrays["keypoints"] = np.asarray(track.xy, float)
        arrays["visibility"] = np.asarray(track.visibility, float)
        arrays["image_size"] = np.asarray(track.image_size)
        # JSON text (no pickles): the estimate and its 1-sd uncertainties.
        arrays["camera_estimate"] = np.asarray(json.dumps(None if estimate is None else estimate.as_dict()))
        arrays["camera_source"] = np.asarray(camera_source)
    else:
        arrays["keypoints"] = np.full((T, 33, 3), np.nan)
        arrays["visibility"] = np.zeros((T, 33))
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, **arrays)
    return path


def effort_sampler_options(fitted: bool) -> dict:
    """``sampler_kw`` of :func:`~capture2notation.effort.estimate_effort` for a fitted capture or a motion file."""
    from capture2notation.effort.likelihood import CAPTURE_RHO_RANGE

    return {"rho_range": CAPTURE_RHO_RANGE} if fitted else {}


def _write_effort(outdir: Path, score: Score, motion, seed: int, workers: int = 1, fitted: bool = False) -> dict:
    from capture2notation.effort import estimate_effort, write_effort

    result = estimate_effort(
        motion.joints,
        labelled_confidence(motion),
        motion.fps,
        score,
        rng=np.random.default_rng(seed),
        times=motion.times,
        workers=workers,
        sampler_kw=effort_sampler_options(fitted),
    )
    paths = write_effort(result, outdir, plots=True, rng=seed)
    return {Path(p).name: Path(p) for p in paths.values()}


def _sound_evidence(path, fps: float):
    """The beat of a video's sound track as tempo evidence, and what became of it (for the page).

    Returns
    -------
    SoundBeats or None
        None when there is no sound, no steady beat, or no beat tracker.
    str
        "" when the beat is used, else why not.
    """
    from dataclasses import replace as _replace

    from capture2notation.io.audio import read_audio
    from capture2notation.io.video import probe
    from capture2notation.quantise.beats import BeatTrackerMissing, sound_beats

    try:
        track = read_audio(path)
    except C2NError as exc:
        log.warning("capture: sound track not read: %s", exc)
        return None, "its sound track could not be read"
    if track is None:
        return None, "no sound track"
    try:
        beats = sound_beats(track)
    except BeatTrackerMissing as exc:
        log.warning("capture: %s; the tempo comes from the movements alone", exc)
        return None, "the sound track was not read: pip install 'capture2notation[audio]' for its beat"
    if beats is None:
        return None, "no steady beat in the sound track"
    # Frames re-timed by --fps-override play the sound as fast as the pictures.
    rate = probe(path).fps
    if abs(fps / rate - 1.0) > 1e-6:
        beats = _replace(beats, tempo=beats.tempo * fps / rate, beat_times=beats.beat_times * rate / fps)
    return beats, ""


def tempo_note(seg, sound: str = "") -> str:
    """Text after "tempo N bpm", e.g. ``" (estimated from the movements, 80% sure; else 36 bpm; give --tempo to fix it)"``.

    Says what set the tempo (``seg.tempo_source``): given, ``--tempo none``
    (one beat a second), no beat found (one beat a second), or estimated —
    from what, how sure (the calibrated confidence,
    :func:`capture2notation.quantise.tempo.estimate_tempo_detail`) and the
    other reading.  `sound` says why a video's sound track was not used.
    """
    source = getattr(seg, "tempo_source", "given")
    if source == NO_TEMPO:
        return " (not estimated, --tempo none: one beat a second, so beats are seconds)"
    if source == "no beat":
        return " (no beat found: one beat a second, so beats are seconds; give --tempo)"
    if not seg.tempo_estimated:
        return " (given)"
    conf = seg.tempo_confidence
    sure = f", {conf:.0%} sure" if np.isfinite(conf) else ""
    other = f"; else {seg.tempo_runner_up} bpm" if seg.tempo_runner_up is not None else ""
    why = f"; {sound}" if sound else ""
    return f" (estimated from {source}{sure}{other}{why}; give --tempo to fix it)"
