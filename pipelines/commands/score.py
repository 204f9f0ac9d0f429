"""``c2n score CANDIDATE REFERENCE -o OUTDIR``: score a performance against a reference."""

from __future__ import annotations

import click

from .options import FPS, Number, check_outdir

#: Seconds: a timing tolerance longer than a minute tells nothing about timing.
TIMING_TOLERANCE = Number(0, 60, "seconds")

__all__ = ["score"]


@click.command("score")
@click.argument("candidate", type=click.Path(exists=True))
@click.argument("reference", type=click.Path(exists=True))
@click.option(
    "-o", "--outdir", required=True, type=click.Path(file_okay=False), help="Folder for summary.json and report.html."
)
@click.option("--fps", type=FPS, default=25.0, show_default=True, help="Frame rate at which scores are danced.")
@click.option(
    "--timing-tolerance",
    type=TIMING_TOLERANCE,
    default=0.2,
    show_default=True,
    help="Seconds of timing offset still counted as on time.",
)
def score(candidate, reference, outdir, fps, timing_tolerance):
    """Compare CANDIDATE with REFERENCE (each a score file, capture folder, BVH/CSV or truth .npz).

    Writes OUTDIR/summary.json and OUTDIR/report.html.
    """
    from pipelines.score import run_score

    check_outdir(outdir)
    s = run_score(candidate, reference, outdir, fps=fps, timing_tolerance=timing_tolerance)
    sa = s["symbol_agreement"]
    t = s["time_s"]
    click.echo(
        f"symbol agreement {'n/a' if sa is None else f'{sa:.0%}'} "
        f"({s['movements_agreeing']} of {s['movements_compared']} movements agree, {s['movements_missing']} missing; "
        f"{t['matched_candidate_s']:.1f} of the candidate's {t['candidate_s']:.1f} s matched), "
        f"MPJPE {s['mpjpe_mm']:.0f} mm, PA-MPJPE {s['pa_mpjpe_mm']:.0f} mm"
    )
    click.echo(f"verdict: {s['verdict']['reason']}")
    click.echo(f"report: {outdir}/report.html")
