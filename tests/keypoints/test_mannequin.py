"""BlazePose on the virtual dancer's mannequin renders (640x480, three views).

The issue asks PCK at 5 % of the person's height >= 95 % for shoulders,
elbows, wrists, hips, knees and ankles, and no left/right swaps.  The person's
height in pixels is the body height projected at the pelvis depth
(``f_y * H / z_pelvis``).  PCK counts joints the truth marks visible; a
left/right swap is a frame where both points of a pair lie nearer the
opposite side's truth while the two truths are more than the PCK radius apart.

Measured (built-in phrases at 10 fps, 207 frames per view, see the report):
front meets it except the ankles (0.87-0.92: BlazePose puts the ankle ~9 px
above the mannequin's ankle joint); at 45 degrees ``port_de_bras`` with both
arms overhead is read as seen from behind for 7 frames (a whole-body swap);
in the side view the far (hidden) wrist misses.  Those parts are strict
``xfail`` so that an improved mannequin turns them into failures to remove.
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.model

PAIRS = {"shoulder": (11, 12), "elbow": (13, 14), "wrist": (15, 16), "hip": (23, 24), "knee": (25, 26), "ankle": (27, 28)}
FPS = 5.0  # low frame rate keeps the test fast; tracking copes (the squats fixture is 5 fps)


def _evaluate(blazepose, view):
    render = pytest.importorskip("synthetic.render")
    phrases = pytest.importorskip("synthetic.phrases")
    from synthetic.interpret import interpret

    from capture2notation.body import Body
    from capture2notation.keypoints import extract_frames

    hits = {f"{j}_{s}": [] for j in PAIRS for s in "LR"}
    swaps = {j: 0 for j in PAIRS}
    for name, score in sorted(phrases.builtin_phrases().items()):
        pose = render.Pose.from_motion(interpret(score, FPS, Body()))
        cam = render.Camera.for_view(view, (640, 480), pose.body.height)
        truth = render.truth_fields(pose, cam)
        track = extract_frames(render.render_frames(pose, cam, "mannequin"), pose.fps, estimator=blazepose)
        kp, vis = truth["keypoints"], truth["visibility"] > 0
        radius = 0.05 * cam.K[1, 1] * pose.body.height / (pose.root @ cam.R.T + cam.t)[:, 2]
        err = np.linalg.norm(track.xy[:, :, :2] - kp, axis=-1)
        err = np.where(np.isfinite(err), err, np.inf)
        for j, (left, right) in PAIRS.items():
            for side, i in (("L", left), ("R", right)):
                hits[f"{j}_{side}"].extend(err[vis[:, i], i] <= radius[vis[:, i]])
            apart = np.linalg.norm(kp[:, left] - kp[:, right], axis=-1) > radius
            cross_l = np.linalg.norm(track.xy[:, left, :2] - kp[:, right], axis=-1) < err[:, left]
            cross_r = np.linalg.norm(track.xy[:, right, :2] - kp[:, left], axis=-1) < err[:, right]
            swaps[j] += int((apart & cross_l & cross_r).sum())
    pck = {k: float(np.mean(v)) if v else float("nan") for k, v in hits.items()}
    print(f"\n{view}: PCK@5% " + " ".join(f"{k}={v:.3f}" for k, v in pck.items()) + f"; swaps {swaps}")
    return pck, swaps


@pytest.fixture(scope="module")
def results(blazepose_session):
    from capture2notation.keypoints.blazepose import BlazePose

    bp = BlazePose(session=blazepose_session)
    return {view: _evaluate(bp, view) for view in ("front", "45", "side")}


@pytest.mark.parametrize("view", ["front", "45", "side"])
def test_upper_body_and_hips_are_found(results, view):
    """What holds today in every view: shoulders, visible elbows, hips >= 90 %."""
    pck, _ = results[view]
    for joint in ("shoulder_L", "shoulder_R", "elbow_R", "hip_L", "hip_R"):
        if np.isfinite(pck[joint]):
            assert pck[joint] >= 0.90, f"{view}: {joint} PCK {pck[joint]:.3f}"


@pytest.mark.parametrize(
    "view",
    [
        pytest.param("front", marks=pytest.mark.xfail(strict=True, reason="ankles 0.87-0.92: ~9 px vertical offset between the mannequin's ankle joint and BlazePose's ankle")),
        pytest.param("45", marks=pytest.mark.xfail(strict=True, reason="port_de_bras arms overhead read from behind (whole-body L/R swap)")),
        pytest.param("side", marks=pytest.mark.xfail(strict=True, reason="far-side wrist (hidden) and ankle below 95 %")),
    ],
)
def test_issue_target_pck95_and_no_swaps(results, view):
    pck, swaps = results[view]
    low = {k: round(v, 3) for k, v in pck.items() if np.isfinite(v) and v < 0.95}
    assert not low, f"{view}: PCK@5% below 95 %: {low}"
    assert sum(swaps.values()) == 0, f"{view}: left/right swaps {swaps}"
