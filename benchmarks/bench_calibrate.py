"""Calibration from rendered board clips: per-camera RMS, centre and orientation error, seconds.

For 2 cameras (front, 45) and 3 (front, 45, side): ``c2n render --views
... --calibration-clip`` of a one-beat phrase, then ``c2n calibrate`` on
the clips with the options the render prints; the estimate is compared with
the renderer's true ``cameras.toml`` (scoring only).  Also the errors after
the best rigid motion of the world (what the cameras' relative geometry
alone is worth, apart from the world frame the standing board fixes).

    nice -n 10 python benchmarks/bench_calibrate.py [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import shlex
import tempfile
import time
from pathlib import Path

import numpy as np
from click.testing import CliRunner

from capture2notation.io.calibration import read_calibration
from pipelines.cli import main

SCORE = "tempo: 240\n0 1 right_arm right middle\n"


def _angle(Ra, Rb) -> float:
    return math.degrees(math.acos(np.clip((np.trace(Ra @ Rb.T) - 1) / 2, -1.0, 1.0)))


def _rigid(A: np.ndarray, B: np.ndarray):
    """R, t minimising |R A + t − B| (Kabsch)."""
    ca, cb = A.mean(0), B.mean(0)
    U, _, Vt = np.linalg.svd((A - ca).T @ (B - cb))
    D = np.diag([1, 1, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, cb - R @ ca


def run(views: str, seed: int, root: Path) -> None:
    out = root / views.replace(",", "_")
    score = root / "p.lab"
    score.write_text(SCORE)
    runner = CliRunner()
    t0 = time.perf_counter()
    r = runner.invoke(
        main, ["render", str(score), "-o", str(out), "--views", views, "--calibration-clip", "--seed", str(seed)]
    )
    if r.exit_code:
        raise SystemExit(r.output)
    t_render = time.perf_counter() - t0
    cmd = shlex.split(r.output.strip().splitlines()[-1])[1:]
    cmd[cmd.index("-o") + 1] = str(out / "estimated.toml")
    t0 = time.perf_counter()
    r = runner.invoke(main, cmd)
    if r.exit_code:
        raise SystemExit(r.output)
    t_cal = time.perf_counter() - t0
    truth, est = read_calibration(out / "cameras.toml"), read_calibration(out / "estimated.toml")
    names = truth.names
    C_t = np.array([truth[n].centre for n in names])
    C_e = np.array([est[n].centre for n in names])
    # a rigid motion from the centres and the optical axes' points 1 m ahead
    A = np.concatenate([C_e, C_e + np.array([est[n].R[2] for n in names])])
    B = np.concatenate([C_t, C_t + np.array([truth[n].R[2] for n in names])])
    Rw, tw = _rigid(A, B)
    print(f"{len(names)} cameras ({views}), seed {seed}: render {t_render:.0f} s, calibrate {t_cal:.0f} s")
    for n in names:
        e, t = est[n], truth[n]
        print(
            f"  {n:>5}: RMS {e.rms_px:.3f} px, centre {100 * np.linalg.norm(e.centre - t.centre):.2f} cm, "
            f"orientation {_angle(e.R, t.R):.3f}°, focal {100 * (e.K[0, 0] / t.K[0, 0] - 1):+.2f} %, "
            f"k1 {e.dist[0]:+.4f} k2 {e.dist[1]:+.4f} | world aligned: centre "
            f"{100 * np.linalg.norm(Rw @ e.centre + tw - t.centre):.2f} cm, orientation {_angle(e.R @ Rw.T, t.R):.3f}°"
        )


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for views in ("front,45", "front,45,side"):
            run(views, args.seed, Path(tmp))
