"""The Labanotation staff as a notator reads it: ``staff.svg`` (and PNG).

Layout (Hutchinson's conventions, as in Wolofsky 1974 ch. III):

* vertical, read from the bottom up; a double line marks the start and the
  end; the centre line carries a tick on every beat; bar lines across the
  three-line staff every ``meter`` beats, with measure numbers on the left;
  long scores continue on further staves to the right (8 measures each by
  default), as on a notator's page;
* columns, from the centre outwards on each side: support, leg gesture
  (then thigh and shin when the score uses them), body (chest, drawn on the
  right), arm (then upper arm and forearm when used), and the head column
  outside the right arm.  ``support`` (both feet) spans both support columns;
* direction shapes (stems and slants placed as in LabanotationSuite's
  LabanEditor viewer): place a rectangle; forward/back a rectangle with a
  step-shaped stem at the top/bottom on the side towards the centre line;
  right/left a triangle pointing sideways (a trapezoid when long); the four
  diagonals a rectangle with a slanted top (forward) or bottom (back) edge
  pointing into the diagonal;
* level shading: high hatched with diagonal strokes, middle a dot in the
  centre, low solid black;
* a symbol's length is its duration (``beat_height`` pixels per beat); a
  bend is shown as ``×N`` (the contraction sign with its degree) at the
  symbol's foot.

The geometry is computed once (:func:`staff_layout`, pure) and drawn by two
thin back ends: hand-written SVG (one ``<g class="symbol">`` per symbol,
with ``data-start``/``data-duration`` in beats) and a matplotlib PNG.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from ..errors import NotationError
from .model import Score, Symbol

__all__ = ["Glyph", "StaffLayout", "render_staff", "staff_layout", "svg_text", "symbol_outline"]

_MARGIN_TOP = 70.0
_MARGIN_BOTTOM = 50.0
_MARGIN_SIDE = 40.0
_PAD = 0.12  # fraction of a column left free on each side of a symbol


@dataclass(frozen=True)
class Glyph:
    """One drawn symbol.

    Attributes
    ----------
    index : int
        Position of the symbol in ``score.symbols``.
    symbol : Symbol
    pieces : tuple of (N, 2) ndarray
        Outline polygon(s) in pixels (x right, y down): one, or one per staff
        when the symbol crosses a staff break.
    centre : tuple of float
        Pixel position of the middle of the symbol (where the middle-level
        dot goes).
    foot : tuple of float
        Pixel position of the middle of the symbol's bottom edge (its start).
    dot_radius : float
        Radius of the middle-level dot, pixels (one column's, even for
        ``support`` which spans two).
    """

    index: int
    symbol: Symbol
    pieces: tuple
    centre: tuple
    foot: tuple
    dot_radius: float


@dataclass
class StaffLayout:
    """Everything to draw, in pixels (x right, y down)."""

    width: float
    height: float
    glyphs: list = field(default_factory=list)
    lines: list = field(default_factory=list)  # (x0, y0, x1, y1, stroke width)
    texts: list = field(default_factory=list)  # (x, y, text, size, anchor)


def _columns(score: Score) -> dict:
    """Column index (signed, 1-based from the centre line) of each part."""
    used = {s.part for s in score.symbols}
    right = ["right_support", "right_leg"]
    left = ["left_support", "left_leg"]
    for side, cols in (("right", right), ("left", left)):
        cols += [p for p in (f"{side}_thigh", f"{side}_shin") if p in used]
        cols.append("chest" if side == "right" else "_left_body")
        cols.append(f"{side}_arm")
        cols += [p for p in (f"{side}_upper_arm", f"{side}_forearm") if p in used]
    right.append("head")
    out = {p: i + 1 for i, p in enumerate(right)}
    out.update({p: -(i + 1) for i, p in enumerate(left)})
    return out


_LABELS = {
    "right_support": "sup",
    "left_support": "sup",
    "right_leg": "leg",
    "left_leg": "leg",
    "right_thigh": "thigh",
    "left_thigh": "thigh",
    "right_shin": "shin",
    "left_shin": "shin",
    "chest": "chest",
    "_left_body": "body",
    "right_arm": "arm",
    "left_arm": "arm",
    "right_upper_arm": "u.arm",
    "left_upper_arm": "u.arm",
    "right_forearm": "f.arm",
    "left_forearm": "f.arm",
    "head": "head",
}


def symbol_outline(direction: str, x0: float, y0: float, x1: float, y1: float, side: str) -> np.ndarray:
    """Outline polygon of a direction symbol in a box.

    Parameters
    ----------
    direction : str
    x0, x1 : float
        Left and right edges, pixels.
    y0, y1 : float
        Bottom (start) and top (end) edges in pixels, y growing downwards, so
        ``y0 > y1``.
    side : {'right', 'left'}
        Side of the centre line (decides where forward/back stems go).

    Returns
    -------
    (N, 2) ndarray
    """
    w, h = x1 - x0, y0 - y1
    c = min(h / 3.0, 0.6 * w)  # depth of stems and slants, bounded for long symbols
    xm = 0.5 * (x0 + x1)
    ym = 0.5 * (y0 + y1)
    s = min(h / 2.0, 0.9 * w)  # vertical run of a side symbol's slanted edges
    shapes = {
        "place": [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
        "right": [(x0, y0), (x1, y0 - s), (x1, y1 + s), (x0, y1)] if s < h / 2 else [(x0, y0), (x1, ym), (x0, y1)],
        "left": [(x1, y0), (x1, y1), (x0, y1 + s), (x0, y0 - s)] if s < h / 2 else [(x1, y0), (x1, y1), (x0, ym)],
        "right_forward": [(x0, y0), (x1, y0), (x1, y1), (x0, y1 + c)],
        "left_forward": [(x0, y0), (x1, y0), (x1, y1 + c), (x0, y1)],
        "right_back": [(x0, y0 - c), (x1, y0), (x1, y1), (x0, y1)],
        "left_back": [(x0, y0), (x1, y0 - c), (x1, y1), (x0, y1)],
    }
    if side == "right":
        shapes["forward"] = [(x0, y0), (x1, y0), (x1, y1 + c), (xm, y1 + c), (xm, y1), (x0, y1)]
        shapes["back"] = [(x0, y0), (xm, y0), (xm, y0 - c), (x1, y0 - c), (x1, y1), (x0, y1)]
    else:
        shapes["forward"] = [(x0, y0), (x1, y0), (x1, y1), (xm, y1), (xm, y1 + c), (x0, y1 + c)]
        shapes["back"] = [(x0, y0 - c), (xm, y0 - c), (xm, y0), (x1, y0), (x1, y1), (x0, y1)]
    if direction not in shapes:
        raise NotationError(f"no staff shape for direction {direction!r}")
    return np.asarray(shapes[direction], dtype=float)


def _clip_band(points: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Clip a polygon to the horizontal band ``lo <= y <= hi`` (Sutherland–Hodgman).

    Parameters
    ----------
    points : (N, 2) ndarray
    lo, hi : float

    Returns
    -------
    (M, 2) ndarray
        The clipped polygon (empty if nothing is left).
    """
    out = [tuple(p) for p in points]
    for inside, bound in ((lambda y: y >= lo, lo), (lambda y: y <= hi, hi)):
        src, out = out, []
        for i, cur in enumerate(src):
            prev = src[i - 1]
            if inside(cur[1]) != inside(prev[1]):
                t = (bound - prev[1]) / (cur[1] - prev[1])
                out.append((prev[0] + t * (cur[0] - prev[0]), bound))
            if inside(cur[1]):
                out.append(cur)
    return np.asarray(out, dtype=float).reshape(-1, 2)


def staff_layout(
    score: Score,
    beat_height: float = 48.0,
    column_width: float = 34.0,
    measures_per_staff: int | None = 8,
) -> StaffLayout:
    """Pixel geometry of the staff of `score`.

    Parameters
    ----------
    score : Score
    beat_height : float
        Pixels per beat (symbol length = duration × this).
    column_width : float
        Pixels per column.
    measures_per_staff : int or None
        Long scores continue on further staves to the right, each of this
        many measures (read left to right, each bottom to top); a symbol that
        crosses a staff break is drawn cut at the top of one staff and
        continued at the bottom of the next.  None keeps a single staff.
    """
    if beat_height <= 0 or column_width <= 0:
        raise NotationError(f"beat_height and column_width must be > 0, got {beat_height}, {column_width}")
    if measures_per_staff is not None and measures_per_staff < 1:
        raise NotationError(f"measures_per_staff must be >= 1 or None, got {measures_per_staff}")
    cols = _columns(score)
    n_right = max(cols.values())
    n_left = -min(cols.values())
    measures = max(1, -(-score.duration // score.meter))  # ceil, at least one measure
    total = measures * score.meter
    per_staff = min(measures, measures_per_staff or measures)
    staff_beats = per_staff * score.meter
    n_staves = -(-measures // per_staff)
    staff_w = (n_left + n_right) * column_width
    gap = 2 * _MARGIN_SIDE
    width = 2 * _MARGIN_SIDE + n_staves * staff_w + (n_staves - 1) * gap
    height = _MARGIN_TOP + staff_beats * beat_height + _MARGIN_BOTTOM
    base = height - _MARGIN_BOTTOM
    lay = StaffLayout(width=width, height=height)

    def centre(j: int) -> float:
        return _MARGIN_SIDE + j * (staff_w + gap) + n_left * column_width

    def y(b, j: int) -> float:
        return base - float(b - j * staff_beats) * beat_height

    half = 2 * column_width  # the three-line staff spans support + leg columns
    for j in range(n_staves):
        cx = centre(j)
        b0, b1 = j * staff_beats, min(total, (j + 1) * staff_beats)
        for x in (cx - half, cx, cx + half):
            lay.lines.append((x, y(b0, j), x, y(b1, j), 1.4))
        for b in range(b0, b1 + 1):
            if b in (0, total):  # double lines outside the start and the end
                for dy in (0.0, 4.0 if b == 0 else -4.0):
                    lay.lines.append((cx - half, y(b, j) + dy, cx + half, y(b, j) + dy, 1.4))
            elif b % score.meter == 0:
                lay.lines.append((cx - half, y(b, j), cx + half, y(b, j), 1.0))
            else:
                lay.lines.append((cx - 4, y(b, j), cx + 4, y(b, j), 1.0))
        for b in range(b0, b1, score.meter):
            lay.texts.append((cx - half - 6, y(b, j) - 4, str(b // score.meter + 1), 11, "end"))
        for part, k in cols.items():
            if part in _LABELS:
                xc = cx + (k - 0.5 if k > 0 else k + 0.5) * column_width
                lay.texts.append((xc, base + 26, _LABELS[part], 9, "middle"))
        lay.texts.append((cx - half / 2, base + 40, "L", 10, "middle"))
        lay.texts.append((cx + half / 2, base + 40, "R", 10, "middle"))
    lay.texts.append((width / 2, 24, score.title or "untitled", 15, "middle"))
    sub = f"\u2669 = {score.tempo}   meter {score.meter}"
    if score.emotion:
        sub += f"   {score.emotion}"
    elif score.effort is not None:
        e = score.effort
        sub += f"   effort b={e.time:g} x0={e.weight:g} S={e.space:g}"
    lay.texts.append((width / 2, 46, sub, 11, "middle"))

    pad = _PAD * column_width
    for i, s in enumerate(score.symbols):
        # Outline in continuous coordinates (x from the centre line, y = −beats·px),
        # then cut at the staff breaks and moved onto each staff.
        if s.part == "support":
            x0, x1, side = -column_width + pad, column_width - pad, "right"
        else:
            k = cols[s.part]
            lo = (k - 1 if k > 0 else k) * column_width
            x0, x1, side = lo + pad, lo + column_width - pad, "right" if k > 0 else "left"
        yv0, yv1 = -float(s.start) * beat_height, -float(s.end) * beat_height
        outline = symbol_outline(s.direction, x0, yv0, x1, yv1, side)
        j0 = min(int(s.start // staff_beats), n_staves - 1)
        j1 = min(int((s.end - Fraction(1, 10**9)) // staff_beats), n_staves - 1)
        pieces = []
        for j in range(j0, j1 + 1):
            band_lo = -float(min(s.end, (j + 1) * staff_beats)) * beat_height
            band_hi = -float(max(s.start, j * staff_beats)) * beat_height
            piece = _clip_band(outline, band_lo, band_hi) if j0 != j1 else outline
            pieces.append(piece + [centre(j), base + j * staff_beats * beat_height])
        mid = (s.start + s.end) / 2
        jm = min(int(mid // staff_beats), n_staves - 1)
        dot = (centre(jm) + (x0 + x1) / 2, y(mid, jm))
        foot = (centre(j0) + (x0 + x1) / 2, y(s.start, j0))
        lay.glyphs.append(Glyph(i, s, tuple(pieces), dot, foot, 0.1 * column_width))
    return lay


def _hatch_pattern() -> str:
    return (
        '<pattern id="hatch" patternUnits="userSpaceOnUse" width="6" height="6" '
        'patternTransform="rotate(45)"><rect width="6" height="6" fill="white"/>'
        '<line x1="0" y1="0" x2="0" y2="6" stroke="black" stroke-width="1.6"/></pattern>'
    )


_XML_INVALID = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]")


def _xml_text(text: str) -> str:
    """Escaped text with the characters XML 1.0 forbids replaced by U+FFFD."""
    return escape(_XML_INVALID.sub("\ufffd", text))


def _glyph_svg(g: Glyph) -> str:
    s = g.symbol
    fill = {"high": "url(#hatch)", "middle": "white", "low": "black"}[s.level]
    attrs = (
        f'id="sym-{g.index}" class="symbol part-{s.part} dir-{s.direction} level-{s.level}" '
        f'data-part="{s.part}" data-direction="{s.direction}" data-level="{s.level}" '
        f'data-bend="{s.bend}" data-start="{s.start}" data-duration="{s.duration}"'
    )
    out = [f"<g {attrs}>", f"<title>{escape(f'{s.part} {s.direction} {s.level} beat {s.start}+{s.duration}')}</title>"]
    for piece in g.pieces:
        pts = " ".join(f"{x:.2f},{y:.2f}" for x, y in piece)
        out.append(f'<polygon class="outline" points="{pts}" fill="{fill}" stroke="black" stroke-width="1.5"/>')
    if s.level == "middle":
        cx, cy = g.centre
        out.append(f'<circle class="dot" cx="{cx:.2f}" cy="{cy:.2f}" r="{g.dot_radius:.2f}" fill="black"/>')
    if s.bend:
        bx, by = g.foot[0], g.foot[1] - 3
        out.append(
            f'<rect x="{bx - 9:.2f}" y="{by - 11:.2f}" width="18" height="12" '
            'fill="white" stroke="black" stroke-width="0.6"/>'
            f'<text class="bend" x="{bx:.2f}" y="{by - 1.5:.2f}" font-size="10" text-anchor="middle" '
            f'font-family="sans-serif">\u00d7{s.bend}</text>'
        )
    out.append("</g>")
    return "".join(out)


def svg_text(lay: StaffLayout) -> str:
    """SVG document of a layout."""
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        (
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{lay.width:.0f}" height="{lay.height:.0f}" '
            f'viewBox="0 0 {lay.width:.2f} {lay.height:.2f}">'
        ),
        f"<defs>{_hatch_pattern()}</defs>",
        f'<rect width="{lay.width:.2f}" height="{lay.height:.2f}" fill="white"/>',
        '<g class="staff" stroke="black">',
    ]
    for x0, y0, x1, y1, sw in lay.lines:
        parts.append(f'<line x1="{x0:.2f}" y1="{y0:.2f}" x2="{x1:.2f}" y2="{y1:.2f}" stroke-width="{sw}"/>')
    parts.append("</g>")
    parts.append('<g class="labels" font-family="sans-serif">')
    for x, y, text, size, anchor in lay.texts:
        parts.append(
            f'<text x="{x:.2f}" y="{y:.2f}" font-size="{size}" text-anchor={quoteattr(anchor)}>{_xml_text(text)}</text>'
        )
    parts.append("</g>")
    parts.append('<g class="symbols">')
    parts += [_glyph_svg(g) for g in lay.glyphs]
    parts.append("</g></svg>")
    return "\n".join(parts) + "\n"


def _render_png(lay: StaffLayout, path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon, Rectangle

    from ..atomic import atomic_path

    # Layout units are pixels at 100 per inch; `dpi` only scales the raster.
    pt = 72.0 / 100.0
    fig = Figure(figsize=(lay.width / 100.0, lay.height / 100.0), dpi=dpi)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, lay.width)
    ax.set_ylim(lay.height, 0)
    ax.axis("off")
    for x0, y0, x1, y1, sw in lay.lines:
        ax.plot([x0, x1], [y0, y1], color="black", lw=sw * pt, solid_capstyle="butt")
    align = {"middle": "center", "end": "right", "start": "left"}
    for x, y, text, size, anchor in lay.texts:
        ax.text(
            x,
            y,
            _XML_INVALID.sub("\ufffd", text),
            fontsize=size * pt,
            ha=align[anchor],
            va="baseline",
            family="sans-serif",
            parse_math=False,
        )
    with matplotlib.rc_context({"hatch.linewidth": 1.2}):
        for g in lay.glyphs:
            s = g.symbol
            face = {"high": "white", "middle": "white", "low": "black"}[s.level]
            for piece in g.pieces:
                ax.add_patch(
                    Polygon(
                        piece,
                        closed=True,
                        facecolor=face,
                        edgecolor="black",
                        lw=1.5 * pt,
                        hatch="////" if s.level == "high" else None,
                    )
                )
            if s.level == "middle":
                ax.add_patch(Circle(g.centre, g.dot_radius, color="black"))
            if s.bend:
                bx, by = g.foot[0], g.foot[1] - 3
                ax.add_patch(Rectangle((bx - 9, by - 11), 18, 12, facecolor="white", edgecolor="black", lw=0.5))
                ax.text(bx, by - 1.5, f"\u00d7{s.bend}", fontsize=10 * pt, ha="center", va="baseline")
        with atomic_path(path, suffix=".png") as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)


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
        ``dpi / 100`` otherwise.
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
        _render_png(lay, png_path, dpi=dpi)
    return out
