"""A small HTML report builder shared by the score and fidelity-study reports.

Plots are matplotlib figures saved as PNG files in a ``plots/`` folder beside
the report (or embedded as data URIs), tables are lists of rows, and every
piece of text is escaped.  The page has no scripts and no external
resources, so it opens offline in any browser.
"""

from __future__ import annotations

import base64
import html
import io
import math
import re
from pathlib import Path

from capture2notation.atomic import atomic_path, write_text
from capture2notation.errors import PipelineError

__all__ = ["Report", "escape", "format_value"]

_CSS = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{font-size:1.3em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}
th{background:#f3f3f3}td:first-child,th:first-child{text-align:left}
figure{margin:1em 0;display:inline-block;vertical-align:top}
figcaption{font-size:.85em;color:#555;max-width:640px}
img{max-width:100%;height:auto;border:1px solid #eee}
.note{background:#fff8e1;border-left:4px solid #f0b400;padding:.5em 1em}
.summary li{margin:.3em 0}
"""


def escape(text) -> str:
    """HTML-escape any value's string form (quotes included)."""
    return html.escape(str(text), quote=True)


def format_value(v, digits: int = 3) -> str:
    """Readable cell text: floats to `digits` significant places, NaN as '–'."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if math.isnan(v):
            return "–"
        if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
            return f"{v:.{digits}g}"
        return f"{v:.{digits}g}" if abs(v) < 1 else f"{v:.{max(digits - 1, 1)}f}".rstrip("0").rstrip(".")
    return str(v)


class Report:
    """An HTML page assembled section by section.

    Parameters
    ----------
    title : str
        Page title and first heading.
    outdir : str or Path
        Folder of the report; plots go to ``outdir/plots/``.
    embed : bool
        Embed plots as data URIs instead of writing PNG files.
    """

    def __init__(self, title: str, outdir, embed: bool = False):
        self.title = title
        self.outdir = Path(outdir)
        self.embed = embed
        self._parts: list[str] = [f"<h1>{escape(title)}</h1>"]
        self._names: set[str] = set()

    def heading(self, text: str, level: int = 2) -> None:
        level = min(max(int(level), 2), 4)
        self._parts.append(f"<h{level}>{escape(text)}</h{level}>")

    def paragraph(self, text: str, css_class: str | None = None) -> None:
        cls = f' class="{escape(css_class)}"' if css_class else ""
        self._parts.append(f"<p{cls}>{escape(text)}</p>")

    def bullets(self, items, css_class: str | None = None) -> None:
        cls = f' class="{escape(css_class)}"' if css_class else ""
        lis = "".join(f"<li>{escape(i)}</li>" for i in items)
        self._parts.append(f"<ul{cls}>{lis}</ul>")

    def table(self, rows, columns, caption: str | None = None, digits: int = 3) -> None:
        """A table of `rows` (sequences or dicts keyed by `columns`)."""
        head = "".join(f"<th>{escape(c)}</th>" for c in columns)
        body = []
        for r in rows:
            cells = [r.get(c, "") for c in columns] if isinstance(r, dict) else list(r)
            body.append("<tr>" + "".join(f"<td>{escape(format_value(v, digits))}</td>" for v in cells) + "</tr>")
        cap = f"<caption>{escape(caption)}</caption>" if caption else ""
        self._parts.append(f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>")

    def figure(self, fig, name: str, caption: str = "", alt: str | None = None) -> str:
        """Add a matplotlib figure; return the image's ``src``.

        Parameters
        ----------
        fig : matplotlib.figure.Figure
            Closed after saving.
        name : str
            File stem (letters, digits, ``_-``), unique within the report.
        caption, alt : str
        """
        import matplotlib.pyplot as plt

        if not re.fullmatch(r"[A-Za-z0-9_\-]+", name):
            raise PipelineError(f"plot name {name!r} must use letters, digits, '_' or '-' only")
        if name in self._names:
            raise PipelineError(f"plot name {name!r} is used twice in one report")
        self._names.add(name)
        try:
            if self.embed:
                buf = io.BytesIO()
                fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
                src = "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
            else:
                target = self.outdir / "plots" / f"{name}.png"
                with atomic_path(target) as tmp:
                    fig.savefig(tmp, format="png", dpi=90, bbox_inches="tight")
                src = f"plots/{name}.png"
        finally:
            plt.close(fig)
        self._parts.append(
            f'<figure><img src="{escape(src)}" alt="{escape(alt or caption or name)}">'
            f"<figcaption>{escape(caption)}</figcaption></figure>"
        )
        return src

    def raw(self, fragment: str) -> None:
        """Append trusted HTML produced by this module's callers (never user text)."""
        self._parts.append(fragment)

    def html(self) -> str:
        return (
            '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{escape(self.title)}</title><style>{_CSS}</style></head><body>\n"
            + "\n".join(self._parts)
            + "\n</body></html>\n"
        )

    def write(self, name: str = "report.html") -> Path:
        """Write the page atomically to ``outdir/name``; return its path."""
        return write_text(self.outdir / name, self.html())
