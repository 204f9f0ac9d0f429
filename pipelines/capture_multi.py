"""Capture from two or more calibrated cameras (issue 15, item 3).

``c2n capture A.mp4 B.mp4 --calibration cameras.toml -o OUT``: keypoints per
view (the views in parallel threads: onnxruntime releases the GIL), the
clips aligned in time (the calibration's ``offset_s``, ``--offsets`` or
``auto``: from the keypoint motion), a confidence-weighted triangulation
(:mod:`capture2notation.fitting.triangulate`), the 3D fit of motion files
(:func:`~capture2notation.fitting.fit3d.fit_points3d`: bone lengths, joint
limits, smoothness), then the one-view capture's quantiser, Effort and
outputs (:func:`pipelines.capture.notate`, called by
:func:`pipelines.capture.capture` with a list of clips), with
``overlay_<camera>.mp4`` per camera.  The world frame is the calibration's (floor z = 0, z up).
"""

from __future__ import annotations

import logging
import shutil
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from capture2notation.errors import PipelineError
from pipelines.capture_input import MOTION_SUFFIXES

__all__ = ["MAX_AUTO_LAG_S", "ViewFiles", "check_views", "load_views", "parse_offsets"]

log = logging.getLogger(__name__)

#: Largest start offset between clips searched by ``--offsets auto``, seconds
#: (two phones started by hand within a couple of seconds of each other).
MAX_AUTO_LAG_S = 2.0
#: Largest difference between two clips' frame rates taken as equal, fps
#: (containers round 25 to 25.0000x).
_FPS_TOL = 0.01


def parse_offsets(text, n: int) -> list[float] | str | None:
    """``--offsets`` as seconds per clip, ``"auto"`` or None.

    Raises
    ------
    PipelineError
        Not ``auto`` nor `n` comma-separated numbers.
    """
    if text is None or (isinstance(text, str) and text.strip() == "auto"):
        return None if text is None else "auto"
    if isinstance(text, (list, tuple)):
        parts = list(text)
    else:
        parts = [p for p in str(text).split(",") if p.strip()]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise PipelineError(f"--offsets {text!r} must be 'auto' or {n} seconds separated by commas") from None
    if len(values) != n or not all(np.isfinite(values)) or any(abs(v) > 3600 for v in values):
        raise PipelineError(f"--offsets {text!r} must be {n} seconds (one per clip, within an hour) or 'auto'")
    return values


def check_views(videos, calibration, fps_override=None):
    """Probe the clips and match each to its calibrated camera, before any keypoints.

    Returns
    -------
    cameras : list of CameraCalibration
    infos : list of VideoInfo

    Raises
    ------
    PipelineError
        Fewer than two clips, two clips of one camera, a camera missing from
        the calibration, other image sizes than the calibration's, frame
        rates that differ; each names the file and the mismatch.
    """
    from capture2notation.errors import CalibrationError
    from capture2notation.io.calibration import camera_name, read_calibration
    from capture2notation.io.video import probe

    if len(videos) < 2:
        raise PipelineError("a multi-camera capture needs at least two clips")
    cal = read_calibration(calibration)
    names = [camera_name(v) for v in videos]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise PipelineError(f"{videos[i]}: camera {n!r} is given twice (also {videos[names.index(n)]})")
    cameras, infos = [], []
    for video, name in zip(videos, names):
        if Path(video).suffix.lower() in MOTION_SUFFIXES:
            raise PipelineError(f"{video}: a multi-camera capture takes video clips, not motion files")
        try:
            cam = cal[name]
        except CalibrationError as exc:
            raise PipelineError(f"{video}: {exc} in {calibration}") from None
        info = probe(video, fps_override)
        if (info.width, info.height) != tuple(cam.image_size):
            raise PipelineError(
                f"{video}: frames are {info.width}x{info.height} but camera {name!r} in {calibration} is "
                f"calibrated for {cam.image_size[0]}x{cam.image_size[1]}"
            )
        if infos and abs(info.fps - infos[0].fps) > _FPS_TOL:
            raise PipelineError(
                f"{video}: frame rate {info.fps:g} fps differs from {infos[0].path}'s {infos[0].fps:g} fps"
            )
        cameras.append(cam)
        infos.append(info)
    return cameras, infos


class _Frames:
    """A stand-in track of `n` frames (the declared length, before keypoints)."""

    def __init__(self, n: int):
        self.times = np.zeros(n)


def _align(tracks, offsets_s, videos, fps: float):
    """Frame ranges of each track covering the common time, from start offsets (s)."""
    shifts = [int(round(o * fps)) for o in offsets_s]  # frames each clip starts late
    lengths = [len(t.times) for t in tracks]
    if not any(shifts) and len(set(lengths)) > 1:
        i = int(np.argmin(lengths))
        j = int(np.argmax(lengths))
        raise PipelineError(
            f"{videos[i]}: {lengths[i]} frames but {videos[j]} has {lengths[j]} "
            "(clips of different lengths: give --offsets or --offsets auto)"
        )
    start = max(shifts)  # on the reference clock
    stop = min(s + n for s, n in zip(shifts, lengths))
    if stop - start < 2:
        raise PipelineError(f"{videos[0]}: the clips do not overlap in time (offsets {offsets_s} s)")
    return [slice(start - s, stop - s) for s in shifts]


def _monocular_fill(joints, jconf, missing, tracks, spans, videos, calibration, floor: float = 0.0):
    """Joints no two views saw, from the monocular fit of the view that sees them best.

    `missing` (T, J) marks them (only joints a landmark measures:
    :data:`~capture2notation.fitting.triangulate.MEASURED_JOINTS`).

    Returns
    -------
    joints : (T, J, 3) ndarray
    jconf : (T, J) ndarray
        :data:`~capture2notation.fitting.multiview.MONO_WEIGHT` × the
        monocular fit's confidence where filled.

    `floor` is the height subtracted from the triangulated joints, metres
    (the monocular fit is in the calibration's world, so it is shifted alike).
    """
    from capture2notation.fitting import Camera, fit_track
    from capture2notation.fitting.camera import undistort_track
    from capture2notation.fitting.multiview import fill_from_view
    from capture2notation.io.calibration import read_calibration

    known = read_calibration(calibration)

    def fit_window(view: int, frames: slice):
        track, span = tracks[view], spans[view]
        camera = Camera.from_calibration(known, videos[view], track.image_size, undistorted=True)
        part = track.frames(slice(span.start + frames.start, span.start + frames.stop))
        return fit_track(undistort_track(part, known, videos[view]), camera=camera)

    visibility = [t.visibility[s] for t, s in zip(tracks, spans)]
    fps = float(tracks[0].fps)
    view, joints, jconf = fill_from_view(joints, jconf, missing, floor, visibility, fps, fit_window)
    log.info("capture: %d joint-frames from %s's monocular fit", int(missing.sum()), videos[view])
    return joints, jconf


def _keypoints(videos, backend, fps_override, progress, flip_test, workers: int, frames: int | None = None):
    """Each clip's keypoints, the clips on `workers` threads; `frames` (their total) sizes the shared progress."""
    from capture2notation.keypoints import extract
    from capture2notation.progress import progress as progress_bar

    # onnxruntime releases the GIL: a thread per view, one intra-op thread each.
    threads = 1 if workers > 1 else 2
    desc = f"keypoints ({backend}, {len(videos)} clips)"
    with progress_bar(total=frames or None, unit="frame", desc=desc, enabled=progress) as bar:
        lock = threading.Lock()

        def step(_index: int) -> None:
            with lock:  # one bar counts every clip's frames
                bar.update(1)

        def one(v):
            # The views' geometry decides each arm and leg pair (match_sides), not one view's visibility.
            return extract(
                v, backend=backend, fps=fps_override, progress=step, flip_test=flip_test, threads=threads, limbs=False
            )

        if workers <= 1:
            return [one(v) for v in videos]
        with ThreadPoolExecutor(max_workers=workers) as pool:
            return list(pool.map(one, videos))


class ViewFiles:
    """Each camera's ``keypoints_<camera>.npz`` and ``overlay_<camera>.mp4``.

    The overlays (decode, draw, encode: OpenCV and the encoder release the
    GIL) are drawn on one thread from the moment the keypoints exist, into a
    scratch folder, while the fit holds the other core; calling the object
    with the capture's staging folder waits for them and moves them in.
    :meth:`close` discards whatever was not moved.

    Parameters
    ----------
    names : sequence of str
        Camera names.
    videos : sequence of Path
    tracks : sequence of KeypointTrack
    overlay : bool
        Draw the overlays.
    """

    def __init__(self, names, videos, tracks, overlay: bool):
        self._tracks = dict(zip(names, tracks))
        self._pool = self._scratch = None
        self._drawings = {}
        self._stop = threading.Event()
        if overlay:
            from capture2notation.keypoints.overlay import write_overlay

            self._scratch = Path(tempfile.mkdtemp(prefix="c2n-overlays-"))
            self._pool = ThreadPoolExecutor(max_workers=1)
            self._drawings = {
                name: self._pool.submit(
                    write_overlay, video, track, self._scratch / f"overlay_{name}.mp4", fps=track.fps, stop=self._stop
                )
                for name, video, track in zip(names, videos, tracks)
            }

    def __call__(self, stage: Path) -> dict:
        """Write the keypoints into `stage`, move the finished overlays there; ``{file name: path}``."""
        files = {f"keypoints_{n}.npz": t.save(stage / f"keypoints_{n}.npz") for n, t in self._tracks.items()}
        for name, drawing in self._drawings.items():
            files[f"overlay_{name}.mp4"] = Path(shutil.move(drawing.result(), stage / f"overlay_{name}.mp4"))
        return files

    def close(self) -> None:
        """Stop drawing (within a frame) and remove the scratch folder."""
        self._stop.set()
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._scratch is not None:
            shutil.rmtree(self._scratch, ignore_errors=True)
            self._scratch = None


def load_views(
    videos,
    calibration,
    backend: str = "blazepose",
    fps_override=None,
    progress: bool = True,
    *,
    offsets=None,
    workers: int = 2,
    overlay: bool = True,
    flip_test: bool = False,
):
    """Joints of a performance seen by two or more calibrated cameras.

    Parameters
    ----------
    videos : sequence of str or Path
        One clip per camera, named by :func:`~capture2notation.io.calibration.camera_name`.
    calibration : str or Path
        Calibration file holding every clip's camera.
    offsets : "auto", sequence of float or str, optional
        Seconds each clip starts after the reference clock; default the
        calibration's ``offset_s``; ``"auto"`` finds them from the keypoint
        motion (relative to the first clip).
    workers : int
        Clips whose keypoints run at once (threads).
    overlay : bool
        Write ``overlay_<camera>.mp4`` per camera.
    Other parameters are :func:`pipelines.capture.capture`'s.

    Returns
    -------
    motion : FitResult
        In the calibration's world, the floor moved to z = 0.
    seconds : dict
        Time per stage.
    views : ViewFiles
        ``views(folder) -> dict`` writes ``keypoints_<camera>.npz`` and moves
        the overlays into `folder` (for :func:`pipelines.capture.notate`);
        the caller closes it.
    source : str
        The cameras used, for the page.
    """
    from capture2notation.errors import FittingError
    from capture2notation.fitting.multiview import fit_views
    from capture2notation.fitting.triangulate import find_offset
    from capture2notation.io.calibration import camera_name

    videos = [Path(v) for v in videos]
    offs = parse_offsets(offsets, len(videos))
    cameras, infos = check_views(videos, calibration, fps_override)
    counts = [i.frame_count for i in infos]
    if offs is None and not any(c.offset_s for c in cameras) and all(counts) and len(set(counts)) > 1:
        # Fail before the slow keypoints: same-clock clips must be equally long.
        _align([_Frames(c) for c in counts], [0.0] * len(counts), videos, 1.0)
    seconds: dict = {}
    t0 = time.perf_counter()
    tracks = _keypoints(videos, backend, fps_override, progress, flip_test, max(1, int(workers)), sum(counts))
    seconds["keypoints"] = time.perf_counter() - t0
    fps = float(tracks[0].fps)
    if offs is None:
        offs = [c.offset_s for c in cameras]
    elif offs == "auto":
        lag = int(round(MAX_AUTO_LAG_S * fps))
        # find_offset: other[i] shows reference[i + lag], i.e. other starts lag frames late.
        offs = [0.0] + [find_offset(tracks[0].xy[..., :2], t.xy[..., :2], lag) / fps for t in tracks[1:]]
        log.info("capture: clip offsets from the motion: %s s", ", ".join(f"{o:+.2f}" for o in offs))
    spans = _align(tracks, list(offs), videos, fps)
    t0 = time.perf_counter()
    uv = np.stack([t.xy[s, :, :2] for t, s in zip(tracks, spans)])
    vis = np.stack(
        [t.visibility[s] * np.clip(np.nan_to_num(t.presence[s]), 0, 1)[:, None] for t, s in zip(tracks, spans)]
    )

    def fill(joints, jconf, missing, floor):
        t1 = time.perf_counter()
        out = _monocular_fill(joints, jconf, missing, tracks, spans, videos, calibration, floor)
        seconds["monocular"] = time.perf_counter() - t1
        return out

    times = np.asarray(tracks[0].times)[spans[0]]
    names = [camera_name(v) for v in videos]
    views = ViewFiles(names, videos, tracks, overlay)
    try:
        motion, _floor = fit_views(uv, vis, cameras, fps, times=times - times[0], fill=fill)
    except FittingError as exc:
        views.close()
        raise PipelineError(f"{videos[0]}: {exc}") from None
    except BaseException:
        views.close()
        raise
    seconds["triangulate and fit"] = time.perf_counter() - t0 - seconds.get("monocular", 0.0)
    source = f"calibration {calibration} ({', '.join(names)})"
    return motion, seconds, views, source
