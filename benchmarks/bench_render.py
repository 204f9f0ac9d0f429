"""Rendering speed: frames per second at 640×480 per style, including mp4 encoding.

Run: ``python benchmarks/bench_render.py [--frames N] [--size WxH]``.
Prints figures; asserts nothing.  The motion is a synthetic sway of arms,
legs and head built with forward kinematics, so the benchmark does not depend
on the interpreter.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from capture2notation.body import JOINTS, Body, joint_index
from synthetic.render import Camera, Pose, make_renderer, open_writer, truth_fields


def _motion(n: int, fps: float = 25.0) -> Pose:
    body = Body()
    t = np.arange(n) / fps
    a = np.zeros((n, len(JOINTS), 3))
    a[:, joint_index("right_shoulder"), 0] = 1.5 * (1 - np.cos(t))  # forward and up overhead
    a[:, joint_index("left_shoulder"), 1] = 1.4 * np.sin(0.7 * t) ** 2
    a[:, joint_index("left_elbow"), 0] = 0.8 * np.sin(t) ** 2
    a[:, joint_index("right_hip"), 1] = -0.9 * np.sin(0.5 * t) ** 2
    a[:, joint_index("left_knee"), 0] = -0.5 * np.sin(1.3 * t) ** 2
    a[:, joint_index("neck"), 2] = 0.8 * np.sin(0.4 * t)
    a[:, joint_index("pelvis"), 2] = 0.6 * np.sin(0.25 * t)
    root = np.tile(body.rest[0], (n, 1))
    return Pose(body.clip(a), root, body, fps)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=250)
    ap.add_argument("--size", default="640x480")
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    pose = _motion(args.frames)
    cam = Camera.for_view("45", size, pose.body.height)
    print(
        f"{args.frames} frames at {size[0]}x{size[1]}, view 45, H.264 encoding included (ffmpeg runs as its own process: the per-CPU-second figures count this process only)"
    )
    t0 = time.perf_counter()
    truth_fields(pose, cam)
    print(
        f"  truth sidecar fields (projection + visibility): {args.frames / (time.perf_counter() - t0):10.0f} frames/s"
    )
    with tempfile.TemporaryDirectory() as tmp:
        for style in ("mannequin", "stick", "markers"):
            t0, c0 = time.perf_counter(), time.process_time()
            r = make_renderer(pose, cam, style)
            t1 = time.perf_counter()
            with open_writer(Path(tmp) / f"{style}.mp4", pose.fps, size) as w:
                for i in range(len(r)):
                    w.write(r.frame(i))
            t2, c2 = time.perf_counter(), time.process_time()
            for i in range(len(r)):
                r.frame(i)
            t3 = time.perf_counter()
            # CPU-time rate: what one core gives when the machine is shared.
            print(
                f"  {style:10s} {args.frames / (t2 - t0):7.1f} frames/s end to end "
                f"({args.frames / (c2 - c0):7.1f} per CPU-second; setup {1e3 * (t1 - t0):.0f} ms; "
                f"drawing alone {args.frames / (t3 - t2):7.1f} frames/s)"
            )


if __name__ == "__main__":
    main()
