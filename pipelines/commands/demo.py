"""``c2n demo``: render the built-in phrases, no user file needed.

:func:`run_demo` is deliberately small so the end-to-end demo can grow around
it (capture, notation, scoring) without changing the command.
"""

from __future__ import annotations

from pathlib import Path

import click

from .render import check_choice, parse_size

__all__ = ["DEMO_PHRASES", "demo", "run_demo"]

#: Built-in phrases the demo renders (names in ``synthetic.phrases.builtin_phrases()``).
DEMO_PHRASES: tuple[str, ...] = ("figure7", "port_de_bras", "leg_phrase")


def run_demo(outdir="c2n-demo", *, fps: float = 25.0, size=(640, 480), view: str = "front",
             style: str = "mannequin", progress: bool = True, phrases=DEMO_PHRASES) -> dict:
    """Render built-in phrases into ``OUTDIR/<phrase>/``.

    Parameters
    ----------
    outdir : str or Path
        Output folder, created if needed.
    fps, size, view, style
        As for :func:`synthetic.render.render_score`.
    progress : bool
        Progress bars over frames.
    phrases : sequence of str
        Names of built-in phrases.

    Returns
    -------
    dict of str to Path
        Each phrase's output folder (video.mp4, truth.npz, score.lab).
    """
    from capture2notation.errors import PipelineError
    from synthetic.phrases import builtin_phrases
    from synthetic.render import render_score

    available = builtin_phrases()
    missing = [p for p in phrases if p not in available]
    if missing:
        raise PipelineError(f"unknown built-in phrase(s) {', '.join(missing)}; available: {', '.join(available)}")
    outdir = Path(outdir)
    return {
        name: render_score(available[name], outdir / name, fps=fps, size=size, view=view, style=style,
                           progress=progress)
        for name in phrases
    }


@click.command("demo")
@click.option("-o", "--output", "outdir", default="c2n-demo", show_default=True,
              type=click.Path(file_okay=False, path_type=str), help="Folder for the demo outputs.")
@click.option("--size", default="640x480", show_default=True, help="Image WIDTHxHEIGHT in pixels.")
@click.option("--view", default="front", show_default=True, help="Camera: front, 45 or side.")
@click.option("--style", default="mannequin", show_default=True, help="Drawing: mannequin, stick or markers.")
def demo(outdir, size, view, style):
    """Render the built-in phrases (Wolofsky's Figure 7, Cecchetti's third
    port de bras, a leg phrase with supports) with their ground truth."""
    from synthetic.render import STYLES, VIEWS

    wh = parse_size(size)
    check_choice(view, "--view", list(VIEWS))
    check_choice(style, "--style", list(STYLES))
    outs = run_demo(outdir, size=wh, view=view, style=style)
    for name, path in outs.items():
        click.echo(f"{name}: {path}/video.mp4 (truth.npz, score.lab beside it)")
    click.echo(f"demo written to {Path(outdir).resolve()}")
