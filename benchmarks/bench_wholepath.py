"""The whole path on phrases kept out of development: accuracy and speed.

Run ``python benchmarks/bench_wholepath.py [--view front|45|side] [--phone H,PITCH,ROLL,HFOV] [--phrases DIR | --random N [--first-seed S]] [--explain]``.

Each phrase (``benchmarks/holdout/*.lab`` by default: eight phrases of arms,
legs and supports written for this measurement and never used to tune the
code) is performed by the virtual dancer, rendered at 25 fps, 640×480, with
the mannequin, and captured twice:

* from the truth sidecar (no perception: the quantiser alone), and
* from the video (BlazePose → 3D fit → quantiser), the tempo estimated
  (or given, ``--tempo-given``), the camera estimated from the person (or
  the renderer's true camera given explicitly, ``--calibrated``: the named
  calibrated condition; a capture never reads the sidecar itself).

Printed (never asserted): per phrase and overall, the symbol agreement
(direction + level per part per beat of the original) and overall the
cells lost out of those compared, the median start-time error in beats, whether the truth capture is exact, the median limb-direction
error and MPJPE of the fit, and frames per second of the whole video capture.
``--random N`` measures N random scores of 16 beats
(:func:`synthetic.random_score`, seeds from ``--first-seed``) instead of
phrases: pick seeds never used in development.  The summary gives the
agreement of each column (part) over all phrases too.  With ``--explain``, under each phrase, the beats it loses: per part, the
reference's state and the capture's
(:func:`capture2notation.compare.agreement.agreement_cells`).

With ``--keypoints render`` the fit is given the renderer's own landmarks
(their pixels, and their positions in camera axes about the hips as world
landmarks) in place of BlazePose's: what the fit and the quantiser make of
perfect keypoints, which separates what perception loses from what they
lose.  ``render-world`` and ``render-2d`` replace only BlazePose's world
landmarks or only its pixels.  The speed is then that of fitting and
quantising alone (after BlazePose, for the mixed modes).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

HOLDOUT = Path(__file__).resolve().parent / "holdout"


def render_track(truth):
    """The renderer's landmarks as a :class:`~capture2notation.keypoints.KeypointTrack`: perfect keypoints.

    Pixels from the sidecar's projected landmarks, world landmarks from their
    3D positions in the camera's axes about the hips' midpoint (BlazePose's
    convention), every landmark inside the image at confidence 1 (a hidden
    one too: a keypoint model places those as well); no image depth.
    """
    from capture2notation.keypoints import KeypointTrack

    track = KeypointTrack.empty(truth.n_frames, truth.fps, truth.image_size, backend="render", times=truth.times)
    xy = track.xy.copy()
    xy[..., :2] = truth.keypoints
    camera_axes = np.asarray(truth.landmarks3d) @ np.asarray(truth.R).T
    world = camera_axes - 0.5 * (camera_axes[:, 23] + camera_axes[:, 24])[:, None]
    w, h = truth.image_size
    inside = (xy[..., 0] >= 0) & (xy[..., 0] < w) & (xy[..., 1] >= 0) & (xy[..., 1] < h)
    return KeypointTrack(
        fps=truth.fps,
        times=truth.times,
        image_size=truth.image_size,
        xy=xy,
        visibility=inside.astype(float),
        presence=np.ones(truth.n_frames),
        world=world,
        crops=track.crops,
        backend="render",
    )


def _keypoint_track(truth, keypoints: str, video: Path):
    """The track a ``--keypoints`` mode fits: the renderer's, or BlazePose's with part of it replaced."""
    import dataclasses

    from capture2notation.keypoints import extract

    perfect = render_track(truth)
    if keypoints == "render":
        return perfect
    track = extract(video, progress=False)
    if keypoints == "render-world":
        return dataclasses.replace(track, world=perfect.world)
    xy = np.array(track.xy, float)
    xy[..., :2] = perfect.xy[..., :2]  # BlazePose's own image depth (column 2) stays
    return dataclasses.replace(track, xy=xy)


def _capture_other_keypoints(truth, tempo, keypoints: str, video: Path):
    """Fit and quantise a ``--keypoints`` mode's track (see :func:`render_track`)."""
    from types import SimpleNamespace

    from capture2notation.fitting import Camera, fit_track
    from capture2notation.quantise.segment import segment_motion

    motion = fit_track(_keypoint_track(truth, keypoints, video), camera=Camera.from_truth(truth))
    seg = segment_motion(np.asarray(motion.joints), float(motion.fps), tempo=tempo)
    return SimpleNamespace(score=seg.score, motion=motion)


def measure(
    path: Path,
    workdir: Path,
    view: str,
    effort: bool,
    tempo_given: bool = False,
    flip_test: bool | None = None,
    keypoints: str = "blazepose",
    calibrated: bool = False,
    phone: tuple[float, float, float, float] | None = None,
) -> dict:
    """Render one phrase, capture it from truth and from video, compare; see the module docstring.

    `phone` = (height m, pitch °, roll °, horizontal field of view °): render
    through :meth:`synthetic.render.camera.Camera.phone` on `view`'s azimuth
    instead of the view's preset camera.
    """
    from capture2notation.compare.agreement import agreement_cells, compare_scores
    from capture2notation.compare.metrics import mpjpe
    from capture2notation.io.truth import read_truth
    from capture2notation.notation.formats import read
    from pipelines.capture import capture
    from pipelines.commands.demo import _limb_error
    from synthetic.render import render_score

    score = read(path)
    camera = None
    if phone is not None:
        from synthetic.render.camera import Camera as RenderCamera

        h, pitch, roll, hfov = phone
        camera = RenderCamera.phone(view, (640, 480), height=h, pitch_deg=pitch, roll_deg=roll, hfov_deg=hfov)
    render = render_score(
        score, workdir / "render", fps=25.0, size=(640, 480), view=view, style="mannequin", progress=False,
        camera=camera,
    )  # fmt: skip
    from_truth = capture(render / "truth.npz", workdir / "truth", tempo=score.tempo, progress=False, effort=False)
    exact = compare_scores(score, from_truth.score).exact
    truth = read_truth(render / "truth.npz")
    t0 = time.perf_counter()
    if keypoints != "blazepose":
        video = _capture_other_keypoints(truth, score.tempo if tempo_given else None, keypoints, render / "video.mp4")
    else:
        video = capture(
            render / "video.mp4",
            workdir / "video",
            progress=False,
            effort=effort,
            overlay=False,
            tempo=score.tempo if tempo_given else None,
            calibration=render / "camera.toml" if calibrated else None,
            **({} if flip_test is None else {"flip_test": flip_test}),
        )
    seconds = time.perf_counter() - t0
    a = compare_scores(score, video.score)
    cells = agreement_cells(score, video.score)
    return {
        "phrase": path.stem,
        "agreement": a.symbol_agreement,
        "start_error": a.median_start_error,
        "truth_exact": exact,
        "tempo": (float(score.tempo), float(video.score.tempo)),
        "limb_deg": _limb_error(np.asarray(truth.joints), np.asarray(video.motion.joints)),
        # With the true camera the fit's absolute position is part of what it
        # gets right or wrong; without it, the position of the whole body along
        # the camera's axis is not observable, so joints are compared about
        # the pelvis.
        "mpjpe_cm": 100 * float(np.nanmean(mpjpe(*_placed(truth.joints, video.motion.joints, calibrated)))),
        "fps": truth.n_frames / seconds,
        "frames": truth.n_frames,
        "missed": [c for c in cells if c.ref != c.cand],
        "cells": len(cells),
        "columns": Counter(c.part for c in cells),
    }


def _placed(ref, cand, absolute: bool):
    """`ref` and `cand` joints (T, J, 3) as compared: absolute, or about the pelvis (joint 0)."""
    ref, cand = np.asarray(ref, float), np.asarray(cand, float)
    if absolute:
        return ref, cand
    return ref - ref[:, :1], cand - cand[:, :1]


def _explain(missed) -> str:
    """The lost cells, one line per part: ``beat: written -> captured`` (beats from 0)."""
    lines = {}
    for c in missed:
        lines.setdefault(c.part, []).append(f"{float(c.beat) - 0.5:g}: {' '.join(c.ref)} -> {' '.join(c.cand)}")
    return "".join(f"    {part:<16} " + "; ".join(v) + "\n" for part, v in lines.items())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--view", default="front", choices=("front", "45", "side"))
    ap.add_argument("--phrases", type=Path, default=HOLDOUT, help="folder of .lab phrases")
    ap.add_argument("--random", type=int, default=0, metavar="N", help="measure N random scores instead of phrases")
    ap.add_argument("--first-seed", type=int, default=80_000, help="seed of the first random score")
    ap.add_argument("--effort", action="store_true", help="include the Effort estimate in the timed capture")
    ap.add_argument("--tempo-given", action="store_true", help="give the video capture the written tempo")
    ap.add_argument("--explain", action="store_true", help="list the beats each phrase loses")
    ap.add_argument(
        "--flip-test",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="BlazePose's mirrored second pass (default: capture's default)",
    )
    ap.add_argument(
        "--keypoints",
        default="blazepose",
        choices=("blazepose", "render", "render-world", "render-2d"),
        help="render: fit the renderer's own landmarks instead (perfect keypoints); render-world, "
        "render-2d: replace only BlazePose's world landmarks, or only its pixels",
    )
    ap.add_argument(
        "--calibrated",
        action="store_true",
        help="give the capture the renderer's true camera (--calibration camera.toml); "
        "by default it sees only the video, as a user's capture does",
    )
    ap.add_argument(
        "--phone",
        type=_phone,
        default=None,
        metavar="H,PITCH,ROLL,HFOV",
        help="render through a phone camera: height m, pitch and roll degrees, horizontal field of view degrees "
        "(e.g. 0.5,10,0,65), as `c2n render --camera-height --pitch --roll --hfov`",
    )
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        paths = sorted(args.phrases.glob("*.lab")) if not args.random else _random_phrases(args, Path(tmp) / "scores")
        for p in paths:
            r = measure(
                p,
                Path(tmp) / p.stem,
                args.view,
                args.effort,
                args.tempo_given,
                args.flip_test,
                args.keypoints,
                args.calibrated,
                args.phone,
            )
            rows.append(r)
            print(
                f"{r['phrase']:<22} agreement {r['agreement']:6.1%}  start error {r['start_error']:5.2f} beat  "
                f"tempo {r['tempo'][0]:g}->{r['tempo'][1]:g}  truth exact {r['truth_exact']!s:<5}  "
                f"limb {r['limb_deg']:4.1f}°  MPJPE {r['mpjpe_cm']:4.1f} cm  {r['fps']:5.1f} fps",
                flush=True,
            )
            if args.explain:
                print(_explain(r["missed"]), end="", flush=True)
    frames = sum(r["frames"] for r in rows)
    weights = np.array([r["frames"] for r in rows], float)
    how = "given" if args.tempo_given else "estimated"
    camera = "true camera given" if args.calibrated else "camera estimated from the video"
    print(
        f"\n{args.view} view, {len(rows)} phrases, {frames} frames, tempo {how}, {args.keypoints} keypoints, {camera}:"
    )
    print(f"  symbol agreement (mean over phrases)  {np.mean([r['agreement'] for r in rows]):.1%}")
    # The columns compared are the parts either score moves, so a capture
    # that writes fewer spurious symbols can lose cells *and* percentage:
    # the lost cells say which.
    print(
        f"  cells lost / compared                 {sum(len(r['missed']) for r in rows)} / {sum(r['cells'] for r in rows)}"
    )
    print(f"  median start error                    {np.nanmedian([r['start_error'] for r in rows]):.2f} beat")
    print(f"  truth captures exact                  {sum(r['truth_exact'] for r in rows)}/{len(rows)}")
    print(f"  median limb-direction error           {np.median([r['limb_deg'] for r in rows]):.1f}°")
    print(f"  MPJPE (mean over phrases)             {np.mean([r['mpjpe_cm'] for r in rows]):.1f} cm")
    print(f"  whole capture speed (frame-weighted)  {np.average([r['fps'] for r in rows], weights=weights):.1f} fps")
    total = sum((r["columns"] for r in rows), Counter())
    lost = Counter(c.part for r in rows for c in r["missed"])
    print(
        "  agreement by column                   " + ", ".join(f"{p} {1 - lost[p] / n:.0%}" for p, n in total.items())
    )


def _phone(text: str) -> tuple[float, float, float, float]:
    """``H,PITCH,ROLL,HFOV`` → four floats (argparse type)."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"expected H,PITCH,ROLL,HFOV (four numbers), got {text!r}")
    return values  # type: ignore[return-value]


def _random_phrases(args, folder: Path) -> list[Path]:
    """``--random`` scores written as .lab files in `folder`."""
    from capture2notation.notation.formats import write
    from synthetic import random_score

    folder.mkdir(parents=True)
    paths = []
    for seed in range(args.first_seed, args.first_seed + args.random):
        paths.append(folder / f"seed{seed}.lab")
        write(random_score(np.random.default_rng(seed), 16), paths[-1])
    return paths


if __name__ == "__main__":
    main()
