"""The report pages' data and their rendering through the Jinja2 templates beside this module.

The markup lives in ``templates/*.html.j2`` (``report.html.j2``, ``combined.html.j2``, their
``base.html.j2`` and ``macros.html.j2``); this module turns results into what the templates
show (tables of display-unit cells) and renders them. Autoescaping is on for every template:
payloads, topic names, file names and parameter values from bags, configs or a command line
are always text, never markup. The pages load nothing from the network: the CSS is inline and
images are files beside the page (relative links) or data URIs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import cache
from pathlib import PurePosixPath
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import iso_utc, s_to_ns
from ertools.views import units

if TYPE_CHECKING:
    import jinja2


def relative_href(path: str | None) -> str | None:
    """``path`` as a link that can only be a relative file path, or None (nothing, or an
    absolute path). Every segment is percent-encoded: a folder named ``javascript:alert(1)``
    would otherwise be read by the browser as a URL scheme, not a folder."""
    if not path:
        return None
    pure = PurePosixPath(path.replace("\\", "/"))
    if pure.is_absolute() or (pure.parts[:1] and ":" in pure.parts[0] and len(pure.parts[0]) == 2):
        return None  # /etc/x, C:/x: not relative to the page
    return "/".join(quote(part, safe="") for part in pure.parts)


def fmt(value: Any, quantity: str | None = None) -> str:
    """A cell's text: a float of a ``quantity`` (already in its display unit) at the decimals
    its data resolves (:func:`ertools.views.units.fixed`), other floats with 6 significant
    digits, NaN/None as an em dash."""
    if value is None:
        return "\u2014"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if math.isnan(value):
            return "\u2014"
        if quantity is not None:
            return units.fixed(value, quantity)
        return f"{value:.6g}"
    return str(value)


def _utc(seconds: float) -> str:
    return iso_utc(s_to_ns(seconds)).replace("+00:00", "Z")


@frozen_dataclass
class Cell:
    text: str
    css: str = ""
    pre: bool = False  # multi-line text, shown in a <pre> block


@frozen_dataclass
class Row:
    cells: tuple[Cell, ...]
    css: str | None = None


@frozen_dataclass
class Table:
    """A table as the ``table`` macro draws it: headers with units, formatted cells."""

    columns: tuple[str, ...]
    rows: tuple[Row, ...]
    caption: str | None = None
    more: int = 0  # rows left out (they are in the CSV)


def table(
    rows: Sequence[dict[str, Any]],
    *,
    columns: Sequence[str] | None = None,
    caption: str | None = None,
    max_rows: int | None = None,
    row_class: str | None = None,
    long_text: int = 80,
) -> Table:
    """A table of ``rows`` (dicts); columns are the union of their keys in order.

    Numbers of a known quantity (:mod:`ertools.views.units`) are converted to their display
    unit and the header names it: ``distance_error`` in metres becomes ``distance_error (mm)``.

    Args:
        rows: the data, in the units the results store.
        columns: which columns, in which order (default: every key).
        caption: a caption above the table.
        max_rows: show at most this many rows and say how many were left out.
        row_class: a column whose value becomes the row's CSS class.
        long_text: texts longer than this get a wide wrapping cell; multi-line texts a
            <pre> block.
    """
    if columns is None:
        columns = list(dict.fromkeys(k for row in rows for k in row))
    shown = rows if max_rows is None else rows[:max_rows]
    # A unit only where the column holds numbers (fbm1's ``error`` is a message, not metres).
    numeric = {c for c in columns if any(units.is_number(r.get(c)) for r in rows)}
    # Instants (epoch seconds, e.g. the trajectory's ``t``) read as UTC times, not 1.448e+09.
    epoch = {c for c in numeric if units.is_epoch(c, [r.get(c) for r in rows])}
    headers = tuple(
        f"{c} (UTC)" if c in epoch else units.header(c) if c in numeric else c for c in columns
    )
    quantities = {c: _quantity(c) for c in numeric}
    out: list[Row] = []
    for row in shown:
        cells = []
        for col in columns:
            value = units.display(col, row.get(col))
            if col in epoch and units.is_number(value):
                text = _utc(value)
            else:
                text = fmt(value, quantities.get(col))
            cells.append(_cell(text, units.is_number(value), long_text, status=col == "status"))
        out.append(Row(tuple(cells), fmt(row.get(row_class, "")) if row_class else None))
    more = len(rows) - max_rows if max_rows is not None and len(rows) > max_rows else 0
    return Table(headers, tuple(out), caption, more)


def _quantity(name: str) -> str | None:
    spec = units.quantity_of(name)
    return spec[0] if spec else None


def _cell(text: str, number: bool, long_text: int, *, status: bool = False) -> Cell:
    css = " ".join([*(["num"] if number else []), *(["status"] if status else [])])
    if "\n" in text:
        return Cell(text, css, pre=True)
    if len(text) > long_text:
        return Cell(text, "long")
    return Cell(text, css)


def key_values(pairs: Sequence[tuple[str, Any]], *, caption: str | None = None) -> Table:
    """A two-column (metric, value) table; each metric's name carries its unit and its value
    the decimals of its quantity."""
    rows = []
    for key, value in pairs:
        number = units.is_number(value)
        name = units.header(key) if number else key
        text = fmt(units.display(key, value), _quantity(key) if number else None)
        rows.append(Row((_cell(name, False, 80), _cell(text, number, 80))))
    return Table(("metric", "value"), tuple(rows), caption)


@frozen_dataclass
class Figure:
    src: str  # relative path beside the page, or a data URI
    caption: str
    wide: bool = False  # spans the figure grid (timelines)


@cache
def environment() -> jinja2.Environment:
    """The templates' environment: autoescaping on, undefined names are errors."""
    import jinja2  # lazy: Jinja2, 170 ms

    return jinja2.Environment(
        loader=jinja2.PackageLoader("ertools.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )


def render(template: str, **context: Any) -> str:
    """A page from one of the templates (``report.html.j2``, ``combined.html.j2``)."""
    return environment().get_template(template).render(**context)
