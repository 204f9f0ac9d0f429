"""Keypoint tracks from the virtual dancer with the pose model's identity errors.

For measuring :mod:`capture2notation.keypoints.identity` without a pose
model: :func:`truth_track` turns the renderer's truth (2D keypoints, world
landmarks, visibility) into a :class:`KeypointTrack` as BlazePose would
report a perfect reading; :func:`with_identity_errors` then puts in what
BlazePose gets wrong — stretches where left and right are exchanged (the
mirror reading: labels exchanged, depth reflected) and back views read as
front views (the mirror reading with a face drawn on the back of the head) —
plus pixel and depth noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capture2notation.keypoints.identity import mirror_frames
from capture2notation.keypoints.track import KeypointTrack

__all__ = ["SimulatedErrors", "facing_camera", "truth_track", "with_identity_errors"]

#: Noise of the simulated pose model: pixels in the image, metres in the
#: world landmarks (BlazePose's world depth is its weakest coordinate).
PIXEL_NOISE_PX = 1.5
WORLD_NOISE_M = 0.015
DEPTH_NOISE_M = 0.04
#: Visibility the pose model gives a face it invents on the back of a head.
HALLUCINATED_FACE_VIS = 0.9
_FACE = np.arange(11)


def facing_camera(front_deg: np.ndarray, R: np.ndarray) -> np.ndarray:
    """(T,) bool: the pelvis faces the camera (its front points towards it).

    Parameters
    ----------
    front_deg : (T,) ndarray
        The pelvis's front, degrees clockwise from +y seen from above.
    R : (3, 3) ndarray
        World-to-camera rotation (OpenCV: z forward).
    """
    a = np.radians(np.asarray(front_deg, dtype=float))
    forward = np.stack([np.sin(a), np.cos(a), np.zeros_like(a)], axis=1)
    return (forward @ np.asarray(R).T)[:, 2] < 0


def truth_track(fields: dict) -> KeypointTrack:
    """A perfect BlazePose-like track from :func:`synthetic.render.job.truth_fields`.

    World landmarks are camera-axis metres centred on the hips (MediaPipe's
    convention); the image ``z`` is the depth relative to the hips in pixels.
    """
    K, R, t = (np.asarray(fields[k], dtype=float) for k in ("K", "R", "t"))
    cam = np.asarray(fields["landmarks3d"]) @ R.T + t
    hips = cam[:, [23, 24]].mean(axis=1, keepdims=True)
    world = cam - hips
    uv = np.asarray(fields["keypoints"], dtype=float)
    z_px = world[:, :, 2] * K[0, 0] / hips[:, :, 2]
    xy = np.concatenate([uv, z_px[..., None]], axis=-1)
    T = xy.shape[0]
    return KeypointTrack(
        fps=float(fields["fps"]),
        times=np.asarray(fields["times"]),
        image_size=np.asarray(fields["image_size"]),
        xy=xy,
        visibility=np.clip(np.asarray(fields["visibility"], dtype=float), 0.05, 1.0),
        presence=np.ones(T),
        world=world,
        crops=np.full((T, 5), np.nan),
        backend="truth",
    )


@dataclass(frozen=True)
class SimulatedErrors:
    """What :func:`with_identity_errors` did: the truth for scoring the decoder.

    Attributes
    ----------
    swapped : (T,) bool
        Frames whose labels are exchanged in the returned track.
    facing : (T,) bool
        Frames where the body truly faces the camera.
    """

    swapped: np.ndarray
    facing: np.ndarray


def with_identity_errors(
    track: KeypointTrack,
    facing: np.ndarray,
    rng: np.random.Generator,
    swaps: tuple[tuple[float, float], ...] = (),
    back_as_front: bool = True,
) -> tuple[KeypointTrack, SimulatedErrors]:
    """A copy of `track` with the pose model's identity errors and noise.

    Parameters
    ----------
    track : KeypointTrack
        A clean track (:func:`truth_track`).
    facing : (T,) bool
        The body faces the camera (:func:`facing_camera`).
    rng : numpy.random.Generator
    swaps : tuple of (start, stop) seconds
        Stretches read with left and right exchanged.
    back_as_front : bool
        Read every back view as a front view (mirror reading, invented face).

    Returns
    -------
    (KeypointTrack, SimulatedErrors)
    """
    T = len(track)
    swapped = np.zeros(T, dtype=bool)
    for a, b in swaps:
        swapped ^= (track.times >= a) & (track.times < b)
    back = ~np.asarray(facing, dtype=bool)
    if back_as_front:
        swapped ^= back
    # The pose model's own reading (not assessed: no identity confidence).
    out = mirror_frames(track, swapped, np.full(T, np.nan))
    xy, world, vis = out.xy, out.world, out.visibility
    if back_as_front:
        vis[np.ix_(back, _FACE)] = HALLUCINATED_FACE_VIS
    xy[..., :2] += rng.normal(0.0, PIXEL_NOISE_PX, xy[..., :2].shape)
    world[..., :2] += rng.normal(0.0, WORLD_NOISE_M, world[..., :2].shape)
    world[..., 2] += rng.normal(0.0, DEPTH_NOISE_M, world[..., 2].shape)
    return out, SimulatedErrors(swapped, np.asarray(facing, dtype=bool))
