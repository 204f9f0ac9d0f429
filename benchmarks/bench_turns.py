"""Turns, flight, travel and the body key in the capture (issue 14 item 3): the figures.

Run ``python benchmarks/bench_turns.py [--seeds 30] [--video N] [--skip-bvh]``.

Printed (never asserted):

* **Truth round trip**: random scores with turns (1/8 to 2 turns, both
  ways), springs, travel and the body key (``random_score(...,
  turns=True, springs=True, travel=True, axes="body")``, fresh seeds
  20260000+i, 8 beats), the dancer's own joints quantised with the tempo
  given: exact scores, turns and flights written right, spring forms seen.
* **Kinect** (``../shared/fixtures/kinect/joints.csv``): agreement of our
  per-frame upper-arm and forearm labels with LabanotationSuite's
  (``joints.labanotationsuite_labels.json``), body key and standard key.
* **Fixture BVH**: the pelvis's total rotation and the turns written (sum
  of amounts); frames with both (smoothed) feet off the floor and the
  flights written.
* ``--video N``: N random scores with turns (and springs) rendered front,
  640×480, 25 fps, captured from the video (BlazePose, no camera, tempo
  given): each written turn matched to a captured one overlapping it (amount
  within 1/8, direction), each flight ≥ 0.3 s matched to a captured flight,
  and the agreement on every column but the front (gestures, supports).
  ``--no-turns`` renders scores without turns instead: the same agreement
  on phrases that do not turn.  Several ``--video-seed0`` values give a
  set of N scores from each and the figures of their pool too.
  ``--keypoints render`` captures each clip
  from the renderer's own landmarks instead of BlazePose's (``render-2d``:
  its pixels on BlazePose's 3D landmarks), the video's face cue kept: what
  the capture makes of perfect keypoints; ``--flip-test`` reads each clip
  with BlazePose's flip test (the mirrored crop averaged in), and
  ``$C2N_POSE_MODEL`` picks another BlazePose model.
* ``--speed`` (alone): time and peak memory of the room-direction decoder
  (``quantise.front_levels``) on 1-, 10- and 60-minute measured fronts.
"""

from __future__ import annotations

import argparse
import collections
import json
import tempfile
import time
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np

#: Shortest written flight counted by ``--video``, seconds (issue 14's "flights of ≥ 0.3 s").
MIN_FLIGHT_S = 0.3
FIXTURES = Path(__file__).resolve().parents[2] / "shared" / "fixtures"
if not FIXTURES.is_dir():
    FIXTURES = Path("/work/shared/fixtures")


def round_trip(n: int, seed0: int = 20260000) -> None:
    import synthetic.random_scores as rs
    from capture2notation.compare.agreement import compare_scores, score_differences
    from capture2notation.notation.facing import springs
    from capture2notation.quantise.segment import segment_motion
    from synthetic.interpret import interpret

    exact, agree = 0, []
    turns_ok = turns_all = flights_ok = flights_all = 0
    forms: collections.Counter = collections.Counter()
    amounts = []
    t0 = time.perf_counter()
    for i in range(n):
        score = rs.random_score(
            np.random.default_rng(seed0 + i), n_beats=8, turns=True, springs=True, travel=True, axes="body"
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            seg = segment_motion(interpret(score, fps=25.0).joints(), 25.0, tempo=score.tempo, axes=score.axes)
        d = score_differences(score, seg.score)
        exact += not d
        agree.append(compare_scores(score, seg.score).symbol_agreement)
        got = set(seg.score.symbols)
        for s in score.symbols:
            if s.is_turn:
                turns_all += 1
                turns_ok += s in got
                amounts.append(s.signed_amount)
            if s.is_air:
                flights_all += 1
                flights_ok += s in got
        for _, form in springs(score):
            forms[form] += 1
        if d:
            print(f"  seed {seed0 + i}: {len(d)} differences, e.g. {d[:2]}")
    span = f" (amounts {min(amounts)}..{max(amounts)})" if amounts else ""
    print(
        f"truth round trip, {n} scores (turns, springs, travel, body key), tempo given: "
        f"{exact}/{n} exact, mean agreement {np.mean(agree):.3f}; "
        f"turns written exactly {turns_ok}/{turns_all}{span}, "
        f"flights {flights_ok}/{flights_all}; spring forms drawn {dict(forms)}; {time.perf_counter() - t0:.0f} s"
    )


def kinect() -> None:
    from capture2notation.fitting.motion import joints_for_labels, read_motion
    from capture2notation.notation.model import LEVELS
    from capture2notation.quantise.labels import DIRECTION_NAMES, label_frames

    path = FIXTURES / "kinect" / "joints.csv"
    m = read_motion(path)
    ref = json.loads((FIXTURES / "kinect" / "joints.labanotationsuite_labels.json").read_text())["frames"]
    ts = np.array([r["timestamp"] for r in ref], float) * 1e-7
    ts -= ts[0]
    mt = np.asarray(m.times, float) - float(m.times[0])
    rows = [int(np.argmin(np.abs(mt - t))) for t in ts]
    for name, joints in (("measured arms", joints_for_labels(m)), ("retargeted fit", m.joints)):
        for axes in ("body", "standard"):
            L = label_frames(joints, m.fps, axes=axes)
            per: collections.Counter = collections.Counter()
            frames_all = 0
            for row, f in zip(ref, rows):
                all_ok = True
                for side in ("right", "left"):
                    for seg, part in (("elbow", "upper_arm"), ("wrist", "forearm")):
                        p = L.index(f"{side}_{part}")
                        ours = (DIRECTION_NAMES[L.direction[f, p]].replace("_", ""), LEVELS[L.level[f, p]])
                        d, lv = row[f"{side} {seg}"]
                        theirs = (
                            d.lower().replace(" ", "").replace("backward", "back"),
                            {"normal": "middle"}.get(lv.lower(), lv.lower()),
                        )
                        ok = ours == theirs
                        per[f"{side}_{part}"] += ok
                        all_ok &= ok
                frames_all += all_ok
            n = len(ref)
            segs = ", ".join(f"{k} {v / n:.1%}" for k, v in sorted(per.items()))
            print(f"kinect {name}, {axes} key: all four segments agree on {frames_all / n:.1%} of {n} frames ({segs})")


def bvh() -> None:
    from capture2notation.fitting.motion import joints_for_labels, read_motion
    from capture2notation.quantise.flight import find_flights
    from capture2notation.quantise.segment import segment_motion
    from capture2notation.quantise.support_state import smooth_positions
    from capture2notation.quantise.turns import continuous_front

    for path in sorted((FIXTURES / "bvh").glob("*.bvh")):
        m = read_motion(path)
        joints = joints_for_labels(m)
        front = continuous_front(joints)
        ok = np.isfinite(front)
        net = float(front[ok][-1] - front[ok][0])
        total = float(np.nansum(np.abs(np.diff(front))))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            seg = segment_motion(joints, m.fps)
        turns = [s for s in seg.score.symbols if s.is_turn]
        written = float(sum(s.signed_amount for s in turns)) * 360
        flights = [s for s in seg.score.symbols if s.is_air]
        off = find_flights(smooth_positions(joints, m.fps), m.fps, measured=True)
        print(
            f"{path.name}: {len(m.times)} frames at {m.fps:.0f} fps; pelvis net rotation {net:+.0f}°, "
            f"path {total:.0f}°; turns written {len(turns)} totalling {written:+.0f}° "
            f"({', '.join(f'{s.direction} {s.amount}' for s in turns[:12])}); "
            f"airborne runs ≥ 0.2 s (smoothed feet, ballistic pelvis) {len(off)}, flights written {len(flights)}"
        )


#: What each ``--keypoints`` mode captures from.
KEYPOINTS = {
    "blazepose": "BlazePose",
    "render": "the renderer's landmarks",
    "render-2d": "the renderer's pixels on BlazePose's 3D",
}


def _oracle_track(render: Path, keypoints: str):
    """The track a ``--keypoints`` mode captures (``bench_wholepath``'s modes), the video's face cue kept.

    The yaw decoder reads the face from the frames, not from the landmarks,
    so the renderer's landmarks take BlazePose's reading of it.
    """
    import dataclasses

    from bench_wholepath import _keypoint_track

    from capture2notation.io.truth import read_truth
    from capture2notation.keypoints import extract

    video = render / "video.mp4"
    track = _keypoint_track(read_truth(render / "truth.npz"), keypoints, video)
    if keypoints == "render":
        track = dataclasses.replace(track, face=extract(video, progress=False).face)
    return track


def video(
    n: int, seed0s=(20261400,), turns: bool = True, keypoints: str = "blazepose", flip_test: bool = False
) -> None:
    """``--video``: n random scores from each first seed in `seed0s`, each set's figures and, for several, their pool."""
    pooled = collections.Counter()
    for seed0 in seed0s:
        counts = _video_set(n, seed0, turns, keypoints, flip_test)
        _print_video(counts, f"video, {n} scores from seed {seed0}", turns, keypoints)
        pooled.update(counts)
    if len(seed0s) > 1:
        _print_video(pooled, f"POOLED, {len(seed0s)} sets of {n} scores", turns, keypoints)


def _video_set(n: int, seed0: int, turns: bool, keypoints: str, flip_test: bool = False) -> collections.Counter:
    """Render, capture and match one set of `n` scores (printing a line per clip); its counts."""
    import synthetic.random_scores as rs
    from capture2notation.compare.agreement import agreement_cells, compare_scores
    from capture2notation.errors import C2NError
    from capture2notation.notation.model import SYMBOL_UNCERTAIN_BELOW
    from pipelines.capture import capture
    from synthetic.render import render_score

    c = collections.Counter()

    def long_flight(s, score) -> bool:  # the flights counted: at least MIN_FLIGHT_S at the score's tempo
        return s.is_air and float(s.duration) * 60 / float(score.tempo) >= MIN_FLIGHT_S

    def same_turn(a, b) -> bool:  # overlapping turns the same way, amounts within an eighth
        return (
            a.is_turn and b.is_turn and a.start < b.end and b.start < a.end and a.direction == b.direction
            and abs(a.amount - b.amount) <= Fraction(1, 8)
        )  # fmt: skip

    for i in range(n):
        score = rs.random_score(np.random.default_rng(seed0 + i), n_beats=8, turns=turns, springs=True)
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            t0 = time.perf_counter()
            render = render_score(
                score, work / "render", fps=25.0, size=(640, 480), view="front", style="mannequin", progress=False
            )
            source = render / "video.mp4"
            if keypoints != "blazepose":
                source = work / "keypoints.npz"
                _oracle_track(render, keypoints).save(source)
            try:
                cap = capture(
                    source, work / "video", progress=False, effort=False, overlay=False, tempo=score.tempo,
                    flip_test=flip_test,
                )  # fmt: skip
            except C2NError as exc:  # counted: every turn and flight of the clip missed
                c["failed"] += 1
                c["turns"] += sum(s.is_turn for s in score.symbols)
                c["flights"] += sum(long_flight(s, score) for s in score.symbols)
                print(f"  video seed {seed0 + i}: capture FAILED: {exc}")
                continue
            got = cap.score
            for s in score.symbols:
                if s.is_turn:
                    c["turns"] += 1
                    c["turns_ok"] += any(same_turn(s, g) for g in got.symbols)
                if long_flight(s, score):
                    c["flights"] += 1
                    c["flights_ok"] += any(g.is_air and g.start <= s.end and s.start <= g.end for g in got.symbols)
            # How the confidence ranks the captured turns: uncertain ones should be the wrong ones.
            for g in got.symbols:
                if g.is_turn:
                    uncertain = g.confidence is not None and g.confidence < SYMBOL_UNCERTAIN_BELOW
                    right = any(same_turn(s, g) for s in score.symbols)
                    c["captured"] += 1
                    c["captured_ok"] += right
                    c["uncertain"] += uncertain
                    c["uncertain_wrong"] += uncertain and not right
            others = [x for x in agreement_cells(score, got) if x.part != "front"]  # gestures, supports
            c["other_cells"] += len(others)
            c["other_ok"] += sum(x.ref == x.cand for x in others)
            print(
                f"  video seed {seed0 + i}: agreement {compare_scores(score, got).symbol_agreement:.3f}, "
                f"turns written {[(s.direction, str(s.amount)) for s in score.symbols if s.is_turn]} captured "
                f"{[(s.direction, str(s.amount)) for s in got.symbols if s.is_turn]}, "
                f"flights {sum(s.is_air for s in score.symbols)} -> {sum(s.is_air for s in got.symbols)}, "
                f"{time.perf_counter() - t0:.0f} s"
            )
    return c


def _print_video(c: collections.Counter, label: str, turns: bool, keypoints: str) -> None:
    """The figures of one set's (or a pool's) counts from :func:`_video_set`."""
    print(
        f"{label} ({'with' if turns else 'without'} turns, front, 640x480, 25 fps, {KEYPOINTS[keypoints]}, "
        f"tempo given): turns within 1/8 and the right way {c['turns_ok']}/{c['turns']}; flights >= 0.3 s found "
        f"{c['flights_ok']}/{c['flights']}; captures failed {c['failed']}"
    )
    print(
        f"agreement on the columns other than the front (gestures, supports): "
        f"{c['other_ok'] / max(c['other_cells'], 1):.3f} of {c['other_cells']} cells"
    )
    if c["captured"]:
        n_unc, n_sure = c["uncertain"], c["captured"] - c["uncertain"]
        wrong_unc = c["uncertain_wrong"] / n_unc if n_unc else float("nan")
        wrong_sure = (c["captured"] - c["captured_ok"] - c["uncertain_wrong"]) / n_sure if n_sure else float("nan")
        print(
            f"captured turns {c['captured']}, right {c['captured_ok'] / c['captured']:.0%}; marked uncertain {n_unc}: "
            f"wrong {wrong_unc:.0%} against {wrong_sure:.0%} of the others "
            f"(ratio {wrong_unc / max(wrong_sure, 1e-9):.1f})"
        )


def speed(minutes=(1, 10, 60), fps: float = 25.0, seed: int = 0) -> None:
    """Time and peak memory of the room-direction decoder on long measured fronts."""
    import tracemalloc

    from capture2notation.quantise.front_levels import ERROR_CORRELATION_S, FRONT_SD_DEG, decode_front_levels

    rng = np.random.default_rng(seed)
    print("\n## decode_front_levels on a measured front (a turn of 1-16 eighths every 4 s, the fit's noise)\n")
    print("| clip | frames | seconds | frames/s | peak memory |")
    print("|---|---|---|---|---|")
    for m in minutes:
        T = int(m * 60 * fps)
        steps = np.zeros(T)
        steps[:: int(4 * fps)] = 45.0 * rng.integers(-16, 17, size=steps[:: int(4 * fps)].size)
        a = np.exp(-1.0 / (ERROR_CORRELATION_S * fps))
        noise = np.zeros(T)
        shocks = rng.normal(0.0, FRONT_SD_DEG * np.sqrt(1 - a * a), T)
        for t in range(1, T):  # AR(1): the fit's errors last ERROR_CORRELATION_S
            noise[t] = a * noise[t - 1] + shocks[t]
        front = np.cumsum(steps) + noise
        t0 = time.perf_counter()
        decode_front_levels(front, fps)
        dt = time.perf_counter() - t0
        tracemalloc.start()  # a second run: tracing slows allocation several times over
        decode_front_levels(front, fps)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"| {m} min | {T} | {dt:.1f} | {T / dt:,.0f} | {peak / 2**20:.0f} MB |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument(
        "--seed0", type=int, default=20260000, help="first seed (development: 20260000; fresh: e.g. 20270000)"
    )
    ap.add_argument("--video", type=int, default=0, help="random scores to render and capture from video")
    ap.add_argument(
        "--video-seed0", type=int, nargs="+", default=[20261400],
        help="first seed of the --video scores; several: a set of --video scores from each, and their pool",
    )  # fmt: skip
    ap.add_argument(
        "--no-turns", action="store_true", help="--video scores without turns: the control for the other columns"
    )
    ap.add_argument("--skip-bvh", action="store_true")
    ap.add_argument(
        "--keypoints", choices=tuple(KEYPOINTS), default="blazepose",
        help="--video clips captured from BlazePose (default) or from the renderer's landmarks",
    )  # fmt: skip
    ap.add_argument("--flip-test", action="store_true", help="--video clips read by BlazePose with its flip test")
    ap.add_argument("--speed", action="store_true", help="time and memory of the turn decoder on 1-60 min fronts")
    args = ap.parse_args()
    if args.speed:
        speed()
        return
    if args.seeds > 0:  # --seeds 0: the video figures alone
        round_trip(args.seeds, args.seed0)
    kinect()
    if not args.skip_bvh:
        bvh()
    if args.video:
        video(
            args.video, tuple(args.video_seed0), turns=not args.no_turns, keypoints=args.keypoints,
            flip_test=args.flip_test,
        )  # fmt: skip


if __name__ == "__main__":
    main()
