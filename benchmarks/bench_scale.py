"""Hours of rehearsal: time and peak memory of a capture as the clip grows.

Three measurements (each prints its table; nothing is asserted):

``--video SECONDS`` (default 60) ``[--cameras front,side]``
    A random score of that length performed by the virtual dancer,
    rendered at 25 fps 640×480 (front), captured from the video alone as
    ``c2n capture`` does it (BlazePose, camera estimated, tempo given,
    Effort with ``--workers``), in a fresh process: wall time per stage, the
    ratio to the clip's duration and the peak resident memory of the
    capture process and of its largest Effort worker.  With ``--cameras``
    the same performance is rendered from each view and captured from all
    of them at once, the renders' cameras given as ``--calibration`` (for
    speed only: ``bench_multiview.py`` measures accuracy with calibrations
    from board clips).

``--minutes 10 20 40 60``
    Long clips without pixels: random one-minute phrases performed back to
    back, their landmarks projected through the front camera with a pose
    model's noise (3 px, 2 cm world landmarks) and saved as a keypoint
    track (cached in ``--workdir``), then ``c2n capture TRACK.npz`` in a fresh
    process (the fit, quantiser and, with ``--effort``, Effort: everything
    but the pose model, which costs the same per frame at any length;
    ``bench_keypoints.py`` measures it).  Prints wall and CPU seconds, peak
    memory and the cost per minute of video, with a straight line fitted
    through the lengths.

``--spans``
    The fit of each held-out phrase (``benchmarks/holdout``, measured only)
    through BlazePose whole and in 2-s spans, quantised with the tempo
    given: cells that differ between the two (the capture fits in 60-s
    spans; 2-s spans make every phrase several).

Run: ``python benchmarks/bench_scale.py --video 60 --minutes 2 4 8 --spans``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

HOLDOUT = Path(__file__).resolve().parent / "holdout"
TEMPO = 90
#: Span of --spans, seconds: with 2 s of context each side, every held-out phrase is several spans.
SHORT_SPAN_S = 2.0
#: A pose model's errors on the synthetic track: pixels, and metres on the world landmarks.
PIXEL_NOISE, WORLD_NOISE = 3.0, 0.02


def long_score(minutes: float, seed: int):
    """Random one-minute phrases back to back (``random_score`` of a whole hour is quadratic)."""
    from capture2notation.notation.model import Score
    from synthetic.random_scores import random_score

    rng = np.random.default_rng(seed)
    beats = TEMPO  # one minute
    symbols = []
    for k in range(max(1, round(minutes))):
        phrase = random_score(rng, beats, tempo=TEMPO)
        symbols += [dataclasses.replace(s, start=s.start + k * beats) for s in phrase.symbols]
    return Score.from_symbols(symbols, tempo=Fraction(TEMPO), title=f"{minutes:g} min, seed {seed}")


def synthetic_track(minutes: float, seed: int, path: Path) -> Path:
    """The performed landmarks of :func:`long_score` as a noisy keypoint track at `path` (cached)."""
    if path.exists():
        return path
    from capture2notation.body import Body
    from capture2notation.keypoints import KeypointTrack
    from synthetic.render.camera import Camera
    from synthetic.render.job import perform_score
    from synthetic.render.scene import Pose, landmark_visibility

    body = Body()
    _, motion = perform_score(long_score(minutes, seed), 25.0, body, "mannequin")
    pose = Pose.from_motion(motion)
    camera = Camera.for_view("front", (640, 480), body.height)
    rng = np.random.default_rng(seed + 1)
    T = len(pose.times)
    xy = np.zeros((T, 33, 3))
    xy[..., :2] = camera.project(pose.landmarks) + rng.normal(0.0, PIXEL_NOISE, (T, 33, 2))
    cam_axes = np.asarray(pose.landmarks) @ np.asarray(camera.R).T
    world = cam_axes - 0.5 * (cam_axes[:, 23] + cam_axes[:, 24])[:, None] + rng.normal(0.0, WORLD_NOISE, (T, 33, 3))
    empty = KeypointTrack.empty(T, 25.0, (640, 480), backend="blazepose", times=pose.times)
    track = dataclasses.replace(
        empty,
        xy=xy,
        visibility=landmark_visibility(pose, camera).astype(float),
        presence=np.ones(T),
        world=world,
    )
    return track.save(path)


def run_capture(args: list, workdir: Path) -> dict:
    """``c2n capture ARGS`` in a fresh process: wall, CPU, peak memory, stage seconds."""
    script = (
        "import json, resource, sys, time\n"
        "from pipelines.cli import main\n"
        "t = time.perf_counter()\n"
        "try:\n"
        "    main(sys.argv[1:], standalone_mode=False)\n"
        "finally:\n"
        "    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
        "    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n"
        "    print('BENCH', json.dumps({'wall': time.perf_counter() - t, 'rss_mb': own / 1024, 'worker_mb': kids / 1024}))\n"
    )
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        [sys.executable, "-c", script, "capture", *map(str, args)], capture_output=True, text=True, cwd=workdir
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    line = [ln for ln in done.stdout.splitlines() if ln.startswith("BENCH ")]
    if done.returncode != 0 or not line:
        raise SystemExit(f"capture {args} failed:\n{done.stderr[-2000:]}")
    out = json.loads(line[-1][6:])
    out["cpu"] = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return out


def bench_video(seconds: float, workers: int, workdir: Path, cameras: tuple[str, ...] = ()) -> None:
    from capture2notation.notation import write
    from synthetic.render import render_score

    score = long_score(seconds / 60.0, seed=6000)
    cut = Fraction(round(seconds * TEMPO / 60))
    score = score.replace(symbols=tuple(s for s in score.symbols if s.end <= cut))
    write(score, workdir / "video_score.lab")
    out = workdir / "video_capture"
    if cameras:
        from bench_multiview import merged_calibration

        renders = {v: render_score(score, workdir / "video_render" / v, view=v, progress=False) for v in cameras}
        calibration = merged_calibration(renders, workdir / "video_render" / "cameras.toml")
        inputs = [renders[v] / "video.mp4" for v in cameras] + ["--calibration", calibration]
        seen = f"{' + '.join(cameras)} (the renders' cameras given)"
    else:
        inputs = [render_score(score, workdir / "video_render", progress=False) / "video.mp4"]
        seen = "front, camera estimated"
    m = run_capture([*inputs, "-o", out, "--tempo", TEMPO, "--workers", workers], workdir)
    duration = len(np.load(out / "capture.npz")["times"]) / 25.0
    print(f"\n## {duration:.0f}-s render, 640×480 25 fps, {seen}, captured with Effort ({workers} workers)\n")
    print("| wall s | × clip | CPU s | peak RSS (capture) | largest worker |")
    print("|---|---|---|---|---|")
    print(
        f"| {m['wall']:.1f} | {m['wall'] / duration:.2f} | {m['cpu']:.1f} | {m['rss_mb']:.0f} MB | {m['worker_mb']:.0f} MB |"
    )
    # the capture's own stage timings, as its page shows them
    stages = re.search(r"keypoints [0-9.]+ s[^<]*", (out / "index.html").read_text(encoding="utf-8"))
    if stages:
        print(f"\nstages (wall): {stages.group(0)}")


def bench_minutes(minutes, effort: bool, workers: int, workdir: Path) -> None:
    rows = []
    for mins in minutes:
        t0 = time.perf_counter()
        track = synthetic_track(mins, seed=7000, path=workdir / f"track_{mins:g}min.npz")
        made = time.perf_counter() - t0
        args = [track, "-o", workdir / f"capture_{mins:g}min", "--tempo", TEMPO, "--workers", workers]
        m = run_capture(args + ([] if effort else ["--no-effort"]), workdir)
        rows.append((mins, m))
        print(
            f"{mins:g} min: wall {m['wall']:.0f} s, CPU {m['cpu']:.0f} s, peak {m['rss_mb']:.0f} MB "
            f"(track made in {made:.0f} s)",
            flush=True,
        )
    what = "with Effort" if effort else "without Effort"
    print(f"\n## Keypoint track → notation {what}, 25 fps ({workers} workers)\n")
    print("| clip | wall s | CPU s | CPU s per minute | peak RSS | largest worker |")
    print("|---|---|---|---|---|---|")
    for mins, m in rows:
        print(
            f"| {mins:g} min | {m['wall']:.0f} | {m['cpu']:.0f} | {m['cpu'] / mins:.1f} | {m['rss_mb']:.0f} MB "
            f"| {m['worker_mb']:.0f} MB |"
        )
    if len(rows) >= 2:
        x = np.array([r[0] for r in rows], float)
        for key in ("cpu", "rss_mb"):
            y = np.array([r[1][key] for r in rows], float)
            slope, icpt = np.polyfit(x, y, 1)
            resid = np.max(np.abs(y - (slope * x + icpt)) / np.maximum(y, 1e-9))
            print(f"\n{key}: {slope:.2f} per minute + {icpt:.1f} (largest deviation from the line {resid:.0%})")


def bench_spans(workdir: Path) -> None:
    from capture2notation.compare.agreement import compare_scores
    from capture2notation.fitting import fit_track
    from capture2notation.fitting.depth import DepthOptions
    from capture2notation.fitting.solver import FitOptions
    from capture2notation.fitting.spans import track_spans
    from capture2notation.keypoints import extract
    from capture2notation.notation.formats import read
    from capture2notation.quantise.segment import segment_motion
    from synthetic.render import render_score

    print("\n## Held-out phrases fitted whole and in 2-s spans (BlazePose, tempo given)\n")
    print("| phrase | frames | spans | matched | unmatched | symbol agreement |")
    print("|---|---|---|---|---|---|")
    opt = FitOptions(depth=DepthOptions(rest_offset=True))
    for path in sorted(HOLDOUT.glob("*.lab")):
        score = read(path)
        render = render_score(score, workdir / "spans" / path.stem, progress=False)
        track = extract(render / "video.mp4", progress=False)
        scores = []
        for span in (np.inf, SHORT_SPAN_S):
            motion = fit_track(track, options=dataclasses.replace(opt, span_s=span))
            scores.append(segment_motion(np.asarray(motion.joints), motion.fps, tempo=score.tempo).score)
        agree = compare_scores(scores[0], scores[1])
        n = len(track)
        print(
            f"| {path.stem} | {n} | {len(track_spans(n, track.fps, SHORT_SPAN_S))} | {agree.matched} | {agree.unmatched} "
            f"| {agree.symbol_agreement:.3f} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--video", type=float, default=None, metavar="SECONDS", help="render and capture a clip this long")
    ap.add_argument(
        "--cameras", default="", metavar="V,V", help="with --video: capture these views together, e.g. front,side"
    )
    ap.add_argument("--minutes", type=float, nargs="*", default=[], help="keypoint-track clip lengths, minutes")
    ap.add_argument("--effort", action="store_true", help="--minutes with Effort (about 0.06 CPU s a movement)")
    ap.add_argument("--spans", action="store_true", help="held-out phrases fitted whole and in spans")
    ap.add_argument("--workers", type=int, default=min(os.cpu_count() or 1, 4), help="Effort processes")
    ap.add_argument("--workdir", type=Path, default=None, help="keep renders and tracks here (default: a temp dir)")
    a = ap.parse_args()
    if a.video is None and not a.minutes and not a.spans:
        a.video = 60.0
    with tempfile.TemporaryDirectory() as tmp:
        workdir = (a.workdir or Path(tmp)).resolve()
        workdir.mkdir(parents=True, exist_ok=True)
        if a.video:
            bench_video(a.video, a.workers, workdir, tuple(v for v in a.cameras.split(",") if v))
        if a.minutes:
            bench_minutes(a.minutes, a.effort, a.workers, workdir)
        if a.spans:
            bench_spans(workdir)


if __name__ == "__main__":
    main()
