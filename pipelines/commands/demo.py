"""``c2n demo``: the whole loop on a built-in phrase, no user file needed.

For each phrase: the virtual dancer performs the score and the renderer
films it (``render/``), the capture turns the video back into notation
(``capture/``: score, staff, Benesh, Effort, ``index.html``), and the
captured performance is scored against the original (``score/report.html``).
``OUTDIR/index.html`` links them all and states how close the loop came.
"""

from __future__ import annotations

import html
import logging
from dataclasses import dataclass
from pathlib import Path

import click
import numpy as np

from .render import check_choice, parse_size

__all__ = ["DEMO_PHRASES", "DemoResult", "demo", "run_demo"]

log = logging.getLogger(__name__)

#: Built-in phrases (names in ``synthetic.phrases.builtin_phrases()``).
DEMO_PHRASES: tuple[str, ...] = ("port_de_bras", "figure7", "leg_phrase")


@dataclass(frozen=True)
class DemoResult:
    """How one phrase went round the loop.

    Attributes
    ----------
    phrase : str
    folder : Path
        ``OUTDIR/<phrase>`` holding ``render/``, ``capture/`` and ``score/``.
    symbols : int
        Symbols in the original and in the captured score, as (original, captured).
    symbol_agreement : float
        Direction + level per part per beat of the original, in [0, 1].
    median_start_error : float
        Beats of the original (NaN when no symbol was matched).
    tempo : tuple of float
        (original, captured) beats per minute.
    limb_error_deg : float
        Median angle between fitted and true limb directions (arms, legs), degrees.
    mpjpe_mm : float
        Mean per-joint position error of the captured performance against the
        original after alignment (from the score report), millimetres.
    seconds : dict of str to float
        Wall-clock time of each stage of the capture.
    differences : tuple of (str, float, str, str)
        The (part, beat, written, captured) cells the agreement misses,
        beats of the original counted from 0.
    """

    phrase: str
    folder: Path
    symbols: tuple[int, int]
    symbol_agreement: float
    median_start_error: float
    tempo: tuple[float, float]
    limb_error_deg: float
    mpjpe_mm: float
    seconds: dict
    differences: tuple = ()

    def line(self) -> str:
        """One line a person reads in the terminal."""
        return (
            f"{self.phrase}: symbol agreement {self.symbol_agreement:.0%} "
            f"(direction + level per part per beat), median start error {self.median_start_error:.2f} beat, "
            f"tempo {self.tempo[1]:g} bpm captured vs {self.tempo[0]:g} written, "
            f"limb directions {self.limb_error_deg:.1f}° off (median), MPJPE {self.mpjpe_mm:.0f} mm"
        )


def _limb_error(truth_joints: np.ndarray, fitted_joints: np.ndarray) -> float:
    """Median angle (degrees) between true and fitted limb directions of arms and legs."""
    from capture2notation.compare.metrics import angle_between, part_vectors

    parts = ("right_arm", "left_arm", "right_leg", "left_leg")
    n = min(len(truth_joints), len(fitted_joints))
    err = angle_between(part_vectors(truth_joints[:n], parts), part_vectors(fitted_joints[:n], parts))
    return float(np.nanmedian(err)) if np.isfinite(err).any() else float("nan")


def run_phrase(
    name: str, score, folder: Path, *, fps: float, size, view: str, style: str, effort: bool, progress: bool
) -> DemoResult:
    """Render `score`, capture the video, compare with the original; see :class:`DemoResult`."""
    from capture2notation.compare.agreement import agreement_cells, compare_scores
    from capture2notation.io.truth import read_truth
    from pipelines.capture import capture
    from pipelines.score import run_score
    from synthetic.render import render_score

    render_dir = render_score(score, folder / "render", fps=fps, size=size, view=view, style=style, progress=progress)
    cap = capture(render_dir / "video.mp4", folder / "capture", progress=progress, effort=effort)
    agreement = compare_scores(score, cap.score)
    truth = read_truth(render_dir / "truth.npz")
    summary = run_score(folder / "capture", render_dir / "truth.npz", folder / "score", fps=fps)
    return DemoResult(
        phrase=name,
        folder=folder,
        symbols=(len(score.symbols), len(cap.score.symbols)),
        symbol_agreement=float(agreement.symbol_agreement),
        median_start_error=float(agreement.median_start_error),
        tempo=(float(score.tempo), float(cap.score.tempo)),
        limb_error_deg=_limb_error(np.asarray(truth.joints), np.asarray(cap.motion.joints)),
        mpjpe_mm=float(summary["mpjpe_mm"]),
        seconds=dict(cap.seconds),
        differences=tuple(
            (c.part, float(c.beat) - 0.5, " ".join(c.ref), " ".join(c.cand))
            for c in agreement_cells(score, cap.score)
            if c.ref != c.cand
        ),
    )


def run_demo(
    outdir="c2n-demo",
    *,
    phrases=("port_de_bras",),
    fps: float = 25.0,
    size=(640, 480),
    view: str = "front",
    style: str = "mannequin",
    effort: bool = True,
    progress: bool = True,
) -> list[DemoResult]:
    """Run the loop render → capture → notation → comparison on built-in phrases.

    Parameters
    ----------
    outdir : str or Path
        Output folder, created if needed; ``OUTDIR/index.html`` links everything.
    phrases : sequence of str
        Names of built-in phrases (see :data:`DEMO_PHRASES`).
    fps, size, view, style
        As for :func:`synthetic.render.render_score`.
    effort : bool
        Estimate Laban Effort in the capture.
    progress : bool
        Progress bars over frames.

    Returns
    -------
    list of DemoResult
    """
    from capture2notation.atomic import write_text
    from capture2notation.errors import PipelineError
    from synthetic.phrases import builtin_phrases

    available = builtin_phrases()
    missing = [p for p in phrases if p not in available]
    if missing:
        raise PipelineError(f"unknown built-in phrase(s) {', '.join(missing)}; available: {', '.join(available)}")
    outdir = Path(outdir)
    results = [
        run_phrase(
            name,
            available[name],
            outdir / name,
            fps=fps,
            size=size,
            view=view,
            style=style,
            effort=effort,
            progress=progress,
        )
        for name in phrases
    ]
    write_text(outdir / "index.html", index_html(results))
    return results


def index_html(results: list[DemoResult]) -> str:
    """The demo's front page: one row per phrase with its figures and links."""
    rows = []
    for r in results:
        name = html.escape(r.phrase)
        rows.append(
            f"<tr><td><b>{name}</b></td><td>{r.symbols[0]} → {r.symbols[1]}</td>"
            f"<td>{r.symbol_agreement:.0%}</td><td>{r.median_start_error:.2f}</td>"
            f"<td>{r.tempo[0]:g} / {r.tempo[1]:g}</td><td>{r.limb_error_deg:.1f}°</td><td>{r.mpjpe_mm:.0f}</td>"
            f'<td><a href="{name}/render/video.mp4">video</a> · <a href="{name}/render/score.lab">score.lab</a></td>'
            f'<td><a href="{name}/capture/index.html">capture</a></td>'
            f'<td><a href="{name}/score/report.html">comparison</a></td></tr>'
        )
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>capture2notation demo</title>
<style>body {{ font-family: sans-serif; margin: 1.5em; max-width: 70em; }}
table {{ border-collapse: collapse; }} td, th {{ padding: 0.3em 0.7em; border-bottom: 1px solid #ddd; text-align: left; }}
</style></head><body>
<h1>capture2notation: the loop on built-in phrases</h1>
<p>Each phrase's score was performed by the virtual dancer and rendered; the video went through
BlazePose, the 3D fit and the quantiser back to notation, which is compared here with the original.</p>
<table><tr><th>phrase</th><th>symbols written → captured</th><th>symbol agreement<br>(direction + level per beat)</th>
<th>median start error (beats)</th><th>tempo written / captured (bpm)</th><th>limb direction error (median)</th>
<th>MPJPE (mm)</th><th>original</th><th>notation</th><th>report</th></tr>
{"".join(rows)}
</table>
{"".join(_differences_html(r) for r in results)}
</body></html>
"""


def _differences_html(r: DemoResult) -> str:
    """Where one phrase's captured score differs from the original, beat by beat."""
    name = html.escape(r.phrase)
    if not r.differences:
        return f"<h2>{name}</h2><p>The captured score agrees with the original on every beat.</p>\n"
    rows = "".join(
        f"<tr><td>{html.escape(part)}</td><td>{beat:g}</td><td>{html.escape(w)}</td><td>{html.escape(c)}</td></tr>"
        for part, beat, w, c in r.differences
    )
    return (
        f"<h2>{name}: where the capture differs</h2>\n<table><tr><th>part</th><th>beat</th>"
        f"<th>written</th><th>captured</th></tr>{rows}</table>\n"
    )


@click.command("demo")
@click.option(
    "-o",
    "--output",
    "outdir",
    default="c2n-demo",
    show_default=True,
    type=click.Path(file_okay=False, path_type=str),
    help="Folder for the demo outputs.",
)
@click.option(
    "--phrase",
    "phrases",
    multiple=True,
    default=("port_de_bras",),
    show_default=True,
    help=f"Built-in phrase to run ({', '.join(DEMO_PHRASES)} or all); repeatable.",
)
@click.option("--size", default="640x480", show_default=True, help="Image WIDTHxHEIGHT in pixels.")
@click.option("--view", default="front", show_default=True, help="Camera: front, 45 or side.")
@click.option("--style", default="mannequin", show_default=True, help="Drawing: mannequin, stick or markers.")
@click.option("--no-effort", is_flag=True, help="Skip the Laban Effort estimate.")
def demo(outdir, phrases, size, view, style, no_effort):
    """The whole loop on a built-in phrase: the virtual dancer performs it,
    the video is captured back into notation (score, staff, Benesh, Effort)
    and compared with the original."""
    from synthetic.render import STYLES, VIEWS

    from .options import check_outdir

    wh = parse_size(size)
    check_choice(view, "--view", list(VIEWS))
    check_choice(style, "--style", list(STYLES))
    check_outdir(outdir)
    names = DEMO_PHRASES if "all" in phrases else tuple(dict.fromkeys(phrases))
    for name in names:
        check_choice(name, "--phrase", [*DEMO_PHRASES, "all"])
    results = run_demo(outdir, phrases=names, size=wh, view=view, style=style, effort=not no_effort)
    for r in results:
        click.echo(r.line())
        click.echo(f"  notation: {r.folder / 'capture'} (score.lab, staff.svg, benesh.json, effort.json)")
    click.echo(f"open {Path(outdir).resolve() / 'index.html'}")
