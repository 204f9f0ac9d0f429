"""Record one performance under one condition, capture it, and measure the result.

Capture paths (``capture`` in the study config):

``truth``
    The virtual dancer's own joints, projected into the condition's camera,
    jittered by the condition's pixel noise plus a 1 px detector floor,
    rounded to the pixel grid, and lifted back to 3D with the true depth.
    Cheapest; it isolates frame rate, image resolution and viewpoint
    geometry.  Compression is not modelled (no image).
``keypoints``
    The 33 BlazePose landmarks of the virtual dancer, projected into the
    condition's camera with the renderer's self-occlusion test (hidden
    landmarks are missing), jittered and rounded as above, with BlazePose-like
    world landmarks (hip-centred, camera axes, Gaussian noise of
    :data:`WORLD_NOISE_M`), then fitted in 3D by
    :func:`capture2notation.fitting.fit_keypoints` with default body
    proportions and the camera the fit estimates from the landmarks (what a
    user without a calibration has).  Compression is not modelled.
``video``
    The whole chain: the mannequin renderer draws the take's kept frames
    (:func:`synthetic.render.job.make_renderer`), each held until the next
    (Neagle's emulation of a low rate at 25 Hz), JPEG-compressed at the
    condition's quality and given Gaussian pixel noise, written once as
    H.264, and :func:`pipelines.capture.capture` (BlazePose, fitting,
    segmentation) reads the video with no calibration.  A few seconds of
    CPU per job.
``keypoints-calibrated``, ``video-calibrated``
    The same with the renderer's camera given to the fit (as ``c2n capture
    --calibration camera.toml`` would): the named calibrated condition.

A condition of several cameras (``cameras`` factor: views joined by ``+``)
is always calibrated, with the renderer's cameras: the truth path
triangulates the jittered joints, the keypoint path fits the jittered
landmarks of every camera with :func:`capture2notation.fitting.multiview.fit_views`
(joints no two cameras see from the monocular fit of the camera that sees
most of them, as a capture does), and the video
path renders a clip per camera and captures them together
(:func:`pipelines.capture.capture` with the cameras' calibration file).

Only the kept frames of a condition reach the capture (the others are
missing, never invented); the metrics that need a full-rate sequence use the
captured frames linearly interpolated in time, as a capture system that
resamples to a uniform rate would.
"""

from __future__ import annotations

import logging
from fractions import Fraction

import numpy as np

from capture2notation.compare.align import align_dtw
from capture2notation.compare.metrics import compare_movements, key_frames, mpjpe, notation_agreement, pa_mpjpe
from capture2notation.compare.resample import decimate, keyframe_resample
from capture2notation.errors import C2NError, PipelineError
from capture2notation.notation.model import PART_SEGMENTS, Score

from .conditions import Condition, Performance, take_variation

__all__ = [
    "CAPTURE_NOTES",
    "DETECTOR_FLOOR_PX",
    "capture",
    "estimate_effort",
    "interpolate_missing",
    "kept_frames",
    "measure",
    "perform",
]

log = logging.getLogger(__name__)

#: Keypoint jitter (px) that even a clean, full-resolution image leaves: our
#: stated assumption for the truth and keypoint paths.
DETECTOR_FLOOR_PX = 1.0
#: Noise (m) of the simulated BlazePose world landmarks on the keypoint path,
#: our stated assumption (MediaPipe's own test tolerance is 0.2 m).
WORLD_NOISE_M = 0.03


#: One sentence per capture path, for the report.
CAPTURE_NOTES = {
    "truth": "truth path — the virtual dancer's joints projected into each camera, jittered and rounded to pixels, "
    "lifted back with the true depth (no image, no pose detector, no fitting; compression not modelled)",
    "keypoints": "keypoint path — the dancer's 33 BlazePose landmarks projected into each camera with self-occlusion, "
    "jittered and rounded to pixels, then fitted in 3D by capture2notation.fitting with the camera it estimates "
    "(no image and no pose detector; compression not modelled)",
    "video": "video path — the renderer draws each take, the kept frames are held in between, JPEG-compressed and "
    "noised, and c2n capture (BlazePose, fitting, segmentation) reads the video with no calibration",
}
CAPTURE_NOTES |= {
    f"{path}-calibrated": CAPTURE_NOTES[path]
    .replace(" with the camera it estimates", " with the renderer's camera, calibrated")
    .replace(" with no calibration", " with the renderer's camera as --calibration")
    for path in ("keypoints", "video")
}


def builtin_scores() -> dict[str, Score]:
    """Built-in phrases of the virtual dancer, name → Score."""
    try:
        from synthetic.phrases import builtin_phrases
    except ImportError as exc:
        raise PipelineError(f"the virtual dancer's phrases are not available ({exc})") from None
    phrases = builtin_phrases()
    if isinstance(phrases, dict):
        return dict(phrases)
    return {getattr(p, "name", None) or p.title: getattr(p, "score", p) for p in phrases}


def perform(perf: Performance, seed: int, fps: float, scores: dict | None = None):
    """The virtual dancer performs one take.

    Returns
    -------
    score : Score
        The phrase as danced: the take's tempo and Effort.
    motion : synthetic.motion.Motion
    """
    from capture2notation.body import Body
    from synthetic.interpret import interpret

    scores = scores if scores is not None else builtin_scores()
    if perf.phrase not in scores:
        raise PipelineError(f"unknown phrase {perf.phrase!r}; built-in phrases are {', '.join(sorted(scores))}")
    var = take_variation(perf, seed)
    score = scores[perf.phrase].replace(tempo=var["tempo"], effort=var["effort"], emotion=None)
    body = Body(height=var["height"])
    motion = interpret(score, fps=fps, body=body)
    return score, motion


def kept_frames(cond: Condition, score: Score, n_frames: int, fps: float) -> np.ndarray:
    """Frames the condition's frame rate keeps (key poses = symbol arrivals)."""
    if cond.resampling == "naive":
        return decimate(n_frames, cond.rate, Fraction(str(fps)))
    kf = key_frames(score, fps, n_frames)
    return keyframe_resample(n_frames, kf, cond.rate, Fraction(str(fps)))


def _camera(cond: Condition, height: float, view: str | None = None):
    from synthetic.render.camera import Camera

    return Camera.for_view(view or cond.view, size=(cond.width, cond.height), body_height=height)


def _calibrated(cond: Condition, height: float) -> list:
    """The condition's cameras: ``(render camera, CameraCalibration named by its view)`` each."""
    from capture2notation.io.calibration import CameraCalibration

    out = []
    for view in cond.views:
        cam = _camera(cond, height, view)
        out.append((cam, CameraCalibration(view, (cond.width, cond.height), cam.K, np.zeros(5), cam.R, cam.t)))
    return out


def _jitter(uv: np.ndarray, cond: Condition, rng: np.random.Generator) -> np.ndarray:
    sigma = float(np.hypot(DETECTOR_FLOOR_PX, cond.noise))
    noisy = uv + rng.normal(0.0, sigma, size=uv.shape)
    return np.floor(noisy) + 0.5  # a detector reports pixel centres


def capture(
    mode: str,
    motion,
    kept: np.ndarray,
    cond: Condition,
    rng: np.random.Generator,
    threads: int = 2,
):
    """Capture the kept frames of a performance.

    Parameters
    ----------
    mode : {"truth", "keypoints", "video", "keypoints-calibrated", "video-calibrated"}
    motion : synthetic.motion.Motion
    kept : (M,) ndarray of int
    cond : Condition
    rng : numpy.random.Generator
    threads : int
        The pose model's threads on the video path (1 when jobs run side by side).

    Returns
    -------
    joints : (T, J, 3) ndarray
        World joints at the kept frames, NaN elsewhere.
    confidence : (T, J) ndarray
        In [0, 1], 0 where missing.
    """
    mode, _, suffix = mode.partition("-")
    if suffix not in ("", "calibrated") or (suffix and mode == "truth"):
        raise PipelineError(
            f"capture path {mode + '-' + suffix!r} is not available; use 'truth', 'keypoints', 'video', "
            "'keypoints-calibrated' or 'video-calibrated'"
        )
    calibrated = suffix == "calibrated"
    truth = motion.joints()
    T, J, _ = truth.shape
    out = np.full((T, J, 3), np.nan)
    conf = np.zeros((T, J))
    if mode == "video":
        # Several cameras are calibrated by construction.
        j, c = _capture_video(motion, kept, cond, rng, calibrated or len(cond.views) > 1, threads)
        out[kept], conf[kept] = j[kept], c[kept]
        out[conf == 0] = np.nan
        return out, conf
    if len(cond.views) > 1:
        return _capture_cameras(mode, motion, kept, cond, rng, out, conf)
    cam = _camera(cond, motion.body.height)
    if mode == "truth":
        p = truth[kept]
        uv, depth = cam.project(p, return_depth=True)
        uv = _jitter(uv, cond, rng)
        k = cam.K
        xc = np.stack([(uv[..., 0] - k[0, 2]) / k[0, 0] * depth, (uv[..., 1] - k[1, 2]) / k[1, 1] * depth, depth], -1)
        out[kept] = (xc - cam.t) @ cam.R  # R^T (x_cam − t), row vectors
        conf[kept] = cam.in_image(uv).astype(float)
        out[conf == 0] = np.nan
        return out, conf
    if mode == "keypoints":
        from capture2notation.fitting import fit_keypoints
        from capture2notation.fitting.camera import Camera as FitCamera
        from synthetic.render.scene import Pose

        uv, vis, world = _simulated_landmarks(Pose.from_motion(motion), cam, kept, cond, rng)
        fitcam = FitCamera(cam.K, cam.R, cam.t, (cond.width, cond.height)) if calibrated else None
        res = fit_keypoints(
            uv,
            vis,
            motion.fps,
            camera=fitcam,
            world=world,
            times=kept / motion.fps,
            image_size=(cond.width, cond.height),
        )
        # The fitter's skeleton places unseen joints by the body model; keep
        # them (confidence 0 still marks them unmeasured for the Effort fit).
        out[kept] = res.joints
        conf[kept] = res.confidence
        return out, conf
    raise PipelineError(f"capture path {mode!r} is not available; use 'truth', 'keypoints' or 'video'")


def _simulated_landmarks(pose, cam, kept, cond: Condition, rng):
    """BlazePose-like landmarks of the kept frames in one camera.

    Returns pixels (M, 33, 2), jittered and NaN where the renderer's
    self-occlusion test hides a landmark; visibility (M, 33) in {0, 1}; and
    world landmarks (M, 33, 3): hip-centred, camera-aligned axes, metres,
    with Gaussian noise of :data:`WORLD_NOISE_M`.
    """
    from synthetic.render.scene import landmark_visibility

    lm = pose.landmarks[kept]
    vis = landmark_visibility(pose, cam)[kept].astype(float)
    uv = _jitter(cam.project(lm), cond, rng)
    uv[vis == 0] = np.nan
    hip = 0.5 * (lm[:, 23] + lm[:, 24])
    world = (lm - hip[:, None]) @ cam.R.T + rng.normal(0.0, WORLD_NOISE_M, lm.shape)
    world[vis == 0] = np.nan
    return uv, vis, world


def _capture_cameras(mode: str, motion, kept, cond: Condition, rng, out, conf):
    """:func:`capture` with several calibrated cameras, truth and keypoint paths (module docstring)."""
    from capture2notation.fitting.multiview import fit_views
    from capture2notation.fitting.triangulate import triangulate

    cams = _calibrated(cond, motion.body.height)
    if mode == "truth":
        p = motion.joints()[kept]
        uv = np.stack([_jitter(cam.project(p), cond, rng) for cam, _ in cams])
        seen = np.stack([cam.in_image(u) for (cam, _), u in zip(cams, uv)])
        uv[~seen] = np.nan
        points, pconf, _ = triangulate(uv, seen.astype(float), [c for _, c in cams])
        out[kept], conf[kept] = points, (pconf > 0).astype(float)
        out[conf == 0] = np.nan
        return out, conf
    if mode == "keypoints":
        from capture2notation.fitting import fit_keypoints
        from capture2notation.fitting.camera import Camera as FitCamera
        from capture2notation.fitting.multiview import fill_from_view
        from synthetic.render.scene import Pose

        pose = Pose.from_motion(motion)
        uv, vis, world = zip(*(_simulated_landmarks(pose, cam, kept, cond, rng) for cam, _ in cams))

        def fit_window(view: int, w: slice):
            cam = cams[view][0]
            return fit_keypoints(
                uv[view][w], vis[view][w], motion.fps, camera=FitCamera(cam.K, cam.R, cam.t, (cond.width, cond.height)),
                world=world[view][w], times=kept[w] / motion.fps, image_size=(cond.width, cond.height),
            )  # fmt: skip

        def fill(joints, jconf, missing, floor):
            # As a capture does: the joints no two cameras saw, from the
            # monocular fit of the camera that sees most of them.
            return fill_from_view(joints, jconf, missing, floor, vis, motion.fps, fit_window)[1:]

        res, _floor = fit_views(
            np.stack(uv), np.stack(vis), [c for _, c in cams], motion.fps, times=kept / motion.fps, fill=fill
        )
        out[kept], conf[kept] = res.joints, res.confidence
        return out, conf
    raise PipelineError(f"capture path {mode!r} is not available; use 'truth', 'keypoints' or 'video'")


def _render_take(path, renderer, shown, cond: Condition, fps: float, rng) -> None:
    """Write the shown frames of a take to `path`, each held frame compressed alike with fresh noise."""
    import cv2

    from capture2notation.io.video import VideoWriter

    image, drawn = None, -1
    with VideoWriter(path, fps, (cond.width, cond.height)) as w:
        for i in range(len(shown)):
            if shown[i] != drawn:
                drawn = int(shown[i])
                image = renderer.frame(drawn)
                if cond.compression:
                    _ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(cond.compression)])
                    image = cv2.imdecode(buf, cv2.IMREAD_COLOR)
            img = image
            if cond.noise:
                noisy = rng.standard_normal(image.shape, dtype=np.float32)
                noisy *= cond.noise
                noisy += image
                img = np.clip(noisy, 0, 255, out=noisy).astype(np.uint8)
            w.write(img)


def _capture_video(motion, kept, cond: Condition, rng, calibrated: bool = False, threads: int = 2):
    """Render, degrade (hold, JPEG, noise) and capture a take; joints (T,J,3) and confidence (T,J).

    The renderer draws each shown frame once, straight into the video the
    capture reads (one H.264 generation, as a camera writes it); a held
    frame repeats the image of the frame it holds, compressed alike, with
    fresh pixel noise.  Several cameras each get a clip
    (``<view>/video.mp4``) and one calibration file.
    """
    import tempfile
    from pathlib import Path

    from capture2notation.compare.resample import hold_map
    from capture2notation.io.calibration import Calibration, write_calibration
    from pipelines.capture import capture as run_capture
    from synthetic.render.job import CAMERA_FILE, make_renderer, write_camera_toml
    from synthetic.render.scene import Pose

    T = motion.n_frames
    if T == 0:
        raise PipelineError("the performance has no frames to render")
    pose = Pose.from_motion(motion)
    shown = hold_map(kept, T)
    with tempfile.TemporaryDirectory(prefix="c2n-fidelity-") as tmp:
        tmp = Path(tmp)
        if len(cond.views) > 1:
            cams = _calibrated(cond, motion.body.height)
            videos = []
            for cam, calib in cams:
                (tmp / calib.name).mkdir()
                videos.append(tmp / calib.name / "video.mp4")
                _render_take(videos[-1], make_renderer(pose, cam, "mannequin"), shown, cond, motion.fps, rng)
            write_calibration(Calibration.of([c for _, c in cams]), tmp / "cameras.toml")
            source, calibration = [str(v) for v in videos], tmp / "cameras.toml"
        else:
            cam = _camera(cond, motion.body.height)
            _render_take(tmp / "video.mp4", make_renderer(pose, cam, "mannequin"), shown, cond, motion.fps, rng)
            source, calibration = tmp / "video.mp4", None
            if calibrated:
                write_camera_toml(cam, tmp / CAMERA_FILE, name="video")
                calibration = tmp / CAMERA_FILE
        run_capture(
            source,
            tmp / "capture",
            effort=False,
            overlay=False,
            progress=False,
            seed=int(rng.integers(2**31)),
            calibration=calibration,
            threads=threads,
        )
        with np.load(tmp / "capture" / "capture.npz") as z:
            joints = np.asarray(z["joints"], float)
            conf = np.asarray(z["confidence"], float) if "confidence" in z.files else np.isfinite(joints[..., 0]) * 1.0
    # The video may round the frame count; pad with missing frames, never invented ones.
    out = np.full((T,) + joints.shape[1:], np.nan)
    c = np.zeros((T, joints.shape[1]))
    n = min(T, len(joints))
    out[:n], c[:n] = joints[:n], conf[:n]
    return out, c


def interpolate_missing(joints: np.ndarray) -> np.ndarray:
    """Fill NaN frames by linear interpolation in time (ends held), per joint.

    Parameters
    ----------
    joints : (T, J, 3) ndarray

    Returns
    -------
    (T, J, 3) ndarray
        Joints never seen at all stay NaN.
    """
    x = np.asarray(joints, dtype=float)
    T = x.shape[0]
    flat = x.reshape(T, -1)
    out = flat.copy()
    t = np.arange(T)
    ok = np.isfinite(flat)
    for c in np.flatnonzero(ok.any(0) & ~ok.all(0)):  # only columns with gaps
        out[:, c] = np.interp(t, t[ok[:, c]], flat[ok[:, c], c])
    return out.reshape(x.shape)


def estimate_effort(joints, confidence, fps: float, score: Score, kept: np.ndarray, rng, bootstrap: int) -> dict:
    """Pooled Effort of a captured phrase from its kept frames, with bootstrap intervals.

    Each gesture symbol's window gives a progress curve
    (:func:`capture2notation.effort.curves.progress_curve`); the curves are
    pooled and fitted by least squares (time b, weight x0) and the Space
    model; the 90 % intervals come from resampling the movements.

    Returns
    -------
    dict
        ``time``, ``weight``, ``space`` → (estimate, lo, hi) and
        ``movements`` (curves used); NaN when fewer than 2 curves survive.
    """
    from scipy import optimize

    from capture2notation.effort import TIME_RANGE, WEIGHT_RANGE, progress
    from capture2notation.effort.curves import progress_curve
    from capture2notation.effort.fit import fit_logistic
    from capture2notation.effort.pooled import pool_curves, pooled_space

    times = kept / fps
    curves = []
    for s in score.symbols:
        if s.part not in PART_SEGMENTS:
            continue
        try:
            c = progress_curve(
                joints[kept], confidence[kept], times, s.part, score.seconds(s.start), score.seconds(s.end)
            )
        except C2NError:
            continue  # too few frames inside this movement at this frame rate
        if c is not None:
            curves.append(c)
    nan3 = (np.nan, np.nan, np.nan)
    if len(curves) < 2:
        return {"time": nan3, "weight": nan3, "space": nan3, "movements": len(curves)}

    def pooled(sel):
        return pool_curves([curves[i] for i in sel])[:3]

    def space(sel):
        # capture2notation.effort's own pooling: whole limbs only, a trend per movement.
        chosen = [curves[i] for i in sel if curves[i].shows_space]
        return pooled_space(chosen).median if chosen else np.nan

    tau, s, w = pooled(np.arange(len(curves)))
    lf = fit_logistic(tau, s, w)
    est = (lf.b, lf.x0, space(range(len(curves))))
    boots = []
    for _ in range(bootstrap):
        sel = rng.integers(0, len(curves), len(curves))
        tau, s, w = pooled(sel)
        # One warm start from the full fit: resamples stay near it, and the
        # multi-start search of fit_logistic would cost 4x as much.
        sw = np.sqrt(w)
        r = optimize.least_squares(
            lambda p, tau=tau, s=s, sw=sw: sw * (progress(tau, p[0], p[1]) - s),
            [lf.b, lf.x0],
            bounds=([TIME_RANGE[0], WEIGHT_RANGE[0]], [TIME_RANGE[1], WEIGHT_RANGE[1]]),
            x_scale=[1.0, 0.1],
        )
        boots.append((r.x[0], r.x[1], space(sel)))
    boots = np.array(boots, dtype=float).reshape(-1, 3)
    lo = np.quantile(boots, 0.05, axis=0) if bootstrap else np.array(est)
    hi = np.quantile(boots, 0.95, axis=0) if bootstrap else np.array(est)
    est = tuple(float(x) for x in est)
    lo, hi = lo.astype(float), hi.astype(float)
    return {
        "time": (est[0], float(min(lo[0], est[0])), float(max(hi[0], est[0]))),
        "weight": (est[1], float(min(lo[1], est[1])), float(max(hi[1], est[1]))),
        "space": (est[2], float(min(lo[2], est[2])), float(max(hi[2], est[2]))),
        "movements": len(curves),
    }


def measure(score: Score, motion, joints, confidence, kept, rng, bootstrap: int) -> dict:
    """Every metric of one captured job against the virtual dancer's truth.

    Returns
    -------
    dict
        Flat numbers for ``results.csv`` (see the report for their meaning).
    """
    fps = motion.fps
    truth = motion.joints()
    rec = interpolate_missing(joints)
    T = len(truth)
    kf = key_frames(score, fps, T)
    row: dict = {"frames": T, "kept_frames": int(len(kept))}
    usable = np.all(np.isfinite(rec[:, :, 0]), axis=0)
    if not usable.any():
        raise PipelineError("the capture recovered no joint at all")
    filled = _fill_unseen(rec)
    al = align_dtw(truth, filled, band=int(round(fps)))
    moves = compare_movements(score, truth, rec, kf, al.candidate_frame(kf), fps, fps)
    gest = [m for m in moves if m.verdict != "n/a"]
    row["symbols"] = len(gest)
    row["symbol_accuracy"] = float(np.mean([m.agree for m in gest])) if gest else np.nan
    row["angle_error_deg"] = float(np.nanmean([m.pose_error for m in gest])) if gest else np.nan
    row["timing_error_s"] = float(np.mean([abs(m.timing_offset) for m in gest])) if gest else np.nan
    row["mpjpe_mm"] = 1000.0 * float(np.nanmean(mpjpe(truth, rec)))
    row["pa_mpjpe_mm"] = 1000.0 * float(np.nanmean(pa_mpjpe(truth, rec)))
    try:
        from capture2notation.quantise.segment import segment_motion

        seg = segment_motion(filled, fps)
        na = notation_agreement(score, seg.score)
        row["notation_accuracy"] = na["fraction"]
        row["notation_extra"] = na["extra"]
        row["tempo_est"] = float(seg.tempo)
    except C2NError as exc:
        log.info("segmentation failed: %s", exc)
        row["notation_accuracy"] = np.nan
        row["notation_extra"] = np.nan
        row["tempo_est"] = np.nan
    row["tempo_obs"] = observed_tempo(rec, fps, score)
    eff = estimate_effort(joints, confidence, fps, score, kept, rng, bootstrap)
    truth_eff = score.resolved_effort()
    row["effort_movements"] = eff["movements"]
    for name in ("time", "weight", "space"):
        est, lo, hi = eff[name]
        true = getattr(truth_eff, name)
        row[f"{name}_est"] = est
        row[f"{name}_lo"] = lo
        row[f"{name}_hi"] = hi
        row[f"{name}_true"] = true
        row[f"{name}_error"] = est - true
        row[f"{name}_covered"] = float(lo <= true <= hi) if np.isfinite(lo) else np.nan
    row["tempo_true"] = float(score.tempo)
    return row


def observed_tempo(joints: np.ndarray, fps: float, score: Score, rel: float = 0.15) -> float:
    """Tempo (bpm) from how long the dancer takes over the phrase's gestures.

    The exercise is known to the observer (as in Neagle's trials: both
    performances of a trial dance the same exercise), so its gestures span
    a known number of beats; the time from the first to the last frame in
    which some limb turns faster than `rel` of the take's peak angular speed
    gives the tempo.  NaN when no movement is seen.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        Captured joints at the full rate (gaps interpolated).
    fps : float
    score : Score
        The exercise (only its beats are used, never its tempo).
    rel : float
        Activity threshold as a fraction of the peak speed.
    """
    from capture2notation.compare.align import limb_features
    from capture2notation.compare.metrics import angle_between

    gest = [s for s in score.symbols if s.part in PART_SEGMENTS]
    if not gest or len(joints) < 3:
        return float("nan")
    from scipy.ndimage import median_filter

    beats = float(max(s.end for s in gest) - min(s.start for s in gest))
    f = limb_features(_fill_unseen(joints))
    speed = np.nan_to_num(angle_between(f[1:], f[:-1])).max(axis=1) * fps  # (T-1,) deg/s
    # A 5-frame running median drops isolated jitter spikes, and the 95th
    # percentile rather than the maximum sets the scale, so one bad frame
    # neither starts the phrase early nor raises the threshold.
    speed = median_filter(speed, size=5, mode="nearest")
    peak = float(np.percentile(speed, 95))
    if peak <= 0:
        return float("nan")
    active = np.flatnonzero(speed > rel * peak)
    span = (active[-1] + 1 - active[0]) / fps
    return 60.0 * beats / span if span > 0 else float("nan")


def _fill_unseen(rec: np.ndarray) -> np.ndarray:
    """Put joints never seen in the whole take on the pelvis.

    Limbs ending at such a joint then have zero length, which the alignment
    features treat as undefined, instead of NaN poisoning whole frames.
    Used only as alignment and segmentation input, never as a measurement.
    """
    out = rec.copy()
    bad = ~np.all(np.isfinite(out), axis=(0, 2))
    if bad.any():
        out[:, bad] = out[:, :1]
    return out
