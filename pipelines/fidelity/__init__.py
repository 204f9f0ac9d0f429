"""The automated fidelity study (issue 4): what recording quality is enough?

``run_fidelity_study(config, outdir, quick=False, scheduler=None)`` builds the
grid (:mod:`.conditions`), runs every job (:mod:`.runner`), and writes
``results.csv``, ``trials.csv``, ``summary.json`` and ``report.html``
(:mod:`.report`).
"""

from __future__ import annotations

from .config import StudyConfig, load_config, quick
from .measure import CAPTURE_NOTES
from .pool import StudyInterrupted
from .runner import STUDY_VERSION, run_condition, run_study

__all__ = [
    "STUDY_VERSION",
    "StudyConfig",
    "StudyInterrupted",
    "load_config",
    "quick",
    "run_condition",
    "run_fidelity_study",
    "run_study",
]


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
