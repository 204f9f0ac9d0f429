"""ChArUco boards: OpenCV's board object and the corners it finds in an image or a clip.

Board coordinates are OpenCV's: metres, origin at the chessboard's top-left
outer corner, x along the columns, y along the rows (down the printed page),
z = x × y into the board.  Corner ``i`` is
``board.getChessboardCorners()[i]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import CalibrationError
from ..io.calibration import Board
from ..io.video import iter_frames, probe

__all__ = [
    "MIN_CORNERS",
    "BoardDetections",
    "cv_board",
    "detect_clip",
    "detect_image",
    "detect_images",
    "object_points",
]

#: Fewest ChArUco corners a view must have to be used: a homography needs 4,
#: and fewer than 6 corners of a 24-corner board leave its pose ill-conditioned.
MIN_CORNERS = 6


#: Half-size, pixels, of the window in which each ChArUco corner is refined
#: again after OpenCV's detector (``cornerSubPix``): a 5 × 5 window keeps to
#: the corner's own two squares when they are only 15-20 px wide, as a
#: whole-body camera sees a poster board; on rendered boards it cut the
#: corners' RMS error from 0.15-0.17 px to 0.10-0.11 px (wider windows: 0.15-0.20).
REFINE_HALF_WINDOW_PX = 2
_REFINE_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)


def cv_board(board: Board):
    """OpenCV's ``CharucoBoard`` for `board` (a one-line error for an unknown dictionary)."""
    name = board.dictionary
    code = getattr(cv2.aruco, name, None)
    if not isinstance(code, int):
        raise CalibrationError(f"--dict {name!r} is not an OpenCV ArUco dictionary (e.g. DICT_4X4_250)")
    dictionary = cv2.aruco.getPredefinedDictionary(code)
    cols, rows = board.squares
    n_markers = (cols * rows) // 2
    if n_markers > dictionary.bytesList.shape[0]:
        raise CalibrationError(
            f"board {cols}x{rows} needs {n_markers} markers; {name} has {dictionary.bytesList.shape[0]}"
        )
    return cv2.aruco.CharucoBoard((cols, rows), board.square, board.marker, dictionary)


def object_points(board: Board) -> np.ndarray:
    """Board coordinates of the inner chessboard corners, metres, ``(N, 3)`` (z = 0)."""
    return np.asarray(cv_board(board).getChessboardCorners(), float).reshape(-1, 3)


def _detector(board: Board):
    return cv2.aruco.CharucoDetector(cv_board(board))


def detect_image(image: np.ndarray, board: Board, detector=None) -> tuple[np.ndarray, np.ndarray]:
    """ChArUco corners in one image.

    Parameters
    ----------
    image : (H, W, 3) or (H, W) uint8 ndarray
    board : Board
    detector : cv2.aruco.CharucoDetector, optional
        Reused between frames.

    Returns
    -------
    ids : (n,) int ndarray
        Corner numbers (rows of :func:`object_points`); empty when fewer than
        :data:`MIN_CORNERS` were found.
    corners : (n, 2) float ndarray
        Sub-pixel positions, pixels (OpenCV: pixel centres at integers).
    """
    det = detector if detector is not None else _detector(board)
    grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    corners, ids, _, _ = det.detectBoard(grey)
    if ids is None or len(ids) < MIN_CORNERS:
        return np.zeros(0, int), np.zeros((0, 2))
    w = REFINE_HALF_WINDOW_PX
    refined = cv2.cornerSubPix(
        grey, np.asarray(corners, np.float32).reshape(-1, 1, 2), (w, w), (-1, -1), _REFINE_CRITERIA
    )
    return np.asarray(ids, int).ravel(), np.asarray(refined, float).reshape(-1, 2)


@dataclass(frozen=True)
class BoardDetections:
    """The board as one camera saw it over a clip.

    Attributes
    ----------
    source : str
        The clip (for messages).
    image_size : (int, int)
        (width, height), pixels.
    fps : float
    n_frames : int
        Frames examined.
    frames : (F,) int ndarray
        Frame numbers with the board found (at least :data:`MIN_CORNERS`).
    ids : list of (n_f,) int ndarray
        Corner numbers per such frame.
    corners : list of (n_f, 2) ndarray
        Pixels per such frame.
    """

    source: str
    image_size: tuple[int, int]
    fps: float
    n_frames: int
    frames: np.ndarray
    ids: list
    corners: list

    def view(self, frame: int) -> tuple[np.ndarray, np.ndarray] | None:
        """(ids, corners) of `frame`, or None where the board was not found."""
        k = np.searchsorted(self.frames, frame)
        if k < len(self.frames) and self.frames[k] == frame:
            return self.ids[k], self.corners[k]
        return None


def detect_images(
    images, board: Board, source: str = "<images>", fps: float = 25.0, image_size=None
) -> BoardDetections:
    """:class:`BoardDetections` of an iterable of (frame number, image) pairs."""
    det = _detector(board)
    frames, ids, corners = [], [], []
    n = 0
    size = image_size
    for index, image in images:
        n += 1
        size = size or (image.shape[1], image.shape[0])
        i, c = detect_image(image, board, det)
        if len(i):
            frames.append(int(index))
            ids.append(i)
            corners.append(c)
    if size is None:
        raise CalibrationError(f"{source}: no frames")
    return BoardDetections(source, (int(size[0]), int(size[1])), float(fps), n, np.array(frames, int), ids, corners)


def detect_clip(video, board: Board, step: int = 1) -> BoardDetections:
    """Find the board in every `step`-th frame of `video`.

    Raises
    ------
    CalibrationError
        The board is never found (names the clip and the board).
    VideoError
        The clip cannot be read.
    """
    path = Path(video)
    info = probe(path)
    frames = ((f.index, f.image) for f in iter_frames(path) if f.index % step == 0)
    out = detect_images(frames, board, str(path), info.fps, info.image_size)
    if len(out.frames) == 0:
        cols, rows = board.squares
        raise CalibrationError(
            f"{path}: the ChArUco board ({cols}x{rows}, {board.square:g} m squares, {board.marker:g} m markers, "
            f"{board.dictionary}) was found in none of its {out.n_frames} frames; check --board, --square, "
            "--marker and --dict"
        )
    return out
