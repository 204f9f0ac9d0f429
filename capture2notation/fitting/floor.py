"""The performer's depth from where the feet meet the floor (known camera).

With a calibrated camera the floor is the plane z = 0, so a foot point on the
floor is where its pixel's ray meets that plane: its distance follows from
one pixel, independently of any segment length.  The figure's image size
against the model's lengths puts the performer 0.2–0.4 m off through
BlazePose (its landmarks sit inside the
silhouette, so the figure looks small and far), and every arm's
foreshortening is judged at that depth: 8 % too near makes an arm in the
image plane look 8 % too long for the model, and one that leaves the plane
by 25° look like it does not.  The floor fixes the depth to within
``Z² / (f h)`` per pixel (≈ 2 cm at 3.8 m, a camera 1 m up and 660 px
focal length).

Each foot is placed by its centre (the midpoint of its heel and toe
landmarks: BlazePose's ankle landmark sits above the joint, the toes alone
are a fifth of a body height in front of it, the heel lifts in relevé) at
its height when standing flat, and the pelvis is taken to stand above it, as
balance keeps the centre of mass over the base of support; with world
landmarks the foot's heel → toe direction moves that point back from the
foot's centre to below the ankle, where the body model stands its pelvis.  Of the two feet
:func:`support_depth` takes the lower one; frames with both feet in the air (a jump) are short, and the fit's floor
term and temporal smoothing settle them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FLOOR_POINTS", "floor_depth", "support_depth"]

#: Model targets that stand on the floor in a flat-footed stance: (heel, toe) of each foot.
FLOOR_POINTS = (("right_heel", "right_toe"), ("left_heel", "left_toe"))
_MIN_CONF = 0.5
#: Metres the floor's depth may differ from the clip-calibrated image-size
#: depth of the same frame before the frame is taken to have no foot on the
#: floor (a jump, a figure whose feet never touch it): the size depth's own
#: frame-to-frame error (its segments foreshorten), 0.3–0.5 m at 3–4 m for
#: the 90 % of frames through BlazePose.
TOL = 0.3


def floor_depth(
    cam, px: np.ndarray, conf: np.ndarray, heights: np.ndarray, pelvis_height: float, shift: np.ndarray | None = None
) -> np.ndarray:
    """Depth (camera z) of the pelvis standing above each foot, per frame.

    Parameters
    ----------
    cam : Camera
        Known camera (floor z = 0 in its world frame).
    px : (T, F, P, 2) ndarray
        Pixels of the points of each foot, e.g. heel and toe (NaN where missing).
    conf : (T, F, P) ndarray
        Their confidences.
    heights : (F,) ndarray
        Height of each foot's centre (the mean of its points) above the floor
        when standing flat, metres.
    pelvis_height : float
        The pelvis's standing height, metres.
    shift : (T, F, 3) ndarray, optional
        World vector from each foot's centre to the point of the floor below
        the pelvis (the foot's centre lies in front of the ankle); NaN or
        None: none.

    Returns
    -------
    (T, F) ndarray
        Camera-axis depth of the pelvis if it stood above that foot on the
        floor, metres; NaN where the foot is not seen or its ray does not
        reach the floor in front of the camera.
    """
    px = np.asarray(px, float)
    T, F = px.shape[:2]
    ok = np.all((np.asarray(conf) >= _MIN_CONF) & np.all(np.isfinite(px), axis=-1), axis=-1)  # (T, F)
    uv = np.nan_to_num(px.mean(axis=2))  # the foot's centre
    rays = np.concatenate([uv, np.ones((T, F, 1))], axis=-1) @ np.linalg.inv(cam.K).T @ cam.R  # world directions
    c = cam.centre
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = (np.asarray(heights, float)[None, :] - c[2]) / rays[..., 2]
    ok &= np.isfinite(lam) & (lam > 0)
    pelvis = c + np.where(ok, lam, 0.0)[..., None] * rays
    if shift is not None:
        pelvis = pelvis + np.nan_to_num(np.asarray(shift, float))
    pelvis[..., 2] = pelvis_height
    depth = cam.to_camera(pelvis)[..., 2]
    return np.where(ok & (depth > 0), depth, np.nan)


def support_depth(feet: np.ndarray, lowness: np.ndarray, size_depth: np.ndarray, tol: float | None = TOL) -> np.ndarray:
    """(T,) depth from the foot that stands on the floor.

    A foot in the air meets the floor plane somewhere else along its ray, so
    of the two feet's depths (:func:`floor_depth`) the supporting one is
    wanted: the lower foot (by the world landmarks, which see a leg lifted
    towards the camera; by the image row without them).  Frames with no
    foot take the image-size depth `size_depth`, rescaled by the clip's
    median ratio of the two (the keypoint model's figure may be smaller or
    larger than the body model, which biases the size depth by a factor).

    Parameters
    ----------
    feet : (T, F) ndarray
        Per-foot depths, NaN where not seen.
    lowness : (T, F) ndarray
        How low each foot is (larger is lower; NaN where unknown).
    size_depth : (T,) ndarray
        Depth from the figure's image size (NaN where unknown).
    tol : float or None
        Frames whose floor depth is farther than this from the calibrated
        size depth keep the latter (None: the calibrated size depth
        throughout, the floor only fixing the clip's scale).

    Returns
    -------
    (T,) ndarray
    """
    feet = np.asarray(feet, float)
    size_depth = np.asarray(size_depth, float)
    rank = np.where(np.isfinite(feet) & np.isfinite(lowness), lowness, -np.inf)
    # A foot seen on the floor but with no lowness still beats no foot at all.
    rank = np.where(np.isfinite(feet) & ~np.isfinite(lowness), -1e300, rank)
    pick = np.argmax(rank, axis=1)
    chosen = feet[np.arange(len(pick)), pick]
    both = np.isfinite(chosen) & np.isfinite(size_depth)
    if not both.any():
        return size_depth.copy()
    k = float(np.median(chosen[both] / size_depth[both]))
    ref = size_depth * k
    if tol is None:
        return ref
    # Both feet off the floor (a jump; a figure whose feet never touch it)
    # puts the floor's depth far from the figure's size: such frames keep
    # the calibrated size depth.
    out = np.where(np.abs(chosen - ref) <= tol, chosen, ref)
    return np.where(np.isfinite(chosen), np.where(np.isfinite(ref), out, chosen), ref)
