"""A capture's input read into motion: what kind of input it is, and for a video its keypoints, camera and fit.

:func:`input_kind` tells a video (file or image folder), a keypoint track
(``c2n keypoints``), a BVH, a Kinect v2 CSV and a truth sidecar apart;
:func:`load_motion` reads any of them into world joints: a video's
keypoints (BlazePose), the camera estimated from the person (or given by a
calibration file) and the 3D fit turned to the yaw the image shows; a
motion file through its reader.  :func:`feet_seen` says in which frames a
foot may show the floor.
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from capture2notation.body import joint_index
from capture2notation.errors import C2NError, PipelineError

__all__ = [
    "FITTED_KINDS",
    "FOOT_SEEN_CONFIDENCE",
    "MAX_ROLL_DEG",
    "MOTION_SUFFIXES",
    "ROLL_NOISE_DEG",
    "VIDEO_SUFFIXES",
    "feet_seen",
    "input_kind",
    "is_fitted",
    "load_motion",
]

log = logging.getLogger(__name__)

#: Input kinds whose joints are fitted to keypoints of one camera: a video
#: (keypoints found here) or a keypoint track saved by ``c2n keypoints``.
FITTED_KINDS = ("video", "keypoints")
VIDEO_SUFFIXES = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".webm", ".mpg", ".mpeg")
MOTION_SUFFIXES = (".bvh", ".csv", ".npz")
_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


def input_kind(path) -> str:
    """Classify INPUT: ``video`` (file or image folder), ``keypoints``, ``bvh``, ``kinect`` or ``truth``.

    Raises
    ------
    PipelineError
        Missing path or unknown file type.
    """
    p = Path(path)
    if p.is_dir():
        if any(f.suffix.lower() in _IMAGE_SUFFIXES for f in p.iterdir()):
            return "video"
        raise PipelineError(
            f"{p}: folder holds no images ({', '.join(_IMAGE_SUFFIXES)}); expected an image sequence "
            "(for a render folder give its video.mp4)"
        )
    if not p.is_file():
        raise PipelineError(f"{p}: no such file or folder")
    ext = p.suffix.lower()
    if ext in VIDEO_SUFFIXES:
        return "video"
    if ext == ".npz":
        return "keypoints" if _is_keypoint_track(p) else "truth"
    kinds = {".bvh": "bvh", ".csv": "kinect"}
    if ext in kinds:
        return kinds[ext]
    raise PipelineError(
        f"{p}: unknown input type {ext!r}; expected a video ({' '.join(VIDEO_SUFFIXES)}), an image folder, "
        "a .bvh, a Kinect .csv, a keypoint track .npz (c2n keypoints) or a truth .npz"
    )


def _is_keypoint_track(path: Path) -> bool:
    """Whether an ``.npz`` is a keypoint track (``c2n keypoints``) rather than a truth sidecar."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return {"xy", "visibility", "presence", "world"} <= set(data.files)
    except (OSError, ValueError) as exc:
        raise PipelineError(f"{path}: cannot read .npz: {exc}") from exc


def _with_fps(motion, fps: float):
    """`motion` re-timed at `fps` (frames unchanged)."""
    T = np.asarray(motion.joints).shape[0]
    return motion.replace(fps=float(fps), times=np.arange(T) / float(fps))


#: Largest camera roll the fit takes from the estimate, degrees.  Phones on a
#: tripod or a table are rolled up to about 10°; the estimate reads roll from
#: the body's balance axis (supporting ankle → hips) across the image, so a
#: larger one is more likely a dancer's lasting side lean than the camera.
MAX_ROLL_DEG = 20.0
#: The roll estimate's own noise, degrees: a dancer's leans across the image
#: read as roll (112 BlazePose tracks of random scores through level cameras
#: at front, 45°, side and −45°: median error 1.4°, 90 % within 3.1°).  Only
#: the roll beyond it is taken (soft threshold): a level camera's fit is not
#: turned by its dancer's leans, a rolled one's mostly is.
ROLL_NOISE_DEG = 2.0


def _fit_roll(estimate) -> float:
    """The roll the unknown camera's fit takes from `estimate` (degrees; 0 without one)."""
    if estimate is None:
        return 0.0
    r = float(estimate.roll_deg)
    return float(np.sign(r) * np.clip(abs(r) - ROLL_NOISE_DEG, 0.0, MAX_ROLL_DEG))


def _estimate_camera(track, seed: int):
    """The camera from the person (:func:`~capture2notation.fitting.camera_estimate.estimate_camera`), or None."""
    from capture2notation.fitting.camera_estimate import estimate_camera

    try:
        return estimate_camera(track.xy, track.visibility, track.world, track.image_size, seed=seed)
    except (C2NError, ValueError, np.linalg.LinAlgError) as exc:
        # The estimate is a report beside the fit (and its roll a refinement): say so and go on.
        log.warning("capture: camera not estimated: %s", exc)
        return None


def load_motion(
    path,
    kind: str,
    backend: str = "blazepose",
    fps_override=None,
    progress: bool = True,
    flip_test: bool = False,
    calibration=None,
    floor: float | None = None,
    threads: int = 2,
    seed: int = 0,
):
    """Joints of INPUT: keypoints + fit for a video, a reader for motion files.

    Parameters
    ----------
    threads : int
        The pose model's onnxruntime threads.
    calibration : str or Path, optional
        A calibration file (DESIGN.md, "Cameras and calibration files") with
        the video's camera; without it the fit estimates the camera from the
        person.  Nothing beside the input is ever read in its place.
    floor : float, optional
        The floor's height, metres (see :func:`capture`); the joints are
        moved so that it is z = 0.
    seed : int
        Seed of the camera estimate's bootstrap.

    Returns
    -------
    motion : FitResult
    track : KeypointTrack or None
    estimate : CameraEstimate or None
        The camera estimated from the person (keypoints and video only; None
        when the feet are never seen or for motion files).  Without
        `calibration` the fit's camera takes its roll.
    seconds : dict
        Time spent in ``keypoints``, ``camera`` and ``fitting`` (or ``read``).
    """
    seconds = {}
    if kind in FITTED_KINDS:
        from capture2notation.fitting import Camera, fit_track
        from capture2notation.fitting.camera import undistort_track
        from capture2notation.fitting.yaw import with_image_yaw
        from capture2notation.keypoints import KeypointTrack, extract

        known = None
        if calibration is not None:
            from capture2notation.io.calibration import read_calibration

            known = read_calibration(calibration)
        t0 = time.perf_counter()
        if kind == "keypoints":
            track = KeypointTrack.load(path)
            if fps_override is not None:
                track = replace(track, fps=float(fps_override), times=np.arange(len(track)) / float(fps_override))
        else:
            track = extract(
                path, backend=backend, fps=fps_override, progress=progress, flip_test=flip_test, threads=threads
            )
        seconds["keypoints"] = time.perf_counter() - t0
        camera, pinhole = None, track
        if known is not None:
            # The fit sees the keypoints through a pinhole; the overlay keeps the image's own pixels.
            pinhole = undistort_track(track, known, path)
            camera = Camera.from_calibration(known, path, track.image_size, undistorted=True)
            log.info("capture: using the camera of %s", calibration)
        t0 = time.perf_counter()
        estimate = _estimate_camera(track, seed)
        seconds["camera"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        roll = 0.0 if camera is not None else _fit_roll(estimate)
        motion = fit_track(pinhole, camera=camera, roll_deg=roll)
        # One view's depth cannot say which way a turning body faces; the image can.
        motion = with_image_yaw(motion, pinhole, camera or Camera.default(track.image_size, roll_deg=roll))
        if floor is not None:
            motion = _lowered(motion, floor)
        seconds["fitting"] = time.perf_counter() - t0
        return motion, track, estimate, seconds
    if calibration is not None:
        raise PipelineError(f"--calibration {calibration}: a camera is for video input, not a {kind} file")
    from capture2notation.fitting.motion import read_motion

    t0 = time.perf_counter()
    motion = read_motion(path, floor=floor)
    seconds["read"] = time.perf_counter() - t0
    if fps_override is not None:
        motion = _with_fps(motion, fps_override)
    return motion, None, None, seconds


def _lowered(motion, floor: float):
    """`motion` moved down by `floor` metres, so a floor at that height is z = 0."""
    shift = np.array([0.0, 0.0, float(floor)])
    return replace(motion, joints=np.asarray(motion.joints) - shift, root=np.asarray(motion.root) - shift)


#: Confidence of a foot's ankle and toe from which the capture counts it as
#: seen: a Kinect's inferred joints carry 0.3, a BlazePose landmark off the
#: image or hidden well under 0.5; only a seen foot may show the floor.
FOOT_SEEN_CONFIDENCE = 0.5


def feet_seen(motion) -> np.ndarray | None:
    """(T, 2) right, left foot seen (ankle and toe at :data:`FOOT_SEEN_CONFIDENCE`), or None without confidence."""
    conf = getattr(motion, "confidence", None)
    if conf is None:
        return None
    conf = np.asarray(conf, float)
    return np.stack(
        [
            np.minimum(conf[:, joint_index(f"{side}_ankle")], conf[:, joint_index(f"{side}_toe")])
            >= FOOT_SEEN_CONFIDENCE
            for side in ("right", "left")
        ],
        axis=1,
    )


def is_fitted(kind: str) -> bool:
    """Whether an input of `kind` (:func:`input_kind`, or ``multiview``) is fitted to a pose model's keypoints.

    A fitted capture's joint error is smooth from frame to frame, so its
    Effort takes the fitted-capture prior on the residuals' correlation
    (:data:`~capture2notation.effort.likelihood.CAPTURE_RHO_RANGE`);
    motion files keep the default prior.
    """
    return kind in (*FITTED_KINDS, "multiview")
