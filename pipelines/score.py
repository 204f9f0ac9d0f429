"""``c2n score CANDIDATE REFERENCE``: how close is a performance to a reference?

Either side may be a score file (danced by the virtual dancer with its
Effort), a capture directory (``capture.npz`` + ``score.lab`` +
``effort.json``), a BVH / Kinect CSV file, or a truth sidecar (``.npz``).
The two are aligned (tempo scaling when both are scores, dynamic time
warping on limb directions otherwise), compared movement by movement, and
summarised in ``summary.json`` and ``report.html``.

What the figures mean:

* A movement *agrees* when the candidate's limb, at the frame aligned to the
  reference's key pose, lies in the same Labanotation direction and level as
  the reference's own limb there (both read with DESIGN.md's thresholds);
  so a performance against itself agrees everywhere, whatever its notation.
* The warping (:func:`~capture2notation.compare.align.align_performances`)
  matches a movement only near its own time; reference movements outside the
  matched stretch are ``missing``, and candidate time matched to nothing
  counts against: ``symbol_agreement`` = agreeing movements / (reference
  movements + the movements the reference would have made in the
  candidate's unmatched time, at the reference's rate).
* ``same_piece`` is the verdict: agreement beyond what chance gives these
  two performances (Cohen's κ against the candidate's own pose frequencies,
  with a one-sided Poisson-binomial test), over most of both performances.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from capture2notation.atomic import write_text
from capture2notation.body import JOINTS, PARENT, joint_index
from capture2notation.compare.align import align_performances, align_tempo
from capture2notation.compare.chance import chance_of_agreeing, same_piece
from capture2notation.compare.metrics import (
    agreement_by_part,
    compare_movements,
    effort_differences,
    mpjpe,
    pa_mpjpe,
    part_vectors,
)
from capture2notation.compare.stats import sign_test, signs_from_differences
from capture2notation.errors import PipelineError
from capture2notation.notation.directions import classify_indices
from capture2notation.notation.model import DIRECTIONS, Score

__all__ = ["Side", "compare_sides", "load_side", "run_score"]

log = logging.getLogger(__name__)

MOTION_SUFFIXES = (".bvh", ".csv")


@dataclass
class Side:
    """One performance ready to compare.

    Attributes
    ----------
    label : str
        Path as given.
    kind : str
        ``score``, ``capture``, ``motion`` (BVH/CSV) or ``truth``.
    joints : (T, J, 3) ndarray
        World joints, metres, canonical joint order.
    fps : float
    score : Score or None
        Notation of the performance (given, estimated by capture, or carried
        by the truth sidecar).
    effort : dict or None
        ``time``/``weight``/``space``/``tempo`` → (median, lo, hi).
    """

    label: str
    kind: str
    joints: np.ndarray
    fps: float
    score: Score | None
    effort: dict | None


def _point(v: float) -> tuple:
    return (float(v), float(v), float(v))


def _score_effort(score: Score) -> dict:
    e = score.resolved_effort()
    return {"time": _point(e.time), "weight": _point(e.weight), "space": _point(e.space), "tempo": _point(score.tempo)}


def _effort_json(d: dict, tempo=None) -> dict:
    """(median, lo, hi) from an ``effort.json`` pooled entry or a plain Effort dict."""
    out = {}
    for k in ("time", "weight", "space"):
        v = d.get(k)
        if isinstance(v, dict) and "median" in v:
            lo, hi = v.get("ci90", [v["median"], v["median"]])
            out[k] = (float(v["median"]), float(lo), float(hi))
        elif isinstance(v, (int, float)):
            out[k] = _point(v)
    t = d.get("tempo", tempo)
    if isinstance(t, (int, float)):
        out["tempo"] = _point(t)
    return out


def load_side(path, fps: float = 25.0) -> Side:
    """Load a candidate or reference (see the module docstring for the kinds).

    Raises
    ------
    PipelineError
        Unknown kind, or a file that its reader rejects (message names it).
    """
    from capture2notation.notation import formats

    p = Path(path)
    if p.is_dir():
        from pipelines.commands.effort import load_capture

        cap = load_capture(p / "capture.npz")
        score = formats.read(p / "score.lab") if (p / "score.lab").is_file() else None
        effort = None
        ej = p / "effort.json"
        if ej.is_file():
            try:
                data = json.loads(ej.read_text(encoding="utf-8"))
            except json.JSONDecodeError as exc:
                raise PipelineError(f"{ej}: not valid JSON ({exc})") from None
            pooled = data.get("pooled") or {}
            effort = _effort_json(pooled, float(score.tempo) if score else None) or None
        return Side(str(path), "capture", np.asarray(cap["joints"], float), float(cap["fps"]), score, effort)
    if not p.is_file():
        raise PipelineError(f"{p}: no such file or capture directory")
    suffix = p.suffix.lower()
    if suffix in MOTION_SUFFIXES:
        from capture2notation.fitting.motion import read_motion

        m = read_motion(p)
        return Side(str(path), "motion", np.asarray(m.joints, float), float(m.fps), None, None)
    if suffix == ".npz":
        from capture2notation.fitting.motion import motion_from_truth
        from capture2notation.io.truth import read_truth

        m = motion_from_truth(p)
        tr = read_truth(p)
        score = formats.loads(tr.score, "json", path=p) if tr.score else None
        effort = None
        if tr.effort:
            try:
                effort = _effort_json(json.loads(tr.effort), float(score.tempo) if score else None)
            except json.JSONDecodeError:
                log.warning("%s: effort field is not JSON; Effort not compared", p)
        if effort is None and score is not None:
            effort = _score_effort(score)
        return Side(str(path), "truth", np.asarray(m.joints, float), float(m.fps), score, effort)
    from pipelines.commands.options import score_format_or_fail

    score_format_or_fail(p, "a capture folder, a .bvh, a Kinect .csv, a truth .npz")
    score = formats.read(p)
    if not score.symbols:
        raise PipelineError(f"{p}: the score has no symbols: there is no performance to compare")
    from synthetic.interpret import interpret

    motion = interpret(score, fps=fps)
    return Side(str(path), "score", motion.joints(), float(fps), score, _score_effort(score))


def _resample(joints: np.ndarray, fps_from: float, fps_to: float) -> np.ndarray:
    """Linear resampling in time to another frame rate (NaN stays NaN)."""
    if abs(fps_from - fps_to) < 1e-9:
        return joints
    T = joints.shape[0]
    t_new = np.arange(int(np.floor((T - 1) / fps_from * fps_to)) + 1) / fps_to
    pos = t_new * fps_from
    i0 = np.clip(np.floor(pos).astype(int), 0, T - 1)
    i1 = np.clip(i0 + 1, 0, T - 1)
    w = (pos - i0)[:, None, None]
    return (1 - w) * joints[i0] + w * joints[i1]


def _centred(j: np.ndarray) -> np.ndarray:
    return j - j[:, joint_index("pelvis")][:, None]


def compare_sides(cand: Side, ref: Side, timing_tolerance: float = 0.2) -> dict:
    """Align and compare a candidate with a reference.

    Returns
    -------
    dict
        ``alignment``, ``movements`` (list of MovementResult), per-part
        agreement, frame errors, Effort differences, sign tests, the matched
        time (``time``) and the ``verdict`` (:class:`~capture2notation.compare.chance.Verdict`),
        and the aligned joint arrays for plotting (``_ref``, ``_cand``).
    """
    fps = ref.fps
    cj = _resample(cand.joints, cand.fps, fps)
    rj = ref.joints
    ref_score = ref.score
    if ref_score is None:
        from capture2notation.quantise.segment import segment

        ref_score = segment(rj, fps)
        log.info("reference has no notation; segmented it into %d symbols", len(ref_score.symbols))
    if not ref_score.symbols:
        raise PipelineError(f"{ref.label}: the reference has no movements to compare")
    dtw_al = align_performances(_fill_unseen(rj, ref.label), _fill_unseen(cj, cand.label), fps)
    if cand.kind == "score" and ref.kind == "score":
        pose_al = align_tempo(len(rj), len(cj), float(ref_score.tempo), float(cand.score.tempo), fps, fps)
    else:
        pose_al = dtw_al
    from capture2notation.compare.metrics import key_frames

    kf = key_frames(ref_score, fps, len(rj))
    # Two scores share their beats: the tempo alignment gives the arrivals too.
    arrival_al = pose_al if pose_al.method == "tempo" else dtw_al
    moves = compare_movements(
        ref_score,
        rj,
        cj,
        pose_al.candidate_frame(kf),
        arrival_al.candidate_frame(kf),
        fps,
        fps,
        timing_tolerance=timing_tolerance,
        against="reference",
    )
    # A reference movement outside the matched stretch has no counterpart.
    inside = pose_al.matched(kf)
    moves = [m if inside[i] or m.verdict == "n/a" else _missing(m) for i, m in enumerate(moves)]
    pairs = pose_al.path
    r_al, c_al = rj[pairs[:, 0]], cj[pairs[:, 1]]
    frame_mpjpe = mpjpe(_centred(r_al), _centred(c_al))
    frame_pa = pa_mpjpe(r_al, c_al)
    gest = [m for m in moves if m.verdict not in ("n/a", "missing")]
    # Elevation (deg) of each moved limb at its key pose, both sides, for the "higher?" question.
    elev = []
    for m in gest:
        v = part_vectors(np.stack([rj[m.ref_frame], cj[m.cand_frame]]), [m.part])[:, 0]
        elev.append(np.degrees(np.arcsin(np.clip(v[1, 2], -1, 1)) - np.arcsin(np.clip(v[0, 2], -1, 1))))
    frame_step = 1.0 / fps
    tests = [
        sign_test(signs_from_differences([m.timing_offset for m in gest], frame_step), "candidate arrives later"),
        sign_test(signs_from_differences(elev, 2.0), "candidate's limb is higher"),
        sign_test(
            signs_from_differences([m.ref_angle_error - m.angle_error for m in gest], 2.0),
            "candidate is nearer the notated direction",
        ),
    ]
    eff = effort_differences(cand.effort, ref.effort) if cand.effort and ref.effort else {}
    time = _matched_time(pose_al, fps)
    chance = _chance(gest, cj, pose_al.cand_span)
    verdict = same_piece(
        [m.agree for m in gest],
        chance,
        time["matched_reference_s"] / time["reference_s"],
        time["matched_candidate_s"] / time["candidate_s"],
    )
    return {
        "alignment": pose_al,
        "dtw": dtw_al,
        "reference_score": ref_score,
        "movements": moves,
        "agreement": agreement_by_part(moves),
        "mpjpe_mm": 1000 * frame_mpjpe,
        "pa_mpjpe_mm": 1000 * frame_pa,
        "effort": eff,
        "sign_tests": tests,
        "time": time,
        "verdict": verdict,
        "_ref": rj,
        "_cand": cj,
    }


def _missing(m):
    from dataclasses import replace

    nan = float("nan")
    return replace(
        m,
        agree=False,
        verdict="missing",
        cand_frame=-1,
        cand_direction="",
        cand_level="",
        cand_bend=-1,
        angle_error=nan,
        pose_error=nan,
        timing_offset=nan,
    )


def _matched_time(al, fps: float) -> dict:
    """Seconds of each performance, and of each matched to the other (frames count 1/fps each)."""
    r0, r1 = al.ref_span
    c0, c1 = al.cand_span
    return {
        "reference_s": al.n_ref / fps,
        "candidate_s": al.n_cand / fps,
        "matched_reference_s": (r1 - r0 + 1) / fps,
        "matched_candidate_s": (c1 - c0 + 1) / fps,
    }


def _chance(gest, cand_joints: np.ndarray, span: tuple[int, int]) -> np.ndarray:
    """Each movement's chance of agreeing: the share of matched candidate frames in the reference's class."""
    if not gest:
        return np.zeros(0)
    parts = sorted({m.part for m in gest})
    di, li = classify_indices(part_vectors(cand_joints[span[0] : span[1] + 1], parts))
    codes = np.where(di >= 0, 3 * di + li, -1).T  # (P, T)
    dirs = list(DIRECTIONS)
    levels = ("high", "middle", "low")
    target = np.array(
        [3 * dirs.index(m.ref_direction) + levels.index(m.ref_level) if m.ref_direction else -2 for m in gest]
    )
    return chance_of_agreeing(target, codes[[parts.index(m.part) for m in gest]])


def _fill_unseen(j: np.ndarray, label: str) -> np.ndarray:
    """Joints for the alignment only: a joint never seen sits on the pelvis, a frame with
    gaps holds the last complete frame."""
    out = j.copy()
    never = ~np.any(np.all(np.isfinite(out), axis=2), axis=0)
    out[:, never] = out[:, :1]
    nan_frames = ~np.all(np.isfinite(out), axis=(1, 2))
    if nan_frames.all():
        raise PipelineError(f"{label}: no frame has every joint known; nothing to align")
    if nan_frames.any():  # hold the last good frame: alignment only, never a measurement
        good = np.flatnonzero(~nan_frames)
        idx = good[np.clip(np.searchsorted(good, np.arange(len(out)), side="right") - 1, 0, None)]
        out = out[idx]
    return out


def summary_dict(cand: Side, ref: Side, res: dict) -> dict:
    """The JSON-ready summary of a comparison."""
    moves = res["movements"]
    gest = [m for m in moves if m.verdict != "n/a"]
    verdicts = {}
    for m in moves:
        verdicts[m.verdict] = verdicts.get(m.verdict, 0) + 1
    timed = [m for m in gest if m.verdict != "missing"]
    t = res["time"]
    agreeing = sum(m.agree for m in gest)
    # Unmatched candidate time counts as the movements the reference makes in that much time.
    unmatched = (t["candidate_s"] - t["matched_candidate_s"]) / t["reference_s"] * len(gest)
    return {
        "candidate": {"path": cand.label, "kind": cand.kind, "fps": cand.fps, "frames": int(len(cand.joints))},
        "reference": {"path": ref.label, "kind": ref.kind, "fps": ref.fps, "frames": int(len(ref.joints))},
        "alignment": {"method": res["alignment"].method, "dtw_cost": res["dtw"].cost},
        "symbol_agreement": agreeing / (len(gest) + unmatched) if gest else None,
        "movements_agreeing": int(agreeing),
        "movements_compared": len(gest),
        "movements_missing": int(verdicts.get("missing", 0)),
        "unmatched_candidate_movements": float(unmatched),
        "time_s": t,
        "verdict": res["verdict"].as_dict(),
        "agreement_by_part": res["agreement"],
        "angle_error_deg": {"mean": float(np.mean([m.pose_error for m in timed])) if timed else None},
        "mpjpe_mm": float(np.nanmean(res["mpjpe_mm"])),
        "pa_mpjpe_mm": float(np.nanmean(res["pa_mpjpe_mm"])),
        "timing_offset_s": {
            "mean": float(np.mean([m.timing_offset for m in timed])) if timed else None,
            "mean_abs": float(np.mean([abs(m.timing_offset) for m in timed])) if timed else None,
        },
        "effort_differences": res["effort"],
        "verdicts": verdicts,
        "movements": [m.as_dict() for m in moves],
        "sign_tests": [t.as_dict() for t in res["sign_tests"]],
    }


def run_score(candidate, reference, outdir, fps: float = 25.0, timing_tolerance: float = 0.2) -> dict:
    """Compare, then write ``summary.json`` and ``report.html`` (with plots) into `outdir`."""
    cand = load_side(candidate, fps)
    ref = load_side(reference, fps)
    res = compare_sides(cand, ref, timing_tolerance)
    summ = summary_dict(cand, ref, res)
    outdir = Path(outdir)
    write_text(outdir / "summary.json", json.dumps(summ, indent=2, default=_json_default) + "\n")
    write_score_report(cand, ref, res, summ, outdir)
    return summ


def _json_default(o):
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        return float(o)
    if isinstance(o, np.bool_):
        return bool(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# --- report ----------------------------------------------------------------------
_BONES = tuple((PARENT[n], n) for n in JOINTS if PARENT[n] is not None)


def _stick(ax, joints: np.ndarray, dx: float, colour: str) -> None:
    """Front view (x right, z up) of one pose, shifted sideways by `dx` metres."""
    pel = joints[joint_index("pelvis")]
    for a, b in _BONES:
        p, q = joints[joint_index(a)], joints[joint_index(b)]
        ax.plot([p[0] - pel[0] + dx, q[0] - pel[0] + dx], [p[2], q[2]], color=colour, lw=2)
    h = joints[joint_index("head")]
    ax.plot([h[0] - pel[0] + dx], [h[2]], "o", color=colour, ms=7)


def _key_pose_figure(res: dict, max_poses: int = 8):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    gest = [m for m in res["movements"] if m.verdict not in ("n/a", "missing")]
    if len(gest) > max_poses:
        gest = [gest[i] for i in np.linspace(0, len(gest) - 1, max_poses).round().astype(int)]
    cols = min(4, max(len(gest), 1))
    rows = max(1, -(-len(gest) // cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.0 * cols, 3.3 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.set_axis_off()
    for ax, m in zip(axes.ravel(), gest):
        _stick(ax, res["_ref"][m.ref_frame], -0.5, "black")
        _stick(ax, res["_cand"][m.cand_frame], 0.5, "#2a6fc9" if m.agree else "#c0392b")
        ax.set_aspect("equal")
        ax.set_title(
            f"{m.part} {m.direction} {m.level}\n→ {m.cand_direction or '?'} {m.cand_level} ({m.verdict})", fontsize=8
        )
    fig.suptitle("Key poses: reference (black, left) and candidate (blue = same symbol, red = different)", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    return fig


def write_score_report(cand: Side, ref: Side, res: dict, summ: dict, outdir) -> Path:
    """``report.html`` with the key-pose stick figures, the plots and the tables."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .report_html import Report

    rep = Report(f"Score: {Path(cand.label).name} against {Path(ref.label).name}", outdir)
    sa = summ["symbol_agreement"]
    mean_abs = summ["timing_offset_s"]["mean_abs"]
    rep.paragraph(
        f"Candidate {cand.label} ({cand.kind}, {cand.fps:g} fps) against reference {ref.label} ({ref.kind}, "
        f"{ref.fps:g} fps), aligned by {summ['alignment']['method']}. Symbol agreement "
        f"{'–' if sa is None else f'{sa:.0%}'}, MPJPE {summ['mpjpe_mm']:.0f} mm (pelvis-centred), "
        f"Procrustes-aligned {summ['pa_mpjpe_mm']:.0f} mm, mean |timing offset| "
        f"{float('nan') if mean_abs is None else mean_abs:.3f} s. "
        f"{summ['movements_agreeing']} of {summ['movements_compared']} reference movements agree "
        f"({summ['movements_missing']} have no matched candidate time); "
        f"{summ['time_s']['matched_candidate_s']:.1f} of the candidate's {summ['time_s']['candidate_s']:.1f} s "
        "are matched, and the rest counts against the agreement at the reference's rate of movements."
    )
    rep.heading("Verdict")
    rep.paragraph(f"{summ['verdict']['reason'][0].upper()}{summ['verdict']['reason'][1:]}.")
    rep.heading("Key poses")
    rep.figure(_key_pose_figure(res), "key_poses", "Stick figures at each key pose of the reference, front view.")
    rep.heading("Errors over the phrase")
    gest = [m for m in res["movements"] if m.verdict not in ("n/a", "missing")]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    t = res["alignment"].path[:, 0] / ref.fps
    axes[0].plot(t, res["mpjpe_mm"], label="MPJPE")
    axes[0].plot(t, res["pa_mpjpe_mm"], label="PA-MPJPE")
    axes[0].set_xlabel("reference time (s)")
    axes[0].set_ylabel("mm")
    axes[0].legend(fontsize=7)
    idx = np.arange(len(gest))
    axes[1].bar(idx, [m.pose_error for m in gest], color=["#2a6fc9" if m.agree else "#c0392b" for m in gest])
    axes[1].set_xlabel("movement")
    axes[1].set_ylabel("limb angle error at key pose (deg)")
    axes[2].bar(idx, [m.timing_offset for m in gest], color="#7fb04a")
    axes[2].axhline(0, color="grey", lw=0.8)
    axes[2].set_xlabel("movement")
    axes[2].set_ylabel("timing offset (s, + = late)")
    rep.figure(fig, "errors", "Frame errors after alignment; per-movement angle error and timing offset.")
    if res["effort"]:
        fig, ax = plt.subplots(figsize=(5, 3))
        names = list(res["effort"])
        d = [res["effort"][n] for n in names]
        ax.errorbar(
            range(len(names)),
            [x["difference"] for x in d],
            yerr=[[x["difference"] - x["lo"] for x in d], [x["hi"] - x["difference"] for x in d]],
            fmt="o",
            capsize=4,
        )
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_xticks(range(len(names)), names)
        ax.set_ylabel("candidate − reference")
        rep.figure(fig, "effort", "Effort differences with their intervals (0 inside = consistent).")
    rep.heading("Movements")
    cols = [
        "index",
        "part",
        "direction",
        "level",
        "ref_direction",
        "ref_level",
        "cand_direction",
        "cand_level",
        "angle_error",
        "pose_error",
        "timing_offset",
        "verdict",
    ]
    rep.table([m.as_dict() for m in res["movements"]], cols)
    rep.heading("Symbol agreement per part")
    rep.table([{"part": k, **v} for k, v in summ["agreement_by_part"].items()], ["part", "n", "agree", "fraction"])
    rep.heading("Sign tests over movements (as Wolofsky 1974, Table III)")
    rep.table(
        [t.as_dict() for t in res["sign_tests"]],
        ["question", "positive", "negative", "total", "fewer", "p", "significant"],
        caption="One-tailed binomial probability of the fewer signs; ties dropped; 5 % level.",
    )
    if res["effort"]:
        rep.heading("Effort differences")
        rep.table(
            [{"parameter": k, **v} for k, v in res["effort"].items()],
            ["parameter", "difference", "lo", "hi", "consistent"],
        )
    return rep.write("report.html")
