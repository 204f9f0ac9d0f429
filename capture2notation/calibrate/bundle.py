"""Bundle adjustment of cameras and board poses (scipy least squares, sparse Jacobian).

Unknowns: per camera its intrinsics ``(fx, fy, cx, cy, k1, k2)`` (OpenCV's
model; k3, p1, p2 held at zero: a phone's lens needs no sixth-order or
tangential term, and freed they trade against k2 and the principal point) and its pose relative to
the reference camera (Rodrigues vector, translation; the reference camera's
pose is the identity, which fixes the gauge); per board view its pose in the
reference camera's frame.  Residuals are pixel offsets of every detected
corner, with a soft-L1 loss so a misdetected corner does not pull the fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

__all__ = ["FREE_INTRINSICS", "N_INTRINSICS", "BundleResult", "Observations", "bundle_adjust", "project", "rodrigues"]

#: Intrinsic parameters per camera: fx, fy, cx, cy, k1, k2, p1, p2.
N_INTRINSICS = 8
#: Intrinsics the bundle adjusts (fx, fy, cx, cy, k1, k2); the tangential
#: terms p1, p2 stay zero: a phone's lens has practically none, and freed
#: they trade against the principal point (rendered clips: principal point
#: 4-7 px and camera centres 1-2 cm off with them free).
FREE_INTRINSICS = (0, 1, 2, 3, 4, 5)
#: Soft-L1 scale, pixels: residuals beyond it count linearly (a corner
#: detector's error is a few tenths of a pixel; a wrong corner is pixels off).
LOSS_SCALE_PX = 1.0


def rodrigues(r: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of Rodrigues vectors ``(..., 3)`` (radians)."""
    r = np.asarray(r, float)
    theta = np.linalg.norm(r, axis=-1)[..., None, None]
    k = np.where(theta > 1e-12, r[..., :, None] / np.maximum(theta, 1e-12), 0.0)[..., 0]
    kx = np.zeros(r.shape[:-1] + (3, 3))
    kx[..., 0, 1], kx[..., 0, 2] = -k[..., 2], k[..., 1]
    kx[..., 1, 0], kx[..., 1, 2] = k[..., 2], -k[..., 0]
    kx[..., 2, 0], kx[..., 2, 1] = -k[..., 1], k[..., 0]
    eye = np.broadcast_to(np.eye(3), kx.shape)
    return eye + np.sin(theta) * kx + (1 - np.cos(theta)) * (kx @ kx)


def project(points_cam: np.ndarray, intr: np.ndarray) -> np.ndarray:
    """Pixels ``(N, 2)`` of camera-frame points ``(N, 3)`` with OpenCV's distortion.

    `intr` is ``(N, 8)`` or ``(8,)``: fx, fy, cx, cy, k1, k2, p1, p2.
    """
    intr = np.broadcast_to(intr, points_cam.shape[:-1] + (N_INTRINSICS,))
    fx, fy, cx, cy, k1, k2, p1, p2 = (intr[..., i] for i in range(N_INTRINSICS))
    z = points_cam[..., 2]
    x, y = points_cam[..., 0] / z, points_cam[..., 1] / z
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 * r2
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return np.stack([fx * xd + cx, fy * yd + cy], axis=-1)


@dataclass(frozen=True)
class Observations:
    """Every detected corner: which camera, which board view, which board point, where.

    Attributes
    ----------
    camera : (M,) int ndarray
    view : (M,) int ndarray
        Board view (a moment of the clip) index.
    points : (M, 3) ndarray
        Board coordinates of the corner, metres.
    pixels : (M, 2) ndarray
    """

    camera: np.ndarray
    view: np.ndarray
    points: np.ndarray
    pixels: np.ndarray


@dataclass(frozen=True)
class BundleResult:
    """Fitted cameras and board poses.

    Attributes
    ----------
    intrinsics : (C, 8) ndarray
    R, t : (C, 3, 3), (C, 3) ndarray
        Reference-camera frame → camera frame.
    board_R, board_t : (V, 3, 3), (V, 3) ndarray
        Board → reference-camera frame.
    residuals : (M, 2) ndarray
        Pixels.
    """

    intrinsics: np.ndarray
    R: np.ndarray
    t: np.ndarray
    board_R: np.ndarray
    board_t: np.ndarray
    residuals: np.ndarray


_NF = len(FREE_INTRINSICS)


def _unpack(x: np.ndarray, n_cam: int, n_view: int, fixed: np.ndarray):
    ni = n_cam * _NF
    intr = fixed.copy()
    intr[:, FREE_INTRINSICS] = x[:ni].reshape(n_cam, _NF)
    ext = np.concatenate([np.zeros((1, 6)), x[ni : ni + 6 * (n_cam - 1)].reshape(n_cam - 1, 6)])
    views = x[ni + 6 * (n_cam - 1) :].reshape(n_view, 6)
    return intr, ext, views


def _residuals(x, obs: Observations, n_cam: int, n_view: int, fixed: np.ndarray) -> np.ndarray:
    intr, ext, views = _unpack(x, n_cam, n_view, fixed)
    Rb = rodrigues(views[:, :3])[obs.view]
    p_ref = np.einsum("mij,mj->mi", Rb, obs.points) + views[obs.view, 3:]
    Rc = rodrigues(ext[:, :3])[obs.camera]
    p_cam = np.einsum("mij,mj->mi", Rc, p_ref) + ext[obs.camera, 3:]
    return (project(p_cam, intr[obs.camera]) - obs.pixels).ravel()


def _sparsity(obs: Observations, n_cam: int, n_view: int):
    m = len(obs.camera)
    ni = n_cam * _NF
    n = ni + 6 * (n_cam - 1) + 6 * n_view
    A = lil_matrix((2 * m, n), dtype=np.int8)
    rows = np.arange(m)
    for k in range(2):
        r = 2 * rows + k
        for j in range(_NF):
            A[r, obs.camera * _NF + j] = 1
        moving = obs.camera > 0
        for j in range(6):
            A[r[moving], ni + 6 * (obs.camera[moving] - 1) + j] = 1
            A[r, ni + 6 * (n_cam - 1) + 6 * obs.view + j] = 1
    return A


def bundle_adjust(
    obs: Observations,
    intrinsics: np.ndarray,
    rvecs: np.ndarray,
    tvecs: np.ndarray,
    board_rvecs: np.ndarray,
    board_tvecs: np.ndarray,
) -> BundleResult:
    """Refine every camera and board pose to minimise the corners' reprojection error.

    Parameters
    ----------
    obs : Observations
    intrinsics : (C, 8) ndarray
        Starting intrinsics.
    rvecs, tvecs : (C, 3) ndarray
        Starting reference → camera poses (row 0 is held at zero).
    board_rvecs, board_tvecs : (V, 3) ndarray
        Starting board → reference poses.
    """
    n_cam, n_view = len(intrinsics), len(board_rvecs)
    fixed = np.array(intrinsics, float)
    fixed[:, [i for i in range(N_INTRINSICS) if i not in FREE_INTRINSICS]] = 0.0
    x0 = np.concatenate(
        [
            fixed[:, FREE_INTRINSICS].ravel(),
            np.hstack([rvecs, tvecs])[1:].ravel(),
            np.hstack([board_rvecs, board_tvecs]).ravel(),
        ]
    )
    sol = least_squares(
        _residuals,
        x0,
        jac_sparsity=_sparsity(obs, n_cam, n_view),
        loss="soft_l1",
        f_scale=LOSS_SCALE_PX,
        x_scale="jac",
        method="trf",
        args=(obs, n_cam, n_view, fixed),
        ftol=1e-7,
        max_nfev=60,
    )
    intr, ext, views = _unpack(sol.x, n_cam, n_view, fixed)
    return BundleResult(
        intr.copy(),
        rodrigues(ext[:, :3]),
        ext[:, 3:].copy(),
        rodrigues(views[:, :3]),
        views[:, 3:].copy(),
        _residuals(sol.x, obs, n_cam, n_view, fixed).reshape(-1, 2),
    )
