"""The measured quantiser on the virtual dancer's own joints under stated noise: the ceiling of any capture.

Run: ``python benchmarks/bench_quantise_noise.py [--scores 40] [--first-seed 5000] [--conditions white,ar,fit3d]``

Random scores (``random_score``, 8 beats, supports and leg gestures
included) are performed by the virtual dancer at 25 fps, and its joints are
quantised by :func:`~capture2notation.quantise.segment.segment_motion` after
one of these, each of which makes the motion *measured* (never exactly
still), as every capture is:

* ``white``: independent jitter of 4 mm per joint coordinate;
* ``ar``: the noise model of a fitted capture stated for Effort
  (``benchmarks/bench_effort_coverage.py``): 5 mm white plus a stationary
  AR(1) error of 10 mm with frame correlation 0.9;
* ``fit3d``: the exact joints through
  :func:`~capture2notation.fitting.fit3d.fit_points3d` (the fit of motion
  files and several cameras: our skeleton, joint limits, smoothness).

The clean joints themselves round-trip exactly (the truth path of
``bench_turns.py``); what these conditions lose is the measured quantiser's
own loss, before any camera or pose model.  Prints the symbol agreement
(mean over scores) and the share of agreeing cells per column.  About one
second a score per condition.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections import Counter

import numpy as np

CONDITIONS = ("white", "ar", "fit3d")
#: White jitter of the ``white`` condition, metres.
WHITE_M = 0.004
#: The ``ar`` condition: white part, smooth part (metres) and its frame correlation.
AR_WHITE_M, AR_SMOOTH_M, AR_RHO = 0.005, 0.010, 0.9
FPS = 25.0


def measured(joints: np.ndarray, condition: str, rng: np.random.Generator) -> np.ndarray:
    """The dancer's (T, J, 3) joints as a capture of `condition` would give them (metres)."""
    if condition == "white":
        return joints + rng.normal(0.0, WHITE_M, joints.shape)
    if condition == "ar":
        e = rng.normal(0.0, AR_SMOOTH_M * np.sqrt(1.0 - AR_RHO**2), joints.shape)
        e[0] = rng.normal(0.0, AR_SMOOTH_M, joints.shape[1:])
        for t in range(1, len(e)):
            e[t] += AR_RHO * e[t - 1]
        return joints + e + rng.normal(0.0, AR_WHITE_M, joints.shape)
    from capture2notation.fitting.fit3d import fit_points3d

    return np.asarray(fit_points3d(joints, np.ones(joints.shape[:2]), FPS, floor=True).joints)


def main() -> None:
    from capture2notation.compare.agreement import agreement_cells, compare_scores
    from capture2notation.quantise.segment import segment_motion
    from synthetic.interpret import interpret
    from synthetic.random_scores import random_score

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scores", type=int, default=40, help="random scores to measure")
    ap.add_argument("--first-seed", type=int, default=5000, help="seed of the first random score")
    ap.add_argument("--conditions", default=",".join(CONDITIONS), help=f"comma-separated, of {CONDITIONS}")
    args = ap.parse_args()
    conditions = [c.strip() for c in args.conditions.split(",") if c.strip()]
    bad = [c for c in conditions if c not in CONDITIONS]
    if bad:
        ap.error(f"--conditions: unknown {bad}; choose from {CONDITIONS}")
    agree = {c: [] for c in conditions}
    total = {c: Counter() for c in conditions}
    right = {c: Counter() for c in conditions}
    t0 = time.perf_counter()
    for seed in range(args.first_seed, args.first_seed + args.scores):
        score = random_score(np.random.default_rng(seed), n_beats=8)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            joints = interpret(score, fps=FPS).joints()
        for k, c in enumerate(conditions):
            rng = np.random.default_rng([seed, k])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                got = segment_motion(measured(joints, c, rng), FPS, tempo=score.tempo).score
            agree[c].append(compare_scores(score, got).symbol_agreement)
            for cell in agreement_cells(score, got):
                total[c][cell.part] += 1
                right[c][cell.part] += cell.ref == cell.cand
    print(
        f"measured quantiser on the dancer's joints, {args.scores} random scores of 8 beats "
        f"(seeds {args.first_seed}..{args.first_seed + args.scores - 1}), 25 fps, tempo given, "
        f"{time.perf_counter() - t0:.0f} s"
    )
    for c in conditions:
        cols = ", ".join(f"{p} {100 * right[c][p] / total[c][p]:.0f}%" for p in sorted(total[c]))
        print(f"  {c:6s} symbol agreement {100 * np.mean(agree[c]):5.1f}%   by column: {cols}")


if __name__ == "__main__":
    main()
