"""A one-view fit turned to face the way the image says.

The fit of one camera's keypoints takes its hips' depth order from the pose
model's world landmarks, which a turning body defeats (its front runs the
wrong way or half way back; :mod:`capture2notation.keypoints.yaw`).  The
yaw decoded from the image alone sets the fitted body's front instead: each
frame is turned about the vertical through its pelvis, which changes no
limb relative to the body and no position of the pelvis.
"""

from __future__ import annotations

import numpy as np

from ..body import body_frame, euler_to_matrix, front_of, joint_index, matrix_to_euler
from ..errors import FittingError
from ..keypoints.yaw import yaw_decoding
from .camera import Camera
from .result import FitResult

__all__ = ["front_from_yaw", "turned_to", "with_image_yaw"]


def front_from_yaw(yaw_deg, R) -> np.ndarray:
    """The world front (DESIGN.md: degrees clockwise from +y seen from above) of a camera-relative yaw.

    Parameters
    ----------
    yaw_deg : (T,) array_like
        Degrees, 0 facing the camera, +90 facing the image's right
        (:func:`~capture2notation.keypoints.yaw.decode_yaw`), unwrapped.
    R : (3, 3) array_like
        The camera's world-to-camera rotation (OpenCV axes: x right, y down,
        z forward; world z up).

    Returns
    -------
    (T,) ndarray
        Degrees, unwrapped as the yaw is; NaN where the yaw is.
    """
    yaw = np.radians(np.asarray(yaw_deg, float))
    R = np.asarray(R, float)
    if R.shape != (3, 3):
        raise FittingError(f"R must have shape (3, 3), got {R.shape}")
    # The yaw turns about the vertical: take the camera's axes level (its
    # roll and pitch do not turn the body).  Facing the camera is looking
    # back along its level optical axis; the image's right is its level x.
    ahead = np.array([R[2, 0], R[2, 1], 0.0])
    if np.linalg.norm(ahead) < 1e-6:
        raise FittingError("the camera looks straight up or down: a body's yaw towards it is undefined")
    ahead /= np.linalg.norm(ahead)
    right = np.array([ahead[1], -ahead[0], 0.0])  # ahead x up
    right *= np.sign(right @ R[0]) or 1.0
    forward = np.sin(yaw)[..., None] * right - np.cos(yaw)[..., None] * ahead
    out = np.full(yaw.shape, np.nan)
    ok = np.isfinite(yaw)
    if ok.any():
        # Unwrapped as the yaw is: its steps are far below half a turn.
        out[ok] = np.degrees(np.unwrap(np.arctan2(forward[ok, 0], forward[ok, 1])))
    return out


def turned_to(result: FitResult, front_deg) -> FitResult:
    """`result` with each frame turned about the vertical through its pelvis to face `front_deg`.

    Parameters
    ----------
    result : FitResult
    front_deg : (T,) array_like
        The front each frame should have, degrees clockwise from +y seen
        from above; NaN leaves a frame as it is.

    Returns
    -------
    FitResult
        Joints, and the pelvis's angles, turned; root and every other angle
        unchanged.
    """
    front = np.asarray(front_deg, float)
    T = result.n_frames
    if front.shape != (T,):
        raise FittingError(f"front_deg must have shape ({T},), got {front.shape}")
    now = front_of(body_frame(np.asarray(result.joints, float))[:, 1])
    turn = (front - now + 180.0) % 360.0 - 180.0
    turn = np.where(np.isfinite(turn), turn, 0.0)
    # A clockwise front change is a rotation by minus that about +z.
    a = -np.radians(turn)
    c, s = np.cos(a), np.sin(a)
    Rz = np.zeros((T, 3, 3))
    Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -s, s, c, 1.0
    root = np.asarray(result.root, float)
    joints = np.einsum("tij,tkj->tki", Rz, np.asarray(result.joints, float) - root[:, None]) + root[:, None]
    angles = np.array(result.angles, float)
    pelvis = joint_index("pelvis")
    angles[:, pelvis] = matrix_to_euler(Rz @ euler_to_matrix(angles[:, pelvis]))
    return result.replace(joints=joints, angles=angles)


def with_image_yaw(result: FitResult, track, camera: Camera) -> FitResult:
    """A one-view fit turned to the yaw decoded from its keypoint track.

    Parameters
    ----------
    result : FitResult
        The fit of `track` (:func:`~.fit.fit_track`).
    track : KeypointTrack
        Its keypoints, left and right decided.
    camera : Camera
        The camera the fit used (:meth:`Camera.default` for an unknown one).

    Returns
    -------
    FitResult
        Turned (:func:`turned_to`), with ``front_readings`` from the decoder.
    """
    decoding = yaw_decoding(track)
    return turned_to(result, front_from_yaw(decoding.yaw, camera.R)).replace(front_readings=decoding.readings)
