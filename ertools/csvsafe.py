"""CSV cells a spreadsheet opens as text, never as a formula.

Excel, LibreOffice and Google Sheets evaluate a cell that begins with ``=``, ``+``, ``-`` or
``@`` (and, in some, a tab or carriage return) as a formula: a team named
``=HYPERLINK("http://...")`` would become a link in every organiser's sheet (OWASP "CSV
injection"). Such text gets a leading apostrophe, which spreadsheets show as text (an option
list ``--team x`` too: a spreadsheet would read it as a formula). Numbers are left alone,
written from a float (``-0.5``) or as text (``"-0.5"``): a spreadsheet reads them as numbers.
"""

from __future__ import annotations

import math
from typing import Any

_FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def spreadsheet_safe(value: Any) -> Any:
    """``value`` as a CSV cell: text beginning like a formula prefixed with ``'``."""
    if isinstance(value, str) and value.startswith(_FORMULA_STARTS) and not _number(value):
        return "'" + value
    return value


def _number(text: str) -> bool:
    try:
        return math.isfinite(float(text)) and text.strip() == text
    except ValueError:
        return False
