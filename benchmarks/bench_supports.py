"""Supports on video without a camera given: the support column and the floor.

Run ``python benchmarks/bench_supports.py [--n N] [--seed S] [--view V]``.

N fresh random scores (``synthetic.random_scores.random_score`` drawn from
``numpy.random.default_rng(S)``; never the holdout) are performed by the
virtual dancer, rendered at 25 fps, 640×480 with the mannequin, and captured
from the video alone (BlazePose → fit with the camera estimated from the
person → quantiser), the tempo given.  Printed (never asserted), per score
and overall:

* the whole symbol agreement (as ``bench_wholepath.py``) and the agreement
  of the support columns alone (cells whose part is a support);
* the support symbols written vs in the score;
* where the fitted feet stand: the median height of the fit's lowest foot
  point over the frames where the truth has a foot on the floor (0 = the
  fitted feet sit on the floor the fit chose, which is what the quantiser
  reads), and the truth's own on those frames (its toe joint rests ~1 cm up).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

#: A truth foot point lower than this is on the floor, metres: the
#: renderer's standing toes and heels sit within a centimetre of z = 0.
TRUTH_ON_FLOOR_M = 0.02


def _foot_points(joints: np.ndarray) -> np.ndarray:
    """The lowest foot point per frame (ankles and toes), metres: ``(T,)``."""
    from capture2notation.body.skeleton import joint_index

    idx = [joint_index(n) for n in ("right_ankle", "right_toe", "left_ankle", "left_toe")]
    return np.nanmin(np.asarray(joints, float)[:, idx, 2], axis=1)


def measure(seed: int, k: int, workdir: Path, view: str) -> dict:
    """Render random score `k` of `seed`, capture it from its video, compare."""
    from capture2notation.compare.agreement import agreement_cells, compare_scores
    from capture2notation.io.truth import read_truth
    from pipelines.capture import capture
    from synthetic.random_scores import random_score
    from synthetic.render import render_score

    rng = np.random.default_rng([seed, k])
    score = random_score(rng, n_beats=8)
    render = render_score(
        score, workdir / "render", fps=25.0, size=(640, 480), view=view, style="mannequin", progress=False
    )
    video = capture(
        render / "video.mp4", workdir / "video", progress=False, effort=False, overlay=False, tempo=score.tempo
    )
    cells = agreement_cells(score, video.score)
    sup = [c for c in cells if "support" in c.part]
    truth = read_truth(render / "truth.npz")
    on = _foot_points(truth.joints) < TRUTH_ON_FLOOR_M
    fitted = _foot_points(video.motion.joints)
    n = min(len(on), len(fitted))
    return {
        "k": k,
        "agreement": compare_scores(score, video.score).symbol_agreement,
        "support_ok": sum(c.ref == c.cand for c in sup),
        "support_n": len(sup),
        "supports": (sum(s.is_support for s in score.symbols), sum(s.is_support for s in video.score.symbols)),
        "feet_z": float(np.nanmedian(fitted[:n][on[:n]])) if on[:n].any() else float("nan"),
        "truth_z": float(np.nanmedian(_foot_points(truth.joints)[:n][on[:n]])) if on[:n].any() else float("nan"),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=6, help="random scores")
    ap.add_argument("--seed", type=int, default=1313, help="seed of the random scores (not the holdout)")
    ap.add_argument("--view", default="front", choices=("front", "45", "side"))
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.n):
            r = measure(args.seed, k, Path(tmp) / str(k), args.view)
            rows.append(r)
            print(
                f"score {k}: agreement {r['agreement']:6.1%}  support column {r['support_ok']}/{r['support_n']}  "
                f"support symbols {r['supports'][0]} written, {r['supports'][1]} captured  "
                f"fitted feet on the floor at {100 * r['feet_z']:+.1f} cm (truth {100 * r['truth_z']:+.1f} cm)",
                flush=True,
            )
    ok, n = sum(r["support_ok"] for r in rows), sum(r["support_n"] for r in rows)
    print(f"\n{args.view} view, {len(rows)} random scores (seed {args.seed}), tempo given, camera estimated:")
    print(f"  symbol agreement (mean over scores)   {np.mean([r['agreement'] for r in rows]):.1%}")
    print(f"  support-column cells agreeing         {ok}/{n} ({ok / max(n, 1):.1%})")
    print(f"  fitted feet on the floor (median)     {100 * np.nanmedian([r['feet_z'] for r in rows]):+.1f} cm")


if __name__ == "__main__":
    main()
