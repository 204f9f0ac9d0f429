"""``report.html`` of a fidelity study: Neagle's Figures 3.13–3.16 redrawn with our observer.

The thesis' bar heights exist only as pictures, so beside our bars we draw
the percentages its text states (78.70 % overall in Experiment 1; in
Experiment 2 78.99 % overall, same pairs angry 86.46 %, happy 71.88 %, sad
61.46 %, different pairs happy–angry 66.67 %, happy–sad and sad–angry
93.75 %).
"""

from __future__ import annotations

import math
import os
from collections import defaultdict

import numpy as np
from scipy import stats

from capture2notation.compare.discrimination import THESIS
from pipelines.report_html import Report

from .measure import CAPTURE_NOTES, DETECTOR_FLOOR_PX

__all__ = ["capture_comparison", "conclusions", "condition_table", "write_report"]

#: Metrics compared between capture paths, condition by condition.
COMPARED = ("symbol_accuracy", "notation_accuracy", "angle_error_deg", "time_abs_error", "percent_correct")

METRICS = (
    ("symbol_accuracy", "symbol accuracy at key poses", 1.0),
    ("notation_accuracy", "notation accuracy (segmented score)", 1.0),
    ("angle_error_deg", "limb angle error at key poses (deg)", 1.0),
    ("timing_error_s", "timing error (s)", 1.0),
    ("mpjpe_mm", "MPJPE (mm)", 1.0),
    ("time_abs_error", "|Effort time error|", 1.0),
    ("weight_abs_error", "|Effort weight error|", 1.0),
    ("space_abs_error", "|Effort space error|", 1.0),
    ("coverage", "90 % interval coverage", 1.0),
)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _mean(vals):
    v = np.array([x for x in vals if x is not None and not (isinstance(x, float) and math.isnan(x))], dtype=float)
    return float(v.mean()) if v.size else float("nan")


def condition_table(rows: list[dict], conditions, summary: dict) -> list[dict]:
    """One line per condition: mean metrics over its test jobs and Experiment 1's % correct."""
    pct = {e["condition"]: e["percent_correct"] for e in summary.get("experiment1", [])}
    trials = {e["condition"]: e.get("n", 0) for e in summary.get("experiment1", [])}
    groups = defaultdict(list)
    for r in rows:
        if r["split"] == "test":
            groups[
                (r["frame_rate"], r["resampling"], r["width"], r["height"], r["view"], r["compression"], r["noise"])
            ].append(r)
    out = []
    for c in conditions:
        g = groups.get(c.params(), [])
        ok = [r for r in g if not r.get("error")]
        line = {"factor": c.factor, "condition": c.label, "jobs": len(g), "failed": len(g) - len(ok)}
        line["symbol_accuracy"] = _mean(r.get("symbol_accuracy") for r in ok)
        line["notation_accuracy"] = _mean(r.get("notation_accuracy") for r in ok)
        line["angle_error_deg"] = _mean(r.get("angle_error_deg") for r in ok)
        line["timing_error_s"] = _mean(r.get("timing_error_s") for r in ok)
        line["mpjpe_mm"] = _mean(r.get("mpjpe_mm") for r in ok)
        for n in ("time", "weight", "space"):
            line[f"{n}_abs_error"] = _mean(
                abs(r[f"{n}_error"]) if r.get(f"{n}_error") is not None else None for r in ok
            )
        line["coverage"] = _mean([r.get(f"{n}_covered") for r in ok for n in ("time", "weight", "space")])
        line["percent_correct"] = pct.get(c.label, float("nan"))
        line["trials"] = trials.get(c.label, 0)
        out.append(line)
    return out


def capture_comparison(by_capture: dict) -> tuple[list[dict], list[str]]:
    """Each condition's mean metrics side by side for every capture path run.

    Parameters
    ----------
    by_capture : dict
        Capture path → ``(rows, trials, summary, conditions)`` (:class:`~.runner.StudyResult`).

    Returns
    -------
    lines : list of dict
        One per condition (in the primary path's order, then any other
        path's own conditions, e.g. compression on the video path), keys
        ``condition``, ``factor`` and ``<metric> [<path>]``; NaN where a
        path did not record the condition.
    columns : list of str
    """
    modes = list(by_capture)
    tables = {m: {t["condition"]: t for t in condition_table(r, c, s)} for m, (r, _t, s, c) in by_capture.items()}
    order = list(dict.fromkeys(label for m in modes for label in tables[m]))
    lines = []
    for label in order:
        first = next(tables[m][label] for m in modes if label in tables[m])
        line = {"factor": first["factor"], "condition": label}
        for key in COMPARED:
            for m in modes:
                line[f"{key} [{m}]"] = tables[m].get(label, {}).get(key, float("nan"))
        lines.append(line)
    return lines, ["factor", "condition"] + [f"{k} [{m}]" for k in COMPARED for m in modes]


def conclusions(table: list[dict], summary: dict) -> list[str]:
    """Plain-language statements of which conditions suffice.

    A level *suffices* when its symbol accuracy is within 5 points of the
    baseline's and the observer's % correct is not significantly below the
    experts' 78.70 % (one-sided exact binomial test at 5 %: with ~70 trials
    a condition's % correct has a standard error of ~5 points, so a strict
    ``>=`` would call levels sufficient or not by chance); when no trials
    ran, on symbol accuracy alone.
    """
    base = next((t for t in table if t["factor"] == "baseline"), None)
    if base is None:
        return ["No baseline condition was measured."]
    lines = [
        (
            f"Baseline ({base['condition']}): symbol accuracy {base['symbol_accuracy']:.0%}, limb angle error "
            f"{base['angle_error_deg']:.1f}°, timing error {base['timing_error_s']:.3f} s; the automated observer "
            f"judged {base['percent_correct']:.1f} % of same/different trials correctly "
            f"(the thesis' experts: {THESIS['experiment1_overall']:.2f} %)."
        )
    ]

    def ok(t):
        good = t["symbol_accuracy"] >= base["symbol_accuracy"] - 0.05
        n = int(t.get("trials") or 0)
        if not math.isnan(t["percent_correct"]) and n:
            k = int(round(t["percent_correct"] / 100.0 * n))
            p = stats.binomtest(k, n, THESIS["experiment1_overall"] / 100.0, alternative="less").pvalue
            good = good and p >= 0.05
        return good

    names = {
        "frame_rate": "frame rate",
        "image_size": "image size",
        "view": "viewpoint",
        "cameras": "calibrated cameras",
        "compression": "compression",
        "noise": "pixel noise",
    }
    for factor, name in names.items():
        levels = [t for t in table if t["factor"] == factor]
        if not levels:
            if factor == "compression" and summary.get("capture") in ("truth", "keypoints"):
                lines.append("Compression: not measured — this capture path has no images to compress.")
            continue
        levels = _with_baseline(table, factor)
        measured = [t for t in levels if t["jobs"] > t["failed"]]
        if not measured:
            lines.append(f"{name.capitalize()}: not measured ({levels[0]['jobs']} jobs failed).")
            continue
        good = [_level(t, factor) for t in measured if ok(t)]
        bad = [
            f"{_level(t, factor)} (symbols {t['symbol_accuracy']:.0%}, observer {t['percent_correct']:.0f} %)"
            for t in measured
            if not ok(t)
        ]
        s = f"{name.capitalize()}: sufficient — {', '.join(good) if good else 'none of the levels tried'}."
        if bad:
            s += f" Not sufficient — {'; '.join(bad)}."
        if factor == "cameras":
            # What a second or third camera buys, in the figure it changes most.
            s += " Limb angle error: " + ", ".join(f"{_level(t, factor)} {t['angle_error_deg']:.1f}°" for t in measured)
            s += " (several cameras are calibrated with the renderer's cameras and triangulated)."
        lines.append(s)
    for method, s in summary.get("experiment2", {}).items():
        rates = ", ".join(f"{k:g} Hz {v:.0f} %" for k, v in sorted(s["by_frame_rate"].items()))
        lines.append(
            f"Experiment 2 design with {method} resampling: {s['overall']:.1f} % correct overall "
            f"(experts {THESIS['experiment2_overall']:.2f} %); by frame rate: {rates}."
        )
    return lines


def _bars(ax, labels, ours, thesis=None, title="", ylabel="% correct"):
    x = np.arange(len(labels))
    ax.bar(x - (0.2 if thesis else 0), ours, width=0.4 if thesis else 0.6, label="automated observer", color="#4a78b0")
    if thesis:
        t = [thesis.get(k, np.nan) for k in labels]
        ax.bar(x + 0.2, t, width=0.4, label="thesis' experts (text)", color="#d9a13b")
    ax.axhline(THESIS["experiment1_overall"], color="#b03a2e", ls="--", lw=1, label="experts overall, Exp. 1 (78.70 %)")
    ax.axhline(50, color="grey", ls=":", lw=1, label="chance")
    ax.set_xticks(x, labels, rotation=30, ha="right")
    ax.set_ylim(0, 105)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="lower right")


def _figures(rep: Report, result, table) -> None:
    plt = _plt()
    summ = result.summary
    exp1 = summ.get("experiment1", [])
    base = next((e for e in exp1 if e["factor"] == "baseline"), exp1[0] if exp1 else None)
    # Figure 3.13: by complexity, same vs different.
    if base:
        trials = [t for t in result.trials if t["experiment"] == 1 and t["condition"] == base["condition"]]
        comps = [c for c in ("easy", "medium", "hard") if any(t["complexity"] == c for t in trials)]
        fig, ax = plt.subplots(figsize=(5.5, 3.6))
        for k, (kind, col) in enumerate((("same", "#4a78b0"), ("different", "#7fb04a"))):
            vals = [
                100 * _mean([t["correct"] for t in trials if t["complexity"] == c and t["same"] == (kind == "same")])
                for c in comps
            ]
            ax.bar(np.arange(len(comps)) + (k - 0.5) * 0.38, vals, width=0.38, label=f"{kind} pairs", color=col)
        ax.axhline(THESIS["experiment1_overall"], color="#b03a2e", ls="--", lw=1, label="experts overall (78.70 %)")
        ax.set_xticks(range(len(comps)), comps)
        ax.set_ylim(0, 105)
        ax.set_ylabel("% correct")
        ax.set_title("By complexity (cf. Neagle Fig. 3.13)", fontsize=10)
        ax.legend(fontsize=7, loc="lower right")
        rep.figure(
            fig,
            "fig313_complexity",
            "Percentage of same/different trials judged correctly at each level of "
            "complexity, baseline condition (Experiment 1 design).",
        )
        # Figure 3.14: same pairs per emotion.
        same = sorted(
            {t["pair"] for t in trials if t["same"]},
            key=lambda p: ("happy", "sad", "angry", "afraid").index(p.split("-")[0]),
        )
        fig, ax = plt.subplots(figsize=(5.5, 3.6))
        _bars(
            ax,
            same,
            [100 * _mean([t["correct"] for t in trials if t["pair"] == p]) for p in same],
            THESIS["experiment2_same"],
            "Same-emotion pairs (cf. Fig. 3.14)",
        )
        rep.figure(
            fig,
            "fig314_same_pairs",
            "Same-emotion pairs judged 'same'. Orange: the percentages the thesis "
            "states for Experiment 2 (its Fig. 3.14 bars are not given as numbers).",
        )
        # Figure 3.15: different pairs.
        diff = sorted({t["pair"] for t in trials if not t["same"]})
        thesis_diff = dict(THESIS["experiment2_different"])
        fig, ax = plt.subplots(figsize=(6.0, 3.6))
        _bars(
            ax,
            diff,
            [100 * _mean([t["correct"] for t in trials if t["pair"] == p]) for p in diff],
            thesis_diff,
            "Different-emotion pairs (cf. Fig. 3.15)",
        )
        rep.figure(
            fig,
            "fig315_different_pairs",
            "Different-emotion pairs judged 'different'. The thesis found "
            "happy–angry (both fast in Laban's Time) at chance in Experiment 1.",
        )
    # Figure 3.16: by frame rate (Experiment 2 design).
    exp2_trials = [t for t in result.trials if t["experiment"] == 2]
    if exp2_trials:
        fig, ax = plt.subplots(figsize=(6.0, 3.8))
        for method, ls in (("keyframe", "-"), ("naive", "--")):
            for comp, mk in (("easy", "o"), ("hard", "s"), ("medium", "^")):
                sel = [t for t in exp2_trials if t["resampling"] == method and t["complexity"] == comp]
                if not sel:
                    continue
                rates = sorted({t["frame_rate"] for t in sel})
                ax.plot(
                    rates,
                    [100 * _mean([t["correct"] for t in sel if t["frame_rate"] == r]) for r in rates],
                    ls=ls,
                    marker=mk,
                    label=f"{method}, {comp}",
                )
        ax.axhline(
            THESIS["experiment2_overall"], color="#b03a2e", ls="--", lw=1, label="experts overall, Exp. 2 (78.99 %)"
        )
        ax.set_xlabel("frame rate (Hz)")
        ax.set_ylabel("% correct")
        ax.set_ylim(0, 105)
        ax.set_title("By frame rate (cf. Fig. 3.16)", fontsize=10)
        ax.legend(fontsize=7, loc="lower right")
        rep.figure(
            fig,
            "fig316_frame_rate",
            "Same/different accuracy by frame rate (Experiment 2 design: happy, sad, "
            "angry), with Neagle's key-frame-preserving resampling (solid) and naive decimation (dashed).",
        )
    # Recovery metrics by frame rate.
    fr = [t for t in table if t["factor"] in ("frame_rate", "baseline")]
    if fr:
        fig, axes = plt.subplots(1, 3, figsize=(11, 3.3))
        for key, ax, lab in zip(
            ("symbol_accuracy", "angle_error_deg", "time_abs_error"),
            axes,
            ("symbol accuracy", "limb angle error at key poses (deg)", "|Effort time error|"),
        ):
            for method, ls in (("keyframe", "-"), ("naive", "--")):
                pts = sorted((_rate_of(t), t[key]) for t in fr if method in t["condition"] or "25 Hz" in t["condition"])
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], ls=ls, marker="o", label=method)
            ax.set_xlabel("frame rate (Hz)")
            ax.set_title(lab, fontsize=9)
            ax.legend(fontsize=7)
        rep.figure(fig, "recovery_frame_rate", "Notation and Effort recovery against frame rate.")
    # Other factors.
    for factor, title in (
        ("image_size", "image size"),
        ("view", "viewpoint"),
        ("cameras", "the number and placement of calibrated cameras"),
        ("compression", "compression"),
        ("noise", "pixel noise"),
    ):
        if not any(t["factor"] == factor for t in table):
            continue
        lv = [t for t in _with_baseline(table, factor) if t["jobs"] > t["failed"]]
        fig, axes = plt.subplots(1, 3, figsize=(11, 3.3))
        labels = [_level(t, factor) for t in lv]
        for key, ax, lab in zip(
            ("symbol_accuracy", "angle_error_deg", "percent_correct"),
            axes,
            ("symbol accuracy", "limb angle error (deg)", "% correct (observer)"),
        ):
            ax.bar(range(len(lv)), [t[key] for t in lv], color="#4a78b0")
            ax.set_xticks(range(len(lv)), labels, rotation=20)
            ax.set_title(lab, fontsize=9)
            if key == "percent_correct":
                ax.axhline(THESIS["experiment1_overall"], color="#b03a2e", ls="--", lw=1)
                ax.set_ylim(0, 105)
        rep.figure(fig, f"factor_{factor}", f"Effect of {title} (other settings at the baseline).")


def _with_baseline(table, factor) -> list[dict]:
    """The levels of one factor, the baseline's own level included, in a natural order."""
    lv = [t for t in table if t["factor"] in (factor, "baseline")]
    if factor == "frame_rate":
        return sorted(lv, key=lambda t: (-_rate_of(t), t["condition"]))
    if factor == "image_size":
        return sorted(lv, key=lambda t: int(_level(t, factor).split("x")[0]))
    if factor == "view":
        order = ("front", "45", "side")
        return sorted(lv, key=lambda t: order.index(_level(t, factor)) if _level(t, factor) in order else 9)
    if factor == "cameras":  # one camera (the baseline), then by how many
        return sorted(lv, key=lambda t: len(_level(t, factor).split("+")))
    if factor == "noise":
        return sorted(lv, key=lambda t: float(_level(t, factor).split("=")[1]))
    return lv


def _rate_of(t) -> float:
    return float(t["condition"].split(" Hz")[0])


def _level(t, factor) -> str:
    parts = t["condition"].split(", ")
    levels = {
        "frame_rate": parts[0],
        "image_size": parts[1],
        "view": parts[2],
        "cameras": parts[2],
        "compression": parts[3],
        "noise": parts[4],
    }
    return levels.get(factor, t["condition"])


def write_report(result, outdir, capture_note: str = "") -> str:
    """Write ``report.html`` (and its plots) for a finished study; return its path."""
    summ = result.summary
    rep = Report("Fidelity study: what recording quality is enough?", outdir)
    table = condition_table(result.rows, result.conditions, summ)
    rep.heading("Conclusions")
    rep.bullets(conclusions(table, summ), css_class="summary")
    cfg = summ.get("config", {})
    jobs = summ.get("jobs", {})
    rep.paragraph(
        f"{jobs.get('total', 0)} jobs ({jobs.get('ran', 0)} run now, {jobs.get('cached', 0)} from the cache, "
        f"{jobs.get('failed', 0)} failed); seed {cfg.get('seed')}; capture path '{summ.get('capture')}'; "
        f"wall time of this run {result.wall_seconds:.0f} s on {os.cpu_count()} cores "
        f"(load average {os.getloadavg()[0]:.1f} at the end; cached jobs cost nothing); the jobs took "
        f"{jobs.get('job_seconds', float('nan')):.0f} s in all when they ran (each job's wall time, at whatever "
        f"load the machine had), i.e. about "
        f"{jobs.get('job_seconds', float('nan')) / max(os.cpu_count() or 1, 1) / 60:.1f} min on {os.cpu_count()} cores."
    )
    note = (
        f"How this study captured the performances: {capture_note or summ.get('capture')}. The virtual dancer "
        f"performs each phrase with each emotion's Effort and tempo (Neagle Tables 5.1–5.5) plus a seeded "
        f"take-to-take variation; keypoint jitter is the condition's pixel noise plus a {DETECTOR_FLOOR_PX:g} px "
        f"detector floor, rounded to the pixel grid. These are stated models, not a camera."
    )
    rep.paragraph(note, css_class="note")
    rep.heading("Same/different emotion judgements (Neagle Experiments 1–2)")
    _figures(rep, result, table)
    rep.heading("Every condition")
    cols = [
        "factor",
        "condition",
        "jobs",
        "failed",
        "symbol_accuracy",
        "notation_accuracy",
        "angle_error_deg",
        "timing_error_s",
        "mpjpe_mm",
        "time_abs_error",
        "weight_abs_error",
        "space_abs_error",
        "coverage",
        "percent_correct",
    ]
    rep.table(
        table,
        cols,
        caption="Means over the test takes of each condition; percent_correct is Experiment 1's "
        "design under that condition.",
    )
    obs = summ.get("observer", {})
    rep.paragraph(
        f"Observer: says 'same' when the RMS of the scaled differences of {', '.join(obs.get('features', []))} is at most "
        f"{obs.get('threshold', float('nan')):.3f} (scales {', '.join(f'{s:.3g}' for s in obs.get('scale', []))}), "
        "calibrated on separate training takes recorded at the baseline."
    )
    by_capture = getattr(result, "by_capture", {})
    if len(by_capture) > 1:
        rep.heading("Capture paths compared")
        lines, cols = capture_comparison(by_capture)
        rep.paragraph(
            "The same performances under the same conditions captured on each path ("
            + "; ".join(f"{m}: {CAPTURE_NOTES.get(m, m)}" for m in by_capture)
            + "). The simulated keypoint path's world landmarks carry Gaussian noise, whereas BlazePose errs by "
            "flipping depth, so the gap between the paths is what idealised perception hides.",
            css_class="note",
        )
        rep.table(lines, cols, caption="Means over the test takes; NaN where a path did not record the condition.")
    errs = sorted({r["error"] for m in by_capture for r in by_capture[m][0] if r.get("error")})
    if errs:
        rep.heading("Failures")
        rep.bullets(errs[:20])
    return str(rep.write("report.html"))
