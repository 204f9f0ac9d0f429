"""Speed of the Effort estimator — prints seconds per posterior and per phrase.

1. Seconds per converged movement posterior (aim ≤ 0.2 s): one-beat arm
   movements at 60 bpm (25 frames) from the virtual dancer's truth joints
   with 5 mm joint jitter — each sampled on its own (``sample_posterior``)
   and all together as independent ensembles of one vectorised emcee run
   (``sample_posteriors``, how ``estimate_effort`` samples a phrase).
2. A 60-second phrase (both arms moving throughout, 1–2 beat symbols at
   60 bpm) through ``estimate_effort`` with 1 and with `--workers` processes
   (aim ≤ 30 s on 2 cores).
3. With ``--capture DIR`` (a ``c2n capture`` output folder holding
   ``capture.npz`` and ``score.lab``): the capture pipeline's Effort step —
   ``estimate_effort`` plus ``write_effort`` with its plots.

Wall-clock and CPU times are both printed: the machine may be shared.
``--white`` times the independent-residual likelihood instead of the
default AR(1) one (the figures before the AR(1) model).

4. With ``--scale``: the Effort step of phrases of ``--lengths`` seconds
   at each of ``--fps``, each in its own process: CPU seconds, peak RSS,
   CPU per posterior (linear in the length and flat in the frame rate is
   the aim).

Usage::

    /work/venv/bin/python benchmarks/bench_effort.py [--n 20] [--workers 2] [--capture DIR] [--white]
    /work/venv/bin/python benchmarks/bench_effort.py --scale --lengths 30 60 120 --fps 25 120
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation.effort import (
    estimate_effort,
    progress_curve,
    sample_posterior,
    sample_posteriors,
    write_effort,
)
from capture2notation.effort.estimate import movement_windows
from capture2notation.notation.model import Effort, Score
from synthetic.arcs import arc_motion, random_arm_score

try:
    from synthetic.interpret import interpret
except ImportError:
    interpret = None

FPS = 25.0


def _joints(score):
    return interpret(score, fps=FPS).joints() if interpret is not None else arc_motion(score, FPS)


def bench_posterior(n: int, seed: int = 0, ar1: bool = True) -> None:
    """Time `n` single-movement posteriors."""
    rng = np.random.default_rng(seed)
    symbols = tuple(
        dataclasses.replace(s, start=Fraction(i), duration=Fraction(1))
        for i, s in enumerate(random_arm_score(rng, n, tempo=60).symbols)
    )
    score = Score(symbols=symbols, tempo=Fraction(60), effort=Effort(time=-3.0, weight=0.45, space=1.0))
    joints = _joints(score)
    joints = joints + 0.005 * rng.standard_normal(joints.shape)
    t = np.arange(len(joints)) / FPS
    curves = [progress_curve(joints, None, t, sym.part, t0, t1) for sym, t0, t1 in movement_windows(score, t)]
    curves = [c for c in curves if c is not None]
    walls, cpus, conv, steps, taus = [], [], [], [], []
    for c in curves:
        w0, c0 = time.perf_counter(), time.process_time()
        post = sample_posterior(c.tau, c.s, c.weight, rng=rng, ar1=ar1)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
        conv.append(post.converged)
        steps.append(post.steps)
        taus.append(post.tau.max())
    walls, cpus = np.array(walls), np.array(cpus)
    ok = np.array(conv)
    print(f"== movement posterior ({len(curves)} movements, {curves[0].tau.size} frames each) ==")
    print(
        f"  one at a time: converged {ok.sum()}/{ok.size}; steps median {np.median(steps):.0f}; "
        f"max tau median {np.median(taus):.1f}"
    )
    print(
        f"    seconds per converged posterior: wall median {np.median(walls[ok]):.3f} s, "
        f"CPU median {np.median(cpus[ok]):.3f} s (aim <= 0.2 s)"
    )
    w0, c0 = time.perf_counter(), time.process_time()
    posts = sample_posteriors([(c.tau, c.s, c.weight, None) for c in curves], rng=rng, ar1=ar1)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    n_ok = sum(p.converged for p in posts)
    print(
        f"  all {len(curves)} in one vectorised run: converged {n_ok}/{len(posts)}; "
        f"steps median {np.median([p.steps for p in posts]):.0f}, max {max(p.steps for p in posts)}"
    )
    print(
        f"    seconds per converged posterior: wall {wall / max(n_ok, 1):.3f} s, CPU {cpu / max(n_ok, 1):.3f} s "
        f"(total {wall:.2f} s wall)"
    )


def sixty_second_phrase(seed: int = 1, tempo: int = 60) -> Score:
    """Both arms moving throughout 60 s at `tempo` (1–2 beat symbols)."""
    rng = np.random.default_rng(seed)
    beats = tempo  # one minute
    syms = []
    for part in ("right_arm", "left_arm"):
        # as many symbols as beats is more than enough; trimmed to the minute
        syms += [s for s in random_arm_score(rng, beats, tempo=tempo, part=part).symbols if s.end <= beats]
    return Score(symbols=tuple(syms), tempo=Fraction(tempo), effort=Effort(time=-2.42, weight=0.6, space=0.0))


def bench_phrase(workers: int, seed: int = 1, ar1: bool = True) -> None:
    score = sixty_second_phrase(seed)
    joints = _joints(score)
    joints = joints + 0.005 * np.random.default_rng(seed).standard_normal(joints.shape)
    for w in sorted({1, workers}):
        w0, c0 = time.perf_counter(), time.process_time()
        ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        res = estimate_effort(joints, None, FPS, score, rng=seed, workers=w, sampler_kw={"ar1": ar1})
        wall = time.perf_counter() - w0
        ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        child_cpu = (ch1.ru_utime + ch1.ru_stime) - (ch0.ru_utime + ch0.ru_stime)
        n_post = len(res.movements) + len(res.parts) + 1
        conv = sum(m.posterior.converged for m in res.movements)
        pooled_conv = res.pooled.posterior.converged and all(p.posterior.converged for p in res.parts.values())
        print(
            f"== 60-second phrase: {len(res.movements)} movements ({conv} converged) + "
            f"{n_post - len(res.movements)} pooled posteriors ({'all' if pooled_conv else 'NOT all'} converged), "
            f"{w} worker(s) =="
        )
        cpu = time.process_time() - c0 + child_cpu
        print(f"  wall {wall:.1f} s (aim <= 30 s on 2 cores); CPU {cpu:.1f} s in all")
    print(
        f"  pooled phrase: b {res.pooled.posterior.summary(0)['median']:.3f} (truth -2.42), "
        f"x0 {res.pooled.posterior.summary(1)['median']:.3f} (0.6), S {res.pooled.space.median:.2f} (0)"
    )


def bench_capture(folder: str, seed: int = 0) -> None:
    """The capture pipeline's Effort step on a capture folder, as ``pipelines.capture`` runs it."""
    import tempfile

    from capture2notation.notation import read
    from pipelines.commands.effort import load_capture

    cap = load_capture(Path(folder) / "capture.npz")
    score = read(Path(folder) / "score.lab")
    w0, c0 = time.perf_counter(), time.process_time()
    res = estimate_effort(
        cap["joints"],
        cap["confidence"],
        cap["fps"],
        score,
        rng=np.random.default_rng(seed),
        times=cap["times"],
        joint_names=cap["joint_names"],
    )
    w1, c1 = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as out:
        write_effort(res, out, plots=True, rng=seed)
    w2, c2 = time.perf_counter(), time.process_time()
    conv = sum(m.posterior.converged for m in res.movements)
    print(
        f"== capture {folder}: {len(cap['times'])} frames, {len(res.movements)} movements ({conv} converged) "
        f"+ {len(res.parts) + (res.pooled is not None)} pooled =="
    )
    print(
        f"  estimate {w1 - w0:.2f} s wall ({c1 - c0:.2f} s CPU); effort.json + plots {w2 - w1:.2f} s wall "
        f"({c2 - c1:.2f} s CPU, incl. importing matplotlib); Effort step {w2 - w0:.2f} s"
    )


def _phrase(seconds: int, seed: int = 1, tempo: int = 60) -> Score:
    """Both arms moving throughout `seconds` at `tempo` (1–2 beat symbols)."""
    rng = np.random.default_rng(seed)
    beats = seconds * tempo // 60
    syms = []
    for part in ("right_arm", "left_arm"):
        syms += [s for s in random_arm_score(rng, beats, tempo=tempo, part=part).symbols if s.end <= beats]
    return Score(symbols=tuple(syms), tempo=Fraction(tempo), effort=Effort(time=-2.42, weight=0.6, space=0.0))


def bench_one(seconds: int, fps: float, seed: int = 1) -> None:
    """One phrase's Effort step (child process of :func:`bench_scale`): prints CPU s, peak RSS, posteriors."""
    score = _phrase(seconds, seed)
    joints = interpret(score, fps=fps).joints() if interpret is not None else arc_motion(score, fps)
    joints = joints + 0.005 * np.random.default_rng(seed).standard_normal(joints.shape)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    c0, w0 = time.process_time(), time.perf_counter()
    res = estimate_effort(joints, None, fps, score, rng=seed)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    n_post = len(res.movements) + len(res.parts) + (res.pooled is not None)
    conv = sum(m.posterior.converged for m in res.movements)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(
        f"RESULT {seconds} {fps} {cpu:.2f} {wall:.2f} {rss / 1024:.0f} {rss0 / 1024:.0f} {n_post} {conv} {len(res.movements)}"
    )


def bench_scale(lengths, fps_list) -> None:
    """Effort step CPU time and peak memory against the phrase's length and frame rate (one process each)."""
    import subprocess
    import sys

    print("== Effort step against length and frame rate (each in its own process; CPU s: the machine is shared) ==")
    print("  length  fps  CPU s  wall s  peak RSS MB (before Effort)  posteriors  CPU ms/posterior  converged")
    for fps in fps_list:
        for seconds in lengths:
            out = subprocess.run(
                [sys.executable, __file__, "--one", str(seconds), str(fps)], capture_output=True, text=True, check=True
            ).stdout
            line = [ln for ln in out.splitlines() if ln.startswith("RESULT")][-1].split()
            _, sec, f, cpu, wall, rss, rss0, n_post, conv, n_mov = line
            print(
                f"  {sec:>5} s {float(f):4.0f}  {float(cpu):5.1f}  {float(wall):6.1f}  {rss:>6} ({rss0})"
                f"  {n_post:>10}  {1000 * float(cpu) / int(n_post):9.0f}  {conv}/{n_mov}",
                flush=True,
            )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20, help="Movement posteriors to time.")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--capture", help="A capture folder (capture.npz + score.lab) to time the Effort step on.")
    ap.add_argument("--white", action="store_true", help="Independent residuals instead of AR(1).")
    ap.add_argument("--scale", action="store_true", help="Effort step against length (--lengths) and --fps.")
    ap.add_argument("--lengths", type=int, nargs="+", default=[30, 60, 120], help="Phrase lengths, seconds.")
    ap.add_argument("--fps", type=float, nargs="+", default=[25.0], help="Frame rates for --scale.")
    ap.add_argument("--one", nargs=2, type=float, metavar=("SECONDS", "FPS"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        bench_one(int(a.one[0]), a.one[1])
        return
    if a.scale:
        bench_scale(a.lengths, a.fps)
        return
    print(
        f"dancer: {'synthetic.interpret' if interpret is not None else 'reference arcs'}; "
        f"residuals: {'white' if a.white else 'AR(1)'}; load average {os.getloadavg()[0]:.1f} (2 cores, shared)"
    )
    bench_posterior(a.n, ar1=not a.white)
    bench_phrase(a.workers, ar1=not a.white)
    if a.capture:
        bench_capture(a.capture)


if __name__ == "__main__":
    main()
