"""What ``c2n score`` says about performances whose relation is known.

Run ``python benchmarks/bench_score.py [--captures N] [--pairs N]``.

Printed (never asserted), each through :func:`pipelines.score.run_score` on
files, as a user would call it:

* a performance against itself, for every kind of input: a score, a BVH of
  it, a capture folder (``c2n capture`` of that BVH), the Kinect fixture, a
  truth sidecar — expected 100 %;
* a time-shifted copy (a BVH of a score with 1 s of its first pose before
  it) against the score: the timing offsets should be the shift;
* pairs of different random scores (score against score, and BVH against
  BVH): low agreement and the verdict "not the same piece";
* a long unrelated performance (a 96-beat random phrase, about a minute)
  against a short reference (16 beats): the matched time and where the
  movements land;
* with ``--captures N``, N random phrases rendered and captured through
  BlazePose, against their scores: a noisy performance of the same piece
  (the verdict should be "same piece").

Random phrases come from ``synthetic.random_score`` with fixed seeds (never
the held-out phrases).  Run it on another checkout with ``PYTHONPATH`` to
compare before and after.
"""

from __future__ import annotations

import argparse
import json
import logging
import tempfile
import warnings
from pathlib import Path

import numpy as np

FIXTURES = Path(__file__).resolve().parents[1].parent / "shared" / "fixtures"


def _summary(cand, ref, out: Path) -> dict:
    from pipelines.score import run_score

    return run_score(cand, ref, out)


def _line(name: str, s: dict) -> str:
    sa = s["symbol_agreement"]
    v = s.get("verdict")
    verdict = "" if v is None else f"  κ {v['kappa']:.2f}, chance {v['chance']:.0%}, same piece: {v['same_piece']}"
    t = s.get("time_s")
    matched = "" if t is None else f"  matched {t['matched_candidate_s']:.1f}/{t['candidate_s']:.1f} s"
    offs = [m["timing_offset"] for m in s["movements"] if m["verdict"] not in ("n/a", "missing")]
    late = f"  median offset {np.median(offs):+.2f} s, max |offset| {np.max(np.abs(offs)):.2f} s" if offs else ""
    return f"{name:<34} agreement {'n/a' if sa is None else f'{sa:6.1%}'}{matched}{late}{verdict}"


def _bvh_of(score, path: Path, prefix_s: float = 0.0, fps: float = 25.0) -> Path:
    from capture2notation.io.bvh import write_bvh
    from synthetic.interpret import interpret

    m = interpret(score, fps=fps)
    angles, root = m.angles, m.root
    k = int(round(prefix_s * fps))
    if k:
        angles = np.concatenate([np.repeat(angles[:1], k, 0), angles])
        root = np.concatenate([np.repeat(root[:1], k, 0), root])
    return write_bvh(path, angles, root, fps)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=10, help="pairs of different random scores")
    ap.add_argument("--captures", type=int, default=0, help="random phrases rendered and captured with BlazePose")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    logging.disable(logging.WARNING)

    from capture2notation.notation import formats
    from synthetic import random_score

    work = Path(tempfile.mkdtemp(prefix="bench_score_"))
    A = random_score(np.random.default_rng(1), n_beats=16)
    lab = formats.write(A, work / "a.lab")
    bvh = _bvh_of(A, work / "a.bvh")

    print("-- a performance against itself (expected 100 %)")
    from pipelines.capture import capture

    cap = work / "cap"
    capture(bvh, cap, effort=False, progress=False)
    kinect = FIXTURES / "kinect" / "joints.csv"
    mocap = FIXTURES / "bvh" / "test_mocapbank.bvh"
    selves = [("score .lab", lab), ("BVH", bvh), ("capture folder (of the BVH)", cap)]
    if mocap.is_file():
        capture(mocap, work / "cap_mocap", effort=False, progress=False)
        selves += [("mocapbank BVH fixture", mocap), ("capture folder (of mocapbank)", work / "cap_mocap")]
    if kinect.is_file():
        selves.append(("Kinect CSV fixture", kinect))
    from synthetic.render.job import render_score

    render = render_score(A, work / "render", size=(160, 120), style="stick", progress=False)
    selves.append(("truth sidecar", render / "truth.npz"))
    for name, path in selves:
        print(_line(name, _summary(path, path, work / "o")))

    print("-- time-shifted copy: 1 s of the first pose before the phrase (offsets expected +1.00 s)")
    shifted = _bvh_of(A, work / "shifted.bvh", prefix_s=1.0)
    print(_line("shifted BVH vs score", _summary(shifted, lab, work / "o")))

    print(f"-- {args.pairs} pairs of different random scores (16 beats each)")
    rows = []
    for seed in range(2, 2 + args.pairs):
        B = random_score(np.random.default_rng(seed), n_beats=16)
        blab = formats.write(B, work / f"b{seed}.lab")
        bbvh = _bvh_of(B, work / f"b{seed}.bvh")
        s1 = _summary(blab, lab, work / "o")
        s2 = _summary(bbvh, bvh, work / "o")
        rows.append((s1, s2))
        print(_line(f"seed {seed}: score vs score", s1))
        print(_line(f"seed {seed}: BVH vs BVH", s2))
    for k, what in ((0, "score vs score"), (1, "BVH vs BVH")):
        agr = [r[k]["symbol_agreement"] for r in rows]
        same = [r[k]["verdict"]["same_piece"] for r in rows if "verdict" in r[k]]
        said = f"said same piece {same.count(True)}/{len(same)}" if same else "no verdict"
        print(f"   {what}: agreement median {np.median(agr):.1%}, max {np.max(agr):.1%}; {said}")

    print("-- a long unrelated performance (96 beats) against a short reference (16 beats)")
    L = random_score(np.random.default_rng(99), n_beats=96)
    long_bvh = _bvh_of(L, work / "long.bvh")
    s = _summary(long_bvh, bvh, work / "o")
    print(_line("long BVH vs short BVH", s))

    if args.captures:
        print(f"-- {args.captures} random phrases rendered (640x480 mannequin, front) and captured with BlazePose")
        for seed in range(200, 200 + args.captures):
            P = random_score(np.random.default_rng(seed), n_beats=16)
            plab = formats.write(P, work / f"p{seed}.lab")
            rdir = render_score(P, work / f"r{seed}", progress=False)
            cdir = work / f"c{seed}"
            capture(rdir / "video.mp4", cdir, effort=False, progress=False)
            print(_line(f"seed {seed}: capture vs its score", _summary(cdir, plab, work / "o")))
            print(_line(f"seed {seed}: capture vs score of seed 1", _summary(cdir, lab, work / "o")))
    print(json.dumps({"work": str(work)}))


if __name__ == "__main__":
    main()
