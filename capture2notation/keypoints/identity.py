"""Left/right and front/back consistency of a whole keypoint track.

One image of a person is ambiguous up to a reflection in depth: the same
silhouette fits a body facing the camera and one facing away with left and
right exchanged.  BlazePose takes the wrong reading for long stretches (a
dancer's left arm called right for seconds) and reads back views as front
views (it draws a face on the back of the head).  Per frame the two readings
are nearly equally good; over the clip they are not, because a body neither
exchanges its limbs nor turns 180° between two frames.

:func:`decode_identity` runs an HMM over the whole clip with the hidden state
(identity as given | left/right swapped) × (facing the camera | back to the
camera), swap durations a mixture of a short and a practically unbounded
geometric component (a heavy tail: a long coherent swap is not made
improbable by its length alone, so the evidence decides).  Evidence:

* **continuity of identity** between consecutive frames: whether the
  labelled landmarks (image and world, depth included) lie nearer their
  constant-velocity prediction from the two frames before as labelled or
  mirrored (a swap starting or ending shows as a jump of every limb to its
  twin's place; a turning body is predicted to keep turning);
* **image order**: facing the camera, a body's left shoulder and hip appear
  to the right of its right ones in the image; with the back to the camera,
  to the left; a swapped labelling reverses this;
* **the face and the depth order**: the face's visibility, the nose in front
  of the ears and shoulders, toes in front of heels (label-free cues of
  facing the camera), tempered because the pose model's errors last many
  frames;
* **continuity of the front**: the facing may only change where the body is
  side-on to the camera (its shoulders and hips close together in the image).

Forward–backward gives per-frame posteriors: the decided identity's
probability is the frame's ``identity_confidence``; the Viterbi path is the
correction.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import numpy as np

from .swap import MIRROR, SWAP_PAIRS
from .track import KeypointTrack

__all__ = [
    "IDENTITY_UNCERTAIN_BELOW",
    "IdentityResult",
    "correct_identity",
    "decode_identity",
    "identity_evidence",
    "mirror_frames",
    "toes_minus_heels",
    "torso_and_order",
]

#: Posterior probability of the decided identity below which a frame is
#: marked uncertain (it is then one wrong frame in ten or worse).
IDENTITY_UNCERTAIN_BELOW = 0.9
#: Probability per frame of a swap starting with the body square to the
#: camera (rare: once per ~40 s at 25 Hz) and side-on to it, where the pose
#: model's two readings look alike (it swaps in pirouettes); in between as
#: the facing flips (:data:`SIDE_WIDTH`).
SWAP_START_PROB = 1e-3
SWAP_START_SIDE_PROB = 0.05
#: Swap durations: a mixture of geometric laws (weight, mean frames): brief
#: label glitches and swaps as long as a clip, so a 20-s swap is nearly as
#: plausible a priori as a 2-s one (a heavy tail).
SWAP_DURATIONS: tuple[tuple[float, float], ...] = ((0.5, 8.0), (0.5, 1e5))
#: Probability per frame of the facing changing when the body is exactly
#: side-on (it falls off as the body turns towards the camera or away).
FLIP_SIDE_PROB = 0.2
#: Facing flips anyway, per frame, whatever the view (a missed side view).
FLIP_FLOOR_PROB = 1e-8
#: Shoulder/hip width in the image, in torso lengths, at which a facing flip
#: is e^-1/2 times as likely as side-on (a body facing the camera is ~0.6 wide).
SIDE_WIDTH = 0.12
#: Spread of a landmark's error from its constant-velocity prediction when
#: the body is still: torso lengths in the image, metres in the world
#: landmarks (the pose model jitters most when side-on).  A moving
#: landmark's spread adds its last step in quadrature (:func:`_switch_evidence`).
STEP_SIGMA_IMAGE = 0.2
STEP_SIGMA_WORLD_M = 0.12
#: Longest frame interval over which a landmark's last velocity predicts its
#: next position, seconds (20 fps and faster): over 0.2 s (5 fps) a limb
#: stops and starts within a movement, and extrapolating its last step
#: read profile views of the built-in phrases as swapped.
VELOCITY_MAX_INTERVAL_S = 0.05
#: Bound on one frame pair's continuity evidence, nats (one bad frame of the
#: pose model must not decide a whole stretch on its own).
CONTINUITY_CAP = 40.0
#: Image-order gain, nats per torso length of left-minus-right width.
ORDER_GAIN = 8.0
#: The pose model's own belief about facing (the face's visibility, the
#: nose ahead of the ears and shoulders, toes ahead of heels in its world
#: landmarks), averaged: nats at full strength.  Weak, because these come
#: from one belief, and that belief is what fails on a back view.
BELIEF_NATS = 1.0
#: The feet in the image, nats at full strength: a camera above the floor
#: sees the nearer end of a foot lower in the image, so toes below heels
#: when the body faces it.  Geometry of the image, which a misread face does
#: not change.
FOOT_IMAGE_NATS = 3.0
#: Toe-minus-heel image height (torso lengths) at which the foot cue is
#: neutral, and the spread to full strength (front views ~+0.17, back
#: views ~-0.10 on the virtual dancer: the heel landmark sits above the sole).
FOOT_IMAGE_OFFSET = 0.03
FOOT_IMAGE_SPREAD = 0.10
#: Depth differences (metres) at which the nose-ahead and toes-ahead cues
#: reach full strength.
NOSE_DEPTH_M = 0.06
TOE_DEPTH_M = 0.06
#: The pose model's per-frame errors last about this long: per-frame cues
#: are tempered to one independent observation per this many seconds.
CUE_CORRELATION_S = 0.2

_NOSE, _EYES, _EARS = 0, (1, 2, 3, 4, 5, 6), (7, 8)
_SHOULDERS, _HIPS = (11, 12), (23, 24)
_HEELS, _TOES = (29, 30), (31, 32)


@dataclass(frozen=True)
class IdentityResult:
    """The decoded identity and facing of every frame.

    Attributes
    ----------
    swapped : (T,) bool ndarray
        The track's left and right are exchanged in this frame (corrected by
        :func:`correct_identity`).
    facing : (T,) int ndarray
        +1 facing the camera, −1 back to the camera, 0 no person.
    confidence : (T,) ndarray
        Posterior probability of the decided identity, in [0.5, 1]; 0 where
        no person was seen.
    p_swapped, p_back : (T,) ndarray
        Posterior probabilities of a swap and of the back to the camera.
    """

    swapped: np.ndarray
    facing: np.ndarray
    confidence: np.ndarray
    p_swapped: np.ndarray
    p_back: np.ndarray

    @property
    def uncertain(self) -> np.ndarray:
        """(T,) bool: frames whose identity could not be decided."""
        return self.confidence < IDENTITY_UNCERTAIN_BELOW


@dataclass(frozen=True)
class IdentityEvidence:
    """Per-frame evidence for the decoder (nats).

    Attributes
    ----------
    valid : (T,) bool
        A person with shoulders and hips in this frame.
    order : (T,) ndarray
        Left-minus-right image width of shoulders and hips, torso lengths
        (positive: as a body facing the camera with correct labels).
    width : (T,) ndarray
        Its magnitude (side-on near 0).
    facing : (T,) ndarray
        Label-free log-odds of facing the camera (face, nose, toes), tempered.
    switch : (T,) ndarray
        Log-odds that the labels' identity changed between frame t−1 and t
        (0 for t = 0 or a missing neighbour).
    temper : float
        Weight of one frame's cues.
    """

    valid: np.ndarray
    order: np.ndarray
    width: np.ndarray
    facing: np.ndarray
    switch: np.ndarray
    temper: float


def _mean_pair(a: np.ndarray, idx) -> np.ndarray:
    return np.nanmean(a[:, list(idx)], axis=1)


def torso_and_order(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The torso's image length and the body's left-minus-right image order in each frame.

    Parameters
    ----------
    xy : (T, 33, ≥2) ndarray
        Image landmarks, pixels (NaN where missing).

    Returns
    -------
    torso : (T,) ndarray
        Shoulders' middle to hips' middle, pixels; NaN where not seen.
    valid : (T,) bool ndarray
        Shoulders and hips seen (a torso longer than 1e-6 px).
    order : (T,) ndarray
        Left-minus-right x of the shoulders and of the hips, averaged, in
        torso lengths: positive as a body facing the camera with correct
        labels; NaN where not seen.
    """
    xy = np.asarray(xy, float)
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        # Frames without a person average nothing (NaN).
        warnings.simplefilter("ignore", RuntimeWarning)
        sh = np.nanmean(xy[:, list(_SHOULDERS), :2], axis=1)
        hp = np.nanmean(xy[:, list(_HIPS), :2], axis=1)
        torso = np.linalg.norm(sh - hp, axis=1)
        valid = np.isfinite(torso) & (torso > 1e-6)
        torso = np.where(valid, torso, np.nan)
        dx = np.stack([xy[:, left, 0] - xy[:, right, 0] for left, right in (_SHOULDERS, _HIPS)], axis=1)
        order = np.nanmean(dx, axis=1) / torso
    return torso, valid, order


def toes_minus_heels(xy: np.ndarray, torso: np.ndarray) -> np.ndarray:
    """The feet's toe-minus-heel image offset in each frame, both feet averaged.

    Label-free: exchanging left and right leaves it as it is.

    Parameters
    ----------
    xy : (T, 33, ≥2) ndarray
        Image landmarks, pixels (NaN where missing; image y points down).
    torso : (T,) ndarray
        Torso lengths, pixels (:func:`torso_and_order`).

    Returns
    -------
    (T, 2) ndarray
        x and y, torso lengths; NaN where no foot is seen.
    """
    xy = np.asarray(xy, float)
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        # Frames without feet average nothing (NaN): they carry no cue.
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(xy[:, list(_TOES), :2] - xy[:, list(_HEELS), :2], axis=1) / np.asarray(torso, float)[:, None]


def identity_evidence(track: KeypointTrack) -> IdentityEvidence:
    """The decoder's per-frame evidence from a track (see the module docstring)."""
    xy = track.xy[:, :, :2]
    vis = np.nan_to_num(track.visibility)
    world = track.world
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        # Frames without a person average nothing (NaN): they are marked invalid below.
        warnings.simplefilter("ignore", RuntimeWarning)
        torso, valid, order = torso_and_order(xy)
        width = np.abs(order)
        order = np.where(valid & np.isfinite(order), order, 0.0)
        width = np.where(valid & np.isfinite(width), width, 0.0)

        # Label-free cues of facing the camera (positive = facing it).
        face_vis = vis[:, [_NOSE, *_EYES]].mean(axis=1)
        cue_face = np.clip(2.0 * (face_vis - 0.5), -1.0, 1.0)
        z = world[:, :, 2]
        head_ref = np.nanmean(np.stack([_mean_pair(z, _EARS), _mean_pair(z, _SHOULDERS)], axis=1), axis=1)
        cue_nose = np.clip((head_ref - z[:, _NOSE]) / NOSE_DEPTH_M, -1.0, 1.0)
        cue_toe = np.clip(np.nanmean(z[:, list(_HEELS)] - z[:, list(_TOES)], axis=1) / TOE_DEPTH_M, -1, 1)
        belief = np.nan_to_num(np.nanmean(np.stack([cue_face, cue_nose, cue_toe], axis=1), axis=1))
        foot_dy = toes_minus_heels(xy, torso)[:, 1]
        foot = np.nan_to_num(np.clip((foot_dy - FOOT_IMAGE_OFFSET) / FOOT_IMAGE_SPREAD, -1.0, 1.0))
    cues = BELIEF_NATS * belief + FOOT_IMAGE_NATS * foot
    temper = float(min(1.0, 1.0 / (track.fps * CUE_CORRELATION_S)))
    facing = np.where(valid, temper * cues, 0.0)
    switch = _switch_evidence(xy, world, torso, valid, float(track.fps))
    return IdentityEvidence(valid, order, width, facing, switch, temper)


def _predicted(a: np.ndarray, extrapolate: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Constant-velocity prediction of frames 1..T−1 from the two frames before each.

    Parameters
    ----------
    a : (T, N, D) ndarray
        Landmark positions (NaN where missing).
    extrapolate : bool
        False: predict the previous frame's positions (the step is still
        returned, to widen the spread).

    Returns
    -------
    pred : (T−1, N, D) ndarray
        Predicted positions of frames 1..T−1 (the previous frame where the one
        before it is missing).
    step : (T−1, N) ndarray
        Length of the step each prediction extrapolated (0 where none).
    """
    last = a[:-1]
    v = np.zeros_like(last)
    v[1:] = a[1:-1] - a[:-2]
    v = np.nan_to_num(v)
    return (last + v if extrapolate else last), np.linalg.norm(v, axis=-1)


def _switch_evidence(xy: np.ndarray, world: np.ndarray, torso: np.ndarray, valid: np.ndarray, fps: float) -> np.ndarray:
    """Log-odds per frame that the labels jumped to their twins since the previous frame.

    Each frame is compared, as labelled and mirrored, with its prediction
    from the two frames before (constant velocity: a turning body keeps
    turning, where a still one would have it jump to its mirror image);
    at frame intervals beyond :data:`VELOCITY_MAX_INTERVAL_S`, with the
    previous frame.
    """
    T = xy.shape[0]
    out = np.zeros(T)
    if T < 2:
        return out
    body = np.unique(SWAP_PAIRS.ravel())
    scale = np.fmax(torso[1:], torso[:-1])[:, None]
    extrapolate = 1.0 / fps <= VELOCITY_MAX_INTERVAL_S
    pred_i, step_i = _predicted(xy, extrapolate)
    pred_w, step_w = _predicted(world, extrapolate)
    mirrored_xy = xy[1:][:, MIRROR]
    same_i = np.linalg.norm(xy[1:, body] - pred_i[:, body], axis=-1) / scale
    cross_i = np.linalg.norm(mirrored_xy[:, body] - pred_i[:, body], axis=-1) / scale
    w_cur = world[1:]
    w_mir = world[1:][:, MIRROR] * np.array([1.0, 1.0, -1.0])  # the mirror reading reflects depth
    same_w = np.linalg.norm(w_cur[:, body] - pred_w[:, body], axis=-1)
    cross_w = np.linalg.norm(w_mir[:, body] - pred_w[:, body], axis=-1)
    # The prediction's error grows with the step it extrapolates (a turning
    # body's landmarks move on arcs, not lines): its spread is the still
    # body's and that step in quadrature, so a fast spin says little.
    sig_i = np.hypot(STEP_SIGMA_IMAGE, step_i[:, body] / scale)
    sig_w = np.hypot(STEP_SIGMA_WORLD_M, step_w[:, body])
    # Cauchy per landmark: when neither reading fits (a lost frame) the two
    # costs are alike and the frame pair says little.
    e_img = np.log1p((same_i / sig_i) ** 2) - np.log1p((cross_i / sig_i) ** 2)
    e_world = np.log1p((same_w / sig_w) ** 2) - np.log1p((cross_w / sig_w) ** 2)
    # Points seen in both frames only; each landmark counts once per source.
    e = np.nansum(np.where(np.isfinite(e_img), e_img, 0.0), axis=1) + np.nansum(
        np.where(np.isfinite(e_world), e_world, 0.0), axis=1
    )
    ok = valid[1:] & valid[:-1]
    out[1:] = np.where(ok, np.clip(e, -CONTINUITY_CAP, CONTINUITY_CAP), 0.0)
    return out


# Hidden states: (swap component k: 0 = as given, 1.. = swapped, duration
# component k-1) × facing (0 = facing the camera, 1 = back to it).
def _states() -> list[tuple[int, int]]:
    return [(k, f) for k in range(1 + len(SWAP_DURATIONS)) for f in (0, 1)]


def _identity_chain(p_start: np.ndarray) -> np.ndarray:
    """(T, K, K) transitions of the identity alone: as given (0) and the swap duration components."""
    K = 1 + len(SWAP_DURATIONS)
    ident = np.zeros((p_start.shape[0], K, K))
    ident[:, 0, 0] = 1.0 - p_start
    for k, (weight, mean) in enumerate(SWAP_DURATIONS, start=1):
        ident[:, 0, k] = p_start * weight
        ident[:, k, k] = 1.0 - 1.0 / mean
        ident[:, k, 0] = 1.0 / mean
    return ident


def _log_transitions(ev: IdentityEvidence) -> tuple[np.ndarray, np.ndarray]:
    """(T, S, S) log transition weights into frame t (t ≥ 1) and (T, S) log emissions."""
    states = _states()
    swap_of = np.array([k > 0 for k, _ in states])
    face_of = np.array([f for _, f in states])
    side = np.where(ev.valid, np.exp(-0.5 * (ev.width / SIDE_WIDTH) ** 2), 1.0)  # unseen frames pin nothing
    p_start = SWAP_START_PROB + (SWAP_START_SIDE_PROB - SWAP_START_PROB) * side
    k_of = np.array([k for k, _ in states])
    base = np.log(np.fmax(_identity_chain(p_start), 1e-300))[:, k_of[:, None], k_of[None, :]]  # (T, S, S)
    p_flip = FLIP_FLOOR_PROB + FLIP_SIDE_PROB * side
    flips = face_of[:, None] != face_of[None, :]
    log_face = np.where(flips[None], np.log(p_flip)[:, None, None], np.log1p(-p_flip)[:, None, None])
    switches = swap_of[:, None] != swap_of[None, :]
    # Relative to keeping the identity: a change of the decided identity is
    # supported by the labels' own jump to their twins.
    log_switch = np.where(switches[None], ev.switch[:, None, None], 0.0)
    trans = base + log_face + log_switch
    # Emissions: image order (expected + when facing == swapped) and the facing cues.
    expected = np.where(face_of == swap_of.astype(int), 1.0, -1.0)
    order_ll = -np.logaddexp(0.0, -ORDER_GAIN * ev.order[:, None] * expected[None])
    face_ll = -np.logaddexp(0.0, np.where(face_of[None] == 0, -1.0, 1.0) * ev.facing[:, None])
    emit = np.where(ev.valid[:, None], order_ll + face_ll, 0.0)
    return trans, emit


def _logsumexp(a: np.ndarray, axis: int) -> np.ndarray:
    m = np.max(a, axis=axis, keepdims=True)
    return np.squeeze(m, axis=axis) + np.log(np.sum(np.exp(a - m), axis=axis))


def decode_identity(track: KeypointTrack) -> IdentityResult:
    """Decide each frame's left/right identity and facing over the whole clip.

    Parameters
    ----------
    track : KeypointTrack
        Any backend's track (missing frames NaN).

    Returns
    -------
    IdentityResult
        Viterbi decision and forward–backward posteriors per frame.
    """
    ev = identity_evidence(track)
    trans, emit = _log_transitions(ev)
    states = _states()
    S, T = len(states), len(track)
    swap_of = np.array([k > 0 for k, _ in states])
    face_of = np.array([f for _, f in states])
    if T == 0:
        empty = np.zeros(0)
        return IdentityResult(empty.astype(bool), empty.astype(int), empty, empty, empty)
    # Start: as given more likely than swapped, either facing.
    prior = np.log(np.where(swap_of, SWAP_START_PROB, 1.0) / 2.0)
    # Viterbi.
    delta = prior + emit[0]
    back = np.zeros((T, S), dtype=int)
    for t in range(1, T):
        cand = delta[:, None] + trans[t]
        back[t] = np.argmax(cand, axis=0)
        delta = cand[back[t], np.arange(S)] + emit[t]
    path = np.zeros(T, dtype=int)
    path[-1] = int(np.argmax(delta))
    for t in range(T - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    # Forward-backward.
    alpha = np.zeros((T, S))
    alpha[0] = prior + emit[0]
    for t in range(1, T):
        alpha[t] = _logsumexp(alpha[t - 1][:, None] + trans[t], axis=0) + emit[t]
    beta = np.zeros((T, S))
    for t in range(T - 2, -1, -1):
        beta[t] = _logsumexp(trans[t + 1] + (emit[t + 1] + beta[t + 1])[None], axis=1)
    post = alpha + beta
    post = np.exp(post - _logsumexp(post, axis=1)[:, None])
    p_swapped = post[:, swap_of].sum(axis=1)
    p_back = post[:, face_of == 1].sum(axis=1)
    swapped = swap_of[path]
    confidence = np.where(swapped, p_swapped, 1.0 - p_swapped)
    confidence = np.where(ev.valid, np.clip(confidence, 0.0, 1.0), 0.0)
    facing = np.where(ev.valid, np.where(face_of[path] == 1, -1, 1), 0)
    return IdentityResult(swapped & ev.valid, facing, confidence, p_swapped, p_back)


def correct_identity(track: KeypointTrack) -> tuple[KeypointTrack, IdentityResult]:
    """The track with swapped frames relabelled, and its ``identity_confidence`` set.

    A swapped frame takes the mirror reading: left and right landmarks
    exchanged and depth (image ``z`` and world ``z``) reflected, the
    correction of exactly the pose model's ambiguity.

    Returns
    -------
    (KeypointTrack, IdentityResult)
        A new track (the input is not modified) and the decision.
    """
    result = decode_identity(track)
    return mirror_frames(track, result.swapped, result.confidence), result


def mirror_frames(
    track: KeypointTrack, frames: np.ndarray, identity_confidence: np.ndarray, pairs=None
) -> KeypointTrack:
    """A copy of `track` with the mirror reading at `frames` and the given ``identity_confidence``.

    The mirror reading is the pose model's ambiguity exactly: left and right
    landmarks exchanged and depth (image ``z`` and world ``z``) reflected.

    Parameters
    ----------
    track : KeypointTrack
    frames : (T,) bool ndarray
        Frames to relabel.
    identity_confidence : (T,) ndarray
        The track's new ``identity_confidence``.
    pairs : sequence of (int, int), optional
        Only these (left, right) landmark pairs are exchanged and reflected
        (one limb's labels, :mod:`.near_side`); default the whole body.
    """
    if pairs is None:
        perm, reflect = MIRROR, np.arange(MIRROR.size)
    else:
        pairs = np.asarray(pairs, dtype=int).reshape(-1, 2)
        perm = np.arange(MIRROR.size)
        perm[pairs[:, 0]], perm[pairs[:, 1]] = pairs[:, 1], pairs[:, 0]
        reflect = pairs.ravel()
    rows = np.flatnonzero(np.asarray(frames, dtype=bool))
    xy, world, vis = track.xy.copy(), track.world.copy(), track.visibility.copy()
    for values in (xy, world, vis):
        values[rows] = values[rows][:, perm]
    for values in (xy, world):
        values[np.ix_(rows, reflect, [2])] *= -1.0
    return replace(track, xy=xy, world=world, visibility=vis, identity_confidence=identity_confidence)
