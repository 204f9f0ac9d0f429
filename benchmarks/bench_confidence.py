"""Symbol confidence: are the symbols marked uncertain the wrong ones?

Renders random scores (fresh seeds), or with ``--holdout`` the phrases of
``benchmarks/holdout/*.lab`` (to measure only, never to tune), with the
virtual dancer, captures each through BlazePose at the score's tempo, and
judges every captured gesture symbol against the truth: wrong when the
truth's limb, held over the frames where the symbol arrives
(:data:`capture2notation.quantise.confidence.HOLD_S`), reads a different
direction or level.  Prints the error rate of uncertain and of confident
symbols and their ratio (the issue asks for at least 3), the area under the
ROC curve (how often a wrong symbol has a lower confidence than a right
one) and, per confidence bin, the mean confidence against the share right
(a calibrated probability has them equal).

Run: ``nice -n 10 .venv/bin/python benchmarks/bench_confidence.py [--clips N] [--seed S] [--holdout] [--out DIR]``
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from capture2notation.body import body_frame, segment_vectors
from capture2notation.io.truth import read_truth
from capture2notation.notation.directions import classify
from capture2notation.notation.formats import read
from capture2notation.notation.model import PART_SEGMENTS, SYMBOL_UNCERTAIN_BELOW
from capture2notation.quantise.confidence import HOLD_S
from pipelines.capture import capture
from synthetic.random_scores import random_score
from synthetic.render.job import render_score

HOLDOUT = Path(__file__).resolve().parent / "holdout"


def judged(seed, root: Path, n_beats: int, view: str, score=None):
    """(confidence, wrong) of every captured gesture symbol of one clip (a random score of `seed`, or `score`)."""
    if score is None:
        score = random_score(np.random.default_rng(seed), n_beats=n_beats, fps=25.0)
    clip = render_score(score, root / f"r{seed}", view=view, progress=False)
    result = capture(clip / "video.mp4", root / f"c{seed}", tempo=float(score.tempo), progress=False,
                     effort=False, overlay=False)  # fmt: skip
    truth = read_truth(clip / "truth.npz")
    joints = truth.joints
    frame = body_frame(joints)
    fps = float(truth.fps)
    hold = max(1, round(HOLD_S * fps))
    out = []
    for s in result.score.symbols:
        if s.part not in PART_SEGMENTS or s.confidence is None:
            continue
        f = min(len(joints) - 1, round(float(s.end) * 60 / float(result.score.tempo) * fps))
        v = np.nanmedian(segment_vectors(joints, *PART_SEGMENTS[s.part], frame)[f : f + hold], axis=0)
        direction, level = classify(v / np.linalg.norm(v))
        wrong = (direction, level) != (s.direction, s.level)
        out.append((s.confidence, wrong))
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clips", type=int, default=4)
    ap.add_argument("--seed", type=int, default=16100)
    ap.add_argument("--beats", type=int, default=16)
    ap.add_argument("--view", default="front")
    ap.add_argument("--holdout", action="store_true", help="the held-out phrases (measure only)")
    ap.add_argument("--out", help="keep renders and captures here")
    args = ap.parse_args(argv)
    if args.holdout:
        items = [(p.stem, read(p)) for p in sorted(HOLDOUT.glob("*.lab"))]
    else:
        items = [(args.seed + i, None) for i in range(args.clips)]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        for key, score in items:
            got = judged(key, root, args.beats, args.view, score)
            if not got:
                continue
            c = np.array([g[0] for g in got])
            w = np.array([g[1] for g in got])
            unc = c < SYMBOL_UNCERTAIN_BELOW
            print(f"{key}: {len(got)} gesture symbols, {int(w.sum())} wrong, {int(unc.sum())} uncertain "
                  f"({int((unc & w).sum())} of them wrong)")  # fmt: skip
            rows += got
    c = np.array([r[0] for r in rows])
    w = np.array([r[1] for r in rows], dtype=bool)
    unc = c < SYMBOL_UNCERTAIN_BELOW
    e_unc = w[unc].mean() if unc.any() else float("nan")
    e_cer = w[~unc].mean() if (~unc).any() else float("nan")
    auc = np.mean([(x < c[~w]).mean() + 0.5 * (x == c[~w]).mean() for x in c[w]]) if w.any() and (~w).any() else np.nan
    print(
        f"ALL {len(items)} clips: {len(rows)} gesture symbols, {int(w.sum())} wrong ({w.mean():.1%}); "
        f"uncertain {int(unc.sum())}: wrong {e_unc:.1%}; confident {int((~unc).sum())}: wrong {e_cer:.1%}; "
        f"ratio {e_unc / e_cer if e_cer else float('inf'):.2f}; AUC {auc:.3f}; mean confidence {c.mean():.2f}, "
        f"right {1 - w.mean():.2f}"
    )
    for lo, hi in ((0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01)):
        m = (c >= lo) & (c < hi)
        if m.any():
            print(
                f"  confidence [{lo:.2f}, {min(hi, 1):.2f}): {int(m.sum())} symbols, mean {c[m].mean():.2f}, "
                f"right {1 - w[m].mean():.1%}"
            )


if __name__ == "__main__":
    main()
