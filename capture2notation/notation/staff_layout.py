"""The geometry of the Labanotation staff (pure: no drawing).

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
  symbol's foot;
* turns (DESIGN.md, "Facing and turns") are turn signs in the support
  column of the foot they turn on (across both support columns on both
  feet or in the air, as in Hutchinson Guest): a parallelogram whose ends
  slant down towards the turn's direction (right: clockwise), with a pin
  inside pointing the amount turned (up = none, right = a quarter turn
  clockwise …) and the amount written beside it; a support symbol at the
  same time keeps the outer half of the column, the turn the inner half;
* after each turn a **front sign** beside the staff (left of the left
  support column) shows the new room direction: a square with a pin
  pointing the way the dancer now faces (up = the starting front), its
  name written under it;
* flight (``support air``) is a gap in the support columns, marked at both
  ends by a short stroke, with its spring form (jump, hop, leap, assemblé,
  sissonne) written in the gap.

The geometry is computed once (:func:`staff_layout`, pure) and drawn by two
thin back ends (:mod:`capture2notation.notation.staff_draw`): hand-written
SVG (one ``<g class="symbol">`` per symbol, with ``data-start``/
``data-duration`` in beats, one ``<g class="front-sign">`` per front sign)
and a matplotlib PNG.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ..errors import NotationError
from .facing import Intervals, SupportIndex, front_changes, room_direction, springs
from .model import Score, Symbol

__all__ = [
    "FrontSign",
    "Glyph",
    "StaffLayout",
    "StaffSpan",
    "staff_layout",
    "symbol_outline",
    "turn_outline",
]

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
    label : str
        Text drawn with the symbol: a turn's amount, a flight's spring form
        (empty otherwise).
    pin : float or None
        A turn's pin, degrees clockwise from up (the amount turned).
    """

    index: int
    symbol: Symbol
    pieces: tuple
    centre: tuple
    foot: tuple
    dot_radius: float
    label: str = ""
    pin: float | None = None


@dataclass(frozen=True)
class FrontSign:
    """The room direction faced after a turn, drawn beside the staff.

    Attributes
    ----------
    centre : tuple of float
        Pixel centre of the sign.
    size : float
        Side of its square, pixels.
    front : Fraction
        Full turns clockwise from the starting front (unwrapped).
    room : str
        Room direction faced (:data:`~capture2notation.notation.facing.ROOM_DIRECTIONS`).
    """

    centre: tuple
    size: float
    front: Fraction
    room: str

    @property
    def pin(self) -> float:
        """Degrees clockwise from up of the pin (the room direction)."""
        return float(self.front % 1) * 360.0


@dataclass(frozen=True)
class StaffSpan:
    """Where one staff's beats lie on the page: beat ``b`` of it is at ``y = y_first - (b - first) * beat_height``.

    Attributes
    ----------
    first, last : Fraction
        The staff's first and last beat (its bottom and top).
    x_left, x_right : float
        The staff's outer column edges, pixels.
    y_first : float
        Pixel y of beat `first` (y grows downwards: later beats are higher).
    beat_height : float
        Pixels per beat.
    """

    first: Fraction
    last: Fraction
    x_left: float
    x_right: float
    y_first: float
    beat_height: float

    def y(self, beat) -> float:
        """Pixel y of `beat` on this staff (not clipped to it)."""
        return self.y_first - float(Fraction(beat) - self.first) * self.beat_height


@dataclass
class StaffLayout:
    """Everything to draw, in pixels (x right, y down); `staves` maps beats to positions."""

    width: float
    height: float
    staves: list = field(default_factory=list)  # StaffSpan, left to right
    glyphs: list = field(default_factory=list)
    lines: list = field(default_factory=list)  # (x0, y0, x1, y1, stroke width)
    texts: list = field(default_factory=list)  # (x, y, text, size, anchor)
    fronts: list = field(default_factory=list)  # FrontSign
    heading: list = field(default_factory=list)  # (y, text, size): centred across the page


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


def turn_outline(direction: str, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Outline of a turn sign in a box: a parallelogram slanting to the turn's direction.

    Parameters
    ----------
    direction : {'right', 'left'}
    x0, x1, y0, y1 : float
        As for :func:`symbol_outline` (``y0 > y1``).

    Returns
    -------
    (4, 2) ndarray
        The bottom and top edges run down towards `direction` (a right turn's
        right corners are the lower ones).
    """
    h = y0 - y1
    c = min(h / 4.0, 0.5 * (x1 - x0))
    if direction == "right":
        return np.asarray([(x0, y0 - c), (x1, y0), (x1, y1 + c), (x0, y1)], dtype=float)
    if direction == "left":
        return np.asarray([(x0, y0), (x1, y0 - c), (x1, y1), (x0, y1 + c)], dtype=float)
    raise NotationError(f"no turn sign for direction {direction!r}; expected right or left")


def _support_box(s: Symbol, feet: frozenset, column_width: float, pad: float) -> tuple[float, float]:
    """x range (from the centre line) of a support or turn symbol; a turn's by the `feet` it turns on."""
    if s.is_turn:
        if feet == {"right"}:
            return pad, column_width - pad
        if feet == {"left"}:
            return -column_width + pad, -pad
        return -column_width + pad, column_width - pad
    if s.part == "support":
        return -column_width + pad, column_width - pad
    k = 1 if s.part == "right_support" else -1
    lo = (k - 1 if k > 0 else k) * column_width
    return lo + pad, lo + column_width - pad


def _share(box: tuple[float, float], inner: bool) -> tuple[float, float]:
    """The inner (towards the centre line) or outer half of a box; a box across the centre halves in height."""
    x0, x1 = box
    if x0 < 0 < x1:  # across both columns: the turn takes the middle, the support the sides
        q = (x1 - x0) / 4
        return (x0 + q, x1 - q) if inner else (x0, x1)
    xm = 0.5 * (x0 + x1)
    near_centre = (x0, xm) if x0 >= 0 else (xm, x1)
    far = (xm, x1) if x0 >= 0 else (x0, xm)
    return near_centre if inner else far


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
        edges = (cx - n_left * column_width, cx + n_right * column_width)
        lay.staves.append(StaffSpan(Fraction(b0), Fraction(b1), *edges, y(b0, j), beat_height))
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
    lay.heading.append((24, score.title or "untitled", 15))
    sub = f"\u2669 = {score.tempo}   meter {score.meter}"
    if score.emotion:
        sub += f"   {score.emotion}"
    elif score.effort is not None:
        e = score.effort
        sub += f"   effort b={e.time:g} x0={e.weight:g} S={e.space:g}"
    lay.heading.append((46, sub, 11))

    pad = _PAD * column_width
    # Indexed once: which feet a turn is on, what overlaps what (no pairwise scans).
    index = SupportIndex(score)
    forms = {a.start: form for a, form in springs(score)}
    air_spans = Intervals((a.start, a.end) for a in score.symbols if a.is_air)
    turn_spans = Intervals((t.start, t.end) for t in score.symbols if t.is_turn)
    support_spans = Intervals((u.start, u.end) for u in score.symbols if u.is_support and not u.is_air)
    for i, s in enumerate(score.symbols):
        # Outline in continuous coordinates (x from the centre line, y = −beats·px),
        # then cut at the staff breaks and moved onto each staff.
        label, pin = "", None
        if s.is_turn or s.is_support:
            in_air = s.is_turn and air_spans.overlaps(s.start, s.end)
            feet = frozenset({"right", "left"}) if in_air or not s.is_turn else index.before(s.end)
            x0, x1 = _support_box(s, feet, column_width, pad)
            side = "right" if x1 > 0 else "left"
            if s.is_turn and support_spans.overlaps(s.start, s.end):
                x0, x1 = _share((x0, x1), inner=True)
            elif s.is_support and not s.is_air and turn_spans.overlaps(s.start, s.end):
                x0, x1 = _share((x0, x1), inner=False)
        else:
            k = cols[s.part]
            lo = (k - 1 if k > 0 else k) * column_width
            x0, x1, side = lo + pad, lo + column_width - pad, "right" if k > 0 else "left"
        yv0, yv1 = -float(s.start) * beat_height, -float(s.end) * beat_height
        if s.is_turn:
            outline = turn_outline(s.direction, x0, yv0, x1, yv1)
            label = f"{'R' if s.direction == 'right' else 'L'} {s.amount}"
            pin = float(s.signed_amount % 1) * 360.0
        elif s.is_air:
            outline = np.empty((0, 2))
            label = forms[s.start] or "air"
        else:
            outline = symbol_outline(s.direction, x0, yv0, x1, yv1, side)
        j0 = min(int(s.start // staff_beats), n_staves - 1)
        j1 = min(int((s.end - Fraction(1, 10**9)) // staff_beats), n_staves - 1)
        pieces = []
        for j in range(j0, j1 + 1) if len(outline) else ():
            band_lo = -float(min(s.end, (j + 1) * staff_beats)) * beat_height
            band_hi = -float(max(s.start, j * staff_beats)) * beat_height
            piece = _clip_band(outline, band_lo, band_hi) if j0 != j1 else outline
            pieces.append(piece + [centre(j), base + j * staff_beats * beat_height])
        mid = (s.start + s.end) / 2
        jm = min(int(mid // staff_beats), n_staves - 1)
        dot = (centre(jm) + (x0 + x1) / 2, y(mid, jm))
        foot = (centre(j0) + (x0 + x1) / 2, y(s.start, j0))
        lay.glyphs.append(Glyph(i, s, tuple(pieces), dot, foot, 0.1 * column_width, label, pin))
        if s.is_air:
            # The gap's ends: short strokes across the support columns.
            for b in (s.start, s.end):
                jb = min(int(b // staff_beats), n_staves - 1)
                if b == s.end and b % staff_beats == 0 and b > 0:
                    jb = min(int(b // staff_beats) - 1, n_staves - 1)
                cx = centre(jb)
                lay.lines.append((cx - 0.7 * column_width, y(b, jb), cx + 0.7 * column_width, y(b, jb), 0.8))
    size = 0.7 * column_width
    for t, front in front_changes(score):
        j = min(int(t.end // staff_beats), n_staves - 1)
        if t.end % staff_beats == 0 and t.end > 0:
            j = min(int(t.end // staff_beats) - 1, n_staves - 1)
        cx = centre(j) - n_left * column_width - 0.5 * size - 6
        lay.fronts.append(FrontSign((cx, y(t.end, j) - 0.5 * size - 2), size, front, room_direction(front)))
    return lay
