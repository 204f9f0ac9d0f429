"""Which way the body faces the camera, over a whole clip, from the image alone.

A single camera's depth is where a pose model errs most: BlazePose's world
landmarks of a turning dancer put the hips' depth order wrong for many
frames, and a 3D fit that follows them turns its hips the wrong way or
half way back.  Two image cues say which way the body faces without any
depth (the yaw θ, 0 facing the camera, +90° facing the image's right):

* **the feet**: toes lie ahead of heels, so the feet's mean toe-minus-heel
  image offset along x is ∝ sin θ (its sign is right on 99 % of frames more
  than 30° from facing or backing the camera, BlazePose on turning renders);
* **the shoulders and hips**: their left-minus-right image offset along x is
  ∝ cos θ (labels as corrected by :mod:`.identity`);
* **the feet's drop**: a camera above the floor sees nearer floor points
  lower in the image, so toes pointing at the camera lie below their heels.
  BlazePose draws it so for a body facing the camera and draws toe and heel
  about level from behind or side-on (medians on development renders: 0.22,
  0.00 and 0.02 torso lengths), so the drop is ∝ max(cos θ, 0).  A raised
  heel (relevé, a pointed foot) lowers the toes as well, so a frame's drop
  only leans one way, and its errors last as long as a pose is held
  (:data:`DROP_SD`, :data:`DROP_OUTLIER_RATE`, :data:`DROP_WEIGHT`);
  a stretch of frames decides.

* **a face in the image** (:mod:`.face`): a face detector on the head
  finds one in about half the frames of a body facing the camera and in
  none of a body seen from behind, whatever the pose model drew there.  Its
  rate facing the camera depends on the video (resolution, light, the
  person), so it is measured on each clip: the yaw is decoded once with the
  rate of the development renders, the clip's rate read from the frames so
  decoded as facing the camera, and the yaw decoded again with it (:data:`FACE_SEEN_SHARE`,
  :data:`FACE_FALSE_RATE`, :data:`FACE_CORRELATION_S`); a clip whose faces
  are too small to find (:data:`MIN_FACE_RATE`), or that never faces the
  camera, is decoded without it.

The feet's sideways cue cannot tell a turn from its mirror image (θ and
180° − θ give the same sin θ, turning the other way); the shoulders' and
hips' order can, but only as right as the left/right labels: where the
identity decoder left them swapped, the order cue is mirrored for a stretch
(on development renders, 13.5 % of the frames away from side views, in
stretches of 1.3 s frame-weighted mean).  The feet's drop does not depend
on the labels, nor does the face: they are what tells a back view the pose
model drew as a front view from a front view.

:func:`decode_yaw` models that directly.  The hidden state is yaw
(:data:`YAW_STEP_DEG` grid) × yaw rate (up to :data:`MAX_RATE_DEG_S`,
changing smoothly, :data:`RATE_CHANGE_SD_DEG_S2`, so a pirouette keeps
turning through its side views, or now and then suddenly,
:data:`RATE_JUMP_SHARE`, as a turn in the air sets off) × whether the
order cue is mirrored (a sticky chain: :data:`MIRRORED_SHARE` of the time,
in stretches of :data:`MIRRORED_MEAN_S`).  Each cue is Gaussian about its expected value
with a share of outliers (:data:`CUE_OUTLIER_RATE`), in units of its value
side-on or facing the camera (:data:`FEET_SIDE_ON`, :data:`WIDTH_FACING`).
Forward–backward gives each frame's posterior over yaw and rate, the
mirrored stretches summed out; the yaw is then the path through the same
lattice that is most probable frame by frame under that posterior
(posterior decoding, which weighs every reading of a stretch rather than
committing to the single best one, as a Viterbi path over the joint state
does).  Long clips are decoded in windows of :data:`WINDOW_S` with
:data:`MARGIN_S` of context on each side, so memory does not grow with
the clip.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .identity import mirror_frames, toes_minus_heels, torso_and_order
from .track import KeypointTrack

__all__ = [
    "CUE_OUTLIER_RATE",
    "CUE_SD",
    "DECODE_FPS",
    "DROP_OUTLIER_RATE",
    "DROP_SD",
    "DROP_WEIGHT",
    "FACE_CORRELATION_S",
    "FACE_FALSE_RATE",
    "FACE_RATE_PRIOR_READINGS",
    "FACE_RATE_RENDERS",
    "FACE_SEEN_SHARE",
    "FACE_SEEN_YAW_DEG",
    "FEET_FACING_DROP",
    "FEET_SIDE_ON",
    "MARGIN_S",
    "MAX_RATE_DEG_S",
    "MIN_FACE_RATE",
    "MIN_FEET_SEEN",
    "MIRRORED_MEAN_S",
    "MIRRORED_SHARE",
    "RATE_CHANGE_SD_DEG_S2",
    "RATE_JUMP_SD_DEG_S2",
    "RATE_JUMP_SHARE",
    "READING_HALF_WIDTH_DEG",
    "WIDTH_FACING",
    "WINDOW_S",
    "YAW_STEP_DEG",
    "YawDecoding",
    "correct_mirrored",
    "decode_yaw",
    "yaw_decoding",
]

#: Resolution of the yaw grid, degrees (an eighth of a turn is 9 steps).
YAW_STEP_DEG = 5.0
#: Fastest yaw rate searched, degrees per second: a turn in the air (a full
#: turn in a 0.4-s spring) peaks at 1,300–1,600°/s, 60° a frame at 25 fps;
#: a quick pirouette's two turns a second stay well inside.
MAX_RATE_DEG_S = 1500.0
#: Spread of the yaw rate's change, degrees per second squared: a
#: pirouette reaches its speed within about a fifth of a second (4° a frame
#: per frame at 25 fps; 2 and 8 measured worse on development renders).
RATE_CHANGE_SD_DEG_S2 = 2500.0
#: Share of frames whose rate change is sudden, and its spread, degrees per
#: second squared: a spring's turn gets up to speed within a tenth of a
#: second (16° a frame per frame at 25 fps).  With the smooth spread alone,
#: full turns in the air were decoded as no turn (a full turn ends looking
#: as it began); with it widened to 6,000 for every frame, the fitted hips'
#: swings were read as eighth turns (development renders).
RATE_JUMP_SHARE = 0.05
RATE_JUMP_SD_DEG_S2 = 10000.0
#: Frame rate the decoder runs at: faster clips are decoded on every n-th
#: frame (the grid's rate step is one yaw step a frame) and interpolated.
DECODE_FPS = 25.0
#: Spread of each cue about its expected value, in units of its full value.
CUE_SD = 0.35
#: Share of frames whose cue is unrelated to the yaw (a foot lifted and
#: pointed, a label glitch of a frame or two).
CUE_OUTLIER_RATE = 0.05
#: Share of the time the shoulders' and hips' order cue is mirrored (labels
#: left swapped by the identity decoder), and the mean length of such a
#: stretch, seconds: 13.5 % of frames and 1.3 s on development renders
#: (BlazePose, turning random scores; module docstring).
MIRRORED_SHARE = 0.15
MIRRORED_MEAN_S = 1.3
#: Share of the frames with a person that must show the feet: with fewer the
#: yaw's side (left or right of the camera) is unknown and none is decoded.
MIN_FEET_SEEN = 0.5
#: The feet cue of a body side-on to the camera, and the width cue of one
#: facing it, torso lengths (shoulders' middle to hips' middle): BlazePose's
#: heel-to-toe landmarks span 0.41 torso lengths side-on and its shoulders
#: and hips 0.55 facing the camera (medians, development renders; the
#: renderer's own landmarks 0.53 and 0.59).  Body proportions, not fitted
#: per clip: a dancer who never turns side-on has no side-on feet to scale by.
FEET_SIDE_ON = 0.41
WIDTH_FACING = 0.55
#: How far below the heels BlazePose draws the toes of a body facing the
#: camera, torso lengths (median over development renders, front and phone
#: cameras 0.4–1.9 m high: 0.13–0.26 per clip, not proportional to the
#: camera's height).  A constant like the two above.
FEET_FACING_DROP = 0.22
#: Spread of the feet's drop about its expected value, in units of
#: :data:`FEET_FACING_DROP`, and its share of outliers (a raised heel or a
#: lifted foot: the drop of a pointed foot says nothing of the view).
DROP_SD = 0.5
DROP_OUTLIER_RATE = 0.3
#: The drop's errors last as long as a pose is held (a heel raised for a
#: relevé, a foot pointed behind), where the other cues' are mostly the pose
#: model's frame-to-frame jitter, so a frame's drop counts for this share of
#: a reading beside them (one frame then favours facing over backing by at
#: most 1.2:1).  Taken at full weight, a held leg gesture turned a body at
#: 45° to the camera round to 135° for seconds (development renders at 45°:
#: yaw within 22.5° on 74 % of frames against 95 % without the cue).  A share
#: of a frame, not a time: weighted per second instead, at 5 fps the drop
#: outvoted the other cues and swapped a whole body for 14 frames.
DROP_WEIGHT = 0.2
#: How often the face detector finds a face, by the body's yaw away from
#: facing the camera (degrees), as a share of its rate facing the camera:
#: turning renders through BlazePose, both development sets, 0.45 of frames
#: within 60° of facing, 0.27–0.33 at 60–75°, 0.07–0.12 side-on, 0.02–0.09
#: at 105–120° and 0–1 % further round (it needs the eyes).
FACE_SEEN_YAW_DEG = (0.0, 55.0, 68.0, 82.0, 98.0, 112.0, 125.0, 180.0)
FACE_SEEN_SHARE = (1.0, 1.0, 0.6, 0.2, 0.17, 0.1, 0.0, 0.0)
#: Probability of a face found where none faces the camera (the profile
#: cascade on hair or a raised arm): 0–2 % of frames with the back turned.
FACE_FALSE_RATE = 0.02
#: How long the detector's misses last, seconds: a bowed head or an arm
#: across the face holds for a pose, so a frame counts for this share of an
#: independent reading.  Chosen so a whole second facing the camera without
#: a face found is as rare as measured: 10 % and 19 % of such seconds on the
#: two development sets, against 88–99 % of seconds with the back turned.
FACE_CORRELATION_S = 0.3
#: A clip whose faces are found in fewer of its frames facing the camera
#: than this does not resolve faces (too small, too dark, turned away all
#: along); its misses say nothing of the view and the cue is not used.
MIN_FACE_RATE = 0.1
#: Rate of faces found facing the camera on the development renders: the
#: first decoding's, and the prior of a clip's own, which counts as this
#: many independent readings (:data:`FACE_CORRELATION_S`) beside the clip's.
#: A clip with no frame facing the camera has no rate of its own and the
#: cue is not used: a profile held for a whole clip otherwise drifts, frame
#: after frame of misses, from side-on towards the back (the built-in
#: phrases filmed side-on: knees and ankles swapped in 7 of 218 frames).
FACE_RATE_RENDERS = 0.45
FACE_RATE_PRIOR_READINGS = 2.0
#: Frames are decoded in windows of this many seconds, each with this much
#: context either side (a turn's evidence reaches a few seconds at most).
WINDOW_S = 60.0
MARGIN_S = 10.0


def _cues(track: KeypointTrack) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-frame feet (∝ sin θ), width (∝ cos θ) and drop (∝ max(cos θ, 0)) cues in units of their full values, and the frames seen."""
    xy = np.asarray(track.xy, float)[:, :, :2]
    torso, seen, width = torso_and_order(xy)
    feet, drop = toes_minus_heels(xy, torso).T  # image y points down: a positive drop has the toes lower
    return feet / FEET_SIDE_ON, width / WIDTH_FACING, drop / FEET_FACING_DROP, seen


def _cue_likelihood(
    obs: np.ndarray, expected: np.ndarray, sd: float = CUE_SD, outliers: float = CUE_OUTLIER_RATE
) -> np.ndarray:
    """(T, N) likelihood of each frame's cue for each expected value (1 where the cue is missing)."""
    r = (obs[:, None] - expected[None]) / sd
    lik = (1.0 - outliers) * np.exp(-0.5 * r**2) + outliers
    return np.where(np.isfinite(obs)[:, None], lik, 1.0)


class _Lattice:
    """The yaw × rate × mirrored chain at one frame rate, and its moves.

    States are arrays ``(N, M, 2)``: yaw bin, rate bin, order cue mirrored.
    Between frames the mirrored flag may change, then the rate (by at most
    ``K`` bins), then the yaw moves by the new rate.
    """

    def __init__(self, fps: float):
        self.fps = fps
        self.grid = np.arange(0.0, 360.0, YAW_STEP_DEG)
        self.N = self.grid.size
        # Each bin's angle from facing the camera, degrees in [0, 180].
        self.away = np.degrees(np.abs(np.angle(np.exp(1j * np.radians(self.grid)))))
        k_max = max(1, int(round(MAX_RATE_DEG_S / fps / YAW_STEP_DEG)))
        # Below half a turn a frame: a faster rate is a slower one the other way.
        k_max = min(k_max, self.N // 2 - 1)
        self.rates = np.arange(-k_max, k_max + 1)
        self.M = self.rates.size
        sd = RATE_CHANGE_SD_DEG_S2 / fps**2 / YAW_STEP_DEG  # rate bins a frame
        jump = RATE_JUMP_SD_DEG_S2 / fps**2 / YAW_STEP_DEG
        # No change larger than the whole range of rates.
        self.K = min(max(1, int(np.ceil(2.0 * max(sd, jump)))), self.M - 1)
        # Back-pointers index the 2K + 1 changes: a byte where they fit (low frame rates need more).
        changes = 2 * self.K + 1
        self.pointer = np.int8 if changes <= np.iinfo(np.int8).max else np.int16
        k = np.arange(-self.K, self.K + 1)

        def normal(spread: float) -> np.ndarray:
            w = np.exp(-0.5 * (k / max(spread, 1e-9)) ** 2)
            return w / w.sum()

        self.change = (1.0 - RATE_JUMP_SHARE) * normal(sd) + RATE_JUMP_SHARE * normal(jump)
        self.log_change = np.log(self.change)
        off = 1.0 / max(2.0, MIRRORED_MEAN_S * fps)
        on = off * MIRRORED_SHARE / (1.0 - MIRRORED_SHARE)
        self.flip = np.array([[1.0 - on, on], [off, 1.0 - off]])  # from -> to
        # The chain has no beginning: its first frame is mirrored at the stationary share.
        self.start = np.array([1.0 - MIRRORED_SHARE, MIRRORED_SHARE])
        n = np.arange(self.N)[:, None]
        self.came_from = (n - self.rates[None, :]) % self.N  # yaw at t-1 of state (n, m) at t
        self.goes_to = (n + self.rates[None, :]) % self.N  # yaw at t+1 of yaw n moving at rate m
        self.m = np.arange(self.M)[None, :]

    def emission(self, feet: np.ndarray, width: np.ndarray, drop: np.ndarray) -> np.ndarray:
        """(T, N, 2) likelihood of each frame's cues for each yaw, order cue as read and mirrored."""
        s, c = np.sin(np.radians(self.grid)), np.cos(np.radians(self.grid))
        # Neither feet cue depends on the left/right labels.
        lf = (
            _cue_likelihood(feet, s)
            * _cue_likelihood(drop, np.maximum(c, 0.0), DROP_SD, DROP_OUTLIER_RATE) ** DROP_WEIGHT
        )
        return np.stack([lf * _cue_likelihood(width, c), lf * _cue_likelihood(width, -c)], axis=-1)

    def face_weight(self, face: np.ndarray) -> float:
        """Share of a reading one assessed frame of `face` counts for (:data:`FACE_CORRELATION_S`)."""
        per_second = max(np.isfinite(face).mean(), 1.0 / max(face.size, 1)) * self.fps
        return min(1.0, 1.0 / (FACE_CORRELATION_S * per_second))

    def face_likelihood(self, face: np.ndarray, rate: float) -> np.ndarray:
        """(T, N) likelihood of each frame's face found (1) or not (0) for each yaw (1 where NaN).

        `rate` is the clip's rate of faces found facing the camera.
        """
        p = FACE_FALSE_RATE + (rate - FACE_FALSE_RATE) * np.interp(self.away, FACE_SEEN_YAW_DEG, FACE_SEEN_SHARE)
        lik = np.where(face[:, None] > 0.5, p[None], 1.0 - p[None])
        return np.where(np.isfinite(face)[:, None], lik ** self.face_weight(face), 1.0)

    def face_rate(self, face: np.ndarray, yaw: np.ndarray) -> float | None:
        """The clip's rate of faces found where yaw bins `yaw` face the camera, or None if too low to use.

        Faces found within 45° of facing, as independent readings
        (:meth:`face_weight`), beside :data:`FACE_RATE_PRIOR_READINGS` at
        the renders' rate; None below :data:`MIN_FACE_RATE` or where no
        frame faces the camera.
        """
        seen = face[(self.away[yaw] < 45.0) & np.isfinite(face)]
        if seen.size == 0:
            return None
        weight = self.face_weight(face)
        readings, found = seen.size * weight, seen.sum() * weight
        rate = (found + FACE_RATE_RENDERS * FACE_RATE_PRIOR_READINGS) / (readings + FACE_RATE_PRIOR_READINGS)
        return float(rate) if rate >= MIN_FACE_RATE else None

    def _rate_mix(self, a: np.ndarray) -> np.ndarray:
        """Sum over the previous rate (the rate-change kernel is symmetric: its own transpose)."""
        out = np.zeros_like(a)
        for i, j in enumerate(range(-self.K, self.K + 1)):
            lo, hi = max(0, -j), min(self.M, self.M - j)
            out[:, lo:hi] += self.change[i] * a[:, lo + j : hi + j]
        return out

    def _best_rate(self, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Best log score over the previous rate, and which change (index into ``change``) gave it."""
        best = np.full(delta.shape, -np.inf)
        arg = np.zeros(delta.shape, self.pointer)
        for i, j in enumerate(range(-self.K, self.K + 1)):
            lo, hi = max(0, -j), min(self.M, self.M - j)
            src = np.full(delta.shape, -np.inf)
            src[:, lo:hi] = delta[:, lo + j : hi + j] + self.log_change[i]
            better = src > best
            best = np.where(better, src, best)
            arg = np.where(better, i, arg)
        return best, arg

    def path_step(self, delta: np.ndarray, unary: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The path's next log scores (N, M) from `delta` and the frame's `unary`, and their back-pointers."""
        best, arg = self._best_rate(delta)
        # A state (n, m) at t came from yaw n − rate(m) at t − 1.
        return best[self.came_from, self.m] + unary, arg[self.came_from, self.m]

    def forward_step(self, a: np.ndarray, e: np.ndarray) -> np.ndarray:
        """The next frame's normalised forward message from `a` and its emission `e` (N, 2)."""
        a = self._rate_mix(a @ self.flip)[self.came_from, self.m] * e[:, None, :]
        return a / max(a.sum(), 1e-300)

    def backward_step(self, b: np.ndarray, e: np.ndarray) -> np.ndarray:
        """The previous frame's normalised backward message from `b` and its emission `e` (N, 2)."""
        g = (b * e[:, None, :])[self.goes_to, self.m]
        b = self._rate_mix(g) @ self.flip.T
        return b / max(b.sum(), 1e-300)


def _posterior_windows(lat: _Lattice, emit: np.ndarray):
    """Yield ``(start, (n, N, M) posterior over yaw and rate, (n,) P(mirrored))``, window by window.

    Forward–backward over each window of :data:`WINDOW_S` with
    :data:`MARGIN_S` of context either side, so memory stays bounded.
    """
    T = emit.shape[0]
    window = max(1, int(round(WINDOW_S * lat.fps)))
    margin = int(round(MARGIN_S * lat.fps))
    for start in range(0, T, window):
        stop = min(T, start + window)
        lo, hi = max(0, start - margin), min(T, stop + margin)
        alpha = np.empty((hi - lo, lat.N, lat.M, 2))
        a = lat.start * emit[lo][:, None, :] * np.ones((1, lat.M, 1))
        alpha[0] = a / a.sum()
        for t in range(lo + 1, hi):
            alpha[t - lo] = lat.forward_step(alpha[t - lo - 1], emit[t])
        b = np.ones((lat.N, lat.M, 2))
        for t in range(hi - 1, stop - 1, -1):
            b = lat.backward_step(b, emit[t])
        post = np.empty((stop - start, lat.N, lat.M))
        mirrored = np.empty(stop - start)
        for t in range(stop - 1, start - 1, -1):
            p = alpha[t - lo] * b
            total = max(p.sum(), 1e-300)
            post[t - start] = p.sum(axis=-1) / total
            mirrored[t - start] = p[..., 1].sum() / total
            b = lat.backward_step(b, emit[t])
        yield start, post, mirrored


def _posterior_path(lat: _Lattice, emit: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The lattice path of greatest summed log posterior, and each frame's posterior over yaw.

    The rate-change prior stays in the path's score, so the path turns as
    smoothly as the chain allows; the posterior replaces the cues.

    Returns
    -------
    yaw, rate : (T,) int ndarray
        Bins of the path.
    yaw_posterior : (T, N) ndarray
        Each frame's posterior over the yaw bins.
    mirrored : (T,) ndarray
        Each frame's posterior probability that the order cue is mirrored.
    """
    T = emit.shape[0]
    back = np.zeros((T, lat.N, lat.M), lat.pointer)
    yaw_posterior = np.zeros((T, lat.N), np.float32)
    mirrored = np.zeros(T)
    delta = None
    for start, post, mirrored_part in _posterior_windows(lat, emit):
        yaw_posterior[start : start + len(post)] = post.sum(axis=2)
        mirrored[start : start + len(post)] = mirrored_part
        for k, p in enumerate(post):
            unary = np.log(p + 1e-9)
            if delta is None:
                delta = unary
            else:
                delta, back[start + k] = lat.path_step(delta, unary)
    yaw, rate = np.zeros(T, int), np.zeros(T, int)
    yaw[-1], rate[-1] = np.unravel_index(int(np.argmax(delta)), delta.shape)
    for t in range(T - 1, 0, -1):
        yaw[t - 1] = (yaw[t] - lat.rates[rate[t]]) % lat.N
        rate[t - 1] = rate[t] + int(back[t, yaw[t], rate[t]]) - lat.K
    return yaw, rate, yaw_posterior, mirrored


#: Half-width, degrees, of the yaw window counted as a reading's own (half
#: an eighth of a turn: the turn quantiser's rounding).
READING_HALF_WIDTH_DEG = 22.5


def _readings(lat: _Lattice, yaw: np.ndarray, yaw_posterior: np.ndarray) -> np.ndarray:
    """(T, 2) posterior mass near the decoded yaw θ and near its mirror image 180° − θ.

    A bin counts for the reading it lies nearer to (within
    :data:`READING_HALF_WIDTH_DEG`); side-on, where the two readings meet,
    neither gets it.
    """
    n = np.arange(lat.N)[None, :]
    mirror = (lat.N // 2 - yaw) % lat.N

    def dist(a):
        d = np.abs(n - a[:, None]) % lat.N
        return np.minimum(d, lat.N - d) * YAW_STEP_DEG

    d_path, d_mirror = dist(yaw), dist(mirror)
    near = (d_path <= READING_HALF_WIDTH_DEG) & (d_path < d_mirror)
    far = (d_mirror <= READING_HALF_WIDTH_DEG) & (d_mirror < d_path)
    return np.stack([(yaw_posterior * near).sum(axis=1), (yaw_posterior * far).sum(axis=1)], axis=1)


@dataclass(frozen=True)
class YawDecoding:
    """What :func:`yaw_decoding` read of a clip.

    Attributes
    ----------
    yaw : (T,) ndarray
        As :func:`decode_yaw` returns it.
    readings : (T, 2) ndarray
        Posterior probability of the yaw lying near the decoded one and near
        its mirror image 180° − θ (the reading the feet cannot tell from it:
        the same sin θ, turning the other way); side-on, where they meet,
        both are small.  NaN where the yaw is.
    mirrored : (T,) ndarray
        Posterior probability that the shoulders' and hips' order is
        mirrored (left and right swapped in the track); NaN where the yaw is.
    """

    yaw: np.ndarray
    readings: np.ndarray
    mirrored: np.ndarray


def _face_per_kept_frame(face: np.ndarray, stride: int) -> np.ndarray:
    """The face cue of every `stride`-th frame: found if found in any frame up to the next, NaN if none looked."""
    T = face.size
    blocks = np.full(((T + stride - 1) // stride) * stride, np.nan)
    blocks[:T] = face
    blocks = blocks.reshape(-1, stride)
    looked = np.isfinite(blocks).any(axis=1)
    return np.where(looked, np.nanmax(np.where(looked[:, None], blocks, 0.0), axis=1), np.nan)


def decode_yaw(track: KeypointTrack) -> np.ndarray:
    """The body's yaw towards the camera in every frame, unwrapped over the clip.

    Parameters
    ----------
    track : KeypointTrack
        A track with left and right already decided
        (:func:`~.identity.correct_identity`; ``extract`` does it).

    Returns
    -------
    (T,) ndarray
        Degrees: 0 facing the camera, +90 facing the image's right, 180 the
        back to the camera; continuous through turns (two turns to the image's
        right end 720° above their start).  NaN in frames without a person,
        and everywhere when the feet are seen in fewer than
        :data:`MIN_FEET_SEEN` of them (a track without feet landmarks).
    """
    return yaw_decoding(track).yaw


def yaw_decoding(track: KeypointTrack) -> YawDecoding:
    """The yaw of :func:`decode_yaw` with the decoder's posterior (:class:`YawDecoding`).

    Parameters
    ----------
    track : KeypointTrack
        As for :func:`decode_yaw`.
    """
    T = len(track)
    if T == 0:
        return YawDecoding(np.zeros(0), np.zeros((0, 2)), np.zeros(0))
    feet, width, drop, seen = _cues(track)
    if not seen.any() or np.isfinite(feet[seen]).mean() < MIN_FEET_SEEN:
        return YawDecoding(np.full(T, np.nan), np.full((T, 2), np.nan), np.full(T, np.nan))
    stride = max(1, int(round(float(track.fps) / DECODE_FPS)))
    keep = np.arange(0, T, stride)
    lat = _Lattice(float(track.fps) / stride)
    emit = lat.emission(feet[keep], width[keep], drop[keep])
    face = _face_per_kept_frame(np.asarray(track.face, float), stride)
    if np.isfinite(face).any():
        # The clip's own rate of faces found facing the camera, read where
        # a decoding at the development sets' rate faces it (decoded without
        # the cue, a long back view drawn as a front view would count as
        # facing without a face and hide the cue that tells it).
        first = _posterior_path(lat, emit * lat.face_likelihood(face, FACE_RATE_RENDERS)[:, :, None])[0]
        face_rate = lat.face_rate(face, first)
        if face_rate is not None:
            emit = emit * lat.face_likelihood(face, face_rate)[:, :, None]
    yaw_i, rate_i, yaw_posterior, mirrored = _posterior_path(lat, emit)
    readings = _readings(lat, yaw_i, yaw_posterior)
    unwrapped = lat.grid[yaw_i[0]] + np.r_[0.0, np.cumsum(lat.rates[rate_i[1:]] * YAW_STEP_DEG)]
    frames = np.arange(T)
    yaw = np.where(seen, np.interp(frames, keep, unwrapped), np.nan)
    readings = np.stack([np.interp(frames, keep, readings[:, k]) for k in range(2)], axis=1)
    mirrored = np.interp(frames, keep, mirrored)
    return YawDecoding(yaw, np.where(seen[:, None], readings, np.nan), np.where(seen, mirrored, np.nan))


def correct_mirrored(track: KeypointTrack) -> tuple[KeypointTrack, YawDecoding]:
    """The track relabelled where the yaw decoder reads its left and right swapped.

    The identity decoder (:func:`~.identity.correct_identity`) judges the
    labels by their own continuity and the pose model's face; the yaw
    chain judges them by the feet and the body's turning, which no label
    changes.  Frames whose order cue the chain reads mirrored more likely
    than not take the mirror reading, with the chain's probability of it
    as their ``identity_confidence``; elsewhere the identity decoder's
    stands (side-on the chain knows nothing of the labels and says only
    its prior).

    Parameters
    ----------
    track : KeypointTrack
        A track already corrected by :func:`~.identity.correct_identity`.

    Returns
    -------
    (KeypointTrack, YawDecoding)
        The relabelled track (the input is not modified) and the decoding
        of the track as given (its yaw is the relabelled track's too).
    """
    decoding = yaw_decoding(track)
    p = np.nan_to_num(decoding.mirrored)
    swap = p > 0.5
    conf = np.where(swap, p, np.asarray(track.identity_confidence, float))
    return mirror_frames(track, swap, conf), decoding
