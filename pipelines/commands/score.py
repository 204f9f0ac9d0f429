"""``c2n score CANDIDATE REFERENCE -o OUTDIR``: score a performance against a reference."""

from __future__ import annotations

import click

__all__ = ["score"]


@click.command("score")
@click.argument("candidate", type=click.Path(exists=True))
@click.argument("reference", type=click.Path(exists=True))
@click.option(
    "-o", "--outdir", required=True, type=click.Path(file_okay=False), help="Folder for summary.json and report.html."
)
@click.option("--fps", type=float, default=25.0, show_default=True, help="Frame rate at which scores are danced.")
@click.option(
    "--timing-tolerance",
    type=float,
    default=0.2,
    show_default=True,
    help="Seconds of timing offset still counted as on time.",
)
def score(candidate, reference, outdir, fps, timing_tolerance):
    """Compare CANDIDATE with REFERENCE (each a score file, capture folder, BVH/CSV or truth .npz).

    Writes OUTDIR/summary.json and OUTDIR/report.html.
    """
    from pipelines.score import run_score

    s = run_score(candidate, reference, outdir, fps=fps, timing_tolerance=timing_tolerance)
    sa = s["symbol_agreement"]
    click.echo(
        f"symbol agreement {'n/a' if sa is None else f'{sa:.0%}'}, MPJPE {s['mpjpe_mm']:.0f} mm, "
        f"PA-MPJPE {s['pa_mpjpe_mm']:.0f} mm; verdicts {s['verdicts']}"
    )
    click.echo(f"report: {outdir}/report.html")
