"""Benchmark of 3D fitting: accuracy against the virtual dancer's truth, and speed.

Run: ``/work/venv/bin/python benchmarks/bench_fitting.py [--blazepose]``

For each built-in phrase the virtual dancer's motion is seen through the
preset cameras (front, 45°, side at 640×480); the truth's own 2D keypoints
and world landmarks (camera-aligned, hip-centred, as BlazePose reports them)
are fitted clean and with noise, and compared with the true joints:

* MPJPE (mean per-joint position error, all joints, cm);
* median and 90th-percentile angular error of the limb directions
  (upper arms, forearms, thighs, shins), degrees.

With ``--blazepose`` the front view is also rendered and run through the
keypoint stage (``capture2notation.keypoints.extract``) before fitting.
Speed is CPU-seconds-based frames per second of :func:`fit_keypoints` (and
wall-clock on this shared machine), plus BVH and Kinect reading rates.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from capture2notation.body import joint_index
from capture2notation.fitting import Camera, fit_keypoints, fit_track
from capture2notation.io.motion import read_motion

_LIMBS = [(f"{s}_{a}", f"{s}_{b}") for s in ("right", "left")
          for a, b in (("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle"))]


def errors(joints: np.ndarray, truth: np.ndarray, confidence: np.ndarray | None = None):
    """MPJPE (m), median and p90 limb-direction error (degrees), over finite frames.

    With `confidence`, only joints (limbs) whose fitted confidence (both ends)
    is at least 0.5 count: what the fit claims to know.
    """
    ok = np.all(np.isfinite(joints), axis=(1, 2))
    j, t = joints[ok], truth[ok]
    c = np.ones(j.shape[:2]) if confidence is None else confidence[ok]
    d = np.linalg.norm(j - t, axis=-1)
    mpjpe = float(np.mean(d[c >= 0.5]))
    ang = []
    for a, b in _LIMBS:
        ia, ib = joint_index(a), joint_index(b)
        sel = (c[:, ia] >= 0.5) & (c[:, ib] >= 0.5)
        u = t[sel, ib] - t[sel, ia]
        v = j[sel, ib] - j[sel, ia]
        cos = np.sum(u * v, -1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
        ang.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    ang = np.concatenate(ang)
    return mpjpe, float(np.median(ang)), float(np.percentile(ang, 90))


def observations(fields: dict, noise_px: float, noise_m: float, rng: np.random.Generator):
    """Keypoints, confidences and camera-aligned world landmarks from truth fields."""
    xy = fields["keypoints"] + rng.normal(0.0, noise_px, fields["keypoints"].shape) if noise_px else fields["keypoints"]
    conf = np.asarray(fields["visibility"], float)
    lm = fields["landmarks3d"]
    hip = 0.5 * (lm[:, 23] + lm[:, 24])
    world = (lm - hip[:, None]) @ np.asarray(fields["R"]).T
    if noise_m:
        world = world + rng.normal(0.0, noise_m, world.shape)
    return xy, conf, world


def timed(fn, *a, **k):
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn(*a, **k)
    return out, time.process_time() - c0, time.perf_counter() - w0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blazepose", action="store_true", help="also render the front view and run BlazePose")
    args = ap.parse_args()
    from synthetic.interpret import interpret
    from synthetic.phrases import PHRASE_NAMES, phrase
    from synthetic.render.camera import Camera as RenderCamera
    from synthetic.render.job import truth_fields
    from synthetic.render.scene import Pose

    rng = np.random.default_rng(0)
    print("Fitting accuracy from the truth's 2D keypoints + world landmarks (640x480)")
    print("all joints | only joints the fit is confident about (>= 0.5; self-occluded landmarks have visibility 0)")
    print(f"{'phrase':14s} {'view':5s} {'noise':>12s} {'frames':>6s} {'MPJPE cm':>9s} {'med deg':>8s} {'p90 deg':>8s} "
          f"| {'MPJPE':>6s} {'med':>5s} {'p90':>6s} {'fps cpu':>8s} {'fps wall':>8s}")
    total_frames, total_cpu = 0, 0.0
    poses = {}
    for name in PHRASE_NAMES:
        motion = interpret(phrase(name), fps=25.0)
        pose = Pose.from_motion(motion)
        poses[name] = pose
        for view in ("front", "45", "side"):
            cam_r = RenderCamera.for_view(view, (640, 480), pose.body.height)
            f = truth_fields(pose, cam_r)
            cam = Camera.from_truth(f)
            for noise_px, noise_m in ((0.0, 0.0), (2.0, 0.02), (5.0, 0.05)):
                xy, conf, world = observations(f, noise_px, noise_m, rng)
                res, cpu, wall = timed(fit_keypoints, xy, conf, pose.fps, camera=cam, world=world)
                m, med, p90 = errors(res.joints, pose.joints)
                mc, medc, p90c = errors(res.joints, pose.joints, res.confidence)
                T = len(xy)
                total_frames += T
                total_cpu += cpu
                label = f"{noise_px:g}px/{noise_m * 100:g}cm"
                print(f"{name:14s} {view:5s} {label:>12s} {T:6d} {m * 100:9.2f} {med:8.2f} {p90:8.2f} "
                      f"| {mc * 100:6.2f} {medc:5.2f} {p90c:6.2f} {T / cpu:8.0f} {T / wall:8.0f}")
    print(f"overall fitting speed: {total_frames / total_cpu:.0f} frames per CPU-second")

    xy, conf, world = observations(truth_fields(poses["leg_phrase"], RenderCamera.for_view("front", (640, 480))), 2.0, 0.0, rng)
    res, cpu, wall = timed(fit_keypoints, xy, conf, 25.0, world=None,
                           camera=Camera.from_truth(truth_fields(poses["leg_phrase"], RenderCamera.for_view("front", (640, 480)))))
    m, med, p90 = errors(res.joints, poses["leg_phrase"].joints)
    print(f"2D keypoints only (no world landmarks), leg_phrase front 2px: MPJPE {m * 100:.1f} cm, median {med:.1f} deg, p90 {p90:.1f} deg")
    f = truth_fields(poses["port_de_bras"], RenderCamera.for_view("front", (640, 480)))
    xy, conf, world = observations(f, 2.0, 0.02, rng)
    res, cpu, wall = timed(fit_keypoints, xy, conf, 25.0, world=world, image_size=(640, 480))
    rel = lambda j: j - j[:, :1]  # noqa: E731 - root-relative
    m, med, p90 = errors(rel(res.joints), rel(poses["port_de_bras"].joints))
    print(f"unknown camera (default {Camera.default((640, 480)).focal:.0f} px focal, refined), port_de_bras front 2px: "
          f"root-relative MPJPE {m * 100:.1f} cm, median {med:.1f} deg; {len(xy) / cpu:.0f} frames/CPU-s incl. focal search")

    fixtures = Path(__file__).resolve().parents[2] / "shared" / "fixtures" / "bvh"
    for bvh in sorted(fixtures.glob("*.bvh")):
        mo, cpu, wall = timed(read_motion, bvh)
        print(f"read_motion {bvh.name}: {mo.n_frames} frames in {cpu:.1f} CPU-s ({mo.n_frames / cpu:.0f} frames/CPU-s, wall {wall:.1f} s)")

    if args.blazepose:
        from capture2notation.keypoints import extract
        from synthetic.render.job import render_motion

        for name in PHRASE_NAMES:
            with tempfile.TemporaryDirectory() as tmp:
                video = render_motion(interpret(phrase(name), fps=25.0), tmp, size=(640, 480), view="front")
                from capture2notation.io.truth import read_truth

                truth = read_truth(Path(tmp) / "truth.npz")
                (track, kcpu, _) = timed(extract, video)
                res, cpu, wall = timed(fit_track, track, camera=Camera.from_truth(truth))
                m, med, p90 = errors(res.joints, truth.joints)
                print(f"BlazePose {name} front 640x480: MPJPE {m * 100:.1f} cm, median {med:.1f} deg, p90 {p90:.1f} deg; "
                      f"keypoints {len(track.times) / kcpu:.0f} fps, fit {len(track.times) / cpu:.0f} fps (CPU)")


if __name__ == "__main__":
    main()
