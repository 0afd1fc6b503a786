"""HTML building blocks for the report pages: escaped text, tables, a page with inline CSS.

Everything that comes from a bag, a config or a command line (payloads, topic names, file
names, parameter values) goes through :func:`esc`; nothing from a bag is ever rendered as raw
HTML or executed. The pages load nothing from the network: the CSS is inline and images are
files beside the page (relative links) or data URIs.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from typing import Any

CSS = """
:root { --fg:#1d2430; --muted:#5b6675; --line:#d9dee5; --bg:#f6f8fa; --accent:#2458a6;
        --bad:#b42318; --warn:#a15c07; --good:#1b7f3b; }
* { box-sizing: border-box; }
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color: var(--fg); margin: 0; background: #fff; }
header { background: #14233c; color: #fff; padding: 18px 32px; }
header h1 { margin: 0 0 4px; font-size: 22px; font-weight: 600; }
header p { margin: 0; color: #c7d2e3; font-size: 13px; }
nav { padding: 8px 32px; background: var(--bg); border-bottom: 1px solid var(--line);
      font-size: 13px; }
nav a { margin-right: 14px; color: var(--accent); text-decoration: none; }
main { padding: 8px 32px 40px; max-width: 1200px; }
h2 { font-size: 18px; margin: 28px 0 10px; padding-bottom: 4px;
     border-bottom: 2px solid var(--line); }
h3 { font-size: 15px; margin: 18px 0 8px; color: #27364d; }
table { border-collapse: collapse; margin: 6px 0 12px; font-size: 13px; }
caption { text-align: left; font-weight: 600; padding: 4px 0; color: var(--muted); }
th, td { border: 1px solid var(--line); padding: 4px 8px; vertical-align: top;
         text-align: left; }
th { background: var(--bg); font-weight: 600; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr:nth-child(even) td { background: #fbfcfd; }
.wrap { overflow-x: auto; max-width: 100%; }
pre { background: var(--bg); border: 1px solid var(--line); padding: 10px; overflow-x: auto;
      font-size: 12px; max-height: 420px; }
code { font-size: 12px; }
td pre { margin: 0; padding: 4px; max-height: 160px; }
.badge { display: inline-block; padding: 1px 8px; border-radius: 10px; font-size: 12px;
         font-weight: 600; margin-right: 6px; }
.ok { background: #e3f4e8; color: var(--good); }
.warn { background: #fdf1dc; color: var(--warn); }
.bad { background: #fde4e1; color: var(--bad); }
.muted { color: var(--muted); font-size: 13px; }
ul.notes li { margin: 3px 0; }
.figs { display: grid; grid-template-columns: repeat(auto-fill, minmax(440px, 1fr));
        gap: 16px; }
figure { margin: 0; }
figure img { width: 100%; border: 1px solid var(--line); }
figure.wide { grid-column: 1 / -1; }
figcaption { font-size: 13px; color: var(--muted); }
dl { display: grid; grid-template-columns: max-content auto; gap: 2px 16px; font-size: 13px; }
dt { font-weight: 600; } dd { margin: 0; word-break: break-all; }
tr.differs td { background: #fff6e5; }
details { margin: 8px 0; } summary { cursor: pointer; padding: 4px 0; }
td.long { min-width: 320px; max-width: 640px; }
tr.same td.status { color: var(--good); }
"""


def esc(value: Any) -> str:
    """Text safe to place in HTML element content and attribute values."""
    return html.escape("" if value is None else str(value), quote=True)


def fmt(value: Any) -> str:
    """A cell's text: floats with 6 significant digits, NaN/None as an em dash."""
    if value is None:
        return "\u2014"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if math.isnan(value):
            return "\u2014"
        return f"{value:.6g}"
    return str(value)


def _is_num(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def table(
    rows: Sequence[dict[str, Any]],
    *,
    columns: Sequence[str] | None = None,
    caption: str | None = None,
    max_rows: int | None = None,
    row_class: str | None = None,
    long_text: int = 80,
) -> str:
    """An HTML table of ``rows`` (dicts); columns are the union of their keys in order.

    Args:
        rows: the data.
        columns: which columns, in which order (default: every key).
        caption: a caption above the table.
        max_rows: show at most this many rows and say how many were left out.
        row_class: a column whose (escaped) value becomes the row's CSS class.
        long_text: texts longer than this get a wide wrapping cell; multi-line texts a
            <pre> block.
    """
    if columns is None:
        columns = list(dict.fromkeys(k for row in rows for k in row))
    shown = rows if max_rows is None else rows[:max_rows]
    out = ['<div class="wrap"><table>']
    if caption:
        out.append(f"<caption>{esc(caption)}</caption>")
    out.append("<thead><tr>" + "".join(f"<th>{esc(c)}</th>" for c in columns) + "</tr></thead>")
    out.append("<tbody>")
    for row in shown:
        cls = f' class="{esc(row.get(row_class, ""))}"' if row_class else ""
        cells = []
        for col in columns:
            value = row.get(col)
            text = fmt(value)
            css = ["num"] if _is_num(value) else []
            if col == "status":
                css.append("status")
            attr = f' class="{" ".join(css)}"' if css else ""
            if "\n" in text:
                cells.append(f"<td{attr}><pre>{esc(text)}</pre></td>")
            elif len(text) > long_text:
                cells.append(f'<td class="long">{esc(text)}</td>')
            else:
                cells.append(f"<td{attr}>{esc(text)}</td>")
        out.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    out.append("</tbody></table></div>")
    if max_rows is not None and len(rows) > max_rows:
        out.append(f'<p class="muted">{len(rows) - max_rows} more row(s) in the CSV file.</p>')
    return "".join(out)


def pre(text: str) -> str:
    return f"<pre>{esc(text)}</pre>"


def notes(items: Iterable[str], css: str = "notes") -> str:
    lines = [f"<li>{esc(i)}</li>" for i in items]
    return f'<ul class="{esc(css)}">' + "".join(lines) + "</ul>" if lines else ""


def definitions(pairs: Iterable[tuple[str, Any]]) -> str:
    items = [f"<dt>{esc(k)}</dt><dd>{esc(fmt(v))}</dd>" for k, v in pairs]
    return "<dl>" + "".join(items) + "</dl>"


def badge(text: str, level: str) -> str:
    """A coloured label; level is ``ok``, ``warn`` or ``bad``."""
    return f'<span class="badge {esc(level)}">{esc(text)}</span>'


def figure(src: str, caption: str, *, wide: bool = False) -> str:
    """An image beside the page (relative path) or a data URI, with its caption.

    Figures go in a :func:`figures` grid; ``wide`` ones (timelines) span its width.
    """
    cls = ' class="wide"' if wide else ""
    return (
        f'<figure{cls}><img src="{esc(src)}" alt="{esc(caption)}" loading="eager">'
        f"<figcaption>{esc(caption)}</figcaption></figure>"
    )


def figures(items: Iterable[str]) -> str:
    """A responsive grid of :func:`figure` elements."""
    return '<div class="figs">' + "".join(items) + "</div>"


def link(href: str, text: str) -> str:
    return f'<a href="{esc(href)}">{esc(text)}</a>'


def section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{esc(anchor)}"><h2>{esc(title)}</h2>{body}</section>'


def page(title: str, subtitle: str, sections: Sequence[tuple[str, str, str]]) -> str:
    """A whole document: header, a navigation bar and the (anchor, title, body) sections.

    ``body`` strings must already be built from the escaping helpers of this module.
    """
    nav = "".join(f'<a href="#{esc(a)}">{esc(t)}</a>' for a, t, _ in sections)
    body = "".join(section(a, t, b) for a, t, b in sections)
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        # No script, no remote resource: a page a referee can open offline and trust.
        '<meta http-equiv="Content-Security-Policy" '
        "content=\"default-src 'none'; img-src 'self' data: file:; style-src 'unsafe-inline'\">"
        f"<title>{esc(title)}</title><style>{CSS}</style></head><body>"
        f"<header><h1>{esc(title)}</h1><p>{esc(subtitle)}</p></header>"
        f"<nav>{nav}</nav><main>{body}</main></body></html>\n"
    )
