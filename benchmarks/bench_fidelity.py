"""Benchmark of the comparison maths and the fidelity study.

Run: ``python benchmarks/bench_fidelity.py [--only] [--video 8] [--workers keypoints] [--quick-study]``

Prints: resampling and DTW speed, seconds per study job on each capture
path (and the full default study's estimated wall time on this machine's
cores); with ``--video N`` the seconds of N seeded random jobs of the full
default grid on the real video path and the full video study's estimate;
with ``--workers PATH`` the wall time of a small study (24 jobs) with 1, 2
and 4 local worker processes and the speed-ups; with ``--quick-study`` the wall
time of ``c2n fidelity-study --quick`` and its observer accuracy.  ``--only``
skips the first three.  Nothing is asserted.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np


def bench_resample() -> None:
    from capture2notation.compare.resample import decimate, keyframe_resample

    n = 200_000
    keys = np.sort(np.random.default_rng(0).choice(n, 5_000, replace=False))
    t = time.perf_counter()
    kept = keyframe_resample(n, keys, 5, 25)
    dt = time.perf_counter() - t
    print(f"keyframe_resample: {n / dt:,.0f} source frames/s ({len(kept)} kept of {n}, {len(keys)} key frames)")
    t = time.perf_counter()
    decimate(n, 5, 25)
    print(f"decimate: {n / (time.perf_counter() - t):,.0f} source frames/s")


def bench_dtw() -> None:
    from capture2notation.compare.align import dtw

    for n in (250, 500, 1000):
        c = np.random.default_rng(1).random((n, n))
        t = time.perf_counter()
        dtw(c)
        print(f"DTW {n}x{n}: {time.perf_counter() - t:.3f} s")


def bench_jobs() -> None:
    from pipelines.fidelity.conditions import Job, Performance, build_conditions, build_jobs, phrase_complexity
    from pipelines.fidelity.config import StudyConfig
    from pipelines.fidelity.measure import builtin_scores
    from pipelines.fidelity.runner import run_condition

    cfg = StudyConfig()
    scores = builtin_scores()
    comp = phrase_complexity(scores)
    conds = build_conditions(cfg)
    n_jobs = {
        mode: len(build_jobs(cfg, sorted(scores), comp, [c for c in conds if c.compression == 0]))
        for mode in ("truth", "keypoints")
    }
    cores = os.cpu_count() or 1
    for mode in ("truth", "keypoints"):
        secs = []
        for name in sorted(scores):
            for emotion in ("happy", "sad"):
                job = Job(conds[0], Performance(name, comp[name], emotion, 0, "test"))
                t = time.perf_counter()
                row = run_condition(job, 0, mode, bootstrap=cfg.bootstrap)
                secs.append(time.perf_counter() - t)
                print(
                    f"  {mode:9s} {name:13s} {emotion:5s} {secs[-1]:6.2f} s  symbols {row.get('symbol_accuracy', float('nan')):.2f}"
                    f"  angle err {row.get('angle_error_deg', float('nan')):5.1f} deg  MPJPE {row.get('mpjpe_mm', float('nan')):6.1f} mm"
                    f"  {row['error']}"
                )
        mean = float(np.mean(secs))
        print(
            f"{mode}: {mean:.2f} s per job; full default study = {n_jobs[mode]} jobs -> "
            f"ESTIMATED {n_jobs[mode] * mean / cores / 60:.1f} min on {cores} cores (load: {os.getloadavg()[0]:.1f})"
        )


def bench_video_sample(n: int = 8, seed: int = 0) -> None:
    """Seconds per video job on a seeded random sample of the full default grid, and the study's estimate."""
    from pipelines.fidelity.conditions import build_conditions, build_jobs, phrase_complexity
    from pipelines.fidelity.config import StudyConfig
    from pipelines.fidelity.measure import builtin_scores
    from pipelines.fidelity.runner import run_condition

    cfg = StudyConfig(capture="video")
    scores = builtin_scores()
    jobs = build_jobs(cfg, sorted(scores), phrase_complexity(scores), build_conditions(cfg))
    pick = np.random.default_rng(seed).choice(len(jobs), n, replace=False)
    secs, cpu = [], []
    for i in pick:
        j = jobs[i]
        t, c = time.perf_counter(), time.process_time()
        row = run_condition(j, cfg.seed, "video", bootstrap=cfg.bootstrap)
        secs.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        print(
            f"  video {j.performance.phrase:13s} {j.performance.emotion:6s} {j.condition.label:45s} "
            f"{row['frames']:4d} frames {secs[-1]:5.1f} s (cpu {cpu[-1]:5.1f} s) {row['error']}"
        )
    cores = os.cpu_count() or 1
    mean, sd = float(np.mean(secs)), float(np.std(secs, ddof=1))
    print(
        f"video: {mean:.1f} s per job (sd {sd:.1f}, cpu {np.mean(cpu):.1f} s, n={n}, seeded random sample); full "
        f"default study on the video path = {len(jobs)} jobs -> ESTIMATED {len(jobs) * mean / cores / 60:.0f} min "
        f"on {cores} cores (perfect scaling; load {os.getloadavg()[0]:.1f})"
    )


def bench_workers(capture: str = "keypoints", repeats: int = 2) -> None:
    """Wall time of one small study with 1, 2 and 4 local worker processes (fresh caches)."""
    from pipelines.fidelity import StudyConfig, run_study

    cfg = StudyConfig(
        phrases=("figure7", "port_de_bras"),
        emotions=("happy", "sad"),
        takes=2,
        training_takes=2,
        capture=capture,
        frame_rates=(25, 5),
        resampling=("keyframe",),
        image_sizes=((320, 240),),
        views=("front",),
        cameras=(),
        compression=(0,),
        noise=(0.0,),
        bootstrap=10,
        baseline={"frame_rate": 25, "image_size": (320, 240), "view": "front", "compression": 0, "noise": 0.0},
    )
    import resource

    def cpu() -> float:
        own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

    wall = {}
    for _rep in range(repeats):
        for w in (1, 2, 4):
            with tempfile.TemporaryDirectory() as d:
                load = os.getloadavg()[0]
                t, c = time.perf_counter(), cpu()
                res = run_study(cfg, d, workers=w, progress=False)
                wall.setdefault(w, []).append(time.perf_counter() - t)
                print(
                    f"  {capture} study, {res.summary['jobs']['total']} jobs, {w} worker(s): {wall[w][-1]:.1f} s wall, "
                    f"{cpu() - c:.1f} s CPU (load before {load:.1f})"
                )
    best = {w: min(v) for w, v in wall.items()}
    print(
        f"speed-up 1 -> 2 local workers ({capture}): {best[1] / best[2]:.2f}x, 1 -> 4: {best[1] / best[4]:.2f}x "
        f"(MEASURED, best of {repeats}; load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"
    )


def bench_quick_study() -> None:
    from pipelines.fidelity import load_config, run_fidelity_study

    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        res = run_fidelity_study(load_config(), d, is_quick=True, progress=False)
        wall = time.perf_counter() - t
        base = next(e for e in res.summary["experiment1"] if e["factor"] == "baseline")
        print(
            f"quick study: {res.summary['jobs']['total']} jobs in {wall:.0f} s (MEASURED); observer at baseline "
            f"{base['percent_correct']:.1f} % correct (experts 78.70 %)"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick-study", action="store_true", help="also time c2n fidelity-study --quick")
    ap.add_argument("--video", type=int, default=0, metavar="N", help="time N random video jobs of the full study")
    ap.add_argument(
        "--workers", choices=("keypoints", "video", "truth"), help="time 1, 2 and 4 workers on a small study"
    )
    ap.add_argument("--only", action="store_true", help="skip the resampling, DTW and per-job figures")
    args = ap.parse_args()
    if not args.only:
        bench_resample()
        bench_dtw()
        bench_jobs()
    if args.video:
        bench_video_sample(args.video)
    if args.workers:
        bench_workers(args.workers)
    if args.quick_study:
        bench_quick_study()


if __name__ == "__main__":
    main()
