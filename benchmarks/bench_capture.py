"""Benchmark of the capture stage: speed and symbol accuracy.

Run ``/work/venv/bin/python benchmarks/bench_capture.py [--random N] [--video K]``.

Prints (never asserts):

1. quantisation speed (frames per second of :func:`segment_motion`);
2. truth round trip: built-in phrases and N random scores interpreted by the
   virtual dancer, quantised from their truth joints — exact symbol matches
   with the tempo given, and how often the estimated tempo is right;
3. with ``--video K``: the whole capture (render → keypoints → fit →
   quantise) on K random scores — symbol agreement, median start error and
   frames per second of the whole capture.

:func:`score_agreement` is the reusable metric (it wraps
:func:`capture2notation.quantise.agreement.compare_scores`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation.notation.model import Score
from capture2notation.quantise.agreement import compare_scores, score_differences
from capture2notation.quantise.segment import segment_motion


def score_agreement(reference: Score, captured: Score, step=Fraction(1)) -> dict:
    """Symbol agreement and start-time error of `captured` against `reference`.

    Parameters
    ----------
    reference, captured : Score
    step : Fraction
        Sampling step in beats of the per-part agreement (1 = per beat).

    Returns
    -------
    dict
        ``symbol_agreement`` (direction + level per part per beat, in
        [0, 1]), ``median_start_error`` (beats, NaN when nothing matched),
        ``matched``, ``unmatched`` (reference gesture symbols with / without a
        captured symbol of the same part and destination) and ``exact``.
    """
    a = compare_scores(reference, captured, step=step)
    return {
        "symbol_agreement": a.symbol_agreement,
        "median_start_error": a.median_start_error,
        "matched": a.matched,
        "unmatched": a.unmatched,
        "exact": a.exact,
    }


#: Random-score families of the truth benchmark: parts drawn, arms split into segments.
FAMILIES = {
    "arms": (("right_arm", "left_arm"), False),
    "arms+head": (("right_arm", "left_arm", "head"), False),
    "split arms": (("right_arm", "left_arm"), True),
    "arms+head+chest": (("right_arm", "left_arm", "head", "chest"), False),
    "full (arms, head, chest, legs, supports)": (("right_arm", "left_arm", "head", "chest", "legs"), False),
}


def dancer_misses(score, motion, tol_deg: float = 0.05) -> int:
    """Gesture symbols whose written pose the dancer does not reach exactly.

    At each gesture symbol's arrival frame, the part's vector must be within
    `tol_deg` of its canonical vector (and a limb's bend within `tol_deg` of
    30° × bend).  Joint extremes stop some targets short; the quantiser then
    reads what was performed, not what was written.
    """
    from capture2notation.notation.directions import canonical_vector
    from capture2notation.quantise.labels import label_frames

    lab = label_frames(motion.joints(), motion.fps)
    misses = 0
    for sym, _, f1 in motion.events:
        if sym.is_support:
            continue
        f = min(f1, lab.vectors.shape[0] - 1)
        v = lab.vectors[f, lab.index(sym.part)]
        c = canonical_vector(sym.direction, sym.level)
        off = np.degrees(np.arctan2(np.linalg.norm(np.cross(v, c)), float(v @ c)))
        bend = lab.bend_deg[f, lab.index(sym.part)]
        bad_bend = np.isfinite(bend) and abs(bend - 30.0 * sym.bend) > tol_deg
        misses += bool(off > tol_deg or bad_bend)
    return misses


def _round_trip(scores, fps: float):
    """(exact count, tempo right count, frames, quantisation seconds, failures) over `scores`."""
    from synthetic.interpret import interpret

    exact = tempo_ok = frames = 0
    seconds = 0.0
    agree = []
    failures = []
    missed = exact_reached = 0
    for name, score in scores:
        motion = interpret(score, fps=fps)
        joints = motion.joints()
        miss = dancer_misses(score, motion) > 0
        missed += miss
        t0 = time.perf_counter()
        seg = segment_motion(joints, fps, tempo=score.tempo)
        seconds += time.perf_counter() - t0
        frames += joints.shape[0]
        diffs = score_differences(score, seg.score)
        exact += not diffs
        exact_reached += not diffs and not miss
        agree.append(score_agreement(score, seg.score)["symbol_agreement"])
        if diffs:
            failures.append((name, diffs))
        tempo_ok += segment_motion(joints, fps).tempo == score.tempo
    return exact, tempo_ok, frames, seconds, failures, float(np.mean(agree)), (missed, exact_reached)


def bench_truth(n_random: int, seed: int, fps: float = 25.0, show: int = 3) -> None:
    """Exactness of the truth round trip (virtual dancer → joints → score), and quantisation speed."""
    import warnings

    from synthetic.phrases import builtin_phrases
    from synthetic.random_scores import random_score

    warnings.simplefilter("ignore")  # the dancer warns about targets beyond its extremes
    rows = [("built-in phrases", list(builtin_phrases().items()))]
    for label, (parts, split) in FAMILIES.items() if n_random > 0 else ():
        rng = np.random.default_rng(seed)
        rows.append((label, [(f"{label} #{i}", random_score(rng, n_beats=8, parts=parts, split_arms=split,
                                                            random_effort=bool(i % 2))) for i in range(n_random)]))
    print(f"truth round trip at {fps:g} fps (tempo given; half the random scores with a random Effort)")
    total_frames, total_s = 0, 0.0
    for label, scores in rows:
        exact, tempo_ok, frames, secs, failures, agree, (missed, exact_reached) = _round_trip(scores, fps)
        total_frames += frames
        total_s += secs
        n = len(scores)
        print(f"  {label:42s} exact {exact:3d}/{n} = {100 * exact / n:5.1f} %   agreement {100 * agree:5.1f} %   "
              f"estimated tempo right {tempo_ok}/{n}")
        print(f"      the dancer reaches every written pose in {n - missed}/{n}; of those, exact {exact_reached}/{n - missed}")
        for name, diffs in failures[:show]:
            print(f"      {name}: " + "; ".join(diffs[:3]))
    print(f"  quantisation speed: {total_frames / total_s:,.0f} frames/s ({total_frames} frames)")


def bench_video(k: int, seed: int, backend: str, view: str, size=(640, 480)) -> None:
    """The whole capture on rendered videos of random scores."""
    from pipelines.capture import capture
    from synthetic.random_scores import random_score
    from synthetic.render import render_score

    rng = np.random.default_rng(seed)
    style = "markers" if backend == "markers" else "mannequin"
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_capture_") as tmp:
        for i in range(k):
            score = random_score(rng, n_beats=8)
            d = Path(tmp) / f"s{i}"
            render_score(score, d, fps=25.0, size=size, view=view, style=style, progress=False)
            t0 = time.perf_counter()
            res = capture(d / "video.mp4", d / "cap", backend=backend, tempo=score.tempo, progress=False,
                          effort=False, overlay=False)
            dt = time.perf_counter() - t0
            a = score_agreement(score, res.score)
            rows.append((a, res.n_frames, dt))
            print(f"  score {i}: agreement {a['symbol_agreement']:.3f}, median start error "
                  f"{a['median_start_error']:.3f} beats, {a['unmatched']} unmatched, {res.n_frames / dt:.1f} frames/s")
    agree = np.mean([r[0]["symbol_agreement"] for r in rows])
    starts = np.nanmedian([r[0]["median_start_error"] for r in rows])
    fps = sum(r[1] for r in rows) / sum(r[2] for r in rows)
    print(f"whole capture ({backend}, {view}, {size[0]}x{size[1]}, {k} random scores, tempo given)")
    print(f"  symbol agreement (direction + level per part per beat): {100 * agree:.1f} %")
    print(f"  median start-time error: {starts:.3f} beats")
    print(f"  speed: {fps:.1f} frames/s (render excluded)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--random", type=int, default=20, help="random scores per family for the truth round trip")
    ap.add_argument("--video", type=int, default=0, help="random scores for the whole capture (slow)")
    ap.add_argument("--backend", default="blazepose", choices=("blazepose", "markers"))
    ap.add_argument("--view", default="front")
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args()
    bench_truth(args.random, args.seed)
    if args.video:
        bench_video(args.video, args.seed + 1, args.backend, args.view)


if __name__ == "__main__":
    main()
