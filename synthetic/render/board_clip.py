"""Calibration clips: a ChArUco board moved through the space, seen by each camera.

OpenCV draws the board (``CharucoBoard.generateImage``); each frame warps it
into the camera with the homography of its pose (rendered at twice the size
and area-averaged down, so its edges are anti-aliased like the dancer's),
over the empty stage of :func:`.scene.floor_background`.  The board's path:
standing upright on the floor at the origin, facing the cameras
(:data:`FLOOR_S`: what fixes the calibrated world), then a sequence of random poses — tilted, near
and far, every other one seen by all cameras, the others near one camera's
image edge, partly out of its frame — each held :data:`HOLD_S` and reached in :data:`MOVE_S` — with
motion blur while it moves and pixel noise on every frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from capture2notation.calibrate import cv_board, floor_frame
from capture2notation.errors import SyntheticError
from capture2notation.io.calibration import Board

from .camera import Camera
from .scene import floor_background
from .video import open_writer

__all__ = ["BOARD", "FLOOR_MARGIN", "BoardPath", "board_frame", "board_path", "floor_origin", "render_board_clip"]

#: The board the renderer moves: 7 × 5 squares of 12 cm (an 84 × 60 cm
#: poster).  An A4 board's 4-cm squares are 7 px wide at the 3.8-m distance of
#: a 640 × 480 camera framing a whole body, too few for its markers.
BOARD = Board((7, 5), 0.12, 0.09, "DICT_4X4_50")
#: Seconds the board lies on the floor at the start.
FLOOR_S = 1.0
#: Seconds each pose is held, and taken to reach the next.
HOLD_S, MOVE_S = 0.3, 0.4
#: Board poses after the floor.  Each held pose's corner errors repeat in
#: all its frames (the same rendering, new sensor noise only), so the poses,
#: not the frames, are the independent views; with too few the focal length
#: trades against the cameras' distance (only their ratio is well seen from
#: a board 2-5 m away): 16 poses left the focal lengths 0.3-0.45 % long and
#: the camera centres 1.3-1.7 cm too far, 48 poses 0.13 % and 0.5-0.6 cm
#: (front + 45, seed 0; a 35-s clip, as long as a calibration video by hand).
N_POSES = 48
#: Largest angle, degrees, between the board's normal and the line to a
#: camera: beyond it the markers are too foreshortened to read.
MAX_INCIDENCE_DEG = 55.0
#: The board's white border below the chessboard, in squares: the board
#: stands on it at the start (``c2n calibrate --margin``, metres).
FLOOR_MARGIN = 0.5
#: Pixels the board's outline keeps from the image edge.
EDGE_MARGIN_PX = 12
#: Space the board's centre moves in, metres (the performer's space).
SPACE = ((-1.0, 1.0), (-1.0, 1.0), (0.5, 1.7))
#: Largest tilt of the board away from facing the cameras, and in-plane turn, degrees.
MAX_TILT_DEG, MAX_SPIN_DEG = 45.0, 30.0
#: Distance range, metres, of the poses shown to one camera near its image edge.
EDGE_DEPTH_M = (1.8, 4.0)
#: Least fraction of the board's corners such a pose keeps in the image.
MIN_SEEN_FRACTION = 0.6
#: Supersampling factor of the warp.
SUPERSAMPLE = 2
#: Pixel noise, standard deviation in grey levels (a phone's sensor noise at
#: indoor light, before compression).
NOISE_SD = 1.5
#: Exposure as a fraction of the frame interval (motion blur while moving).
EXPOSURE = 0.5
#: Board image resolution, pixels per square.
_PX_PER_SQUARE = 60


@dataclass(frozen=True)
class BoardPath:
    """Keyframes of the board: board → world poses and the times they are held from."""

    R: np.ndarray  # (P, 3, 3)
    p: np.ndarray  # (P, 3) board origin in the world, metres
    board: Board

    @property
    def seconds(self) -> float:
        return FLOOR_S + (len(self.R) - 1) * (HOLD_S + MOVE_S)

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Board → world (R, p) at time `t` seconds."""
        if t <= FLOOR_S:
            return self.R[0], self.p[0]
        k, u = divmod(t - FLOOR_S, HOLD_S + MOVE_S)
        k = int(k)
        if k + 1 >= len(self.R):
            return self.R[-1], self.p[-1]
        s = min(1.0, u / MOVE_S)
        s = s * s * (3 - 2 * s)  # smoothstep: the hand starts and stops gently
        rot = Slerp([0.0, 1.0], Rotation.from_matrix(self.R[k : k + 2]))(s).as_matrix()
        return rot, (1 - s) * self.p[k] + s * self.p[k + 1]


def floor_origin(cameras: list[Camera]) -> tuple[float, float, float]:
    """Where the board stands at the start: (x, y, yaw°) for :func:`floor_frame`.

    Upright at the origin (the performer's spot), its face turned towards the
    cameras' mean azimuth, so the calibrated world is the renderer's.
    """
    mean = np.mean([c.position for c in cameras], axis=0)
    azimuth = math.degrees(math.atan2(mean[0], mean[1]))  # clockwise from +y
    return 0.0, 0.0, -azimuth


def _corners(board: Board) -> np.ndarray:
    w, h = board.squares[0] * board.square, board.squares[1] * board.square
    return np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0.0]])


def _visible(R, p, board: Board, cameras: list[Camera], max_incidence: float = MAX_INCIDENCE_DEG) -> bool:
    world = _corners(board) @ R.T + p
    centre = world.mean(axis=0)
    normal = -R[:, 2]  # the printed face looks along −z of the board
    for cam in cameras:
        to_cam = cam.position - centre
        cos = normal @ to_cam / np.linalg.norm(to_cam)
        if cos < math.cos(math.radians(max_incidence)):
            return False
        uv = cam.project(world)
        w, h = cam.size
        m = EDGE_MARGIN_PX
        if not (np.all(np.isfinite(uv)) and np.all((uv >= m) & (uv <= np.array([w - m, h - m])))):
            return False
    return True


def _facing(direction, rng: np.random.Generator) -> np.ndarray:
    """Board → world rotation facing horizontal `direction`, then randomly tilted and turned."""
    face = np.array([direction[0], direction[1], 0.0])
    z = -face / np.linalg.norm(face)  # board z points into the board, away from the viewer
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)  # board y runs down the printed page
    R = np.stack([x, y, z], axis=1)
    spin = Rotation.from_rotvec(z * math.radians(rng.uniform(-MAX_SPIN_DEG, MAX_SPIN_DEG)))
    axis = rng.normal(size=3)
    axis -= (axis @ z) * z
    tilt = Rotation.from_rotvec(axis / np.linalg.norm(axis) * math.radians(rng.uniform(0, MAX_TILT_DEG)))
    return (tilt * spin).as_matrix() @ R


def _partly_seen(R, p, board: Board, cam: Camera) -> bool:
    """At least :data:`MIN_SEEN_FRACTION` of the inner corners inside `cam`'s image, face towards it."""
    from capture2notation.calibrate import object_points

    world = object_points(board) @ R.T + p
    to_cam = cam.position - world.mean(axis=0)
    if -R[:, 2] @ to_cam / np.linalg.norm(to_cam) < math.cos(math.radians(MAX_INCIDENCE_DEG)):
        return False
    uv = cam.project(world)
    w, h = cam.size
    m = EDGE_MARGIN_PX
    inside = np.isfinite(uv).all(axis=1) & np.all((uv >= m) & (uv <= np.array([w - m, h - m])), axis=1)
    return bool(inside.mean() >= MIN_SEEN_FRACTION)


def board_path(
    cameras: list[Camera], rng: np.random.Generator, board: Board = BOARD, n_poses: int = N_POSES
) -> BoardPath:
    """A random path of the board: on the floor, then `n_poses` keyframes.

    Every other keyframe every camera sees whole; the others one camera sees
    near its image edge.

    Raises
    ------
    SyntheticError
        No pose every camera sees (cameras facing away from each other).
    """
    M, o = floor_frame(board, floor_origin(cameras), "standing", FLOOR_MARGIN * board.square)
    if not _visible(M, o, board, cameras):
        raise SyntheticError("the cameras do not all see the floor in front of them; place them round one space")
    Rs, ps = [M], [o]
    mean = np.mean([c.position for c in cameras], axis=0)
    centre_b = _corners(board).mean(axis=0)
    tries = 0
    while len(Rs) < n_poses + 1:
        tries += 1
        if tries > 20000:
            raise SyntheticError("found no board pose every camera sees; are the cameras round one space?")
        if len(Rs) % 2 == 0:
            # A pose near one camera's image edge, seen by it alone (ChArUco corners
            # are read from a partial view): what pins its principal point and lens.
            cam = cameras[int(rng.integers(len(cameras)))]
            uv = rng.uniform([0, 0], cam.size)
            ray = cam.R.T @ np.linalg.solve(cam.K, [uv[0], uv[1], 1.0])
            c = cam.position + rng.uniform(*EDGE_DEPTH_M) * ray / np.linalg.norm(ray)
            R = _facing(cam.position - c, rng)
            p = c - R @ centre_b
            if _partly_seen(R, p, board, cam) and np.all((_corners(board) @ R.T + p)[:, 2] > 0.05):
                Rs.append(R)
                ps.append(p)
            continue
        c = np.array([rng.uniform(*SPACE[0]), rng.uniform(*SPACE[1]), rng.uniform(*SPACE[2])])
        R = _facing(mean - c, rng)
        p = c - R @ centre_b
        if _visible(R, p, board, cameras):
            Rs.append(R)
            ps.append(p)
    return BoardPath(np.array(Rs), np.array(ps), board)


class _BoardImage:
    def __init__(self, board: Board):
        cols, rows = board.squares
        self.margin = int(round(FLOOR_MARGIN * _PX_PER_SQUARE))
        size = (cols * _PX_PER_SQUARE + 2 * self.margin, rows * _PX_PER_SQUARE + 2 * self.margin)
        img = cv_board(board).generateImage(size, marginSize=self.margin)
        self.image = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
        s = board.square / _PX_PER_SQUARE
        # board image pixel (centres at integers) → board coordinates, metres
        self.S = np.array([[s, 0, (0.5 - self.margin) * s], [0, s, (0.5 - self.margin) * s], [0, 0, 1.0]])


def board_frame(
    camera: Camera, poses: list, background: np.ndarray, image: _BoardImage, rng: np.random.Generator
) -> np.ndarray:
    """One frame: the board at each of `poses` (sub-frame samples, averaged: motion blur) over `background`."""
    a = SUPERSAMPLE
    w, h = camera.size
    A = np.array([[a, 0, (a - 1) / 2], [0, a, (a - 1) / 2], [0, 0, 1.0]])
    acc = np.zeros((h, w, 3))
    for R_wb, p_wb in poses:
        Rc = camera.R @ R_wb
        H = camera.K @ np.column_stack([Rc[:, 0], Rc[:, 1], camera.R @ p_wb + camera.t])
        Hs = A @ H @ image.S
        big = cv2.warpPerspective(image.image, Hs, (a * w, a * h), flags=cv2.INTER_LINEAR)
        mask = cv2.warpPerspective(
            np.ones(image.image.shape[:2], np.float32), Hs, (a * w, a * h), flags=cv2.INTER_LINEAR
        )
        small = cv2.resize(big, (w, h), interpolation=cv2.INTER_AREA).astype(float)
        alpha = cv2.resize(mask, (w, h), interpolation=cv2.INTER_AREA)[..., None]
        acc += background * (1 - alpha) + small * alpha
    frame = acc / len(poses) + rng.normal(0.0, NOISE_SD, acc.shape)
    return np.clip(np.round(frame), 0, 255).astype(np.uint8)


def render_board_clip(
    camera: Camera, path: BoardPath, out, fps: float, rng: np.random.Generator, offset_s: float = 0.0
) -> Path:
    """Write the calibration clip `out` (``.mp4``) of the board following `path`, seen by `camera`.

    Frame ``i`` shows the board at ``i / fps + offset_s`` seconds; while the
    board moves, three poses over :data:`EXPOSURE` of the frame interval are
    averaged (motion blur).
    """
    if not (np.isfinite(fps) and fps > 0):
        raise SyntheticError(f"fps {fps!r} must be positive")
    image = _BoardImage(path.board)
    background = floor_background(camera).astype(float)
    n = int(math.ceil(path.seconds * fps))
    out = Path(out)
    with open_writer(out, fps, camera.size) as writer:
        for i in range(n):
            t = i / fps + offset_s
            times = t + np.array([-0.5, 0.0, 0.5]) * EXPOSURE / fps
            poses = [path.at(float(s)) for s in times]
            if np.allclose(poses[0][1], poses[-1][1], atol=1e-6) and np.allclose(poses[0][0], poses[-1][0], atol=1e-9):
                poses = poses[1:2]
            writer.write(board_frame(camera, poses, background, image, rng))
    return out
