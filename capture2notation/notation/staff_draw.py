"""Drawing a :class:`~capture2notation.notation.staff.StaffLayout`: SVG text and a matplotlib PNG.

Both back ends draw the same geometry: outlines filled by level (hatched
high, a dot for middle, black low), turn pins and amounts, spring forms in
flight gaps, bend marks, and the front signs beside the staff.  An
uncertain symbol (:attr:`~capture2notation.notation.model.Symbol.uncertain`)
is drawn in grey with a dashed outline, so it reads as a guess at a glance.
"""

from __future__ import annotations

import re
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from .staff_layout import FrontSign, Glyph, StaffLayout

__all__ = ["UNCERTAIN_GREY", "render_png", "svg_text"]

#: Ink of an uncertain symbol (black for the others).
UNCERTAIN_GREY = "#8c8c8c"
#: Dash pattern of an uncertain symbol's outline, pixels on / off.
UNCERTAIN_DASH = (4.0, 2.5)


def _hatch_pattern() -> str:
    return "".join(
        f'<pattern id="{name}" patternUnits="userSpaceOnUse" width="6" height="6" '
        'patternTransform="rotate(45)"><rect width="6" height="6" fill="white"/>'
        f'<line x1="0" y1="0" x2="0" y2="6" stroke="{ink}" stroke-width="1.6"/></pattern>'
        for name, ink in (("hatch", "black"), ("hatch-uncertain", UNCERTAIN_GREY))
    )


_XML_INVALID = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]")


def _xml_text(text: str) -> str:
    """Escaped text with the characters XML 1.0 forbids replaced by U+FFFD."""
    return escape(_XML_INVALID.sub("\ufffd", text))


def _pin_end(cx: float, cy: float, deg: float, r: float) -> tuple[float, float]:
    """Point at `r` pixels from (cx, cy), `deg` degrees clockwise from up (y grows down)."""
    a = np.radians(deg)
    return cx + r * float(np.sin(a)), cy - r * float(np.cos(a))


def _glyph_svg(g: Glyph) -> str:
    s = g.symbol
    level = s.level or "none"
    ink = UNCERTAIN_GREY if s.uncertain else "black"
    hatch = "url(#hatch-uncertain)" if s.uncertain else "url(#hatch)"
    fill = {"high": hatch, "middle": "white", "low": ink, "none": "white"}[level]
    dash = f' stroke-dasharray="{UNCERTAIN_DASH[0]:g} {UNCERTAIN_DASH[1]:g}"' if s.uncertain else ""
    certainty = " uncertain" if s.uncertain else ""
    attrs = (
        f'id="sym-{g.index}" class="symbol part-{s.part} dir-{s.direction} level-{level}{certainty}" '
        f'data-part="{s.part}" data-direction="{s.direction}" data-level="{s.level or ""}" '
        f'data-bend="{s.bend}" data-start="{s.start}" data-duration="{s.duration}"'
    )
    if s.amount is not None:
        attrs += f' data-amount="{s.amount}"'
    if s.is_air:
        attrs += f' data-spring="{g.label}"'
    if s.confidence is not None:
        attrs += f' data-confidence="{s.confidence:.3f}"'
    what = f"{s.part} {s.direction} {s.level or ''}".rstrip()
    if s.amount is not None:
        what += f" amount={s.amount}"
    if s.is_air:
        what += f" ({g.label})"
    if s.confidence is not None:
        what += f" confidence {s.confidence:.2f}" + (" (uncertain)" if s.uncertain else "")
    out = [f"<g {attrs}>", f"<title>{escape(f'{what} beat {s.start}+{s.duration}')}</title>"]
    for piece in g.pieces:
        pts = " ".join(f"{x:.2f},{y:.2f}" for x, y in piece)
        out.append(f'<polygon class="outline" points="{pts}" fill="{fill}" stroke="{ink}" stroke-width="1.5"{dash}/>')
    if s.level == "middle":
        cx, cy = g.centre
        out.append(f'<circle class="dot" cx="{cx:.2f}" cy="{cy:.2f}" r="{g.dot_radius:.2f}" fill="{ink}"/>')
    if g.pin is not None:
        cx, cy = g.centre
        r = 2.2 * g.dot_radius
        tx, ty = _pin_end(cx, cy, g.pin, r)
        out.append(
            f'<line class="pin" x1="{cx:.2f}" y1="{cy:.2f}" x2="{tx:.2f}" y2="{ty:.2f}" stroke="black" '
            f'stroke-width="1.4"/><circle cx="{tx:.2f}" cy="{ty:.2f}" r="1.8" fill="black"/>'
        )
    if g.label:
        cx, cy = g.foot if s.is_turn else g.centre
        dy = -4.0 if s.is_turn else 3.0
        style = ' font-style="italic"' if s.is_air else ""
        cls = "amount" if s.is_turn else "spring"
        out.append(
            f'<text class="{cls}" x="{cx:.2f}" y="{cy + dy:.2f}" font-size="9" text-anchor="middle" '
            f'font-family="sans-serif"{style}>{escape(g.label)}</text>'
        )
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


def _front_svg(f: FrontSign) -> str:
    cx, cy = f.centre
    h = f.size / 2
    tx, ty = _pin_end(cx, cy, f.pin, 0.8 * h)
    return (
        f'<g class="front-sign" data-front="{f.front}" data-room="{f.room}">'
        f"<title>front: {f.room} ({f.front} turns)</title>"
        f'<rect x="{cx - h:.2f}" y="{cy - h:.2f}" width="{f.size:.2f}" height="{f.size:.2f}" fill="white" '
        'stroke="black" stroke-width="1"/>'
        f'<line x1="{cx:.2f}" y1="{cy:.2f}" x2="{tx:.2f}" y2="{ty:.2f}" stroke="black" stroke-width="1.6"/>'
        f'<circle cx="{tx:.2f}" cy="{ty:.2f}" r="2" fill="black"/>'
        f'<text x="{cx:.2f}" y="{cy + h + 9:.2f}" font-size="7" text-anchor="middle" '
        f'font-family="sans-serif">{escape(f.room)}</text></g>'
    )


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
    heading = [(lay.width / 2, y, text, size, "middle") for y, text, size in lay.heading]
    for x, y, text, size, anchor in lay.texts + heading:
        parts.append(
            f'<text x="{x:.2f}" y="{y:.2f}" font-size="{size}" text-anchor={quoteattr(anchor)}>{_xml_text(text)}</text>'
        )
    parts.append("</g>")
    parts.append('<g class="symbols">')
    parts += [_glyph_svg(g) for g in lay.glyphs]
    parts.append("</g>")
    parts.append('<g class="fronts">')
    parts += [_front_svg(f) for f in lay.fronts]
    parts.append("</g></svg>")
    return "\n".join(parts) + "\n"


def _render_page(lay: StaffLayout, path, dpi: int, x_range: tuple) -> None:
    """Write the part of the layout between ``x_range`` (pixels) as a PNG, atomically."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon, Rectangle

    from ..atomic import atomic_path

    # Layout units are pixels at 100 per inch; `dpi` only scales the raster.
    pt = 72.0 / 100.0
    xa, xb = x_range
    fig = Figure(figsize=((xb - xa) / 100.0, lay.height / 100.0), dpi=dpi)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(xa, xb)

    def inside(x: float) -> bool:
        return xa <= x < xb

    # only what lies on the page is drawn (a long staff has many pages)
    lay = StaffLayout(
        width=lay.width,
        height=lay.height,
        staves=lay.staves,
        glyphs=[g for g in lay.glyphs if inside(g.centre[0])],
        lines=[ln for ln in lay.lines if max(ln[0], ln[2]) >= xa and min(ln[0], ln[2]) < xb],
        texts=[t for t in lay.texts if inside(t[0])]
        + [((xa + xb) / 2, y, t, size, "middle") for y, t, size in lay.heading],
        fronts=[f for f in lay.fronts if inside(f.centre[0])],
    )
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
            ink = UNCERTAIN_GREY if s.uncertain else "black"
            face = {"high": "white", "middle": "white", "low": ink, None: "white"}[s.level]
            for piece in g.pieces:
                ax.add_patch(
                    Polygon(
                        piece,
                        closed=True,
                        facecolor=face,
                        edgecolor=ink,
                        lw=1.5 * pt,
                        hatch="////" if s.level == "high" else None,
                        linestyle=(0, UNCERTAIN_DASH) if s.uncertain else "solid",
                    )
                )
            if s.level == "middle":
                ax.add_patch(Circle(g.centre, g.dot_radius, color=ink))
            if g.pin is not None:
                tx, ty = _pin_end(g.centre[0], g.centre[1], g.pin, 2.2 * g.dot_radius)
                ax.plot([g.centre[0], tx], [g.centre[1], ty], color="black", lw=1.4 * pt)
                ax.add_patch(Circle((tx, ty), 1.8, color="black"))
            if g.label:
                cx, cy = g.foot if s.is_turn else g.centre
                ax.text(
                    cx,
                    cy + (-4.0 if s.is_turn else 3.0),
                    g.label,
                    fontsize=9 * pt,
                    ha="center",
                    va="baseline",
                    style="italic" if s.is_air else "normal",
                    parse_math=False,
                )
            if s.bend:
                bx, by = g.foot[0], g.foot[1] - 3
                ax.add_patch(Rectangle((bx - 9, by - 11), 18, 12, facecolor="white", edgecolor="black", lw=0.5))
                ax.text(bx, by - 1.5, f"\u00d7{s.bend}", fontsize=10 * pt, ha="center", va="baseline")
        for f in lay.fronts:
            cx, cy = f.centre
            h = f.size / 2
            ax.add_patch(Rectangle((cx - h, cy - h), f.size, f.size, facecolor="white", edgecolor="black", lw=0.7))
            tx, ty = _pin_end(cx, cy, f.pin, 0.8 * h)
            ax.plot([cx, tx], [cy, ty], color="black", lw=1.6 * pt)
            ax.add_patch(Circle((tx, ty), 2.0, color="black"))
            ax.text(cx, cy + h + 9, f.room, fontsize=7 * pt, ha="center", va="baseline", parse_math=False)
        with atomic_path(path, suffix=".png") as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)


#: Staves on one PNG page: a long clip's staff is drawn page by page, so the
#: raster (4 bytes a pixel) stays about 30 MB whatever the clip's length.
PAGE_STAVES = 8


def png_pages(path, n_pages: int) -> list:
    """The PNG files of a staff of `n_pages` pages: `path`, then ``STEM-2.png``, ``STEM-3.png``, …"""
    path = Path(path)
    return [path] + [path.with_name(f"{path.stem}-{k}{path.suffix}") for k in range(2, n_pages + 1)]


def render_png(lay: StaffLayout, path, dpi: int) -> list:
    """Write the layout as PNG pages of :data:`PAGE_STAVES` staves (layout pixels at 100 dpi, scaled by ``dpi / 100``).

    Returns
    -------
    list of Path
        The pages written (atomically), in order (:func:`png_pages`).
    """
    staves = lay.staves or []
    groups = [staves[i : i + PAGE_STAVES] for i in range(0, len(staves), PAGE_STAVES)] or [[]]
    paths = png_pages(path, len(groups))
    for k, (group, out) in enumerate(zip(groups, paths)):
        # a page runs from halfway across the gap before its first staff to
        # halfway across the gap after its last (the whole width on one page)
        xa = 0.0 if k == 0 else 0.5 * (staves[k * PAGE_STAVES - 1].x_right + group[0].x_left)
        last = (k + 1) * PAGE_STAVES
        xb = lay.width if last >= len(staves) else 0.5 * (group[-1].x_right + staves[last].x_left)
        _render_page(lay, out, dpi, (xa, xb))
    return paths
