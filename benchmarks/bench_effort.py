"""Speed of the Effort estimator — prints seconds per posterior and per phrase.

1. Seconds per converged movement posterior (aim ≤ 0.2 s): one-beat arm
   movements at 60 bpm (25 frames) from the virtual dancer's truth joints
   with 5 mm joint jitter.
2. A 60-second phrase (both arms moving throughout, 1–2 beat symbols at
   60 bpm) with the movements' posteriors in parallel processes (aim ≤ 30 s
   on 2 cores).

Wall-clock and CPU times are both printed: the machine may be shared.

Usage::

    /work/venv/bin/python benchmarks/bench_effort.py [--n 20] [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import time
from fractions import Fraction

import numpy as np

from capture2notation.effort import estimate_effort, progress_curve, sample_posterior
from capture2notation.effort.estimate import movement_windows
from capture2notation.effort.testing import arc_motion, random_arm_score
from capture2notation.notation.model import Effort, Score

try:
    from synthetic.interpret import interpret
except ImportError:
    interpret = None

FPS = 25.0


def _joints(score):
    return interpret(score, fps=FPS).joints() if interpret is not None else arc_motion(score, FPS)


def bench_posterior(n: int, seed: int = 0) -> None:
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
        post = sample_posterior(c.tau, c.s, c.weight, rng=rng)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
        conv.append(post.converged)
        steps.append(post.steps)
        taus.append(post.tau.max())
    walls, cpus = np.array(walls), np.array(cpus)
    ok = np.array(conv)
    print(f"== movement posterior ({len(curves)} movements, {curves[0].tau.size} frames each) ==")
    print(f"  converged {ok.sum()}/{ok.size}; steps median {np.median(steps):.0f}; max tau median {np.median(taus):.1f}")
    print(f"  seconds per converged posterior: wall median {np.median(walls[ok]):.3f} s, "
          f"CPU median {np.median(cpus[ok]):.3f} s (aim <= 0.2 s)")


def sixty_second_phrase(seed: int = 1, tempo: int = 60) -> Score:
    """Both arms moving throughout 60 s at `tempo` (1–2 beat symbols)."""
    rng = np.random.default_rng(seed)
    beats = tempo  # one minute
    syms = []
    for part in ("right_arm", "left_arm"):
        # as many symbols as beats is more than enough; trimmed to the minute
        syms += [s for s in random_arm_score(rng, beats, tempo=tempo, part=part).symbols if s.end <= beats]
    return Score(symbols=tuple(syms), tempo=Fraction(tempo), effort=Effort(time=-2.42, weight=0.6, space=0.0))


def bench_phrase(workers: int, seed: int = 1) -> None:
    score = sixty_second_phrase(seed)
    joints = _joints(score)
    joints = joints + 0.005 * np.random.default_rng(seed).standard_normal(joints.shape)
    w0, c0 = time.perf_counter(), time.process_time()
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = estimate_effort(joints, None, FPS, score, rng=seed, workers=workers)
    wall = time.perf_counter() - w0
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    child_cpu = (ch1.ru_utime + ch1.ru_stime) - (ch0.ru_utime + ch0.ru_stime)
    n_post = len(res.movements) + len(res.parts) + 1
    conv = sum(m.posterior.converged for m in res.movements)
    print(f"== 60-second phrase: {len(res.movements)} movements ({conv} converged) + {n_post - len(res.movements)} "
          f"pooled posteriors, {workers} workers ==")
    cpu = time.process_time() - c0 + child_cpu
    print(f"  wall {wall:.1f} s (aim <= 30 s on 2 cores); CPU {cpu:.1f} s in all, "
          f"i.e. {cpu / workers:.1f} s on {workers} idle cores")
    print(f"  pooled phrase: b {res.pooled.posterior.summary(0)['median']:.3f} (truth -2.42), "
          f"x0 {res.pooled.posterior.summary(1)['median']:.3f} (0.6), S {res.pooled.space.median:.2f} (0)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20, help="Movement posteriors to time.")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    print(f"dancer: {'synthetic.interpret' if interpret is not None else 'reference arcs'}")
    bench_posterior(a.n)
    bench_phrase(a.workers)


if __name__ == "__main__":
    main()
