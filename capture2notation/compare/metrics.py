"""Metrics between a candidate performance and a reference.

Joint-position errors (MPJPE and its Procrustes-aligned form), limb-direction
errors at the reference's key poses, per-movement symbol agreement, timing
offsets and Effort differences, gathered into one verdict per movement.
Positions are metres, angles degrees, times seconds unless said otherwise.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..body import body_frame, joint_index
from ..errors import CompareError
from ..notation.directions import bend_angle, bend_degree, canonical_vector, classify_indices
from ..notation.model import DIRECTIONS, PART_MIDDLE_JOINT, PART_SEGMENTS, Score

__all__ = [
    "MovementResult",
    "agreement_by_part",
    "angle_between",
    "compare_movements",
    "effort_differences",
    "key_frames",
    "mpjpe",
    "notation_agreement",
    "pa_mpjpe",
    "part_vectors",
    "procrustes_align",
]

_DIRS = tuple(DIRECTIONS)
_LEVELS = ("high", "middle", "low")


def _check_pair(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 3 or a.shape[-1] != 3:
        raise CompareError(f"joint arrays must both be (T, J, 3) of one shape, got {a.shape} and {b.shape}")
    return a, b


def mpjpe(ref: np.ndarray, cand: np.ndarray) -> np.ndarray:
    """Mean per-joint position error of each frame.

    Parameters
    ----------
    ref, cand : (T, J, 3) ndarray
        Matched frames of world joints, metres (NaN where unknown).

    Returns
    -------
    (T,) ndarray
        Mean Euclidean distance over joints known on both sides, metres;
        NaN for frames with no such joint.
    """
    ref, cand = _check_pair(ref, cand)
    d = np.linalg.norm(cand - ref, axis=-1)
    ok = np.isfinite(d)
    count = ok.sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, np.where(ok, d, 0.0).sum(-1) / count, np.nan)


def procrustes_align(ref: np.ndarray, cand: np.ndarray, scale: bool = True) -> np.ndarray:
    """Best similarity transform of each candidate frame onto the reference.

    The per-frame least-squares rotation (Kabsch/Umeyama, via a batched SVD)
    with optional isotropic scale and translation; the same optimum as
    :func:`scipy.linalg.orthogonal_procrustes` on centred points.

    Parameters
    ----------
    ref, cand : (T, J, 3) ndarray
        Matched frames, metres.  Joints missing on either side are ignored.
    scale : bool
        Also fit a scale factor.

    Returns
    -------
    (T, J, 3) ndarray
        The aligned candidate (NaN where the candidate joint is NaN, and
        whole frames with fewer than 3 shared joints).
    """
    ref, cand = _check_pair(ref, cand)
    ok = np.all(np.isfinite(ref), -1) & np.all(np.isfinite(cand), -1)  # (T, J)
    w = ok.astype(float)[..., None]
    n = np.maximum(w.sum(1, keepdims=True), 1.0)
    r0 = np.nan_to_num(ref) * w
    c0 = np.nan_to_num(cand) * w
    mr = r0.sum(1, keepdims=True) / n
    mc = c0.sum(1, keepdims=True) / n
    x = (c0 - mc) * w
    y = (r0 - mr) * w
    h = np.einsum("tji,tjk->tik", x, y)  # (T, 3, 3) cross-covariance
    u, s, vt = np.linalg.svd(h)
    # Reflection guard: a proper rotation even for near-planar poses.
    d = np.sign(np.linalg.det(np.einsum("tij,tjk->tik", u, vt)))
    d[d == 0] = 1.0
    s = s.copy()
    s[:, 2] *= d
    u = u.copy()
    u[:, :, 2] *= d[:, None]
    rot = np.einsum("tij,tjk->tik", u, vt)  # maps x rows: x @ rot ≈ y
    if scale:
        var = np.einsum("tji,tji->t", x, x)
        k = np.where(var > 0, s.sum(1) / np.where(var > 0, var, 1.0), 1.0)
    else:
        k = np.ones(len(ref))
    out = k[:, None, None] * np.einsum("tji,tik->tjk", np.nan_to_num(cand) - mc, rot) + mr
    out[~np.all(np.isfinite(cand), -1)] = np.nan
    out[ok.sum(1) < 3] = np.nan
    return out


def pa_mpjpe(ref: np.ndarray, cand: np.ndarray) -> np.ndarray:
    """Procrustes-aligned MPJPE of each frame (metres), see :func:`procrustes_align`."""
    return mpjpe(ref, procrustes_align(ref, cand))


def part_vectors(joints: np.ndarray, parts) -> np.ndarray:
    """Body-frame unit vectors of notated parts.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
    parts : sequence of str
        Gesture parts (keys of ``PART_SEGMENTS``).

    Returns
    -------
    (T, P, 3) ndarray
    """
    joints = np.asarray(joints, dtype=float)
    try:
        a = np.array([joint_index(PART_SEGMENTS[p][0]) for p in parts], dtype=int)
        b = np.array([joint_index(PART_SEGMENTS[p][1]) for p in parts], dtype=int)
    except KeyError as exc:
        raise CompareError(
            f"part {exc.args[0]!r} has no limb segment; expected one of {' '.join(PART_SEGMENTS)}"
        ) from None
    v = joints[:, b] - joints[:, a]
    nrm = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        v = np.where(nrm > 1e-12, v / nrm, np.nan)
    return np.einsum("tij,tpj->tpi", body_frame(joints), v)


def angle_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between vectors along the last axis, degrees (NaN if either is NaN)."""
    u = np.asarray(u, float)
    v = np.asarray(v, float)
    # atan2 of |u×v| and u·v stays accurate near 0° and 180°.
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1)))


def key_frames(score: Score, fps: float, n_frames: int | None = None, t0: float = 0.0) -> np.ndarray:
    """Frame at which each symbol of `score` arrives (its key pose).

    Parameters
    ----------
    score : Score
    fps : float
        Frame rate of the performance (Hz).
    n_frames : int, optional
        Clip to ``[0, n_frames)``.
    t0 : float
        Time (s) of beat 0 in the performance.

    Returns
    -------
    (S,) ndarray of int
        One frame per symbol of ``score.symbols`` (same order).
    """
    ends = np.array([score.seconds(s.end) for s in score.symbols], dtype=float) + t0
    f = np.floor(ends * fps + 0.5).astype(int)
    if n_frames is not None:
        f = np.clip(f, 0, int(n_frames) - 1)
    return f


@dataclass(frozen=True)
class MovementResult:
    """Comparison of one reference movement (symbol) with the candidate.

    Attributes
    ----------
    index : int
        Position of the symbol in the reference score.
    part, direction, level : str
        The reference symbol.
    bend : int
    ref_frame, cand_frame : int
        Reference key frame and the candidate frame aligned to it.
    cand_direction, cand_level : str
        The candidate's pose at `cand_frame`, classified with DESIGN.md's
        thresholds ("" when undefined).
    cand_bend : int
        Candidate bend degree (−1 when not applicable).
    agree : bool
        Direction and level agree (with the notation, or with the
        reference's own pose when compared ``against="reference"``).
    angle_error : float
        Degrees between the candidate limb and the symbol's canonical vector.
    ref_angle_error : float
        The same for the reference itself (how well the reference hits its
        own notation), for context.
    pose_error : float
        Degrees between candidate and reference limbs at the key pose.
    timing_offset : float
        Candidate arrival − reference arrival, seconds.
    verdict : str
        ``match`` (pose and timing), ``late/early`` (pose right, timing off),
        ``pose`` (wrong symbol), ``n/a`` (supports: not evaluated here);
        ``c2n score`` adds ``missing`` (no candidate time matched to it).
    ref_direction, ref_level : str
        The reference's own pose at `ref_frame`, classified ("" when undefined).
    """

    index: int
    part: str
    direction: str
    level: str
    bend: int
    ref_frame: int
    cand_frame: int
    cand_direction: str
    cand_level: str
    cand_bend: int
    agree: bool
    angle_error: float
    ref_angle_error: float
    pose_error: float
    timing_offset: float
    verdict: str
    ref_direction: str = ""
    ref_level: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def compare_movements(
    ref_score: Score,
    ref_joints: np.ndarray,
    cand_joints: np.ndarray,
    pose_frames: np.ndarray,
    arrival_frames: np.ndarray,
    fps_ref: float,
    fps_cand: float,
    ref_t0: float = 0.0,
    timing_tolerance: float = 0.2,
    against: str = "notation",
) -> list[MovementResult]:
    """Compare the candidate with every gesture symbol of the reference score.

    Parameters
    ----------
    ref_score : Score
        The reference notation (its symbols are the movements).
    ref_joints : (Tr, J, 3) ndarray
    cand_joints : (Tc, J, 3) ndarray
    pose_frames : (S,) array_like of int
        Candidate frame at which to read each movement's pose (from the
        alignment: tempo scaling or DTW).
    arrival_frames : (S,) array_like of int
        Candidate frame where the candidate reaches each key pose (from DTW),
        used for the timing offset.
    fps_ref, fps_cand : float
        Frame rates (Hz).
    ref_t0 : float
        Time (s) of beat 0 in the reference.
    timing_tolerance : float
        |offset| (s) up to which timing counts as right.
    against : {"notation", "reference"}
        What the candidate's pose must agree with: the reference's symbol,
        or the reference's own pose at its key frame, classified the same
        way.  The second compares two performances as they are: a captured
        reference whose joints do not quite hold what its quantised score
        says (a chest written ``forward middle`` whose key frame is 25°
        up) then counts against neither side, and a performance against
        itself agrees exactly.

    Returns
    -------
    list of MovementResult
        One per symbol, in score order (supports get verdict ``n/a``).
    """
    if against not in ("notation", "reference"):
        raise CompareError(f"against must be 'notation' or 'reference', got {against!r}")
    kf = key_frames(ref_score, fps_ref, len(ref_joints), ref_t0)
    pose_frames = np.clip(np.asarray(pose_frames, dtype=int), 0, len(cand_joints) - 1)
    arrival_frames = np.asarray(arrival_frames, dtype=int)
    if len(pose_frames) != len(kf) or len(arrival_frames) != len(kf):
        raise CompareError(
            f"need one candidate frame per symbol ({len(kf)}), got {len(pose_frames)} and {len(arrival_frames)}"
        )
    gestures = [i for i, s in enumerate(ref_score.symbols) if s.part in PART_SEGMENTS]
    parts = sorted({ref_score.symbols[i].part for i in gestures})
    if parts:
        cv = part_vectors(cand_joints, parts)
        rv = part_vectors(ref_joints, parts)
    out = []
    for i, sym in enumerate(ref_score.symbols):
        offset = float(arrival_frames[i] / fps_cand - kf[i] / fps_ref)
        if sym.part not in PART_SEGMENTS:
            out.append(
                MovementResult(
                    i,
                    sym.part,
                    sym.direction,
                    sym.level,
                    sym.bend,
                    int(kf[i]),
                    int(pose_frames[i]),
                    "",
                    "",
                    -1,
                    False,
                    np.nan,
                    np.nan,
                    np.nan,
                    offset,
                    "n/a",
                )
            )
            continue
        p = parts.index(sym.part)
        c = cv[pose_frames[i], p]
        r = rv[kf[i], p]
        di, li = classify_indices(np.stack([c, r]))
        cdir = _DIRS[di[0]] if di[0] >= 0 else ""
        clev = _LEVELS[li[0]] if li[0] >= 0 else ""
        rdir = _DIRS[di[1]] if di[1] >= 0 else ""
        rlev = _LEVELS[li[1]] if li[1] >= 0 else ""
        target = canonical_vector(sym.direction, sym.level)
        cbend = -1
        if sym.part in PART_MIDDLE_JOINT:
            a, b = PART_SEGMENTS[sym.part]
            m = PART_MIDDLE_JOINT[sym.part]
            j = cand_joints[pose_frames[i]]
            cbend = int(bend_degree(bend_angle(j[joint_index(a)], j[joint_index(m)], j[joint_index(b)])))
        want = (sym.direction, sym.level) if against == "notation" else (rdir, rlev)
        agree = bool(cdir) and (cdir, clev) == want
        if against == "reference" and not rdir:
            # The reference's own pose is not measured at its key frame (a limb
            # the sensor lost): there is nothing to agree with.
            verdict = "n/a"
        elif not agree:
            verdict = "pose"
        elif abs(offset) <= timing_tolerance:
            verdict = "match"
        else:
            verdict = "late" if offset > 0 else "early"
        out.append(
            MovementResult(
                i,
                sym.part,
                sym.direction,
                sym.level,
                sym.bend,
                int(kf[i]),
                int(pose_frames[i]),
                cdir,
                clev,
                cbend,
                bool(agree),
                float(angle_between(c, target)),
                float(angle_between(r, target)),
                float(angle_between(c, r)),
                offset,
                verdict,
                rdir,
                rlev,
            )
        )
    return out


def agreement_by_part(results: list[MovementResult]) -> dict[str, dict]:
    """Symbol agreement per part over the evaluated movements.

    Returns
    -------
    dict
        ``part → {"n": count, "agree": count, "fraction": agree / n,
        "bend_agree": count of bends that also agree}``; supports are left
        out (no limb direction to compare).
    """
    table: dict[str, dict] = {}
    for r in results:
        if r.verdict == "n/a":
            continue
        row = table.setdefault(r.part, {"n": 0, "agree": 0, "bend_agree": 0})
        row["n"] += 1
        row["agree"] += int(r.agree)
        row["bend_agree"] += int(r.agree and (r.cand_bend < 0 or r.cand_bend == r.bend))
    for row in table.values():
        row["fraction"] = row["agree"] / row["n"]
    return table


def effort_differences(cand: dict, ref: dict) -> dict[str, dict]:
    """Candidate − reference Effort, with a conservative interval.

    Parameters
    ----------
    cand, ref : dict
        ``name → (median, lo, hi)`` for any of ``time``, ``weight``,
        ``space``, ``tempo`` (a point value has ``lo == hi == median``).

    Returns
    -------
    dict
        ``name → {"difference", "lo", "hi", "consistent"}`` for the names
        present on both sides; the interval ``[lo_c − hi_r, hi_c − lo_r]``
        contains every difference of values inside the two intervals, and
        `consistent` says whether it contains 0.
    """
    out = {}
    for name in ("time", "weight", "space", "tempo"):
        if name not in cand or name not in ref:
            continue
        try:
            mc, lc, hc = (float(x) for x in cand[name])
            mr, lr, hr = (float(x) for x in ref[name])
        except (TypeError, ValueError):
            raise CompareError(
                f"effort {name} must be (median, lo, hi), got {cand[name]!r} and {ref[name]!r}"
            ) from None
        lo, hi = lc - hr, hc - lr
        out[name] = {"difference": mc - mr, "lo": lo, "hi": hi, "consistent": bool(lo <= 0.0 <= hi)}
    return out


def notation_agreement(ref: Score, est: Score, tolerance_s: float = 0.3) -> dict:
    """How many reference gesture symbols the estimated notation wrote too.

    A reference symbol is *found* when the estimate has a symbol of the same
    part arriving within `tolerance_s` seconds (each score on its own
    tempo), and *agrees* when that nearest symbol also has the same
    direction and level.

    Returns
    -------
    dict
        ``{"n": reference gesture symbols, "found": count, "agree": count,
        "fraction": agree / n (NaN when n = 0), "extra": estimated gesture
        symbols matched to no reference symbol}``.
    """
    gestures = [s for s in ref.symbols if s.part in PART_SEGMENTS]
    est_by_part: dict[str, list] = {}
    for s in est.symbols:
        if s.part in PART_SEGMENTS:
            est_by_part.setdefault(s.part, []).append(s)
    used = set()
    found = agree = 0
    for s in gestures:
        cands = est_by_part.get(s.part, [])
        if not cands:
            continue
        t = ref.seconds(s.end)
        dt = np.array([abs(est.seconds(c.end) - t) for c in cands])
        k = int(np.argmin(dt))
        if dt[k] <= tolerance_s:
            found += 1
            used.add(id(cands[k]))
            agree += int(cands[k].direction == s.direction and cands[k].level == s.level)
    n_est = sum(len(v) for v in est_by_part.values())
    return {
        "n": len(gestures),
        "found": found,
        "agree": agree,
        "fraction": agree / len(gestures) if gestures else float("nan"),
        "extra": n_est - len(used),
    }
