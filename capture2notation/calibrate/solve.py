"""Calibrate two or more cameras from their clips of a moving ChArUco board.

1. Intrinsics with distortion per camera (OpenCV ``calibrateCamera`` on up
   to :data:`MAX_INTRINSIC_VIEWS` views spread over the clip), and the
   board's pose in every view (``solvePnP``, IPPE).
2. Each camera's pose relative to the first from the views it shares with a
   camera already placed (the clips are taken to be synchronised frame by
   frame; a rotation mean and a median translation over the shared views).
3. Bundle adjustment of every camera and board pose (:mod:`.bundle`).
4. The world frame from the floor: the clips start with the board still,
   standing upright on its lower edge on the floor (or lying face up on it,
   ``floor="lying"``) where every camera sees it; the first view two
   cameras share is that board, and the world is fixed by it (z up, the
   floor at z = 0; :func:`floor_frame`).  Cameras at chest height see a
   board lying on the floor too obliquely for its markers at 640 × 480,
   hence the standing board by default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..errors import CalibrationError
from ..io.calibration import Board, Calibration, CameraCalibration
from .board import BoardDetections, object_points
from .bundle import N_INTRINSICS, Observations, bundle_adjust

__all__ = [
    "FLOOR_POSES",
    "MAX_INTRINSIC_VIEWS",
    "MAX_RMS_PX",
    "MAX_VIEWS",
    "CalibrationResult",
    "calibrate_cameras",
    "floor_frame",
]

#: Views per camera given to ``calibrateCamera`` for the starting intrinsics
#: (spread over the clip; more add time, not accuracy, before the bundle).
MAX_INTRINSIC_VIEWS = 40
#: Board views (moments) in the bundle adjustment, spread over the clips.
MAX_VIEWS = 120
#: Fewest views a camera needs for its intrinsics (OpenCV needs 3 planar views
#: of different tilts; one more to spare).
MIN_VIEWS = 4
#: Frames whose board pose is within this of the first shared view's (metres,
#: degrees; a single view's pose scatters by millimetres and tenths of a
#: degree) belong to the board still on the floor, fitted as one pose.
STILL_M, STILL_DEG = 0.01, 1.0
#: Largest difference between two clips' frame rates taken as equal, fps
#: (containers round 25 to 25.0000x).
FPS_TOL = 0.01
#: Largest acceptable reprojection RMS, pixels: a sound ChArUco calibration is
#: well under one pixel; several pixels mean a wrong board, unsynchronised
#: clips or a moving camera.
MAX_RMS_PX = 3.0


@dataclass(frozen=True)
class CalibrationResult:
    """A calibration and how well it fits.

    Attributes
    ----------
    calibration : Calibration
    rms_px : dict of str to float
        Reprojection RMS per camera, pixels (root mean square corner distance).
    views : dict of str to int
        Board views of each camera in the bundle adjustment.
    shared_views : int
        Views seen by two or more cameras.
    """

    calibration: Calibration
    rms_px: dict
    views: dict
    shared_views: int


def _spread(items: np.ndarray, n: int) -> np.ndarray:
    if len(items) <= n:
        return items
    return items[np.round(np.linspace(0, len(items) - 1, n)).astype(int)]


def _intrinsics(det: BoardDetections, obj: np.ndarray) -> np.ndarray:
    """(8,) fx, fy, cx, cy, k1, k2, p1, p2 from up to MAX_INTRINSIC_VIEWS views."""
    counts = np.array([len(i) for i in det.ids])
    good = np.flatnonzero(counts >= 2 * 4)
    if len(good) < MIN_VIEWS:
        raise CalibrationError(
            f"{det.source}: the board is well seen in only {len(good)} frames; {MIN_VIEWS} are needed "
            "(move it through the space, tilted, near and far)"
        )
    pick = _spread(good, MAX_INTRINSIC_VIEWS)
    objs = [obj[det.ids[k]].astype(np.float32) for k in pick]
    imgs = [det.corners[k].astype(np.float32) for k in pick]
    flags = cv2.CALIB_FIX_K3 | cv2.CALIB_ZERO_TANGENT_DIST
    try:
        _, K, dist, _, _ = cv2.calibrateCamera(objs, imgs, det.image_size, None, None, flags=flags)
    except cv2.error as exc:
        raise CalibrationError(f"{det.source}: OpenCV could not calibrate the camera: {exc.err}") from None
    d = np.asarray(dist, float).ravel()
    return np.array([K[0, 0], K[1, 1], K[0, 2], K[1, 2], d[0], d[1], d[2], d[3]])


def _K_dist(intr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    K = np.array([[intr[0], 0, intr[2]], [0, intr[1], intr[3]], [0, 0, 1.0]])
    return K, np.array([intr[4], intr[5], intr[6], intr[7], 0.0])


def _poses(det: BoardDetections, obj: np.ndarray, intr: np.ndarray) -> dict:
    """Frame → (R, t) board → camera, by PnP."""
    K, dist = _K_dist(intr)
    out = {}
    for f, ids, px in zip(det.frames, det.ids, det.corners):
        ok, rvec, tvec = cv2.solvePnP(obj[ids], px, K, dist, flags=cv2.SOLVEPNP_IPPE)
        if ok:
            out[int(f)] = (cv2.Rodrigues(rvec)[0], np.asarray(tvec, float).ravel())
    return out


def _mean_rotation(Rs: list) -> np.ndarray:
    U, _, Vt = np.linalg.svd(np.sum(Rs, axis=0))
    R = U @ Vt
    return R if np.linalg.det(R) > 0 else U @ np.diag([1, 1, -1]) @ Vt


def _relative(pose_c: dict, pose_p: dict, shared) -> tuple[np.ndarray, np.ndarray]:
    """Camera p frame → camera c frame from the board views both saw."""
    Rs, ts = [], []
    for f in shared:
        (Rc, tc), (Rp, tp) = pose_c[f], pose_p[f]
        R = Rc @ Rp.T
        Rs.append(R)
        ts.append(tc - R @ tp)
    R = _mean_rotation(Rs)
    return R, np.median(np.array(ts), axis=0)


#: How the board stands at the clips' start to fix the world: upright on its
#: lower edge (seen well by cameras at chest height) or lying face up.
FLOOR_POSES = ("standing", "lying")


def _still_start(shared_frames: list, poses: list, seen: dict) -> list:
    """The first shared frame and the shared frames after it while the board stays still there."""
    first = shared_frames[0]
    c = seen[first][0]
    R0, t0 = poses[c][first]
    run = [first]
    for f in shared_frames[1:]:
        if c not in seen[f]:
            break
        R, t = poses[c][f]
        angle = math.degrees(math.acos(np.clip((np.trace(R @ R0.T) - 1) / 2, -1.0, 1.0)))
        if np.linalg.norm(t - t0) > STILL_M or angle > STILL_DEG:
            break
        run.append(f)
    return run


def floor_frame(
    board: Board, origin=(0.0, 0.0, 0.0), pose: str = "standing", margin: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """World-from-board transform of the board that fixes the world.

    Parameters
    ----------
    board : Board
    origin : (x, y, yaw) floats
        ``standing``: the floor point below the chessboard's centre, metres,
        and the angle of the printed face's normal from world +y, degrees
        anticlockwise seen from above (0: the face looks along +y, towards a
        front camera).  ``lying``: the chessboard's centre, and the angle from
        world +x to its columns.
    pose : {"standing", "lying"}
        Upright on its lower edge, or face up on the floor.
    margin : float
        ``standing``: height of the chessboard's lower edge above the floor
        (the board's border below it), metres.

    Returns
    -------
    M : (3, 3) ndarray
        ``X_world = M @ X_board + o`` (board: x along the columns, y down the
        page, z into the board).
    o : (3,) ndarray
    """
    if pose not in FLOOR_POSES:
        raise CalibrationError(f"--floor {pose!r} is not one of {', '.join(FLOOR_POSES)}")
    x, y, yaw = (float(v) for v in origin)
    c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    w, h = board.squares[0] * board.square, board.squares[1] * board.square
    if pose == "lying":
        M = Rz @ np.diag([1.0, -1.0, -1.0])
        return M, np.array([x, y, 0.0]) - M @ np.array([w / 2, h / 2, 0.0])
    # Seen from +y: the columns run to world −x, the page's down is −z, into the board is −y.
    M = Rz @ np.array([[-1.0, 0, 0], [0, 0, -1.0], [0, -1.0, 0]])
    return M, np.array([x, y, float(margin)]) - M @ np.array([w / 2, h, 0.0])


def calibrate_cameras(
    detections: list[BoardDetections],
    names: list[str],
    board: Board,
    origin=(0.0, 0.0, 0.0),
    floor: str = "standing",
    margin: float = 0.0,
) -> CalibrationResult:
    """Calibrate every camera from its board detections (the clips synchronised by frame number).

    Parameters
    ----------
    detections : list of BoardDetections
        One per camera, at least two.
    names : list of str
        Camera names, in the same order.
    board : Board
    origin : (x, y, yaw)
    floor : {"standing", "lying"}
    margin : float
        See :func:`floor_frame`.

    Raises
    ------
    CalibrationError
        Fewer than two cameras, clips of different frame rates, a camera that
        never sees the board together with the others, too few views, or a
        fit above :data:`MAX_RMS_PX`.
    """
    if len(detections) < 2:
        raise CalibrationError(f"calibration needs two or more clips, got {len(detections)}")
    if len(set(names)) != len(names):
        raise CalibrationError(f"two clips have the same camera name: {', '.join(names)}")
    for d in detections[1:]:
        if abs(d.fps - detections[0].fps) > FPS_TOL:
            raise CalibrationError(
                f"{d.source}: frame rate {d.fps:g} fps differs from {detections[0].source}'s "
                f"{detections[0].fps:g} fps; the calibration pairs the clips frame by frame (film at one rate)"
            )
    obj = object_points(board)
    intr = np.array([_intrinsics(d, obj) for d in detections])
    poses = [_poses(d, obj, i) for d, i in zip(detections, intr)]
    n_cam = len(detections)
    # Place the cameras one by one, each from the placed camera it shares most views with.
    R_ext: dict[int, np.ndarray] = {0: np.eye(3)}
    t_ext: dict[int, np.ndarray] = {0: np.zeros(3)}
    while len(R_ext) < n_cam:
        best = None
        for c in range(n_cam):
            if c in R_ext:
                continue
            for p in R_ext:
                shared = sorted(set(poses[c]) & set(poses[p]))
                if best is None or len(shared) > len(best[2]):
                    best = (c, p, shared)
        assert best is not None
        c, p, shared = best
        if not shared:
            lost = [names[k] for k in range(n_cam) if k not in R_ext]
            raise CalibrationError(
                f"{detections[c].source}: camera {', '.join(lost)} never sees the board in the same frame as "
                f"{', '.join(names[k] for k in R_ext)}; film the board where the cameras see it together"
            )
        R, t = _relative(poses[c], poses[p], shared)
        R_ext[c], t_ext[c] = R @ R_ext[p], R @ t_ext[p] + t
    # Board views: moments seen by any camera, spread over the clip.
    seen: dict[int, list[int]] = {}
    for c, pc in enumerate(poses):
        for f in pc:
            seen.setdefault(f, []).append(c)
    shared_frames = sorted(f for f, cs in seen.items() if len(cs) >= 2)
    still = _still_start(shared_frames, poses, seen)
    rest = np.array([f for f in sorted(seen) if f not in still])
    shared_rest = np.array([f for f in shared_frames if f not in still])
    keep = set(_spread(rest, MAX_VIEWS).tolist()) | set(_spread(shared_rest, MAX_VIEWS // 2).tolist())
    # View 0 is the board on the floor: every frame of its still start, one pose.
    groups = [still] + [[f] for f in sorted(keep)]
    b_rvec, b_tvec = np.zeros((len(groups), 3)), np.zeros((len(groups), 3))
    cams, views, pts, pix = [], [], [], []
    for v, group in enumerate(groups):
        f0 = group[0]
        cs = seen[f0]
        c0 = max(cs, key=lambda c: len(detections[c].view(f0)[0]))  # type: ignore[index]
        Rb, tb = poses[c0][f0]
        # board → ref = (ref → c0)⁻¹ ∘ (board → c0)
        b_rvec[v] = cv2.Rodrigues(R_ext[c0].T @ Rb)[0].ravel()
        b_tvec[v] = R_ext[c0].T @ (tb - t_ext[c0])
        for f in group:
            for c in seen[f]:
                got = detections[c].view(f)
                assert got is not None
                ids, px = got
                cams.append(np.full(len(ids), c))
                views.append(np.full(len(ids), v))
                pts.append(obj[ids])
                pix.append(px)
    obs = Observations(np.concatenate(cams), np.concatenate(views), np.concatenate(pts), np.concatenate(pix))
    rvecs = np.array([cv2.Rodrigues(R_ext[c])[0].ravel() for c in range(n_cam)])
    tvecs = np.array([t_ext[c] for c in range(n_cam)])
    res = bundle_adjust(obs, intr, rvecs, tvecs, b_rvec, b_tvec)
    # World frame from the board on the floor.
    v0 = 0
    M, o = floor_frame(board, origin, floor, margin)
    Rb, tb = res.board_R[v0], res.board_t[v0]
    out, rms, nviews = [], {}, {}
    for c, name in enumerate(names):
        sq = np.sum(res.residuals[obs.camera == c] ** 2, axis=1)
        rms[name] = float(np.sqrt(np.mean(sq)))
        nviews[name] = int(len(np.unique(obs.view[obs.camera == c])))
        Rw = res.R[c] @ Rb @ M.T
        tw = res.R[c] @ (tb - Rb @ M.T @ o) + res.t[c]
        U, _, Vt = np.linalg.svd(Rw)  # re-orthonormalise against rounding
        K, dist = _K_dist(res.intrinsics[c])
        out.append(CameraCalibration(name, detections[c].image_size, K, dist, U @ Vt, tw, rms_px=rms[name]))
    # The worst camera is named: one bad clip spreads some of its error to the
    # cameras it shares board views with through the bundle adjustment.
    for c, name in sorted(enumerate(names), key=lambda cn: -np.nan_to_num(rms[cn[1]], nan=np.inf)):
        if not rms[name] <= MAX_RMS_PX:
            raise CalibrationError(
                f"{detections[c].source}: camera {name}'s reprojection RMS is {rms[name]:.2f} px, above the "
                f"{MAX_RMS_PX:g} px a sound calibration stays under (wrong board size, unsynchronised clips "
                "or a moving camera?)"
            )
    assert N_INTRINSICS == 8
    return CalibrationResult(Calibration.of(out, board), rms, nviews, len(shared_frames))
