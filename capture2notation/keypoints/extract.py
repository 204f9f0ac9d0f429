"""Video → :class:`KeypointTrack`: the stage's entry points.

:func:`extract` reads a video file or image folder; :func:`extract_frames`
takes any iterable of frames (e.g. rendered in memory).  Both stream: memory
grows only with the track (33 points per frame), never with the video.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..errors import KeypointError
from ..io.video import Frame, iter_frames, probe
from .track import NUM_LANDMARKS, KeypointTrack

__all__ = ["BACKENDS", "extract", "extract_frames"]

BACKENDS = ("blazepose", "markers")


def _make_backend(backend: str, model, threads: int, smooth: bool, markers, flip_test: bool = False):
    if backend == "blazepose":
        from .blazepose import BlazePose

        return BlazePose(model, threads=threads, smooth=smooth, flip_test=flip_test)
    if backend == "markers":
        from .markers import MarkerTracker

        return MarkerTracker(markers)
    raise KeypointError(f"unknown keypoint backend {backend!r}; expected one of {', '.join(BACKENDS)}")


def extract_frames(
    frames: Iterable,
    fps: float,
    *,
    backend: str = "blazepose",
    model=None,
    threads: int = 2,
    smooth: bool = True,
    markers=None,
    estimator=None,
    progress=None,
    flip_test: bool | None = None,
    identity: bool = True,
    limbs: bool = True,
    faces: bool = True,
) -> KeypointTrack:
    """Keypoints of a stream of frames.

    Parameters
    ----------
    frames : iterable of Frame or (H, W, 3) uint8 ndarray
        BGR frames in time order; bare arrays are timed ``index / fps``.
    fps : float
        Frame rate, frames per second.
    backend : {"blazepose", "markers"}
        Pose model or colour markers.
    model : str or Path, optional
        ONNX pose model (BlazePose only); default ``$C2N_POSE_MODEL`` or the cache.
    threads : int
        onnxruntime intra-op threads.
    smooth : bool
        One-euro smoothing (BlazePose only).
    markers : sequence of MarkerSpec, optional
        Marker colours (markers only); default the renderer's marker set.
    estimator : BlazePose or MarkerTracker, optional
        Reuse an existing estimator (its ONNX session); it is reset first and
        its ``smooth`` flag set from `smooth`.
    progress : callable, optional
        Called with each processed frame index (e.g. a tqdm ``update``).
    flip_test : bool, optional
        BlazePose only: also read the mirrored crop and average (more
        accurate, twice the inference cost).  Default: off for a new
        estimator, unchanged for a given one.
    identity : bool
        BlazePose only: decide left/right and front/back over the whole clip
        and correct the track (:func:`~.identity.correct_identity`, then
        :func:`~.yaw.correct_mirrored` from the feet and the turning, then
        each arm and leg pair side-on, :func:`~.near_side.correct_near_side`,
        and each pair drawn on top of itself,
        :func:`~.overlap.correct_overlapping`, unless `limbs` is off), which
        sets ``identity_confidence``; otherwise it is NaN (not assessed).
    limbs : bool
        With `identity`: also decide each arm and leg pair side-on from the
        pose model's visibility, and each overlapping pair from its
        neighbours.  Several calibrated cameras decide the limbs
        by their geometry instead (:func:`~capture2notation.fitting.triangulate.match_sides`),
        which the visibility only disturbs, so their captures turn it off.
    faces : bool
        BlazePose only: look for a face at the head every
        :data:`~.face.FACE_EVERY_S` (the track's ``face``; the yaw decoder
        reads it as a cue of facing the camera).

    Returns
    -------
    KeypointTrack
        Frames with no person (or no marker) are NaN with visibility 0.  A
        frame identical to the one before it is not read again: it repeats
        that frame's keypoints.

    Raises
    ------
    KeypointError
        Unknown backend, no frames, or frames of changing size.
    """
    est = (
        estimator if estimator is not None else _make_backend(backend, model, threads, smooth, markers, bool(flip_test))
    )
    if hasattr(est, "smooth"):
        est.smooth = bool(smooth)
    if flip_test is not None and hasattr(est, "flip_test"):
        est.flip_test = bool(flip_test)
    est.reset()
    times, xy, vis, pres, world, crops, face = [], [], [], [], [], [], []
    size = None
    detector, next_face = None, -np.inf
    if faces and est.backend == "blazepose":
        from .face import FACE_EVERY_S, FaceDetector

        detector = FaceDetector()
    last_image, r = None, None
    for i, item in enumerate(frames):
        frame = item if isinstance(item, Frame) else Frame(i, i / float(fps), np.asarray(item))
        h, w = frame.image.shape[:2]
        if size is None:
            size = (w, h)
        elif size != (w, h):
            raise KeypointError(f"frame {frame.index} is {w}x{h}, expected {size[0]}x{size[1]} like frame 0")
        # A frame identical to the one before (a held frame: a low frame rate
        # padded to the container's, a frozen screen recording) is the same
        # observation; reading it again would only cost time and tell the
        # filters the body stood still.
        if last_image is None or not np.array_equal(frame.image, last_image):
            r = est.process(frame.image, frame.time)
        last_image = frame.image
        times.append(frame.time)
        if r is None:
            xy.append(np.full((NUM_LANDMARKS, 3), np.nan))
            vis.append(np.zeros(NUM_LANDMARKS))
            pres.append(0.0)
            world.append(np.full((NUM_LANDMARKS, 3), np.nan))
            crops.append(np.full(5, np.nan))
        else:
            xy.append(r.xy)
            vis.append(r.visibility)
            pres.append(r.presence)
            world.append(r.world)
            crops.append(r.crop)
        face.append(np.nan)
        if detector is not None and r is not None and frame.time >= next_face:
            face[-1] = detector(frame.image, r.xy)
            # Half a frame early counts as on time: frame times are rounded.
            next_face = frame.time + FACE_EVERY_S - 0.5 / float(fps)
        if progress is not None:
            progress(frame.index)
    if size is None:
        raise KeypointError("no frames to extract keypoints from")
    track = KeypointTrack(
        fps=fps,
        times=np.array(times),
        image_size=np.array(size),
        xy=np.array(xy),
        visibility=np.clip(np.array(vis), 0.0, 1.0),
        presence=np.array(pres),
        world=np.array(world),
        crops=np.array(crops),
        backend=est.backend,
        face=np.array(face),
    )
    if identity and track.backend == "blazepose":
        from .identity import correct_identity
        from .near_side import correct_near_side
        from .overlap import correct_overlapping
        from .yaw import correct_mirrored

        track, _ = correct_identity(track)
        track, decoding = correct_mirrored(track)
        if limbs:
            track, _ = correct_near_side(track, decoding.yaw)
            track, _ = correct_overlapping(track, decoding.yaw)
    return track


def extract(
    video,
    backend: str = "blazepose",
    *,
    model=None,
    fps: float | None = None,
    start: int = 0,
    stop: int | None = None,
    threads: int = 2,
    smooth: bool = True,
    markers=None,
    estimator=None,
    progress=False,
    flip_test: bool | None = None,
    identity: bool = True,
    limbs: bool = True,
    faces: bool = True,
) -> KeypointTrack:
    """Keypoints of a video file or image folder.

    Parameters
    ----------
    video : str or Path
        mp4/avi/mov file or folder of images.
    backend : {"blazepose", "markers"}
    model : str or Path, optional
        ONNX pose model; default ``$C2N_POSE_MODEL`` or the cache (fetched on first use).
    fps : float, optional
        Frame rate of an image folder (default 30) or override for a file.
    start, stop : int
        Frame range ``[start, stop)``.
    threads, smooth, markers, estimator, flip_test, identity, limbs, faces
        As :func:`extract_frames`.
    progress : bool or callable
        True: show progress on stderr (a bar on a terminal, else a line every
        30 s); a callable is called with each processed frame's index
        instead (e.g. one bar shared by several clips).

    Returns
    -------
    KeypointTrack
    """
    info = probe(video, fps=fps)
    frames = iter_frames(video, fps=fps, start=start, stop=stop)
    if not progress or callable(progress):
        return extract_frames(
            frames, info.fps, backend=backend, model=model, threads=threads, smooth=smooth,
            markers=markers, estimator=estimator, progress=progress or None, flip_test=flip_test,
            identity=identity, limbs=limbs, faces=faces,
        )  # fmt: skip
    from ..progress import progress as progress_bar

    total = max(0, (info.frame_count if stop is None else min(stop, info.frame_count)) - start) or None
    with progress_bar(total=total, unit="frame", desc=f"keypoints ({backend})") as bar:
        return extract_frames(
            frames, info.fps, backend=backend, model=model, threads=threads, smooth=smooth,
            markers=markers, estimator=estimator, progress=lambda _i: bar.update(1), flip_test=flip_test,
            identity=identity, limbs=limbs, faces=faces,
        )  # fmt: skip
