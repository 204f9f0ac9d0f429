"""Benchmark: forward kinematics and score interpretation, frames per second.

Run: ``python benchmarks/bench_kinematics.py``.  Prints figures, asserts
nothing.  Aims (issue 2): forward kinematics >= 50,000 frames/s; the
interpreter a few thousand frames/s.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from capture2notation.body import JOINTS, Body, forward_kinematics
from synthetic.interpret import interpret
from synthetic.phrases import builtin_phrases
from synthetic.random_scores import random_score


def _best(fn, repeats: int = 5) -> float:
    """Best wall time of `repeats` calls, seconds."""
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    body = Body()
    rng = np.random.default_rng(0)
    for T in (1_000, 10_000, 100_000):
        angles = body.clip(rng.uniform(-1, 1, (T, len(JOINTS), 3)))
        root = np.tile(body.rest[0], (T, 1))
        dt = _best(lambda angles=angles, root=root: forward_kinematics(angles, root, body))
        print(f"forward_kinematics  T={T:>7,}  {T / dt:>12,.0f} frames/s")

    for name, score in builtin_phrases().items():
        m = interpret(score, 25.0)
        dt = _best(lambda score=score: interpret(score, 25.0))
        print(f"interpret {name:<14} {m.n_frames:>5} frames  {m.n_frames / dt:>9,.0f} frames/s")

    scores = [random_score(np.random.default_rng(s), n_beats=32) for s in range(5)]
    frames, total = 0, 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for sc in scores:
            n = interpret(sc, 25.0).n_frames
            frames += n
            total += _best(lambda sc=sc: interpret(sc, 25.0), repeats=3)
    print(f"interpret random 32-beat scores  {frames:>5} frames  {frames / total:>9,.0f} frames/s")

    t = time.perf_counter()
    for s in range(10):
        random_score(np.random.default_rng(100 + s), n_beats=8)
    print(f"random_score (8 beats, verified)  {(time.perf_counter() - t) / 10 * 1000:.0f} ms per score")


if __name__ == "__main__":
    main()
