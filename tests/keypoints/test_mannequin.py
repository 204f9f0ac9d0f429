"""BlazePose on the virtual dancer's mannequin renders (640x480, three views).

The issue asks PCK at 5 % of the person's height >= 95 % for shoulders,
elbows, wrists, hips, knees and ankles, and no left/right swaps.  The person's
height in pixels is the body height projected at the pelvis depth
(``f_y * H / z_pelvis``).  PCK counts joints the truth marks visible; a
left/right swap is a frame where both points of a pair lie nearer the
opposite side's truth while the two truths are more than the PCK radius apart.

Measured on the built-in phrases at 5 fps, the turning one at 10 fps
(bench_keypoints.py gives 10 fps):
with the flip test (``flip_test=True``: the model also reads the mirrored
crop) every joint in every view is >= 0.97 and nothing is swapped; one pass
per frame (the default) is >= 0.97 front and at 45 degrees, but in profile
the near elbow (0.91: arm raised towards the camera or folded in front of
the face) and the far ankle (0.95) fall short.  BlazePose still puts the
ankles 6-9 px (about 0.025 H) above the body's ankle joint.  So the issue's
target is asserted with the flip test, and a floor plus "no swaps" on the
default path.
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.model

#: Issue 16: at least 99 % of frames with the right identity, per left/right pair.
MAX_SWAPPED_FRACTION = 0.01
FPS = 5.0  # low frame rate keeps the test fast; tracking copes in place (the squats fixture is 5 fps)
#: A half turn in two beats moves the body 36° between frames at 5 fps, too far
#: for the tracker to keep the sides (every landmark swapped for 20 of 57 frames
#: in profile); at 10 fps and 25 fps nothing is swapped.
TURN_FPS = 10.0


def _evaluate(blazepose, poses, view, flip_test):
    """PCK per joint name (e.g. ``elbow_L``) and swap counts per pair over the phrases' poses."""
    from capture2notation.keypoints import extract_frames
    from capture2notation.keypoints.evaluate import PAIRS, left_right_swaps, person_height_px
    from synthetic import render

    hits = {f"{j}_{s}": [] for j in PAIRS for s in "LR"}
    swaps = dict.fromkeys(PAIRS, 0)
    n_frames = 0
    for pose in poses:
        cam = render.Camera.for_view(view, (640, 480), pose.body.height)
        truth = render.truth_fields(pose, cam)
        frames = render.render_frames(pose, cam, "mannequin")
        track = extract_frames(frames, pose.fps, estimator=blazepose, flip_test=flip_test)
        radius = 0.05 * person_height_px(cam.K, cam.R, cam.t, pose.root, pose.body.height)
        err = np.linalg.norm(track.xy[:, :, :2] - truth["keypoints"], axis=-1)
        ok = np.where(np.isfinite(err), err, np.inf) <= radius[:, None]
        vis = truth["visibility"] > 0
        for j, (left, right) in PAIRS.items():
            hits[f"{j}_L"].extend(ok[vis[:, left], left])
            hits[f"{j}_R"].extend(ok[vis[:, right], right])
        for j, frames in left_right_swaps(track.xy, truth["keypoints"], radius).items():
            swaps[j] += int(frames.sum())
        n_frames += len(track)
    pck = {k: float(np.mean(v)) if v else float("nan") for k, v in hits.items()}
    print(
        f"\n{view} (flip test {flip_test}): PCK@5% "
        + " ".join(f"{k}={v:.3f}" for k, v in pck.items())
        + f"; swaps {swaps} in {n_frames} frames"
    )
    return pck, {j: n / n_frames for j, n in swaps.items()}


@pytest.fixture(scope="module")
def results(blazepose_session):
    from capture2notation.body import Body
    from capture2notation.keypoints.blazepose import BlazePose
    from synthetic import phrases, render
    from synthetic.interpret import interpret

    poses = [
        render.Pose.from_motion(
            interpret(score, TURN_FPS if any(s.part == "turn" for s in score.symbols) else FPS, Body())
        )
        for _, score in sorted(phrases.builtin_phrases().items())
    ]
    bp = BlazePose(session=blazepose_session)
    return {
        (view, flip): _evaluate(bp, poses, view, flip) for view in ("front", "45", "side") for flip in (False, True)
    }


@pytest.mark.slow
@pytest.mark.parametrize("view", ["front", "45", "side"])
def test_one_pass_per_frame_finds_every_joint_without_swaps(results, view):
    """The default path: a floor (measured >= 0.89) and no left/right swaps."""
    pck, swaps = results[view, False]
    low = {k: round(v, 3) for k, v in pck.items() if np.isfinite(v) and v < 0.85}
    assert not low, f"{view}: PCK@5% below 85 %: {low}"
    worst = max(swaps.values())
    assert worst <= MAX_SWAPPED_FRACTION, f"{view}: fraction of frames swapped {swaps}"


@pytest.mark.slow
@pytest.mark.parametrize("view", ["front", "45", "side"])
def test_issue_target_pck95_and_no_swaps(results, view):
    """The issue's target, met with the flip test."""
    pck, swaps = results[view, True]
    low = {k: round(v, 3) for k, v in pck.items() if np.isfinite(v) and v < 0.95}
    assert not low, f"{view}: PCK@5% below 95 %: {low}"
    worst = max(swaps.values())
    assert worst <= MAX_SWAPPED_FRACTION, f"{view}: fraction of frames swapped {swaps}"
