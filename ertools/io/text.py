"""Text trajectories as pose sources: TUM, KITTI, EuRoC ground-truth CSV and ertools' own CSV
export, detected by content (:func:`sniff`) and read into a :class:`PoseStream`
(:func:`read_text_poses`).

The layouts are evo's (``evo_ape tum|kitti|euroc``):

- ``tum``: ``t x y z qx qy qz qw``, space separated, ``#`` comments.
- ``kitti``: 12 numbers a row, the 3x4 ``[R|t]`` row-major, no time: rows are paired by index.
  The stream's stamps are the row numbers in seconds (0, 1, 2, ...).
- ``euroc``: ``#timestamp [ns], p_RS_R_x, p_RS_R_y, p_RS_R_z, q_RS_w, q_RS_x, q_RS_y, q_RS_z,
  ...`` (comma separated, at least 8 columns, the quaternion scalar first).
- ``csv``: ertools' export (``t_ns,t_s,x,y,z,qx,qy,qz,qw,frame_id``), read back exactly.

Times are kept exactly: a decimal stamp becomes int64 nanoseconds by integer arithmetic
(rounded half to even past the 9th decimal), and the floats evo parses from the same text
are kept beside them (:attr:`PoseStream.t_s`) so that evo's association can be reproduced.
A bad value is one line naming its row (the file's line number) and column.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import NoReturn

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64
from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import open_regular, read_regular_text, why_not
from ertools.io.names import TEXT_FORMATS, TextFormat
from ertools.streams import PoseStream

CSV_HEADER = "t_ns,t_s,x,y,z,qx,qy,qz,qw,frame_id"
# How many bytes the sniffer reads: a few comment lines and the first data row.
_SNIFF_BYTES = 8192
_NS = 1_000_000_000
_COLUMNS: dict[TextFormat, tuple[str, ...]] = {
    "tum": ("t", "x", "y", "z", "qx", "qy", "qz", "qw"),
    "kitti": ("r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz"),
    "euroc": ("timestamp", "p_x", "p_y", "p_z", "q_w", "q_x", "q_y", "q_z"),
    "csv": ("t_ns", "t_s", "x", "y", "z", "qx", "qy", "qz", "qw", "frame_id"),
}


@frozen_dataclass
class _Rows:
    """The data rows of a text file (stripped) and their 1-based line numbers."""

    text: list[str]
    lines: list[int]
    fmt: TextFormat

    def cells(self, r: int) -> list[str]:
        """Row ``r`` split into its cells (errors only: the reads below never split rows)."""
        if self.fmt in ("tum", "kitti"):
            return self.text[r].split()
        return self.text[r].split(",", len(_COLUMNS[self.fmt]) - 1)


def _bag_magic(head: bytes) -> bool:
    return head.startswith((b"#ROSBAG V", b"\x89MCAP"))


def sniff(path: str | Path) -> TextFormat | None:
    """The text layout of ``path`` from its first data row, None for a bag (or a folder).

    Raises:
        BagError: a text file that is none of the layouts (it says what its first row holds).
    """
    p = Path(path)
    if not p.is_file():
        return None
    try:
        with open_regular(p) as f:
            head = f.read(_SNIFF_BYTES)
    except OSError:
        return None  # the bag reader says why
    if not head or _bag_magic(head) or b"\x00" in head:
        return None
    try:
        text = head.decode("utf-8-sig")
    except UnicodeDecodeError:
        return None
    lines = text.splitlines()
    if len(head) == _SNIFF_BYTES and len(lines) > 1:
        lines = lines[:-1]  # the last one may be cut
    first_comment = next((ln.strip() for ln in lines if ln.strip().startswith("#")), "")
    data = next((ln.strip() for ln in lines if ln.strip() and not ln.strip().startswith("#")), "")
    if data.startswith(CSV_HEADER) or first_comment.startswith(CSV_HEADER):
        return "csv"
    if first_comment.lower().startswith("#timestamp") and "," in first_comment:
        return "euroc"
    if not data:
        raise BagError("a text file with no data row: not a bag, TUM, KITTI or EuRoC file", path=p)
    if "," in data:
        if len(data.split(",")) >= 8:
            return "euroc"
    else:
        n = len(data.split())
        if n == 8:
            return "tum"
        if n == 12:
            return "kitti"
    fields = len(data.split(",")) if "," in data else len(data.split())
    raise BagError(
        f"not a bag, and its first data row ({fields} field(s)) is no TUM (8 numbers), KITTI "
        "(12) or EuRoC (8+ comma-separated) row; give --input-format to say which",
        path=p,
    )


def _rows(path: Path, fmt: TextFormat) -> _Rows:
    try:
        text = read_regular_text(path, "utf-8-sig")
    except UnicodeDecodeError as err:
        raise BagError(f"not a {fmt.upper()} text file (not UTF-8 text)", path=path) from err
    except OSError as err:
        raise BagError(f"cannot read: {why_not(err)}", path=path) from err
    stripped = [ln.strip() for ln in text.splitlines()]
    header = fmt == "csv"
    keep = [
        i
        for i, ln in enumerate(stripped)
        if ln and not ln.startswith("#") and not (header and ln.startswith("t_ns,"))
    ]
    rows = [stripped[i] for i in keep]
    want = len(_COLUMNS[fmt])
    if fmt in ("tum", "kitti"):
        # One space between values (as every writer does): count the spaces, else split.
        if "  " in text or "\t" in text:
            counts = np.fromiter((len(r.split()) for r in rows), dtype=np.intp, count=len(rows))
        else:
            counts = np.fromiter((r.count(" ") + 1 for r in rows), dtype=np.intp, count=len(rows))
        bad = counts != want
    else:
        counts = np.fromiter((r.count(",") + 1 for r in rows), dtype=np.intp, count=len(rows))
        # EuRoC rows have 8 or more columns; ertools' frame_id may hold a quoted comma.
        bad = counts < want
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise BagError(
            f"row {keep[k] + 1}: {counts[k]} values, a {fmt.upper()} row has "
            f"{want}{' or more' if fmt in ('euroc', 'csv') else ''}",
            path=path,
        )
    if not rows:
        raise BagError(f"no data rows in this {fmt.upper()} file", path=path)
    return _Rows(rows, [i + 1 for i in keep], fmt)


def _parse(text: str) -> F64 | None:
    """Whitespace-separated numbers by NumPy's C parser (correctly rounded, as float()),
    None when a token is no number."""
    try:
        out: F64 = np.fromstring(text, dtype=np.float64, sep=" ")
    except ValueError:
        return None
    return out


def _floats(rows: _Rows, cols: list[int], path: Path) -> F64:
    """The numbers of columns ``cols`` (all of a row's first columns up to max(cols))."""
    fmt, n = rows.fmt, len(rows.text)
    width = max(cols) + 1
    if fmt in ("tum", "kitti"):
        parsed = _parse("\n".join(rows.text))
        block = None if parsed is None else parsed.reshape(n, -1)[:, :width]
    else:
        # Only the first ``width`` cells: EuRoC's extra columns, ertools' frame_id (one
        # value repeated on every row: cut as a common suffix, without splitting rows).
        first = rows.text[0]
        tail = first[len(",".join(first.split(",", width)[:width])) :]
        if all(r.endswith(tail) for r in rows.text):
            body = [r[: len(r) - len(tail)] for r in rows.text] if tail else rows.text
            parsed = _parse("\n".join(body).replace(",", " "))
        else:
            cut = [r.split(",", width)[:width] for r in rows.text]
            parsed = _parse("\n".join(" ".join(c) for c in cut))
        block = None if parsed is None or parsed.size != n * width else parsed.reshape(n, width)
    if block is None:
        _first_bad(rows, cols, path)
        raise AssertionError("unreachable: NumPy refused rows whose cells all parse")
    out: F64 = np.ascontiguousarray(block[:, cols])
    if not np.isfinite(out).all():
        r, c = np.argwhere(~np.isfinite(out))[0]
        _bad_value(rows, int(r), cols[int(c)], path, "not a finite number")
    return out


def _first_bad(rows: _Rows, cols: list[int], path: Path) -> None:
    """Only on the error path: find the first cell that is no number, row by row."""
    for r in range(len(rows.text)):
        cells = rows.cells(r)
        for c in cols:
            try:
                float(cells[c])
            except ValueError:
                _bad_value(rows, r, c, path, "not a number")


def _bad_value(rows: _Rows, r: int, c: int, path: Path, why: str) -> NoReturn:
    # The cell is not quoted: a message may reach published pages, and the file may be
    # anything (docs/qa.md, "bytes of arbitrary files").
    name = _COLUMNS[rows.fmt][c]
    raise BagError(f"row {rows.lines[r]}, column {c + 1} ({name}) is {why}", path=path)


def _first_cells(rows: _Rows) -> list[str]:
    if rows.fmt in ("tum", "kitti"):
        return [r.split(None, 1)[0] for r in rows.text]
    return [r.partition(",")[0] for r in rows.text]


def _plain_decimal_ns(tokens: list[str]) -> tuple[I64, npt.NDArray[np.bool_]]:
    """Plain decimal seconds (``-?d{1,10}(.d{0,9})?``) -> int64 ns by digit arithmetic on the
    bytes, one character column at a time (vectorised over the tokens); the mask says which
    tokens were plain (the others are left 0 for the caller)."""
    n = len(tokens)
    raw = np.array(tokens, dtype="S")
    width = raw.dtype.itemsize
    if n == 0 or width > 21:
        return np.zeros(n, dtype=np.int64), np.zeros(n, dtype=bool)
    m = raw.view(np.uint8).reshape(n, width)
    neg = m[:, 0] == ord("-")
    dots = np.count_nonzero(m == ord("."), axis=1)
    at = np.where(dots > 0, np.argmax(m == ord("."), axis=1), width - np.count_nonzero(m == 0, 1))
    length = width - np.count_nonzero(m == 0, axis=1)
    whole = at - neg
    ok = (dots <= 1) & (whole >= 1) & (whole <= 10) & (length - at - 1 <= 9)
    ns = np.zeros(n, dtype=np.int64)
    ended = np.zeros(n, dtype=bool)
    for j in range(width):
        c = m[:, j]
        is_pad = c == 0
        ok &= ~(ended & ~is_pad)  # a NUL only as the padding at the end
        ended |= is_pad
        digit = (c >= ord("0")) & (c <= ord("9"))
        sign = (j == 0) & neg
        ok &= digit | is_pad | (c == ord(".")) | sign
        # The power of ten of this digit in nanoseconds: 8 + (dot - j) before the dot,
        # 9 - (j - dot) after it.
        exp = np.where(j < at, 8 + at - j, 9 - (j - at))
        use = digit & ok & (exp >= 0)
        if use.any():
            ns += np.where(use, (c.astype(np.int64) - ord("0")) * 10 ** np.clip(exp, 0, 18), 0)
    # 10 whole digits can pass int64 ns (after 2262): only up to 9 223 372 035 s.
    top = ok & (whole == 10)
    if top.any():
        idx = np.flatnonzero(top)
        big = np.array([tokens[i].lstrip("-")[:10] > "9223372035" for i in idx.tolist()])
        ok[idx[big]] = False
    return np.where(ok, np.where(neg, -ns, ns), 0).astype(np.int64), ok


def _decimal_ns(rows: _Rows, path: Path) -> I64:
    """The first column, decimal seconds, as int64 ns exactly (integer arithmetic; half to
    even past the 9th decimal, exponents via Decimal)."""
    from decimal import ROUND_HALF_EVEN, Decimal, InvalidOperation  # lazy: decimal, 1 ms, text only

    tokens = _first_cells(rows)
    out, plain = _plain_decimal_ns(tokens)
    for r in np.flatnonzero(~plain).tolist():  # exponents, long fractions: rare
        token = tokens[r]
        try:
            d = Decimal(token)
            if not d.is_finite():
                raise InvalidOperation
            ns = int((d * _NS).quantize(Decimal(1), rounding=ROUND_HALF_EVEN))
        except (InvalidOperation, ValueError):
            _bad_value(rows, r, 0, path, "not a time in seconds")
        if abs(ns) >= 2**63:
            _bad_value(rows, r, 0, path, "out of the int64 nanosecond range")
        out[r] = ns
    return out


def _int_ns(rows: _Rows, path: Path) -> I64:
    tokens = _first_cells(rows)
    ok = np.fromiter(
        (t.lstrip("-").isdigit() and len(t) <= 19 for t in tokens), dtype=bool, count=len(tokens)
    )
    if not ok.all():
        _bad_value(rows, int(np.flatnonzero(~ok)[0]), 0, path, "not an integer time in ns")
    return np.fromiter(map(int, tokens), dtype=np.int64, count=len(tokens))


def _quat_from_matrices(rot: npt.NDArray[np.float64]) -> F64:
    from scipy.spatial.transform import Rotation  # lazy: scipy, 300 ms

    q: F64 = Rotation.from_matrix(rot).as_quat()
    return q


def read_text_poses(path: str | Path, fmt: TextFormat | None = None) -> PoseStream:
    """The poses of a text trajectory (``fmt`` None: :func:`sniff` it).

    Raises:
        BagError: not a text trajectory, or a bad value (its row and column named).
    """
    p = Path(path)
    if not p.exists():
        raise BagError("no such file or directory", path=p, transient=True)
    kind = fmt if fmt is not None else sniff(p)
    if kind is None:
        raise BagError("not a text trajectory (TUM, KITTI, EuRoC or ertools CSV)", path=p)
    rows = _rows(p, kind)
    source = str(p)
    if kind == "tum":
        t_ns = _decimal_ns(rows, p)
        nums = _floats(rows, list(range(8)), p)
        return PoseStream(t_ns, nums[:, 1:4], nums[:, 4:8], source=source, t_s=nums[:, 0])
    if kind == "euroc":
        t_ns = _int_ns(rows, p)
        nums = _floats(rows, list(range(8)), p)
        # evo: the stamp parsed as a float, then divided by 1e9 (float64 both times).
        t_s = nums[:, 0] / 1e9
        quat = nums[:, [5, 6, 7, 4]]  # EuRoC writes w first
        return PoseStream(t_ns, nums[:, 1:4], quat, source=source, t_s=t_s)
    if kind == "kitti":
        nums = _floats(rows, list(range(12)), p)
        m = nums.reshape(-1, 3, 4)
        n = len(m)
        t_ns = np.arange(n, dtype=np.int64) * _NS
        return PoseStream(
            t_ns,
            np.ascontiguousarray(m[:, :, 3]),
            _quat_from_matrices(m[:, :, :3]),
            source=source,
            t_s=np.arange(n, dtype=np.float64),
        )
    t_ns = _int_ns(rows, p)
    nums = _floats(rows, list(range(2, 9)), p)
    frame = _csv_frame(p)
    return PoseStream(t_ns, nums[:, 0:3], nums[:, 3:7], frame_id=frame, source=source)


def _csv_frame(path: Path) -> str:
    """The frame_id of ertools' CSV (one value repeated): read with the csv module, which
    undoes the RFC 4180 quoting the writer applied."""
    import csv  # lazy: csv, 1 ms, only to read a CSV export back

    with io.TextIOWrapper(open_regular(path), encoding="utf-8", newline="") as f:
        reader = csv.reader(f)
        next(reader, None)
        row = next(reader, None)
    return row[9] if row is not None and len(row) > 9 else ""


def is_text_trajectory(path: str | Path, forced: str | None = None) -> TextFormat | None:
    """The text layout to read ``path`` with: ``forced`` (``--input-format``; ``bag`` gives
    None), else :func:`sniff`'s answer."""
    if forced == "bag":
        return None
    for kind in TEXT_FORMATS:
        if forced == kind:
            return kind
    if forced is not None:
        raise ValueError(f"unknown input format {forced!r}")
    return sniff(path)
