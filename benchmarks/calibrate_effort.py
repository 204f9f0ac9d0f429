"""Calibration study of the Effort estimator (issue 3) — prints its figures.

Part 1, recovery: synthetic performances with known Effort (b ~ U[−4.5, −1.8],
x0 ~ U[0.3, 0.8], S ∈ {0, 0.5, 1}), animated by the virtual dancer
(``synthetic.interpret``) and read back from the truth joints at 25 Hz:
median absolute error of b and x0, and how often the 90 % intervals contain
the truth.  Also with capture-like Gaussian jitter on the joints.

Part 2, emotion: performances of the four presets by synthetic performers
who vary about the preset (``emotion.PERFORMER_SD``).  A calibration set
(seed 2005) fits the per-feature spreads (``--derive`` prints the
``SPREAD`` constant of ``capture2notation/effort/emotion.py``); a separate
test set (seed 2006) gives the 4-way confusion matrix and Neagle's
Experiment 1 same/different judgements (% correct overall and per pair).

Through BlazePose (``--blazepose N``): :func:`recovery_through_capture`
with :func:`blazepose_capture` renders each performance, reads it back with
``pipelines.capture.capture`` (BlazePose, 3D fitting) and scores the Effort
estimated from those joints.

Usage::

    /work/venv/bin/python benchmarks/calibrate_effort.py [--quick] [--derive] [--workers 2] [--blazepose N]
"""

from __future__ import annotations

import argparse
import concurrent.futures
import itertools
import time
from fractions import Fraction

import numpy as np

from capture2notation.body import JOINTS
from capture2notation.effort import estimate_effort
from capture2notation.effort.emotion import (
    PERFORMER_SD,
    emotion_probabilities,
    preset_features,
)
from capture2notation.effort.estimate import _emotion_input
from capture2notation.notation.effort import PRESETS
from capture2notation.notation.model import Effort
from synthetic.arcs import arc_motion, random_arm_score

try:
    from synthetic.interpret import interpret
except ImportError:  # the dancer not installed: fall back to the reference arcs
    interpret = None

FPS = 25.0
EMOTIONS = tuple(PRESETS)


def _truth_joints(score, fps=FPS):
    """(T, J, 3) truth joints of `score` from the virtual dancer (or the reference arcs)."""
    if interpret is not None:
        return interpret(score, fps=fps).joints()
    return arc_motion(score, fps)


def _performance(seed: int, effort: Effort, tempo, n_moves: int = 3):
    """A seeded arm phrase performed with `effort` at `tempo`."""
    rng = np.random.default_rng(seed)
    part = ("right_arm", "left_arm")[int(rng.integers(2))]
    return random_arm_score(rng, n_moves, tempo=tempo, part=part, effort=effort)


#: Options of estimate_effort for every recovery run (set by main()).
ESTIMATE_KW: dict = {}


def _recovery_job(args):
    seed, noise, capture_fn, est_kw = args
    rng = np.random.default_rng(seed)
    truth = Effort(
        time=float(rng.uniform(-4.5, -1.8)),
        weight=float(rng.uniform(0.3, 0.8)),
        space=float(rng.choice([0.0, 0.5, 1.0])),
    )
    score = _performance(seed, truth, 60)
    if capture_fn is None:
        joints = _truth_joints(score)
        if noise > 0:
            joints = joints + noise * rng.standard_normal(joints.shape)
        conf, fps, times = None, FPS, None
    else:
        joints, conf, fps, times, captured = capture_fn(score, FPS)
        if est_kw.get("windows") == "captured":
            score = captured.replace(effort=score.effort)
    t0, c0 = time.perf_counter(), time.process_time()
    res = estimate_effort(
        joints,
        conf,
        fps,
        score,
        rng=rng,
        times=times,
        refine=est_kw.get("refine", True),
        sampler_kw=est_kw.get("sampler_kw"),
    )
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    rows = []
    for m in res.movements:
        rows.append(
            (
                truth.time,
                truth.weight,
                truth.space,
                m.posterior.summary(0),
                m.posterior.summary(1),
                {"median": m.space.median, "ci90": m.space.ci90},
                m.posterior.converged,
            )
        )
    return rows, wall, cpu, len(res.movements) + len(res.parts) + (res.pooled is not None)


def _print_recovery(title, results):
    rows = [r for rr, *_ in results for r in rr]
    wall = sum(w for _, w, _, _ in results)
    cpu = sum(c for _, _, c, _ in results)
    n_post = sum(n for *_, n in results)
    eb = np.array([abs(r[3]["median"] - r[0]) for r in rows])
    ex = np.array([abs(r[4]["median"] - r[1]) for r in rows])
    es = np.array([abs(r[5]["median"] - r[2]) for r in rows])

    def cover(k, j):
        return 100 * np.mean([r[k]["ci90"][0] <= r[j] <= r[k]["ci90"][1] for r in rows])

    conv = 100 * np.mean([r[6] for r in rows])
    print(f"\n== {title}: {len(results)} performances, {len(rows)} movements ==")
    print(f"  median |error| b  = {np.median(eb):.4f}   (aim <= 0.3)    90th pct {np.percentile(eb, 90):.4f}")
    print(f"  median |error| x0 = {np.median(ex):.4f}   (aim <= 0.05)   90th pct {np.percentile(ex, 90):.4f}")
    print(f"  median |error| S  = {np.median(es):.4f}")
    print(f"  90% interval coverage: b {cover(3, 0):.1f}%  x0 {cover(4, 1):.1f}%  S {cover(5, 2):.1f}%  (aim 85-95%)")
    print(f"  converged: {conv:.1f}% of movement posteriors")
    print(f"  time: {wall / n_post:.2f} s wall, {cpu / n_post:.2f} s CPU per posterior (shared machine)")


def recovery(n_perf: int, seed: int, noise: float, workers: int, capture_fn=None, title=None):
    """Run part 1 on `n_perf` performances; returns the per-performance results."""
    seeds = np.random.default_rng(seed).integers(0, 2**63 - 1, size=n_perf)
    args = [(int(s), noise, capture_fn, dict(ESTIMATE_KW)) for s in seeds]
    if workers > 1 and capture_fn is None:
        with concurrent.futures.ProcessPoolExecutor(workers) as ex:
            results = list(ex.map(_recovery_job, args))
    else:
        results = [_recovery_job(a) for a in args]
    _print_recovery(title or f"recovery from truth joints at 25 Hz, joint jitter {noise * 1000:g} mm", results)
    return results


def recovery_through_capture(capture_fn, n_perf: int = 30, seed: int = 1974):
    """Part 1 through a capture path (e.g. render → BlazePose → 3D fitting).

    Parameters
    ----------
    capture_fn : callable
        ``capture_fn(score, fps) -> (joints (T,J,3), confidence (T,J), fps, times (T,), captured Score)``:
        animate and render `score`, then recover 3D joints (and the quantised
        score) from the video.  The movement windows come from the truth
        score unless ``ESTIMATE_KW["windows"] == "captured"``.
    """
    return recovery(n_perf, seed, 0.0, 1, capture_fn=capture_fn, title="recovery through the capture path")


#: Captures already made in this process (a second prior reads the same videos).
_CAPTURED: dict = {}


def blazepose_capture(score, fps=FPS, size=(640, 480), view="front"):
    """A `capture_fn` for :func:`recovery_through_capture`: render → BlazePose → 3D joints.

    The virtual dancer performs and the renderer films `score`
    (``synthetic.render.render_score``); ``pipelines.capture.capture``
    (BlazePose keypoints and 3D fitting, Effort off) reads the video back.

    Returns
    -------
    joints (T, J, 3), confidence (T, J), fps, times (T,)
        From the capture's ``capture.npz``.
    captured : Score
        The capture's quantised ``score.lab``.
    """
    key = (repr(score), fps, size, view)
    if key not in _CAPTURED:
        _CAPTURED[key] = _blazepose_capture(score, fps, size, view)
    return _CAPTURED[key]


def _blazepose_capture(score, fps, size, view):
    import tempfile
    from pathlib import Path

    from capture2notation.notation import read
    from pipelines.capture import capture
    from synthetic.render.job import render_score

    with tempfile.TemporaryDirectory(prefix="c2n-effort-cal-") as tmp:
        tmp = Path(tmp)
        render_score(score, tmp / "render", fps=fps, size=size, view=view, progress=False)
        capture(
            tmp / "render" / "video.mp4",
            tmp / "capture",
            effort=False,
            overlay=False,
            progress=False,
            tempo=float(score.tempo),
        )
        with np.load(tmp / "capture" / "capture.npz") as z:
            names = tuple(str(n) for n in z["joint_names"])
            if names != tuple(JOINTS):
                raise RuntimeError(f"capture joints {names} differ from the canonical {tuple(JOINTS)}")
            return (
                np.asarray(z["joints"], float),
                np.asarray(z["confidence"], float),
                float(z["fps"]),
                np.asarray(z["times"], float),
                read(tmp / "capture" / "score.lab"),
            )


# --- emotion -------------------------------------------------------------------
def _performer(rng, emotion: str):
    """Effort and tempo of one synthetic performer of `emotion` (preset + variation)."""
    p = PRESETS[emotion]
    sd = PERFORMER_SD
    b = float(np.clip(p.effort.time + sd[0] * rng.standard_normal(), -4.9, -1.6))
    x0 = float(np.clip(p.effort.weight + sd[1] * rng.standard_normal(), 0.1, 0.9))
    s = float(np.clip(p.effort.space + sd[2] * rng.standard_normal(), 0.0, 1.0))
    tempo = float(p.tempo) * float(np.exp(sd[3] * rng.standard_normal()))
    return Effort(b, x0, s), Fraction(round(tempo * 4), 4)


def _emotion_job(args):
    seed, emotion = args
    rng = np.random.default_rng(seed)
    effort, tempo = _performer(rng, emotion)
    score = _performance(seed, effort, tempo, n_moves=4)
    res = estimate_effort(_truth_joints(score), None, FPS, score, rng=rng, per_movement=False)
    x, sd = _emotion_input(res.pooled, res.tempo)
    return emotion, x, sd


def emotion_set(n_per: int, seed: int, workers: int):
    """Features of `n_per` performers per emotion: list of (emotion, x (4,), sd (4,))."""
    seeds = np.random.default_rng(seed).integers(0, 2**63 - 1, size=n_per * len(EMOTIONS))
    args = [(int(s), EMOTIONS[i % len(EMOTIONS)]) for i, s in enumerate(seeds)]
    if workers > 1:
        with concurrent.futures.ProcessPoolExecutor(workers) as ex:
            return list(ex.map(_emotion_job, args))
    return [_emotion_job(a) for a in args]


def derive_spread(cal) -> tuple:
    """RMS of (feature − preset) over a calibration set: the SPREAD constant."""
    names, mu = preset_features()
    resid = np.array([x - mu[names.index(e)] for e, x, _ in cal])
    return tuple(float(v) for v in np.sqrt(np.mean(resid**2, axis=0)))


def emotion_figures(test, spread, seed: int, trials_per_pair: int = 200):
    """4-way confusion matrix and same/different pair judgements on a test set."""
    probs = [(e, emotion_probabilities(x, sd, spread)) for e, x, sd in test]
    conf = np.zeros((4, 4), dtype=int)
    for e, p in probs:
        conf[EMOTIONS.index(e), EMOTIONS.index(max(p, key=p.get))] += 1
    print("\n== emotion: 4-way confusion (rows truth, columns judged) ==")
    print("          " + " ".join(f"{e:>7}" for e in EMOTIONS))
    for i, e in enumerate(EMOTIONS):
        print(f"  {e:>7} " + " ".join(f"{v:7d}" for v in conf[i]) + f"   {100 * conf[i, i] / conf[i].sum():5.1f}%")
    print(f"  overall {100 * np.trace(conf) / conf.sum():.1f}% correct")

    rng = np.random.default_rng(seed)
    by = {e: [p for ee, p in probs if ee == e] for e in EMOTIONS}
    pairs = [(a, a) for a in EMOTIONS] + list(itertools.combinations(EMOTIONS, 2))
    print("\n== emotion: same/different pairs (Neagle Experiment 1 design; experts 78.7% overall) ==")
    correct_all = []
    for a, b in pairs:
        ok = []
        for _ in range(trials_per_pair):
            i = rng.integers(len(by[a]))
            j = rng.integers(len(by[b]))
            if a == b and len(by[a]) > 1:
                while j == i:  # two different performers
                    j = rng.integers(len(by[b]))
            pa, pb = by[a][i], by[b][j]
            same = max(pa, key=pa.get) == max(pb, key=pb.get)
            ok.append(same == (a == b))
        correct_all += ok
        print(f"  {a + '-' + b:<14} {100 * np.mean(ok):5.1f}% correct")
    print(
        f"  overall   {100 * np.mean(correct_all):5.1f}% correct ({len(pairs)} pair types x {trials_per_pair} trials)"
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="Small sets (a smoke run).")
    ap.add_argument("--derive", action="store_true", help="Print the SPREAD constant from the calibration set.")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--skip-recovery", action="store_true")
    ap.add_argument("--skip-emotion", action="store_true")
    ap.add_argument(
        "--blazepose",
        type=int,
        default=0,
        metavar="N",
        help="Also part 1 through render -> BlazePose -> 3D fitting on N performances (slow).",
    )
    ap.add_argument(
        "--windows",
        choices=("truth", "captured"),
        default="truth",
        help="Through BlazePose: movement windows from the truth score or the captured (quantised) one.",
    )
    ap.add_argument("--no-refine", action="store_true", help="Use the score's windows as given (no refinement).")
    ap.add_argument(
        "--rho-prior",
        choices=("default", "capture", "both"),
        default="default",
        help="Through BlazePose: the AR(1) rho prior RHO_RANGE, CAPTURE_RHO_RANGE, or both on the same captures.",
    )
    a = ap.parse_args(argv)
    ESTIMATE_KW.update(windows=a.windows, refine=not a.no_refine)
    n_perf, n_emo = (6, 6) if a.quick else (40, 30)
    print(
        f"dancer: {'synthetic.interpret' if interpret is not None else 'reference arcs (synthetic.interpret missing)'}"
    )
    if not a.skip_recovery:
        recovery(n_perf, 1974, 0.0, a.workers)
        recovery(n_perf, 1974, 0.005, a.workers)
    if a.blazepose:
        from capture2notation.effort.likelihood import CAPTURE_RHO_RANGE

        priors = {"default": [None], "capture": [CAPTURE_RHO_RANGE], "both": [None, CAPTURE_RHO_RANGE]}[a.rho_prior]
        for rho_range in priors:
            ESTIMATE_KW["sampler_kw"] = None if rho_range is None else {"rho_range": rho_range}
            print(f"\nrho prior: {'RHO_RANGE' if rho_range is None else 'CAPTURE_RHO_RANGE'}")
            recovery_through_capture(blazepose_capture, n_perf=a.blazepose)
    if not a.skip_emotion:
        t0 = time.perf_counter()
        cal = emotion_set(n_emo, 2005, a.workers)
        spread = derive_spread(cal)
        print(
            f"\ncalibration set (seed 2005, {len(cal)} performances): SPREAD = "
            f"({', '.join(f'{v:.4f}' for v in spread)})  [time, weight, space, log_tempo]"
        )
        if not a.derive:
            from capture2notation.effort.emotion import SPREAD

            spread = SPREAD
            print(f"using the stored SPREAD = {SPREAD}")
        test = emotion_set(n_emo, 2006, a.workers)
        emotion_figures(test, spread, seed=7)
        print(f"(emotion study {time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
