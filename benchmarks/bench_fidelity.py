"""Benchmark of the comparison maths and the fidelity study.

Run: ``/work/venv/bin/python benchmarks/bench_fidelity.py [--quick-study]``

Prints: resampling and DTW speed, seconds per study job on each capture
path (and the full default study's estimated wall time on this machine's
cores), and with ``--quick-study`` the wall time of ``c2n fidelity-study
--quick`` and its observer accuracy.  Nothing is asserted.
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
    args = ap.parse_args()
    bench_resample()
    bench_dtw()
    bench_jobs()
    if args.quick_study:
        bench_quick_study()


if __name__ == "__main__":
    main()
