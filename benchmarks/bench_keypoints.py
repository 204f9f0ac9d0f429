"""Keypoint stage benchmark: end-to-end speed and accuracy against MediaPipe.

Run: ``python benchmarks/bench_keypoints.py [--frames N] [--threads T]``

Prints
* end-to-end frames per second (decode + localise + infer + filter) of
  :func:`capture2notation.keypoints.extract` on mannequin renders written to
  mp4 at 640×480 and 1280×720, with the share of each step, and without
  looking for faces (``faces=False``: the yaw decoder's face cue);
* the landmark model alone (ms per call, 1 session, ``threads`` intra-op);
* accuracy on MediaPipe's fixtures (``pose.jpg``, ``pose_squats.mp4``) when
  ``../shared/fixtures`` is present: the error distribution per coordinate;
* on mannequin renders of the built-in phrases (front, 45°, side): PCK at
  5 % of the person's height per joint, left/right swaps and the mean
  signed error (x, y) in pixels, with one pass per frame and with the flip
  test (``flip_test``: the mirrored crop read too and averaged).

Speed and the fixtures are measured with one pass per frame (the default)
and, at 640×480, with the flip test.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from capture2notation.io.video import VideoWriter, iter_frames
from capture2notation.keypoints import extract, extract_frames
from capture2notation.keypoints.blazepose import BlazePose, crop_to_tensor

FIXTURES = Path(os.environ.get("C2N_FIXTURES", ROOT.parent / "shared" / "fixtures"))


def _demo_pose(n_frames: int, fps: float):
    """A deterministic arm-and-leg movement for the virtual dancer."""
    from capture2notation.body import JOINTS, Body
    from capture2notation.body.skeleton import joint_index
    from synthetic.render.scene import Pose

    a = np.zeros((n_frames, len(JOINTS), 3))
    s = 0.5 - 0.5 * np.cos(np.linspace(0, 2 * np.pi, n_frames))
    a[:, joint_index("right_shoulder"), 1] = -1.3 * s
    a[:, joint_index("left_shoulder"), 0] = 1.1 * s
    a[:, joint_index("right_elbow"), 0] = 1.2 * s
    a[:, joint_index("right_hip"), 0] = 0.5 * s
    a[:, joint_index("right_knee"), 0] = -0.8 * s
    root = np.zeros((n_frames, 3))
    root[:, 2] = Body().rest[0, 2]
    return Pose(a, root, Body(), fps)


def _render(path: Path, size, n_frames: int) -> None:
    from synthetic.render.camera import Camera
    from synthetic.render.job import render_frames

    pose = _demo_pose(n_frames, 25.0)
    cam = Camera.for_view("45", size, pose.body.height)
    with VideoWriter(path, pose.fps, size) as w:
        for frame in render_frames(pose, cam, "mannequin"):
            w.write(frame)


def bench_end_to_end(bp: BlazePose, size, n_frames: int, tmp: Path) -> None:
    video = tmp / f"bench_{size[0]}x{size[1]}.mp4"
    if not video.exists():
        _render(video, size, n_frames)
    t0 = time.perf_counter()
    n_decoded = sum(1 for _ in iter_frames(video))
    t_decode = time.perf_counter() - t0
    # Without faces first: the first run of a process also warms the caches.
    t0 = time.perf_counter()
    extract(video, estimator=bp, faces=False)
    t_no_faces = time.perf_counter() - t0
    t0, c0 = time.perf_counter(), time.process_time()
    track = extract(video, estimator=bp)
    t_all, c_all = time.perf_counter() - t0, time.process_time() - c0
    frames = [f.image for f in iter_frames(video, stop=20)]
    t0 = time.perf_counter()
    for f in frames:
        crop_to_tensor(f, np.array([size[0] / 2, size[1] / 2, size[1], size[1], 0.2]))
    t_crop = (time.perf_counter() - t0) / len(frames)
    print(
        f"end-to-end {size[0]}x{size[1]}{' (flip test)' if bp.flip_test else ''}: {len(track) / t_all:6.1f} fps "
        f"({1000 * t_all / len(track):.1f} ms/frame wall, {1000 * c_all / len(track):.1f} ms/frame CPU, {len(track)} frames; "
        f"decode {1000 * t_decode / n_decoded:.1f} ms, crop+convert {1000 * t_crop:.2f} ms, "
        f"person found in {np.mean(track.presence > 0):.0%}; load average {os.getloadavg()[0]:.1f}); "
        f"without looking for faces {len(track) / t_no_faces:.1f} fps"
    )


def bench_model(bp: BlazePose, n: int = 50) -> None:
    x = np.random.default_rng(0).random((1, 3, 256, 256), dtype=np.float32)
    name = bp.session.get_inputs()[0].name
    for _ in range(5):
        bp.session.run(None, {name: x})
    times = []
    c0 = time.process_time()
    for _ in range(n):
        t0 = time.perf_counter()
        bp.session.run(None, {name: x})
        times.append(time.perf_counter() - t0)
    cpu = 1000 * (time.process_time() - c0) / n
    t = 1000 * np.array(times)
    print(
        f"model alone: median {np.median(t):.1f} ms/call wall (p10 {np.percentile(t, 10):.1f}, "
        f"p90 {np.percentile(t, 90):.1f}); {cpu:.1f} ms CPU/call; load average {os.getloadavg()[0]:.1f}"
    )


def bench_fixtures(bp: BlazePose) -> None:
    import cv2

    mp = FIXTURES / "mediapipe"
    if not (mp / "pose.jpg").exists():
        print(f"fixtures not found under {FIXTURES}; skipping accuracy")
        return
    exp = json.loads((mp / "pose_expected.json").read_text())
    est = bp.estimate_image(cv2.imread(str(mp / "pose.jpg")))
    err = np.abs(est.xy[:, :2] - np.array(exp["pixel_xy"]))
    werr = np.abs(est.world - np.array(exp["world_xyz_m"]))
    print(
        f"pose.jpg: max {err.max():.1f} px (tolerance 15), median {np.median(err):.1f} px; world max {werr.max():.3f} m (tolerance 0.2)"
    )
    ref = np.array(json.loads((mp / "pose_squats.full.json").read_text()))
    for smooth in (True, False):
        track = extract(mp / "pose_squats.mp4", estimator=bp, smooth=smooth)
        e = np.abs(track.xy[:, :, :2] - ref[:, :, :2]).ravel()
        q = np.percentile(e, [50, 90, 95, 99, 100])
        print(
            f"pose_squats.mp4 ({'smoothed' if smooth else 'raw'}): {np.mean(e <= 31):.1%} of {e.size} coordinates "
            f"within 31 px; percentiles 50/90/95/99/max = {' / '.join(f'{v:.1f}' for v in q)} px"
        )


def bench_mannequin(bp: BlazePose, fps: float) -> None:
    """PCK@5 % of person height per joint, left/right swaps and bias on the built-in phrases."""
    from capture2notation.body import Body
    from capture2notation.keypoints.evaluate import PAIRS, left_right_swaps, pck, person_height_px
    from synthetic import render
    from synthetic.interpret import interpret
    from synthetic.phrases import builtin_phrases

    joints = [i for pair in PAIRS.values() for i in pair]
    for view in ("front", "45", "side"):
        hits, counts, swaps, n = {}, {}, dict.fromkeys(PAIRS, 0), 0
        signed = {j: [] for j in joints}
        for name, score in sorted(builtin_phrases().items()):
            pose = render.Pose.from_motion(interpret(score, fps, Body()))
            cam = render.Camera.for_view(view, (640, 480), pose.body.height)
            truth = render.truth_fields(pose, cam)
            track = extract_frames(render.render_frames(pose, cam, "mannequin"), pose.fps, estimator=bp)
            radius = 0.05 * person_height_px(cam.K, cam.R, cam.t, pose.root, pose.body.height)
            vis = truth["visibility"] > 0
            d = track.xy[:, :, :2] - truth["keypoints"]
            for j in joints:
                signed[j].append(d[vis[:, j], j])
            for j, v in pck(track.xy, truth["keypoints"], radius, vis, joints).items():
                if np.isfinite(v):
                    hits[j] = hits.get(j, 0.0) + v * vis[:, j].sum()
                    counts[j] = counts.get(j, 0) + vis[:, j].sum()
            for pair, frames in left_right_swaps(track.xy, truth["keypoints"], radius).items():
                swaps[pair] += int(frames.sum())
                if frames.any():
                    print(f"  {view} {name}: {pair} swapped in frames {np.flatnonzero(frames).tolist()}")
            n += len(track)
        names = {i: f"{p}_{s}" for p, (left, right) in PAIRS.items() for s, i in (("L", left), ("R", right))}
        row = " ".join(f"{names[j]}={hits[j] / counts[j]:.3f}" for j in joints if counts.get(j))
        mode = "flip test" if bp.flip_test else "one pass"
        print(f"mannequin {view}, {mode} ({n} frames at {fps:g} fps, visible joints): PCK@5% {row}; swaps {swaps}")
        bias = {j: np.nanmean(np.concatenate(signed[j]), axis=0) for j in joints if counts.get(j)}
        print(
            "  mean signed error (x, y) px: "
            + " ".join(f"{names[j]}=({b[0]:+.1f},{b[1]:+.1f})" for j, b in bias.items())
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=150, help="frames per rendered benchmark video")
    ap.add_argument("--threads", type=int, default=2, help="onnxruntime intra-op threads")
    ap.add_argument(
        "--mannequin-fps", type=float, default=10.0, help="frame rate of the mannequin accuracy renders (0: skip)"
    )
    args = ap.parse_args()
    bp = BlazePose(threads=args.threads)
    print(f"onnxruntime threads: {args.threads}; cpu count: {os.cpu_count()}")
    bench_model(bp)
    with tempfile.TemporaryDirectory(prefix="c2n-bench-") as tmp:
        for size in ((640, 480), (1280, 720)):
            bench_end_to_end(bp, size, args.frames, Path(tmp))
        bp.flip_test = True
        bench_end_to_end(bp, (640, 480), args.frames, Path(tmp))
        bp.flip_test = False
    bench_fixtures(bp)
    if args.mannequin_fps > 0:
        for flip in (False, True):
            bp.flip_test = flip
            bench_mannequin(bp, args.mannequin_fps)


if __name__ == "__main__":
    main()
