"""BlazePose (full) landmarks with onnxruntime, without the person detector.

MediaPipe finds the person with a detector model whose TFLite uses an
operator the converter lacks, so the person is localised with the landmark
model alone, the way MediaPipe tracks between frames
(``pose_landmark_cpu.pbtxt``):

1. *acquire*: run the model on the whole frame, letterboxed to a square;
   when it finds no one there (a person under about half the frame's
   height), search square crops over the frame, largest first
   (:func:`search_crops`), at most once every ``SEARCH_INTERVAL_S`` on video;
2. *refine*: the auxiliary points 33 (hip centre) and 34 (full-body scale
   point) define the next crop as in ``PoseLandmarksToRoi``
   (``AlignmentPointsRectsCalculator`` then ``RectTransformationCalculator``):
   centre = point 33, side = 2·|p34 − p33| × 1.25, rotation making p33→p34
   point up; run again on that crop (twice by default);
3. *track*: on video, the next frame's crop comes from this frame's
   (smoothed) auxiliary points; when the pose-present score falls below 0.5
   the person is re-acquired from the full frame.

Positions are refined with the heatmaps (:mod:`.heatmap`) and smoothed over
time with MediaPipe's one-euro filter (:mod:`.filter`).  Two additions to
MediaPipe's graph: on video, a frame whose left and right are exchanged
against the previous frame (a front/back misreading) is flipped back
(:mod:`.swap`); and optionally (``flip_test``) the model also reads the
mirror image of each crop and the two answers are averaged, which roughly
halves the model's own noise at twice the inference cost.
"""

from __future__ import annotations

import functools
import logging
import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import KeypointError, ModelError
from .filter import AUX_FILTER, POSE_FILTER, VISIBILITY_ALPHA, WORLD_FILTER, LowPass, OneEuroFilter, object_scale
from .heatmap import refine_from_heatmap
from .model import INPUT_SHAPE, OUTPUT_SHAPES, resolve_model
from .swap import MIRROR, mirror_landmarks, swap_evidence

__all__ = [
    "BlazePose",
    "PoseEstimate",
    "average_estimates",
    "crop_from_aux",
    "crop_matrix",
    "crop_to_tensor",
    "decode_outputs",
    "full_frame_crop",
    "make_session",
    "search_crops",
]

logger = logging.getLogger(__name__)

INPUT_SIZE = INPUT_SHAPE[-1]
NUM_ALL = 39  # 33 body landmarks + aux 33, 34 + 4 unused
ROI_SCALE = 1.25  # RectTransformationCalculator scale_x/scale_y in PoseLandmarksToRoi
PRESENCE_THRESHOLD = 0.5  # ThresholdingCalculator in the pose graph
MIN_CROP_PX = 16.0  # smaller crops are upsampled noise: re-acquire instead
#: Sides of the searched crops, as fractions of the frame's shorter side.  The
#: landmark model finds a person who fills about half its crop's height or
#: more (a 190-px figure: pose present 1.0 in a 360-px crop, 0.01 in a 480-px
#: one), so a 640x480 frame searched at these sides finds people from about
#: 110 px tall; the letterboxed full frame finds those over about half its side.
SEARCH_SCALES = (0.75, 0.5)
#: Neighbouring searched crops overlap by half their side, so a person who
#: fits in one crop's middle is never cut by every crop.
SEARCH_STEP = 0.5
#: While no one is found on video, the crops are searched at most this often
#: (seconds of video): a search costs about twenty model runs (640x480), so a
#: clip with nobody in it runs at most about twice the cost of tracking.
SEARCH_INTERVAL_S = 1.0
#: A frame is flipped back when its mirrored labelling lies nearer the previous
#: frame by more than this fraction of the person's size (summed over the 11
#: body pairs).  Measured between consecutive frames that are not flipped:
#: at most -0.17 (median -6.8) on mannequin renders at 5 and 10 fps, at most
#: -3.0 on ``pose_squats.mp4``; a flipped frame scores the negative of that.
SWAP_MARGIN = 0.25


@dataclass
class PoseEstimate:
    """The model's answer for one frame, in image coordinates.

    Attributes
    ----------
    xy : (33, 3) ndarray
        Pixel x, y and z (z in pixels, the scale of x; smaller = closer).
    visibility : (33,) ndarray
        Sigmoid of the visibility logit.
    presence : float
        Pose-present probability (the model's pose flag).
    world : (33, 3) ndarray
        World landmarks, metres, rotated back into the image axes.
    aux : (2, 2) ndarray
        Pixel positions of auxiliary points 33 and 34.
    crop : (5,) ndarray
        Crop that produced this answer: cx, cy, w, h (pixels), rotation (rad).
    """

    xy: np.ndarray
    visibility: np.ndarray
    presence: float
    world: np.ndarray
    aux: np.ndarray
    crop: np.ndarray


def make_session(model=None, threads: int = 2):
    """An onnxruntime CPU session for the pose model, built once per process and reused.

    Parameters
    ----------
    model : str or Path, optional
        ONNX file; default :func:`~capture2notation.keypoints.model.resolve_model`.
    threads : int
        Intra-op threads (the landmark model gains little beyond 2).

    Notes
    -----
    Building a session (reading, pruning and optimising the graph) takes
    about 0.7 s; a process that captures many clips (the fidelity study's
    workers) builds it once per model file, size, modification time and
    thread count.  Sessions are safe to share between threads, not across
    a fork (onnxruntime's thread pool stays behind), so the process id is
    part of the key.
    """
    path = Path(resolve_model(model))
    try:
        st = path.stat()
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the pose model: {exc}") from exc
    return _session(str(path.resolve()), st.st_size, st.st_mtime_ns, int(threads), os.getpid())


@functools.lru_cache(maxsize=4)
def _session(path: str, _size: int, _mtime_ns: int, threads: int, _pid: int):
    """Build the session of :func:`make_session` (the arguments after `path` only key the cache)."""
    import onnx
    import onnxruntime as ort
    from onnx.utils import Extractor

    try:
        graph = onnx.load(str(path))
        outputs = [o.name for o in graph.graph.output]
        # Drop the segmentation head (output 2): nothing here uses it and
        # onnxruntime runs every node of the graph, wanted or not (~20 %).
        keep = [name for i, name in enumerate(outputs) if i != 2] if len(outputs) == 5 else outputs
        pruned = Extractor(graph).extract_model([i.name for i in graph.graph.input], keep).SerializeToString()
    except Exception as exc:  # onnx raises many untyped errors on bad files
        raise ModelError(f"{path}: cannot read the pose model as ONNX: {exc}") from exc
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = int(threads)
    opts.inter_op_num_threads = 1
    opts.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    # Full graph optimisation fuses Conv+Clip and roughly halves the run time
    # against the basic level; building it takes < 0.1 s (pruning ~0.3 s), so
    # an optimised copy is not cached.
    opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    try:
        session = ort.InferenceSession(pruned, opts, providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises untyped errors
        raise ModelError(f"{path}: onnxruntime cannot load the pose model: {exc}") from exc
    expected = [OUTPUT_SHAPES[i] for i in (0, 1, 3, 4)]
    got = [tuple(o.shape) for o in session.get_outputs()]
    inputs = [tuple(i.shape) for i in session.get_inputs()]
    if got != expected or inputs != [INPUT_SHAPE]:
        raise ModelError(
            f"{path}: not the BlazePose full landmark model: inputs {inputs}, outputs {got}; "
            f"expected input {INPUT_SHAPE} and outputs {OUTPUT_SHAPES}"
        )
    return session


def full_frame_crop(width: int, height: int) -> np.ndarray:
    """The square crop that letterboxes the whole frame: (cx, cy, side, side, 0)."""
    side = float(max(width, height))
    return np.array([width / 2.0, height / 2.0, side, side, 0.0])


def search_crops(width: int, height: int, scales=SEARCH_SCALES) -> list[np.ndarray]:
    """Square crops covering the frame at each of `scales`, for finding a small person.

    Parameters
    ----------
    width, height : int
        Frame size, pixels.
    scales : sequence of float
        Crop sides as fractions of ``min(width, height)``, searched in order.

    Returns
    -------
    list of (N_s, 5) ndarray
        Per scale, the crops (cx, cy, side, side, 0) in pixels, overlapping by
        ``SEARCH_STEP`` of their side and covering the whole frame.
    """
    out = []
    for scale in scales:
        side = float(scale) * min(width, height)
        centres = []
        for extent in (width, height):
            n = max(1, int(np.ceil((extent - side) / (SEARCH_STEP * side) - 1e-9)) + 1)
            centres.append(np.linspace(side / 2.0, max(side / 2.0, extent - side / 2.0), n))
        cx, cy = np.meshgrid(*centres)
        crops = np.zeros((cx.size, 5))
        crops[:, 0], crops[:, 1], crops[:, 2:4] = cx.ravel(), cy.ravel(), side
        out.append(crops)
    return out


def crop_from_aux(aux: np.ndarray, scale: float = ROI_SCALE) -> np.ndarray:
    """MediaPipe's pose ROI from the two auxiliary points.

    Parameters
    ----------
    aux : (2, 2) ndarray
        Pixel positions of point 33 (centre) and point 34 (scale/rotation).
    scale : float
        Margin factor (1.25 in ``pose_landmarks_to_roi.pbtxt``).

    Returns
    -------
    (5,) ndarray
        cx, cy, w, h in pixels (square) and rotation in radians, clockwise in
        the image, such that the centre→scale-point vector points up.
    """
    (x0, y0), (x1, y1) = np.asarray(aux, dtype=float)
    side = 2.0 * np.hypot(x1 - x0, y1 - y0) * scale
    rotation = np.pi / 2 - np.arctan2(-(y1 - y0), x1 - x0)
    rotation = rotation - 2 * np.pi * np.floor((rotation + np.pi) / (2 * np.pi))
    return np.array([x0, y0, side, side, rotation])


def _usable(crop: np.ndarray) -> bool:
    """A crop worth running the model on: finite and at least MIN_CROP_PX wide."""
    return bool(np.isfinite(crop).all() and crop[2] >= MIN_CROP_PX)


def _rotation(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def crop_matrix(crop: np.ndarray, size: int = INPUT_SIZE) -> np.ndarray:
    """Affine (2, 3) matrix mapping image pixels to model-input pixels.

    The crop's corners map to the input's corners (MediaPipe's
    ``ImageToTensorCalculator`` convention), so normalised model coordinates
    ``uv`` map back with ``p = c + R(rot) @ ((uv - 0.5) * (w, h))``.
    """
    cx, cy, w, h, rot = crop
    a = np.diag([size / w, size / h]) @ _rotation(rot).T
    b = size / 2.0 - a @ np.array([cx, cy])
    return np.hstack([a, b[:, None]])


def crop_to_tensor(image: np.ndarray, crop: np.ndarray, border: int = cv2.BORDER_REPLICATE) -> np.ndarray:
    """Cut the crop out of a BGR frame as the model's (1, 3, 256, 256) RGB input in [0, 1]."""
    patch = cv2.warpAffine(
        image, crop_matrix(crop), (INPUT_SIZE, INPUT_SIZE), flags=cv2.INTER_LINEAR, borderMode=border
    )
    rgb = cv2.cvtColor(patch, cv2.COLOR_BGR2RGB)
    return (rgb.transpose(2, 0, 1)[None].astype(np.float32)) * np.float32(1.0 / 255.0)


def _sigmoid(x):
    return 1.0 / (1.0 + np.exp(-np.asarray(x, dtype=float)))


def decode_outputs(outputs, crop: np.ndarray, refine: bool = True, mirrored: bool = False) -> PoseEstimate:
    """Turn the model's outputs for one crop into image-space landmarks.

    Parameters
    ----------
    outputs : sequence of ndarray
        Model outputs: landmarks (1, 195), pose flag (1, 1), heatmaps
        (1, 39, 64, 64), world landmarks (1, 117) — the segmentation output
        is pruned by :func:`make_session`; a full 5-output list is accepted.
    crop : (5,) ndarray
        The crop the input was cut from.
    refine : bool
        Apply the heatmap refinement (MediaPipe does).
    mirrored : bool
        The input was the crop flipped left-right: positions are flipped back
        and left/right landmarks exchanged, so the answer describes the
        unflipped image.
    """
    if len(outputs) == 5:
        outputs = [outputs[i] for i in (0, 1, 3, 4)]
    raw = np.asarray(outputs[0], dtype=float).reshape(NUM_ALL, 5)
    uv = raw[:, :2] / INPUT_SIZE
    if refine:
        uv, _ = refine_from_heatmap(uv, np.asarray(outputs[2])[0])
    world = np.asarray(outputs[3], dtype=float).reshape(NUM_ALL, 3)
    vis_logit = raw[:33, 3]
    if mirrored:
        uv = np.column_stack([1.0 - uv[:, 0], uv[:, 1]])
        world = world * np.array([-1.0, 1.0, 1.0])
        body = np.r_[MIRROR, np.arange(33, NUM_ALL)]  # auxiliary points have no side
        uv, world, raw, vis_logit = uv[body], world[body], raw[body], vis_logit[MIRROR]
    cx, cy, w, h, rot = crop
    rmat = _rotation(rot)
    xy = ((uv - 0.5) * np.array([w, h])) @ rmat.T + np.array([cx, cy])
    z = raw[:, 2] / INPUT_SIZE * w
    world_xy = world[:, :2] @ rmat.T
    return PoseEstimate(
        xy=np.column_stack([xy, z])[:33],
        visibility=_sigmoid(vis_logit),
        presence=float(np.asarray(outputs[1]).ravel()[0]),
        world=np.column_stack([world_xy, world[:, 2]])[:33],
        aux=xy[33:35].copy(),
        crop=np.asarray(crop, dtype=float).copy(),
    )


def average_estimates(a: PoseEstimate, b: PoseEstimate) -> PoseEstimate:
    """Mean of two answers for the same crop (e.g. the image and its mirror image)."""
    return PoseEstimate(
        xy=0.5 * (a.xy + b.xy),
        visibility=0.5 * (a.visibility + b.visibility),
        presence=0.5 * (a.presence + b.presence),
        world=0.5 * (a.world + b.world),
        aux=0.5 * (a.aux + b.aux),
        crop=a.crop.copy(),
    )


class BlazePose:
    """BlazePose landmark estimator with person tracking and smoothing.

    Parameters
    ----------
    model : str or Path, optional
        ONNX model (default: ``$C2N_POSE_MODEL`` or the cache, fetched on first use).
    threads : int
        onnxruntime intra-op threads.
    refinements : int
        Crop refinements after the full-frame pass when (re-)acquiring.
    presence_threshold : float
        Below this pose-present score the frame has no person and the tracker
        re-acquires from the full frame.
    smooth : bool
        Apply the one-euro filter on video (:meth:`process`).
    session : onnxruntime.InferenceSession, optional
        Reuse an existing session (the model is then not resolved again).
    fix_swaps : bool
        On video, undo front/back flips against the previous frame
        (:mod:`.swap`).
    flip_test : bool
        Also run the model on the mirrored crop and average (twice the cost;
        on the mannequin renders it lifts the worst joint, the near elbow
        seen in profile, from PCK@5% 0.91 to 0.98 at 5 fps).
    """

    backend = "blazepose"

    def __init__(
        self,
        model=None,
        *,
        threads: int = 2,
        refinements: int = 2,
        presence_threshold: float = PRESENCE_THRESHOLD,
        smooth: bool = True,
        session=None,
        fix_swaps: bool = True,
        flip_test: bool = False,
    ):
        self.session = session if session is not None else make_session(model, threads)
        self._input_name = self.session.get_inputs()[0].name
        self.refinements = int(refinements)
        self.presence_threshold = float(presence_threshold)
        self.smooth = bool(smooth)
        self.fix_swaps = bool(fix_swaps)
        self.flip_test = bool(flip_test)
        self.reset()

    def reset(self) -> None:
        """Forget the tracked crop, the filters and the search clock (call between videos)."""
        self._next_search = -np.inf  # video time (s) from which the crops may be searched again
        self._lose()

    def _lose(self) -> None:
        """Forget the tracked crop and the filters (the person was lost)."""
        self._crop = None
        self._previous = None  # last returned image landmarks (33, 3), left/right consistent
        self._f_xy = OneEuroFilter(*POSE_FILTER)
        self._f_aux = OneEuroFilter(*AUX_FILTER)
        self._f_world = OneEuroFilter(*WORLD_FILTER)
        self._f_vis = LowPass(VISIBILITY_ALPHA)

    def infer(self, image: np.ndarray, crop: np.ndarray) -> PoseEstimate:
        """Run the model on `crop` of a BGR frame (H, W, 3) uint8 (and its mirror image, with ``flip_test``)."""
        tensor = crop_to_tensor(image, crop)
        est = decode_outputs(self.session.run(None, {self._input_name: tensor}), crop)
        if not self.flip_test:
            return est
        flipped = np.ascontiguousarray(tensor[..., ::-1])
        other = decode_outputs(self.session.run(None, {self._input_name: flipped}), crop, mirrored=True)
        scale = object_scale(est.xy)
        if np.isfinite(scale) and swap_evidence(other.xy, est.xy) > SWAP_MARGIN * scale:
            # The two passes read the body as facing opposite ways: their mean
            # would fold it in two.  Keep the direct pass (the tracker's swap
            # test then judges it against the previous frame).
            return est
        return average_estimates(est, other)

    def estimate_image(self, image: np.ndarray, search: bool = True) -> PoseEstimate:
        """Locate the person in a still image: full frame, searched crops, then refined crops.

        Parameters
        ----------
        image : (H, W, 3) uint8 ndarray
            BGR frame.
        search : bool
            When the whole frame shows no one, search :func:`search_crops`
            (largest first; the most confident crop of the first side that
            finds someone).
        """
        if image.ndim != 3 or image.shape[2] != 3:
            raise KeypointError(f"expected a BGR image (H, W, 3), got shape {image.shape}")
        height, width = image.shape[:2]
        est = self.infer(image, full_frame_crop(width, height))
        if est.presence < self.presence_threshold and search:
            for crops in search_crops(width, height):
                best = max((self.infer(image, crop) for crop in crops), key=lambda e: e.presence)
                if best.presence >= self.presence_threshold:
                    logger.debug("person found in a %.0f-px crop at (%.0f, %.0f)", *best.crop[[2, 0, 1]])
                    est = best
                    break
        for _ in range(self.refinements):
            crop = crop_from_aux(est.aux)
            if est.presence < self.presence_threshold or not _usable(crop):
                break
            est = self.infer(image, crop)
        return est

    def process(self, image: np.ndarray, t: float) -> PoseEstimate | None:
        """Next video frame: track, re-acquire when lost, smooth.

        Parameters
        ----------
        image : (H, W, 3) uint8 ndarray
            BGR frame.
        t : float
            Timestamp, seconds (increasing).

        Returns
        -------
        PoseEstimate or None
            None when no person is found in this frame.
        """
        est = None
        if self._crop is not None:
            est = self.infer(image, self._crop)
            if est.presence < self.presence_threshold:
                logger.debug("t=%.3f s: pose lost (score %.2f), re-acquiring", t, est.presence)
                est = None
        if est is None:
            self._lose()
            search = t >= self._next_search
            if search:
                self._next_search = t + SEARCH_INTERVAL_S
            est = self.estimate_image(image, search=search)
            if est.presence < self.presence_threshold:
                return None
        if self.fix_swaps and self._previous is not None:
            self._unflip(est, t)
        if self.smooth:
            # As in LandmarksSmoothingCalculator, each set's speed is measured
            # in units of its own bounding-box size.
            scale, aux_scale = object_scale(est.xy), object_scale(est.aux)
            if np.isfinite(scale) and scale > 1e-6:
                est.xy = self._f_xy(t, est.xy, 1.0 / scale)
            if np.isfinite(aux_scale) and aux_scale > 1e-6:
                est.aux = self._f_aux(t, est.aux, 1.0 / aux_scale)
            est.world = self._f_world(t, est.world)
            est.visibility = self._f_vis(est.visibility)
        crop = crop_from_aux(est.aux)
        self._crop = crop if _usable(crop) else None  # else re-acquire next frame
        self._previous = est.xy.copy()
        return est

    def _unflip(self, est: PoseEstimate, t: float) -> None:
        """Exchange left and right in `est` (in place) when the previous frame says it is flipped."""
        scale = object_scale(self._previous)
        evidence = swap_evidence(est.xy, self._previous)
        if np.isfinite(evidence) and np.isfinite(scale) and evidence > SWAP_MARGIN * scale:
            logger.debug("t=%.3f s: left/right flip undone (evidence %.2f person sizes)", t, evidence / scale)
            est.xy = mirror_landmarks(est.xy, depth_axis=2)
            est.world = mirror_landmarks(est.world, depth_axis=2)
            est.visibility = mirror_landmarks(est.visibility)
