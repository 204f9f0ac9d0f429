"""Benchmark of 3D fitting: accuracy against the virtual dancer's truth, and speed.

Run: ``/work/venv/bin/python benchmarks/bench_fitting.py [--blazepose]``
or   ``/work/venv/bin/python benchmarks/bench_fitting.py --labels [--seeds 0 1 ...] [--no-phrases] [--views front 45 side] [--cache DIR]``

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

With ``--labels`` the whole perception path is measured instead: the
built-in phrases and random scores (``random_score`` with the ``--seeds``,
default 0–5) are rendered as mannequins at 25 fps, 640×480, in each view, run
through BlazePose and fitted with the sidecar's camera, as ``c2n capture``
does.  Per view it prints MPJPE, the limb-direction error, the per-frame
LABEL AGREEMENT of every part (direction + level with DESIGN.md's
thresholds, :func:`capture2notation.quantise.labels.label_frames` of the
fitted against the true joints), the kinds of disagreement (``place``:
one of the two is place high/low — an elevation or depth error;
``level``; ``front/back`` and ``left/right``: mirrored sectors;
``adjacent``: a neighbouring sector; ``support``), the root's error and
the fitting speed.  ``--cache DIR`` keeps the rendered tracks (and reuses
them on the next run).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from capture2notation.body import joint_index
from capture2notation.fitting import Camera, fit_keypoints, fit_track
from capture2notation.fitting.motion import read_motion

_LIMBS = [
    (f"{s}_{a}", f"{s}_{b}")
    for s in ("right", "left")
    for a, b in (("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle"))
]


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


_CATEGORIES = ("place", "level", "front/back", "left/right", "adjacent", "other", "missing", "support")


def disagreement_kinds(d_true: np.ndarray, l_true: np.ndarray, d_fit: np.ndarray, l_fit: np.ndarray) -> np.ndarray:
    """Kind of each label disagreement (``"ok"`` where direction and level agree).

    Parameters
    ----------
    d_true, l_true, d_fit, l_fit : (N,) ndarray of int
        Direction (0–7 sectors clockwise from forward, 8 place, −1 missing)
        and level indices of the true and fitted labels.

    Returns
    -------
    (N,) ndarray of str
        ``ok``, ``missing``, ``place`` (one is place, the other not),
        ``level`` (same direction), ``front/back`` (sector mirrored across
        the body's side axis), ``left/right`` (mirrored across the
        sagittal plane), ``adjacent`` (45° apart) or ``other``.
    """
    out = np.full(d_true.shape, "ok", dtype=object)
    s_t, s_f = d_true % 8, d_fit % 8
    sectors = (d_true != 8) & (d_fit != 8) & (d_true != d_fit)
    kinds = (
        (sectors, "other"),
        (sectors & np.isin((s_f - s_t) % 8, (1, 7)), "adjacent"),
        (sectors & (s_f == (-s_t) % 8), "left/right"),
        (sectors & (s_f == (4 - s_t) % 8), "front/back"),
        ((d_true == d_fit) & (l_true != l_fit), "level"),
        ((d_true == 8) != (d_fit == 8), "place"),
        (d_fit < 0, "missing"),
    )
    for mask, name in kinds:  # later kinds take precedence
        out[mask] = name
    out[(d_true == d_fit) & (l_true == l_fit)] = "ok"
    return out


def label_agreement(joints: np.ndarray, truth: np.ndarray, fps: float, confidence: np.ndarray | None = None) -> dict:
    """Per-part per-frame label agreement of fitted joints with the truth.

    Parameters
    ----------
    joints, truth : (T, J, 3) ndarray
    fps : float
    confidence : (T, J) ndarray, optional
        The fit's joint confidence; a gesture part's is the lower of its two ends'.

    Returns
    -------
    dict
        part -> ``(agreement in [0, 1], kinds (N,) of str, confidence (N,))``
        over the frames where the true label is defined (all frames for
        supports, whose confidence is NaN).
    """
    from capture2notation.body import joint_index
    from capture2notation.notation.model import PART_SEGMENTS
    from capture2notation.quantise.labels import label_frames

    lf, lt = label_frames(joints, fps), label_frames(truth, fps)
    out = {}
    for p, part in enumerate(lt.parts):
        dt, ltv, df, lfv = lt.direction[:, p], lt.level[:, p], lf.direction[:, p], lf.level[:, p]
        if part in PART_SEGMENTS:
            sel = dt >= 0
            kinds = disagreement_kinds(dt[sel], ltv[sel], df[sel], lfv[sel])
            a, b = (joint_index(n) for n in PART_SEGMENTS[part])
            conf = (
                np.full(kinds.shape, np.nan)
                if confidence is None
                else np.minimum(confidence[sel, a], confidence[sel, b])
            )
        else:
            ok = (dt == df) & (ltv == lfv)
            kinds = np.where(ok, "ok", "support").astype(object)
            conf = np.full(kinds.shape, np.nan)
        out[part] = (float(np.mean(kinds == "ok")) if kinds.size else float("nan"), kinds, conf)
    return out


def _clips(seeds, phrases: bool = True):
    from synthetic.phrases import PHRASE_NAMES, phrase
    from synthetic.random_scores import random_score

    clips = {name: phrase(name) for name in PHRASE_NAMES} if phrases else {}
    for seed in seeds:
        clips[f"random{seed}"] = random_score(np.random.default_rng(seed), n_beats=8)
    return clips


def _track_and_truth(name, score, view, cache: Path | None):
    """Render `score` in `view`, run BlazePose; reuse `cache/<name>_<view>` when present."""
    from capture2notation.io.truth import read_truth
    from capture2notation.keypoints import KeypointTrack, extract
    from synthetic.render.job import render_score

    def make(folder: Path):
        render_score(score, folder, fps=25.0, size=(640, 480), view=view, style="mannequin", progress=False)
        track = extract(folder / "video.mp4")
        return track, read_truth(folder / "truth.npz")

    if cache is None:
        with tempfile.TemporaryDirectory() as tmp:
            return make(Path(tmp))
    folder = cache / f"{name}_{view}"
    if (folder / "track.npz").is_file() and (folder / "truth.npz").is_file():
        return KeypointTrack.load(folder / "track.npz"), read_truth(folder / "truth.npz")
    track, truth = make(folder)
    track.save(folder / "track.npz")
    (folder / "video.mp4").unlink()
    return track, truth


def label_benchmark(seeds, views, cache: Path | None, phrases: bool = True) -> None:
    """Print per-view label agreement, limb error, MPJPE and speed through BlazePose (see the module docstring)."""
    from collections import Counter, defaultdict

    from capture2notation.notation.model import PART_SEGMENTS

    clips = _clips(seeds, phrases)
    print(f"Label agreement through BlazePose: {len(clips)} clips ({', '.join(clips)}), mannequin, 25 fps, 640x480")
    for view in views:
        parts, kinds, calib = defaultdict(list), Counter(), []
        frames, cpu, mp, med, p90, root_err = 0, 0.0, [], [], [], []
        print(f"\n== view {view}")
        print(
            f"{'clip':14s} {'frames':>6s} {'MPJPE cm':>8s} {'med deg':>7s} {'p90 deg':>7s} {'gesture %':>9s} "
            f"{'support %':>9s} {'root cm':>7s} {'fit fps':>7s}"
        )
        for name, score in clips.items():
            track, truth = _track_and_truth(name, score, view, cache)
            res, c, _ = timed(fit_track, track, camera=Camera.from_truth(truth))
            m, md, p9 = errors(res.joints, truth.joints)
            agree = label_agreement(res.joints, truth.joints, float(track.fps), res.confidence)
            for part, (a, k, cf) in agree.items():
                parts[part].append((a, k.size))
                kinds.update(k[k != "ok"].tolist())
                if part in PART_SEGMENTS:
                    calib.append(np.stack([cf, k == "ok"], axis=1))
            gest = np.mean([agree[p][0] for p in PART_SEGMENTS])
            sup = np.mean([agree[p][0] for p in ("support", "right_support", "left_support")])
            rerr = float(np.nanmedian(np.linalg.norm(res.root - truth.root, axis=1)))
            T = len(track.times)
            frames, cpu = frames + T, cpu + c
            mp.append(m), med.append(md), p90.append(p9), root_err.append(rerr)
            print(
                f"{name:14s} {T:6d} {m * 100:8.1f} {md:7.1f} {p9:7.1f} {gest * 100:9.1f} {sup * 100:9.1f} "
                f"{rerr * 100:7.1f} {T / c:7.0f}"
            )

        def pooled(part, parts=parts):  # frame-weighted over clips
            a = np.array(parts[part])
            return float(np.sum(a[:, 0] * a[:, 1]) / max(np.sum(a[:, 1]), 1))

        gest = np.mean([pooled(p) for p in PART_SEGMENTS])
        sup = np.mean([pooled(p) for p in ("support", "right_support", "left_support")])
        print(
            f"{view}: {frames} frames, fit {frames / cpu:.0f} frames/CPU-s; mean over clips: MPJPE "
            f"{np.mean(mp) * 100:.1f} cm, median limb error {np.mean(med):.1f} deg (p90 {np.mean(p90):.1f}), "
            f"root error {np.mean(root_err) * 100:.1f} cm; label agreement: gestures {gest * 100:.1f} %, "
            f"supports {sup * 100:.1f} %"
        )
        print("  per part: " + "  ".join(f"{p} {pooled(p) * 100:.0f}" for p in parts))
        cal = np.concatenate(calib)
        bins = ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1.01))
        print(
            "  gesture agreement by the fit's confidence: "
            + ", ".join(
                f"[{lo:.2f},{min(hi, 1):.2f}) {np.mean(cal[(cal[:, 0] >= lo) & (cal[:, 0] < hi), 1]) * 100:.0f} % "
                f"of {np.sum((cal[:, 0] >= lo) & (cal[:, 0] < hi))}"
                for lo, hi in bins
                if np.any((cal[:, 0] >= lo) & (cal[:, 0] < hi))
            )
        )
        total = sum(kinds.values())
        print(
            "  disagreements: "
            + ", ".join(f"{k} {kinds[k]} ({kinds[k] / max(total, 1) * 100:.0f} %)" for k in _CATEGORIES if kinds[k])
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blazepose", action="store_true", help="also render the front view and run BlazePose")
    ap.add_argument("--labels", action="store_true", help="label agreement through BlazePose (see above)")
    ap.add_argument(
        "--seeds", type=int, nargs="*", default=list(range(6)), help="seeds of the random scores in --labels"
    )
    ap.add_argument("--no-phrases", action="store_true", help="leave the built-in phrases out of --labels")
    ap.add_argument("--views", nargs="+", default=["front", "45", "side"], choices=["front", "45", "side"])
    ap.add_argument("--cache", type=Path, default=None, help="folder keeping rendered tracks for --labels")
    args = ap.parse_args()
    if args.labels:
        label_benchmark(args.seeds, args.views, args.cache, phrases=not args.no_phrases)
        return
    from synthetic.interpret import interpret
    from synthetic.phrases import PHRASE_NAMES, phrase
    from synthetic.render.camera import Camera as RenderCamera
    from synthetic.render.job import truth_fields
    from synthetic.render.scene import Pose

    rng = np.random.default_rng(0)
    print("Fitting accuracy from the truth's 2D keypoints + world landmarks (640x480)")
    print("all joints | only joints the fit is confident about (>= 0.5; self-occluded landmarks have visibility 0)")
    print(
        f"{'phrase':14s} {'view':5s} {'noise':>12s} {'frames':>6s} {'MPJPE cm':>9s} {'med deg':>8s} {'p90 deg':>8s} "
        f"| {'MPJPE':>6s} {'med':>5s} {'p90':>6s} {'fps cpu':>8s} {'fps wall':>8s}"
    )
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
                print(
                    f"{name:14s} {view:5s} {label:>12s} {T:6d} {m * 100:9.2f} {med:8.2f} {p90:8.2f} "
                    f"| {mc * 100:6.2f} {medc:5.2f} {p90c:6.2f} {T / cpu:8.0f} {T / wall:8.0f}"
                )
    print(f"overall fitting speed: {total_frames / total_cpu:.0f} frames per CPU-second")

    xy, conf, world = observations(
        truth_fields(poses["leg_phrase"], RenderCamera.for_view("front", (640, 480))), 2.0, 0.0, rng
    )
    res, cpu, wall = timed(
        fit_keypoints,
        xy,
        conf,
        25.0,
        world=None,
        camera=Camera.from_truth(truth_fields(poses["leg_phrase"], RenderCamera.for_view("front", (640, 480)))),
    )
    m, med, p90 = errors(res.joints, poses["leg_phrase"].joints)
    print(
        f"2D keypoints only (no world landmarks), leg_phrase front 2px: MPJPE {m * 100:.1f} cm, median {med:.1f} deg, p90 {p90:.1f} deg"
    )
    f = truth_fields(poses["port_de_bras"], RenderCamera.for_view("front", (640, 480)))
    xy, conf, world = observations(f, 2.0, 0.02, rng)
    res, cpu, wall = timed(fit_keypoints, xy, conf, 25.0, world=world, image_size=(640, 480))

    def rel(j):
        return j - j[:, :1]

    m, med, p90 = errors(rel(res.joints), rel(poses["port_de_bras"].joints))
    print(
        f"unknown camera (default {Camera.default((640, 480)).focal:.0f} px focal, refined), port_de_bras front 2px: "
        f"root-relative MPJPE {m * 100:.1f} cm, median {med:.1f} deg; {len(xy) / cpu:.0f} frames/CPU-s incl. focal search"
    )

    fixtures = Path(__file__).resolve().parents[2] / "shared" / "fixtures" / "bvh"
    for bvh in sorted(fixtures.glob("*.bvh")):
        mo, cpu, wall = timed(read_motion, bvh)
        print(
            f"read_motion {bvh.name}: {mo.n_frames} frames in {cpu:.1f} CPU-s ({mo.n_frames / cpu:.0f} frames/CPU-s, wall {wall:.1f} s)"
        )

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
                print(
                    f"BlazePose {name} front 640x480: MPJPE {m * 100:.1f} cm, median {med:.1f} deg, p90 {p90:.1f} deg; "
                    f"keypoints {len(track.times) / kcpu:.0f} fps, fit {len(track.times) / cpu:.0f} fps (CPU)"
                )


if __name__ == "__main__":
    main()
