"""``c2n fidelity-study [--config study.toml] [--quick] [--scheduler ADDRESS] -o OUTDIR``."""

from __future__ import annotations

import time

import click

__all__ = ["fidelity_study"]


@click.command("fidelity-study")
@click.option(
    "--config",
    "config_path",
    type=click.Path(exists=True, dir_okay=False),
    default=None,
    help="study.toml (defaults: every built-in phrase, four emotions, all factors).",
)
@click.option("--quick", is_flag=True, help="A tiny grid that finishes in a few minutes on 2 cores.")
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Run the jobs on a Dask distributed cluster (e.g. tcp://host:8786) instead of local cores.",
)
@click.option(
    "--workers", type=click.IntRange(1, 256), default=None, help="Local worker processes (default: number of cores)."
)
@click.option("--seed", type=click.IntRange(min=0), default=None, help="Override the config's seed.")
@click.option(
    "--capture",
    default=None,
    metavar="PATH[,PATH...]",
    help="Override the config's capture path(s): video, keypoints, truth, keypoints-calibrated, video-calibrated "
    "or auto; several (comma-separated, e.g. video,keypoints) are compared in the report, the first is primary.",
)
@click.option("-o", "--outdir", required=True, type=click.Path(file_okay=False), help="Output folder (resumable).")
def fidelity_study(config_path, quick, scheduler, workers, seed, capture, outdir):
    """Measure which frame rate, image size, view, compression and noise still recover the notation and emotion.

    Writes OUTDIR/results.csv (one row per performance × condition),
    trials.csv (same/different judgements), summary.json and report.html.
    Finished jobs are cached under OUTDIR/cache as they finish: Ctrl-C stops at
    once (exit 130, SIGTERM 143) and the same command resumes.
    """
    import sys

    from pipelines.fidelity import StudyInterrupted, load_config, run_fidelity_study

    from .options import check_outdir

    check_outdir(outdir)
    overrides: dict = {} if seed is None else {"seed": seed}
    if capture is not None:
        overrides["capture"] = [c.strip() for c in capture.split(",")]
    cfg = load_config(config_path, overrides)
    t0 = time.perf_counter()
    try:
        result = run_fidelity_study(cfg, outdir, is_quick=quick, scheduler=scheduler, workers=workers)
    except StudyInterrupted as exc:
        click.echo(f"c2n: {exc}", err=True)
        sys.exit(128 + exc.signum)
    s = result.summary
    base = next((e for e in s.get("experiment1", []) if e["factor"] == "baseline"), None)
    click.echo(
        f"{s['jobs']['total']} jobs ({s['jobs']['cached']} cached, {s['jobs']['failed']} failed) "
        f"in {time.perf_counter() - t0:.0f} s; capture path: {s['capture']}"
    )
    for mode, other in s.get("other_captures", {}).items():
        click.echo(
            f"also captured on the {mode} path: {other['jobs']['total']} jobs ({other['jobs']['failed']} failed)"
        )
    if base:
        click.echo(f"observer at baseline: {base['percent_correct']:.1f} % correct (experts 78.70 %)")
    click.echo(f"report: {outdir}/report.html")
