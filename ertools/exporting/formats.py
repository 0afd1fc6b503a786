"""Pose streams as text for other tools: TUM, KITTI and CSV (evo, pandas, spreadsheets).

The ``format_*`` functions are pure (a :class:`PoseStream` in, text out); :func:`write_poses`
is the thin file writer. Every number is written so that reading it back gives the same
value: times are the int64 nanoseconds written as seconds with exactly 9 decimals (integer
arithmetic, no float on the way), floats as Python's ``repr`` (the shortest text that parses
back to the same double, at most 17 significant digits).

The text is built column-wise: ``map`` over ``tolist()`` and ``str.join`` run in C, so an
hour of 120 Hz mocap (430 k poses) needs no Python loop body per pose.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Literal

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I64
from ertools.atomic import write_text
from ertools.errors import BagError
from ertools.streams import PoseStream

ExportFormat = Literal["tum", "kitti", "csv"]
FORMATS: tuple[ExportFormat, ...] = ("tum", "kitti", "csv")
# File name suffixes of the pair mode (evo reads any name; these say what is inside).
SUFFIXES: dict[ExportFormat, str] = {"tum": ".tum", "kitti": ".kitti", "csv": ".csv"}
CSV_COLUMNS = ("t_ns", "t_s", "x", "y", "z", "qx", "qy", "qz", "qw", "frame_id")


def seconds_text(t_ns: I64) -> list[str]:
    """Nanoseconds as exact decimal seconds, ``1447934399.008333333``: 9 decimals, no float.

    A float64 holds an epoch stamp only to ~0.2 us; the text keeps every nanosecond, so a
    reader that parses it as a decimal (or as int ns) gets the stamp back exactly.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    # abs and a sign so that -0.5 s reads "-0.500000000", not floor division's "-1.500000000".
    mag = np.abs(t)
    whole, frac = np.divmod(mag, np.int64(1_000_000_000))
    sign = np.where(t < 0, "-", "").tolist()
    return list(map("{}{}.{:09d}".format, sign, whole.tolist(), frac.tolist()))


def _floats(column: F64) -> list[str]:
    """repr of every value: the shortest text that parses back to the same double."""
    return list(map(repr, np.asarray(column, dtype=np.float64).tolist()))


def _lines(columns: Iterable[list[str]], sep: str) -> str:
    rows = map(sep.join, zip(*columns, strict=True))
    text = "\n".join(rows)
    return text + "\n" if text else ""


def format_tum(stream: PoseStream) -> str:
    """TUM RGB-D text: one ``timestamp tx ty tz qx qy qz qw`` line per pose, no header.

    evo (``evo_ape tum``), the TUM benchmark tools and most SLAM evaluation scripts read it.
    """
    cols = [seconds_text(stream.t_ns)]
    cols += [_floats(stream.xyz[:, i]) for i in range(3)]
    cols += [_floats(stream.quat_xyzw[:, i]) for i in range(4)]
    return _lines(cols, " ")


def rotation_matrices(quat_xyzw: F64, where: str = "") -> npt.NDArray[np.float64]:
    """(N, 3, 3) rotation matrices of (normalised) quaternions, through SciPy.

    Raises:
        BagError: a zero or non-finite quaternion (it has no rotation matrix).
    """
    from scipy.spatial.transform import Rotation  # lazy: scipy, 300 ms

    q = np.asarray(quat_xyzw, dtype=np.float64)
    if len(q) == 0:
        return np.empty((0, 3, 3))
    norm = np.sqrt(np.einsum("ij,ij->i", q, q))
    bad = ~(np.isfinite(norm) & (norm > 1e-9))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise BagError(
            f"{where or 'pose stream'}: {int(bad.sum())} pose(s) have a zero or NaN quaternion "
            f"(first at index {i}); KITTI needs a rotation matrix for every pose: "
            "export as TUM or CSV instead"
        )
    m: npt.NDArray[np.float64] = Rotation.from_quat(q).as_matrix()
    return m


def format_kitti(stream: PoseStream) -> str:
    """KITTI odometry text: the 3x4 ``[R|t]`` row-major, 12 numbers per line, no time stamps.

    KITTI files have no time: a reader pairs two files row by row. :func:`format_times`
    gives the stamps as KITTI's ``times.txt`` does.
    """
    rot = rotation_matrices(stream.quat_xyzw, stream.source)
    cols: list[list[str]] = []
    for r in range(3):
        cols += [_floats(rot[:, r, c]) for c in range(3)]
        cols.append(_floats(stream.xyz[:, r]))
    return _lines(cols, " ")


def format_times(stream: PoseStream, origin_ns: int | None = None) -> str:
    """KITTI ``times.txt``: one time per pose, seconds since ``origin_ns`` (default: the first
    pose, as KITTI counts from the start of the sequence), exact to the nanosecond."""
    if len(stream) == 0:
        return ""
    t0 = int(stream.t_ns[0]) if origin_ns is None else origin_ns
    return _lines([seconds_text(stream.t_ns - np.int64(t0))], " ")


def _csv_field(text: str) -> str:
    """A CSV field, quoted (RFC 4180) only when it has to be."""
    if any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


def format_csv(stream: PoseStream) -> str:
    """CSV with a header: ``t_ns, t_s, x, y, z, qx, qy, qz, qw, frame_id``.

    ``t_ns`` is the exact int64 stamp, ``t_s`` the same in seconds (9 decimals) for tools
    that want seconds (spreadsheets, plotting tools, pandas ``read_csv``).
    """
    n = len(stream)
    cols = [list(map(str, stream.t_ns.tolist())), seconds_text(stream.t_ns)]
    cols += [_floats(stream.xyz[:, i]) for i in range(3)]
    cols += [_floats(stream.quat_xyzw[:, i]) for i in range(4)]
    cols.append([_csv_field(stream.frame_id)] * n)
    return ",".join(CSV_COLUMNS) + "\n" + _lines(cols, ",")


def format_poses(stream: PoseStream, fmt: ExportFormat) -> str:
    """The stream in one of :data:`FORMATS`."""
    if fmt == "tum":
        return format_tum(stream)
    if fmt == "kitti":
        return format_kitti(stream)
    if fmt == "csv":
        return format_csv(stream)
    raise ValueError(f"unknown export format {fmt!r}; choose from {', '.join(FORMATS)}")


def write_poses(stream: PoseStream, path: str | Path, fmt: ExportFormat) -> Path:
    """Write the stream to ``path`` (its folder is created) and return the path."""
    out = Path(path)
    text = format_poses(stream, fmt)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, text)
    return out
