"""How far a limb segment leaves the image plane, from its image length.

A segment of length ``L`` whose image is ``l`` metres long at its depth
leaves the image plane by the fraction ``q = sqrt(1 − (l/L)²)`` of its length
(the sine of its angle to the plane).  The keypoint model's world landmarks
give that fraction too, but badly for arms: on the renders of the built-in
phrases their arm depth follows the truth with a regression slope of only
0.1–0.4, and BlazePose leans forearms 10–20° towards the camera.  Near the
image plane the 2D evidence against such a lean is of second order
(``1 − cos 20° = 6 %`` of the length), so the continuous fit keeps whatever
out-of-plane amount its starting pose and direction targets carry: an arm
bent up at the side reads as forward-up, a hanging arm as forward low.

:func:`bound_depth` therefore keeps the world landmarks' depth fraction only
within the band the image length allows, given a relative uncertainty
``eps`` of ``l / L``.  ``eps`` sums what is not known exactly: the per-clip
segment length (~5 %, the spread of limb-to-height ratios between adults
and of our estimate), the performer's depth (~3 %, ±0.1 m at 3–4 m) and the
landmark's placement on the joint (a few pixels, ~3 % of a 60 px upper arm);
added in quadrature ≈ 7 %, rounded up to 10 %.  Near the plane the band is
wide (its width grows as ``1/q``), so the world landmarks still decide there
whenever the image cannot; far from the plane the image length decides.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EPS", "bound_depth", "depth_band"]

#: Relative uncertainty of a segment's image length over its length (see the module docstring).
EPS = 0.10


def depth_band(ratio: np.ndarray, eps: float = EPS) -> tuple[np.ndarray, np.ndarray]:
    """The out-of-plane fractions a segment may have given its image-length ratio.

    Parameters
    ----------
    ratio : (...) ndarray
        Image length (metres at the segment's depth) over the segment's length;
        NaN where not measured.
    eps : float
        Relative uncertainty of `ratio`.

    Returns
    -------
    lo, hi : (...) ndarray
        Bounds of ``|d_z| / |d|`` (0 and 1 where `ratio` is NaN).
    """
    ratio = np.asarray(ratio, float)
    known = np.isfinite(ratio)
    r = np.where(known, ratio, 0.0)
    lo = np.sqrt(np.clip(1.0 - (r * (1.0 + eps)) ** 2, 0.0, 1.0))
    hi = np.sqrt(np.clip(1.0 - (r * (1.0 - eps)) ** 2, 0.0, 1.0))
    return np.where(known, lo, 0.0), np.where(known, hi, 1.0)


def bound_depth(d: np.ndarray, ratio: np.ndarray, eps: float = EPS, side: np.ndarray | None = None) -> np.ndarray:
    """Segment vectors whose depth fraction is brought into the band of their image length.

    The depth component keeps its sign; the image-plane part keeps its
    direction and is rescaled so the vector keeps its length.

    Parameters
    ----------
    d : (T, 3) ndarray
        Segment vectors, camera-aligned axes (z away from the camera); NaN
        rows pass through.
    ratio : (T,) ndarray
        Image length over segment length (see :func:`depth_band`).
    eps : float
    side : (T,) ndarray, optional
        Sign of the depth (+1 away from the camera) for vectors lying exactly
        in the image plane that must leave it; default away.

    Returns
    -------
    (T, 3) ndarray
    """
    d = np.asarray(d, float)
    n = np.linalg.norm(d, axis=-1)
    ok = np.isfinite(n) & (n > 1e-9) & np.isfinite(ratio)
    lo, hi = depth_band(ratio, eps)
    safe = np.where(ok, n, 1.0)
    uz = np.where(ok, d[:, 2], 0.0) / safe
    new_z = np.sign(uz) * np.clip(np.abs(uz), lo, hi)
    # A segment exactly in the plane that must leave it goes to `side`.
    default = np.ones_like(uz) if side is None else np.where(np.asarray(side) < 0, -1.0, 1.0)
    new_z = np.where(uz == 0.0, default * lo, new_z)
    plane = np.where(ok[:, None], d[:, :2], 0.0)
    pn = np.linalg.norm(plane, axis=-1)
    scale = np.sqrt(np.maximum(1.0 - new_z**2, 0.0)) * safe / np.maximum(pn, 1e-12)
    out = np.concatenate([plane * scale[:, None], (new_z * safe)[:, None]], axis=1)
    out = np.where((pn > 1e-12)[:, None], out, np.concatenate([plane, (new_z * safe)[:, None]], axis=1))
    return np.where(ok[:, None], out, d)
