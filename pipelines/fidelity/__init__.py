"""The automated fidelity study (issue 4): what recording quality is enough?

``run_fidelity_study(config, outdir, quick=False, scheduler=None)`` builds the
grid (:mod:`.conditions`), runs every job (:mod:`.runner`), and writes
``results.csv``, ``trials.csv``, ``summary.json`` and ``report.html``
(:mod:`.report`).
"""

from __future__ import annotations

from .config import StudyConfig, load_config, quick
from .runner import STUDY_VERSION, run_condition, run_study

__all__ = ["STUDY_VERSION", "StudyConfig", "load_config", "quick", "run_condition", "run_fidelity_study", "run_study"]

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


def run_fidelity_study(
    cfg: StudyConfig,
    outdir,
    is_quick: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
):
    """Run a study end to end and write its report; return the :class:`~.runner.StudyResult`."""
    from .measure import builtin_scores
    from .report import write_report

    if is_quick:
        scores = builtin_scores()
        # the two shortest phrases (in seconds at their own tempo): quickest to run
        by_length = sorted(scores, key=lambda n: (scores[n].seconds(scores[n].duration), n))
        cfg = quick(cfg, tuple(by_length))
    result = run_study(cfg, outdir, scheduler=scheduler, workers=workers, progress=progress)
    write_report(result, outdir, CAPTURE_NOTES.get(result.summary.get("capture"), ""))
    return result
