"""The tempo without ``--tempo``: from the movements, and from a click track.

Run ``python benchmarks/bench_tempo.py [--seeds 200] [--clips 24] [--holdout]``.

Printed (never asserted), each as the share of captures within 4 % of the
written tempo (and within 2 % with a click track), the shares read at half
and at double the tempo, and the calibration of the stated confidence
(captures grouped by the confidence they were given, against how many of
them were right):

1. **From the truth** (the dancer's joints, ``synthetic.interpret(score,
   fps).joints()``, quantised): random scores (``synthetic.random_score``,
   seeds from 10 000: never used in development; tempo 60–120 bpm as the
   generator draws it, and again log-uniform over 36–132 bpm, the range of
   dance tempi the prior covers), the built-in phrases at 25, 30 and 50
   fps, and (``--holdout``) the held-out phrases, reported only.
2. **From truth with a click track**: the same scores, their sound a click
   track at the written tempo (:func:`synthetic.render.sound.click_track`),
   beat-tracked (:mod:`capture2notation.quantise.beats`, needs librosa).
3. **From video** (``--clips`` renders, 25 fps, 640×480, front view,
   mannequin; captured from a folder holding only the video, so no camera
   is known: BlazePose → fit → quantiser), and from **the same videos with
   a click track** muxed in (``c2n render --audio click``): the whole
   capture as a user runs it reads the sound track.  Slow (tens of seconds
   per clip on a shared machine), hence fewer clips.
"""

from __future__ import annotations

import argparse
import itertools
import shutil
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HOLDOUT = Path(__file__).resolve().parent / "holdout"
#: First seed of the random scores measured here (development used 0–399 and 2000–2299).
FIRST_SEED = 10_000
#: Confidence bins of the calibration table.
BINS = (0.0, 0.5, 0.8, 0.95, 1.0001)


def _scores(n: int, log_uniform: bool, fps: float = 25.0):
    from synthetic import random_score

    for i in range(n):
        seed = FIRST_SEED + i + (100_000 if log_uniform else 0)
        bpm = None
        if log_uniform:
            bpm = int(round(36 * (132 / 36) ** np.random.default_rng([seed, 1]).uniform()))
        yield f"seed{seed}", random_score(np.random.default_rng(seed), tempo=bpm, fps=fps)


def _phrases(holdout: bool):
    from capture2notation.notation import read
    from synthetic.phrases import PHRASE_NAMES, phrase

    if holdout:
        return [(p.stem, read(p)) for p in sorted(HOLDOUT.glob("*.lab"))]
    return [(name, phrase(name)) for name in PHRASE_NAMES]


def _click(score, seconds: float):
    from capture2notation.io.audio import AUDIO_RATE, SoundTrack
    from capture2notation.quantise.beats import sound_beats
    from synthetic.render.sound import click_track

    return sound_beats(SoundTrack(click_track(score.tempo, score.meter, seconds), AUDIO_RATE, "click"))


def _from_truth(score, fps: float, click: bool):
    from capture2notation.quantise.segment import segment_motion
    from synthetic import interpret

    joints = interpret(score, fps).joints()
    evidence = _click(score, joints.shape[0] / fps) if click else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        seg = segment_motion(joints, fps, tempo_evidence=evidence)
    return float(seg.tempo), seg.tempo_confidence if seg.tempo_estimated else float("nan")


def _summary(label: str, rows, tol: float = 0.04) -> None:
    """Print the accuracy and calibration of (written, estimated, confidence) rows."""
    if not rows:
        print(f"{label}: no rows")
        return
    w, e, c = (np.array(x, float) for x in zip(*rows))
    r = e / w
    right = np.abs(r - 1) <= tol
    half, double = np.abs(r - 0.5) <= 0.5 * tol, np.abs(r - 2) <= 2 * tol
    print(
        f"{label}: n={len(rows)}  within {tol:.0%} {right.mean():.1%}  half {half.mean():.1%}  "
        f"double {double.mean():.1%}  other {(~(right | half | double)).mean():.1%}  "
        f"mean confidence {np.nanmean(c):.2f}"
    )
    ok = np.isfinite(c)
    for lo, hi in itertools.pairwise(BINS):
        m = ok & (c >= lo) & (c < hi)
        if m.any():
            print(
                f"    confidence [{lo:.2f}, {min(hi, 1):.2f}): n={m.sum():4d}  said {c[m].mean():.2f}  right {right[m].mean():.2f}"
            )


def _video_rows(n_clips: int, workdir: Path, seeds_start: int):
    """(written, from the movements, conf), (written, with a click track, conf) per rendered clip."""
    from capture2notation.quantise.segment import segment_motion
    from pipelines.capture import capture
    from synthetic.phrases import PHRASE_NAMES, phrase
    from synthetic.render import render_score
    from synthetic.render.sound import add_sound

    items = [(name, phrase(name)) for name in PHRASE_NAMES]
    items += list(_scores(max(n_clips - len(items), 0), log_uniform=False))[: max(n_clips - len(items), 0)]
    motion_rows, click_rows = [], []
    for name, score in items[:n_clips]:
        t0 = time.perf_counter()
        render = workdir / name / "render"
        render_score(score, render, fps=25.0, size=(640, 480), view="front", progress=False)
        clip = workdir / name / "clip" / "video.mp4"
        clip.parent.mkdir(parents=True)
        shutil.copy(render / "video.mp4", clip)  # no truth.npz beside it: no known camera
        T = int(np.load(render / "truth.npz")["joints"].shape[0])
        add_sound(clip, "click", score.tempo, score.meter, T / 25.0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = capture(clip, workdir / name / "capture", progress=False, effort=False, overlay=False)
            joints, fps = np.asarray(res.motion.joints), float(res.motion.fps)
            alone = segment_motion(joints, fps)
        click_rows.append((float(score.tempo), float(res.score.tempo), res.segmentation.tempo_confidence))
        motion_rows.append((float(score.tempo), float(alone.tempo), alone.tempo_confidence))
        print(
            f"  {name:14s} written {float(score.tempo):5.1f}  movements {float(alone.tempo):5.1f} "
            f"({alone.tempo_confidence:.0%})  click {float(res.score.tempo):5.1f} [{res.segmentation.tempo_source}]"
            f"  {time.perf_counter() - t0:.0f} s",
            flush=True,
        )
        shutil.rmtree(workdir / name, ignore_errors=True)
    return motion_rows, click_rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=200, help="random scores per tempo distribution (truth)")
    ap.add_argument("--clips", type=int, default=24, help="rendered videos (3 built-in phrases + random scores)")
    ap.add_argument("--holdout", action="store_true", help="also report the held-out phrases (never tuned on)")
    ap.add_argument("--no-click", action="store_true", help="skip the click-track rows (need librosa)")
    args = ap.parse_args()
    from capture2notation.quantise.beats import beat_tracker_available

    click = not args.no_click and beat_tracker_available()
    if not args.no_click and not click:
        print("librosa is not installed (pip install 'capture2notation[audio]'): click-track rows skipped")
    t0 = time.perf_counter()
    print("From the truth (the dancer's joints), tempo not given:")
    phrases = [(n, s, f) for n, s in _phrases(False) for f in (25.0, 30.0, 50.0)]
    for label, items in (
        ("  random scores, 60-120 bpm", [(n, s, 25.0) for n, s in _scores(args.seeds, False)]),
        ("  random scores, 36-132 bpm log-uniform", [(n, s, 25.0) for n, s in _scores(args.seeds, True)]),
        ("  built-in phrases at 25/30/50 fps", phrases),
    ):
        rows = [(float(s.tempo), *_from_truth(s, f, False)) for _, s, f in items]
        _summary(label, rows)
        if label.startswith("  random scores, 60"):
            base = rows
        if label.startswith("  built-in"):
            _summary("  random scores (60-120) and built-in phrases together", base + rows)
        if click:
            _summary(
                label + ", with a click track", [(float(s.tempo), *_from_truth(s, f, True)) for _, s, f in items], 0.02
            )
    if args.holdout:
        rows = [(float(s.tempo), *_from_truth(s, 25.0, False)) for _, s in _phrases(True)]
        _summary("  held-out phrases (reported only)", rows)
    print(f"  ({time.perf_counter() - t0:.0f} s)")
    if args.clips > 0:
        print(f"\nFrom video ({args.clips} clips, 25 fps, 640x480, front view, no camera given), tempo not given:")
        with tempfile.TemporaryDirectory() as tmp:
            motion_rows, click_rows = _video_rows(args.clips, Path(tmp), FIRST_SEED)
        _summary("  from the movements", motion_rows)
        if click:
            _summary("  with a click track (the whole capture)", click_rows, 0.02)
        print(f"  ({time.perf_counter() - t0:.0f} s in all; wall-clock on a shared machine is a noisy lower bound)")


if __name__ == "__main__":
    main()
