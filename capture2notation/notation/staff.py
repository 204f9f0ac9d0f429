"""The Labanotation staff as a notator reads it: ``staff.svg`` (and PNG).

The front door: :func:`render_staff` lays a score out
(:mod:`capture2notation.notation.staff_layout`, where the conventions of the
drawing are described) and draws it
(:mod:`capture2notation.notation.staff_draw`).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import NotationError
from .model import Score
from .staff_draw import PAGE_STAVES, png_pages, render_png, svg_text
from .staff_layout import FrontSign, Glyph, StaffLayout, staff_layout, symbol_outline, turn_outline

__all__ = [
    "PAGE_STAVES",
    "FrontSign",
    "Glyph",
    "StaffLayout",
    "png_pages",
    "render_staff",
    "staff_layout",
    "svg_text",
    "symbol_outline",
    "turn_outline",
]


def render_staff(
    score: Score,
    path_svg,
    png_path=None,
    *,
    beat_height: float = 48.0,
    column_width: float = 34.0,
    measures_per_staff: int | None = 8,
    dpi: int = 100,
) -> Path:
    """Draw the staff of `score` to an SVG file, and optionally a PNG.

    Parameters
    ----------
    score : Score
    path_svg : str or Path
        Output SVG (written atomically).
    png_path : str or Path, optional
        Output PNG of the same drawing (matplotlib, written atomically); the
        image has the layout's pixel size at ``dpi`` 100, scaled by
        ``dpi / 100`` otherwise.  A staff of more than
        :data:`~.staff_draw.PAGE_STAVES` staves continues on further pages,
        ``STEM-2.png`` and on (:func:`~.staff_draw.png_pages`).
    beat_height, column_width : float
        Pixels per beat and per column.
    measures_per_staff : int or None
        Measures on each staff before the score continues on the next staff
        to the right (None: one staff however long).
    dpi : int
        Resolution of the PNG.

    Returns
    -------
    Path
        The SVG path.
    """
    from ..atomic import write_text

    if not isinstance(score, Score):
        raise NotationError(f"render_staff needs a Score, got {type(score).__name__}")
    lay = staff_layout(score, beat_height, column_width, measures_per_staff)
    out = write_text(path_svg, svg_text(lay))
    if png_path is not None:
        render_png(lay, png_path, dpi=dpi)
    return out
