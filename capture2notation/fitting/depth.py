"""Which side of the image plane each arm segment points to: a discrete choice over time.

One view measures an arm segment's image length, so with the segment's
length its depth is known up to a sign: the elbow lies on its pixel's ray at
one of the two points a whole upper arm away from the shoulder, and the wrist
likewise from the elbow.  Each arm therefore has four candidate poses per frame
(elbow near / far × wrist near / far).  The continuous solver only refines
whichever side it starts on, and the keypoint model's world landmarks alone
get it wrong often on foreshortened arms.

:func:`choose_arm_depths` scores the candidates of every frame with evidence
a real video has and picks the sequence of minimum total cost by dynamic
programming (Viterbi):

* the world landmarks' segment directions (as the solver's direction term),
  less the depth they give the arm where the image shows it hanging
  straight (DESIGN.md's starting pose; BlazePose puts that elbow a quarter
  of the upper arm behind the shoulder on our renders, and a forward arm's
  elbow behind it too);
* the relative depth of the image landmarks (BlazePose's ``xy[..., 2]``), an
  independent estimate from the image model (less its own hanging offset);
* anatomy: the arm cannot point back and up (shoulder extension ends a
  little above the horizontal behind the body), and the elbow bends one way,
  so a bent arm's forearm leaves the upper arm towards the upper arm's front
  (give or take its twist) — the 2D shape of a bent elbow tells the side;
* temporal continuity: moving from one candidate to another between frames
  costs the 3D distance the elbow and wrist would jump.  Near the image plane
  the candidates merge and switching is free; far from it a flip is a jump of
  twice the depth, which needs strong evidence.

Where the chosen candidates are clearly apart, their side sets the sign of
the depth of the world landmarks' upper arm and forearm, so that the
starting pose and the direction prior of the fit agree with the choice.  The
magnitude stays the landmarks' only within the band the segment's image
length allows (:mod:`~capture2notation.fitting.foreshorten`): near the
image plane that band is wide (foreshortening against a model length is a
poor measure there), far from it the image length decides.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .camera import Camera
from .foreshorten import EPS, bound_depth
from .ik import _swing
from .model import PoseModel

__all__ = ["DepthOptions", "arm_candidates", "choose_arm_depths", "remove_leg_rest_offsets", "viterbi"]

#: Target names of each arm: shoulder, elbow, wrist, hand tip.
_ARMS = tuple(tuple(f"{s}_{p}" for p in ("shoulder", "elbow", "wrist", "hand_tip")) for s in ("right", "left"))
#: BlazePose landmarks of the same points (for the image landmarks' relative depth).
_ARM_LANDMARKS = ((12, 14, 16, 20), (11, 13, 15, 19))


@dataclass(frozen=True)
class DepthOptions:
    """Weights of the depth-sign choice (costs in units of a negative log-likelihood).

    Attributes
    ----------
    sigma_world : float
        Spread of a world-landmark segment direction (unit-vector difference).
    sigma_image_z : float
        Spread of the image landmarks' relative depth of a segment, as a
        fraction of the segment's length.
    sigma_step : float
        Spread of the elbow's and wrist's movement between frames at 25 fps,
        metres (scaled by ``25 / fps``).
    back_high : float
        Cost of an arm (shoulder → wrist) pointing straight back and up;
        intermediate directions cost in proportion to their backward and
        upward components.
    apart : float
        A segment's chosen side overrides the world landmarks' only where its
        two candidates' depth differs by more than this fraction of its
        length (elsewhere the side hardly matters and is noise).
    band : float or None
        Relative uncertainty of a segment's image length over its length:
        the world landmarks' out-of-plane fraction is brought into the band
        that image length allows (:func:`~capture2notation.fitting.foreshorten.bound_depth`);
        None keeps it.
    elbow : float
        Cost of a forearm bent fully towards the upper arm's back.
    elbow_slack : float
        Bends up to this much (sine of the angle past the side) towards the
        back are free: the upper arm's twist.
    rest_offset : bool
        Remove the depth the world (and image) landmarks give a limb the
        image shows hanging straight (:func:`_remove_rest_offset`): on for
        BlazePose tracks (:func:`~capture2notation.fitting.fit_track`), off
        for landmarks without that bias.
    """

    sigma_world: float = 0.3
    sigma_image_z: float = 0.5
    sigma_step: float = 0.06
    back_high: float = 8.0
    apart: float = 0.3
    band: float | None = EPS
    elbow: float = 6.0
    elbow_slack: float = 0.3
    rest_offset: bool = False


def _on_ray(ray: np.ndarray, centre: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The near and far points of rays ``(..., 3)`` at `radius` from `centre` ``(..., 3)``.

    Where the ray misses the sphere (the image segment is longer than the
    model's), both are the ray's closest point to the centre.
    """
    rr = np.sum(ray * ray, axis=-1)
    rp = np.sum(ray * centre, axis=-1)
    disc = rp**2 - rr * (np.sum(centre * centre, axis=-1) - radius**2)
    root = np.sqrt(np.maximum(disc, 0.0))
    near = ray * ((rp - root) / rr)[..., None]
    far = ray * ((rp + root) / rr)[..., None]
    return near, far


def arm_candidates(
    cam: Camera, shoulder: np.ndarray, elbow_px: np.ndarray, wrist_px: np.ndarray, upper: float, fore: float
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate elbow and wrist positions of one arm, camera coordinates.

    Parameters
    ----------
    cam : Camera
    shoulder : (T, 3) ndarray
        Shoulder positions, camera coordinates, metres.
    elbow_px, wrist_px : (T, 2) ndarray
        Pixels of the elbow and wrist.
    upper, fore : float
        Lengths of the upper arm and forearm, metres.

    Returns
    -------
    elbow, wrist : (T, 4, 3) ndarray
        Candidates ordered (elbow near, wrist near), (near, far), (far, near),
        (far, far); "near" is towards the camera.
    """
    Kinv = np.linalg.inv(cam.K)
    T = shoulder.shape[0]
    ray_e = np.concatenate([elbow_px, np.ones((T, 1))], axis=1) @ Kinv.T
    ray_w = np.concatenate([wrist_px, np.ones((T, 1))], axis=1) @ Kinv.T
    e_near, e_far = _on_ray(ray_e, shoulder, upper)
    elbow = np.stack([e_near, e_near, e_far, e_far], axis=1)
    w_near, w_far = _on_ray(ray_w[:, None], elbow[:, ::2], fore)  # (T, 2, 3) per elbow candidate
    wrist = np.stack([w_near[:, 0], w_far[:, 0], w_near[:, 1], w_far[:, 1]], axis=1)
    return elbow, wrist


def viterbi(unary: np.ndarray, pairwise: np.ndarray) -> np.ndarray:
    """Minimum-cost state sequence.

    Parameters
    ----------
    unary : (T, S) ndarray
        Cost of each state in each frame.
    pairwise : (T - 1, S, S) ndarray
        Cost of going from state i at frame t to state j at frame t + 1.

    Returns
    -------
    (T,) ndarray of int
    """
    T, S = unary.shape
    back = np.zeros((T, S), dtype=int)
    acc = unary[0].copy()
    for t in range(1, T):
        tot = acc[:, None] + pairwise[t - 1]
        back[t] = np.argmin(tot, axis=0)
        acc = tot[back[t], np.arange(S)] + unary[t]
    path = np.empty(T, dtype=int)
    path[-1] = int(np.argmin(acc))
    for t in range(T - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


#: A limb hangs in the image when both its segments point within this of
#: straight down (degrees) at nearly their full length (fraction).  A leg
#: lifted forward comes at the camera, whose perspective makes up much of
#: its foreshortening (45° forward keeps 0.92 of its image length in a front
#: view), so such frames pass too: the offset is the *median* over the
#: frames that pass, which standing frames outnumber in a dance.
_HANG_DEG = 15.0
_HANG_LENGTH = 0.9
#: Fewest hanging frames that measure the world landmarks' rest offset.
_MIN_REST_FRAMES = 5


def _hanging(cam: Camera, ok, s_px, e_px, w_px, depth, upper: float, fore: float) -> np.ndarray:
    """(T,) frames where the image shows a limb hanging straight (DESIGN.md's starting pose)."""
    down = (cam.R @ np.array([0.0, 0.0, -1.0]))[:2]
    down = down / max(np.linalg.norm(down), 1e-9)
    out = np.asarray(ok, bool).copy()
    for a, b, seg in ((s_px, e_px, upper), (e_px, w_px, fore)):
        v = b - a
        n = np.linalg.norm(v, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            out &= (v @ down) > np.cos(np.radians(_HANG_DEG)) * n
            out &= n * depth / cam.focal > _HANG_LENGTH * seg
    return out


def _clip_median(rest: dict | None, key, values: np.ndarray, where: np.ndarray) -> float:
    """The median of `values` over `where`, or the clip's own where `rest` already holds it.

    A long clip is fitted in spans (:mod:`.spans`); its rest offsets are a
    property of the clip (the pose model's bias for this figure), measured
    once over frames spread across it and then given to every span, so a
    span does not carry an offset of its own.  `rest` None: measure here;
    a dict: use its entry for `key` or, missing, measure and store it (NaN
    when fewer than :data:`_MIN_REST_FRAMES` frames show the rest pose).
    """
    if rest is not None and key in rest:
        return rest[key]
    value = float("nan")
    if np.sum(where) >= _MIN_REST_FRAMES:
        with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices: no offset
            value = float(np.nanmedian(values[where]))
    if rest is not None:
        rest[key] = value
    return value


def _remove_rest_offset(tw: np.ndarray, chain, hanging: np.ndarray, followers=(), rest: dict | None = None) -> None:
    """Take out of the world targets `tw` (in place) the depth they give a limb that hangs.

    BlazePose's world landmarks put the elbow of an arm hanging straight
    about a quarter of the upper arm behind the shoulder and the wrist as
    far in front of the elbow (the relaxed arm of its training data), and
    carry that offset into every pose: a forward arm comes out with its
    elbow behind the shoulder.  Where the image shows the limb hanging at
    full length (:func:`_hanging`), the depth is zero by DESIGN.md's
    starting pose, so each segment's median depth there, as a fraction of
    its length, is the offset removed from every frame.

    Parameters
    ----------
    tw : (T, N, 3) ndarray
        World targets, camera-aligned axes (modified).
    chain : (3,) sequence of int
        Target indices of the limb's root, middle and end joints.
    hanging : (T,) ndarray of bool
    followers : sequence of int
        Targets that move with the end joint (hand tip; heel and toe).
    rest : dict, optional
        The clip's offsets (see :func:`_clip_median`).
    """
    a, m, e = chain
    carried = [tw[:, f] - tw[:, e] for f in followers]
    segs, offsets = [], []
    for i, j in ((a, m), (m, e)):
        d = tw[:, j] - tw[:, i]
        n = np.linalg.norm(d, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            offset = _clip_median(rest, ("world", i, j), d[:, 2] / n, hanging)
        if np.isfinite(offset):
            d[:, 2] -= offset * n
        segs.append(d)
        offsets.append(offset)
    if not np.isfinite(offsets).any():
        return
    tw[:, m] = tw[:, a] + segs[0]
    tw[:, e] = tw[:, m] + segs[1]
    for f, c in zip(followers, carried):
        tw[:, f] = tw[:, e] + c


def remove_leg_rest_offsets(
    model: PoseModel,
    cam: Camera,
    params: np.ndarray,
    names,
    tx: np.ndarray,
    tc: np.ndarray,
    tw: np.ndarray,
    rest: dict | None = None,
) -> np.ndarray:
    """World targets with the depth they give a straight standing leg taken out (a copy).

    The legs' counterpart of the arms' rest offset (:func:`_remove_rest_offset`):
    BlazePose's world landmarks put the ankle of a straight standing leg
    behind the hip on our renders, and a leg lifted forward behind it too.

    Parameters
    ----------
    model : PoseModel
        Supplies the clip's thigh and shin lengths.
    cam : Camera
    params : (T, 3 + D) ndarray
        Starting parameters (they place the hips in depth).
    names : sequence of str
        Target names of `tx`, `tc`, `tw`.
    tx : (T, N, 2) ndarray
    tc : (T, N) ndarray
    tw : (T, N, 3) ndarray
    rest : dict, optional
        The clip's rest offsets, measured once for a clip fitted in spans
        (see :func:`_clip_median`); None measures them on these frames.

    Returns
    -------
    (T, N, 3) ndarray
    """
    tw = tw.copy()
    pts = cam.to_camera(model.forward(params))
    for side in ("right", "left"):
        chain = [f"{side}_{j}" for j in ("hip", "knee", "ankle")]
        if any(n not in names for n in chain):
            continue
        i_h, i_k, i_a = (names.index(n) for n in chain)
        m_h, m_k, m_a = (model.index(n) for n in chain)
        seen = (tc[:, i_h] > 0) & (tc[:, i_k] > 0) & (tc[:, i_a] > 0)
        hanging = _hanging(
            cam,
            seen,
            tx[:, i_h],
            tx[:, i_k],
            tx[:, i_a],
            pts[:, m_h, 2],
            float(np.linalg.norm(model.offsets[m_k])),
            float(np.linalg.norm(model.offsets[m_a])),
        )
        followers = [names.index(f"{side}_{j}") for j in ("heel", "toe") if f"{side}_{j}" in names]
        _remove_rest_offset(tw, (i_h, i_k, i_a), hanging, followers, rest)
    return tw


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-9)


def choose_arm_depths(
    model: PoseModel,
    cam: Camera,
    params: np.ndarray,
    names,
    tx: np.ndarray,
    tc: np.ndarray,
    tw: np.ndarray | None,
    image_z: np.ndarray | None,
    fps: float,
    opt: DepthOptions | None = None,
    rest: dict | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Choose each arm's depth candidate per frame and write it into the world targets.

    Parameters
    ----------
    model : PoseModel
        Supplies the clip's segment lengths.
    cam : Camera
    params : (T, 3 + D) ndarray
        Starting parameters (they place the shoulders in depth and give the
        body's facing).
    names : sequence of str
        Target names; `tx`, `tc`, `tw` are indexed by them.
    tx : (T, N, 2) ndarray
        Target pixels.
    tc : (T, N) ndarray
        Target confidences.
    tw : (T, N, 3) ndarray or None
        World targets, camera-aligned axes, metres.
    image_z : (T, 33) ndarray or None
        Relative depth of the image landmarks, pixels (+ away from the camera).
    fps : float
    opt : DepthOptions, optional
    rest : dict, optional
        As for :func:`remove_leg_rest_offsets`.

    Returns
    -------
    tw : (T, N, 3) ndarray
        World targets whose elbows, wrists and hand tips lie on the chosen
        side (a copy; built from the shoulders when `tw` is None).
    states : (2, T) ndarray of int
        Chosen candidate of the right and left arm (see :func:`arm_candidates`).
    """
    opt = opt or DepthOptions()
    T = tx.shape[0]
    tw = np.full(tx.shape[:2] + (3,), np.nan) if tw is None else tw.copy()
    pts = cam.to_camera(model.forward(params))
    # The body's forward and up in camera axes, for the anatomical prior.
    yaw_dof = np.nonzero((model.dof_joint == 0) & (model.dof_axis == 2))[0][0] + 3
    yaw = params[:, yaw_dof]
    forward = np.stack([-np.sin(yaw), np.cos(yaw), np.zeros(T)], axis=1) @ cam.R.T
    right = np.stack([np.cos(yaw), np.sin(yaw), np.zeros(T)], axis=1) @ cam.R.T
    up = cam.R @ np.array([0.0, 0.0, 1.0])
    scale = 25.0 / fps if fps > 0 else 1.0
    states = np.zeros((2, T), dtype=int)
    for side, (arm, lms) in enumerate(zip(_ARMS, _ARM_LANDMARKS)):
        i_s, i_e, i_w, i_h = (names.index(n) for n in arm)
        m_s, m_e, m_w = (model.index(n) for n in arm[:3])
        upper = float(np.linalg.norm(model.offsets[m_e]))
        fore = float(np.linalg.norm(model.offsets[m_w]))
        # A hidden shoulder (the arm raised at the camera covers it) whose
        # world target was imputed stands where the starting pose puts it.
        shown = tc[:, i_s] > 0
        placed = shown | np.all(np.isfinite(tw[:, i_s]), axis=1)
        seen = placed & (tc[:, i_e] > 0) & (tc[:, i_w] > 0)
        if not seen.any():
            continue
        # The shoulder on its own pixel's ray, at the starting pose's depth.
        depth = pts[:, m_s, 2]
        s_px = np.where((seen & shown)[:, None], tx[:, i_s], cam.K[:2, 2])
        S = np.concatenate([(s_px - cam.K[:2, 2]) / np.diag(cam.K)[:2], np.ones((T, 1))], axis=1) * depth[:, None]
        S = np.where((seen & ~shown)[:, None], pts[:, m_s], S)
        e_px = np.where(seen[:, None], tx[:, i_e], s_px)
        w_px = np.where(seen[:, None], tx[:, i_w], s_px)
        if opt.rest_offset:
            hanging = _hanging(cam, seen & shown, s_px, e_px, w_px, depth, upper, fore)
            _remove_rest_offset(tw, (i_s, i_e, i_w), hanging, (i_h,), rest)
        E, W = arm_candidates(cam, S, e_px, w_px, upper, fore)  # (T, 4, 3)
        u_up, u_fore = _unit(E - S[:, None]), _unit(W - E)
        unary = np.zeros((T, 4))
        # World landmarks: the solver's direction term.
        ok = seen & np.all(np.isfinite(tw[:, [i_s, i_e, i_w]]), axis=(1, 2))
        if ok.any():
            w_up = _unit(np.nan_to_num(tw[:, i_e] - tw[:, i_s]))
            w_fore = _unit(np.nan_to_num(tw[:, i_w] - tw[:, i_e]))
            cost = (
                np.sum((u_up - w_up[:, None]) ** 2, -1) * tc[:, [i_e]]
                + np.sum((u_fore - w_fore[:, None]) ** 2, -1) * tc[:, [i_w]]
            ) / (2 * opt.sigma_world**2)
            unary += np.where(ok[:, None], cost, 0.0)
        # Image landmarks' relative depth, as a fraction of the segment's length.
        if image_z is not None:
            z = image_z[:, list(lms[:3])]
            okz = seen & np.all(np.isfinite(z), axis=1)
            px_per_m = cam.focal / np.maximum(depth, 0.1)
            dz_up = (z[:, 1] - z[:, 0]) / (px_per_m * upper)
            dz_fore = (z[:, 2] - z[:, 1]) / (px_per_m * fore)
            if opt.rest_offset:
                # The image landmarks' depth carries the same rest offset.
                off_up = _clip_median(rest, ("image_z", i_s, i_e), dz_up, hanging & okz)
                off_fore = _clip_median(rest, ("image_z", i_e, i_w), dz_fore, hanging & okz)
                if np.isfinite(off_up) and np.isfinite(off_fore):
                    dz_up, dz_fore = dz_up - off_up, dz_fore - off_fore
            cost = (
                (u_up[..., 2] - np.clip(np.nan_to_num(dz_up), -1, 1)[:, None]) ** 2
                + (u_fore[..., 2] - np.clip(np.nan_to_num(dz_fore), -1, 1)[:, None]) ** 2
            ) / (2 * opt.sigma_image_z**2)
            unary += np.where(okz[:, None], cost, 0.0)
        # Anatomy: no arm points back and up.
        v = _unit(W - S[:, None])
        back = np.maximum(-np.sum(v * forward[:, None], -1), 0.0)
        high = np.maximum(v @ up + 0.2, 0.0) / 1.2
        unary += np.where(seen[:, None], opt.back_high * back * high, 0.0)
        # The elbow bends one way: the forearm leaves the upper arm towards the
        # upper arm's front (after the shortest swing from hanging), give or
        # take the upper arm's twist; a bend towards its back costs in
        # proportion to the bend.
        if opt.elbow > 0:
            body = np.stack([right, forward, np.broadcast_to(up, forward.shape)], axis=-1)  # (T, 3, 3) columns
            u_l = np.einsum("tji,tsj->tsi", body, u_up)
            f_l = np.einsum("tji,tsj->tsi", body, u_fore)
            front = _swing(u_l)[..., :, 1]
            perp = f_l - np.sum(f_l * u_l, -1, keepdims=True) * u_l
            wrong = np.maximum(-np.sum(perp * front, -1) - opt.elbow_slack * np.linalg.norm(perp, axis=-1), 0.0)
            unary += np.where(seen[:, None], opt.elbow * wrong, 0.0)
        # Continuity: the jump of the elbow and the wrist relative to the shoulder.
        rel_e, rel_w = E - S[:, None], W - S[:, None]
        jump = np.sum((rel_e[1:, None, :] - rel_e[:-1, :, None]) ** 2, -1) + np.sum(
            (rel_w[1:, None, :] - rel_w[:-1, :, None]) ** 2, -1
        )  # (T-1, from, to)
        both = (seen[1:] & seen[:-1])[:, None, None]
        pair = np.where(both, jump / (2 * (opt.sigma_step * scale) ** 2), 0.0)
        path = viterbi(unary, pair)
        states[side] = path
        pick = np.arange(T), path
        e_c, w_c = E[pick], W[pick]
        # World targets (camera-aligned, hip-centred): the chosen side sets the
        # sign of each segment's depth where the candidates are clearly apart;
        # the magnitude stays the world landmarks' (foreshortening against a
        # model length overstates the depth of segments near the image plane).
        d_up = tw[:, i_e] - tw[:, i_s]
        d_fore = tw[:, i_w] - tw[:, i_e]
        # Image length over model length of each segment, at its start's depth.
        r_up = np.where(seen & shown, np.linalg.norm(e_px - s_px, axis=1) * S[:, 2] / (cam.focal * upper), np.nan)
        r_fore = np.where(seen, np.linalg.norm(w_px - e_px, axis=1) * e_c[:, 2] / (cam.focal * fore), np.nan)
        for d, c, L, r in ((d_up, e_c - S, upper, r_up), (d_fore, w_c - e_c, fore, r_fore)):
            apart = seen & (np.abs(c[:, 2]) > opt.apart * L) & np.isfinite(d[:, 2])
            flip = apart & (np.sign(d[:, 2]) != np.sign(c[:, 2]))
            d[flip, 2] = -d[flip, 2]
            # How far the segment leaves the image plane is what its image
            # length says, within that length's uncertainty: the world
            # landmarks' amount is kept only inside that band.
            if opt.band is not None:
                d[:] = bound_depth(d, r, opt.band, side=np.sign(c[:, 2]))
        hand = tw[:, i_h] - tw[:, i_w]
        tw[:, i_e] = tw[:, i_s] + d_up
        tw[:, i_w] = tw[:, i_e] + d_fore
        tw[:, i_h] = tw[:, i_w] + hand
    return tw, states
