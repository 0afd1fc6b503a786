"""Read one file with ertools and with the official readers, and judge ertools' answer.

An *answer* has three parts, each judged on its own:

- ``summary``: topic -> (type, count, first, last record time ns); ertools' is
  :func:`ertools.io.info.describe` (what ``ertools info`` prints), the official one lists the
  connections (channels) and counts the messages it iterates.
- ``poses``: the ``PoseStamped`` topic as rows (record time, x, y, z, qx, qy, qz, qw);
  ertools' is :func:`ertools.io.reader.read_poses` (``time_source="record"``), the official one
  deserializes every message with rosbags (definitions stored in the file).
- ``tf``: ``world -> robot`` from ``/tf`` as rows (header stamp, translation, rotation);
  ertools' is :func:`ertools.io.reader.read_tf`.

Official readers: rosbags' ``AnyReader`` for ROS1, ``mcap``'s seeking reader for MCAP
(it falls back to a linear read when the summary has no chunk indexes).

Verdict of a part:

- ``agree``: the official reader answers and ertools' answer is the same (same topics, types,
  counts, times to the ns; pose rows as a multiset, values to 1e-9, NaN equal to NaN);
- ``salvaged``: the official reader fails, ertools answers, and everything it answers is true
  of the undamaged file (topics and types as there, counts no larger, times inside the
  topic's true span; every pose row one of the true rows): a partial read, never made up;
- ``refused``: ertools raises an ErtoolsError with a one-line message;
- ``misread``: the official reader answers from bytes that fail a CRC the MCAP format
  defines (:func:`mcap_crc_evidence`: ``mcap``'s own readers refuse them with CRC checks
  on), and ertools' answer is exactly the undamaged file's: a judge error, not ertools',
  counted on its own (never as an agreement);
- ``disagree``: ertools answers and the answer is neither of the above (or refuses with a
  message of several lines);
- ``traceback``: ertools raises anything else.

A case is its worst part: traceback > disagree > misread > refused > salvaged > agree.
"""

from __future__ import annotations

import contextlib
import io
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fuzz.seeds import POSE_TOPIC, TF_CHILD, TF_PARENT, TF_TOPIC

PARTS = ("summary", "poses", "tf")
ORDER = ("agree", "salvaged", "refused", "misread", "disagree", "traceback")
POSE_TOL = 1e-9

Summary = dict[str, tuple[str, int, int | None, int | None]]
Rows = tuple[np.ndarray, np.ndarray]  # (t int64 (N,), values float64 (N, 7))


@dataclass(frozen=True)
class Outcome:
    ok: bool
    value: Any = None
    why: str = ""


def _short(msgtype: str) -> str:
    return msgtype.replace("/msg/", "/")


def _rows(t: list[int], v: list[list[float]]) -> Rows:
    return np.asarray(t, dtype=np.int64), np.asarray(v, dtype=np.float64).reshape(-1, 7)


# ertools ------------------------------------------------------------------------------------


def ertools_answer(path: Path) -> dict[str, Outcome | str]:
    """Each part as an Outcome, or the text of a traceback (a bug)."""
    from ertools.errors import BagError, ErtoolsError
    from ertools.io.info import describe
    from ertools.io.reader import read_poses, read_tf

    def summary() -> Summary:
        info = describe(path)
        if info.fatal_problem is not None:
            # what `ertools info` refuses with exit 1 and one line
            raise BagError(info.fatal_problem)
        s = info.summary
        return {t.name: (t.msgtype, t.count, t.first_ns, t.last_ns) for t in s.topics}

    def poses() -> Rows:
        p = read_poses(path, POSE_TOPIC, time_source="record")
        return p.t_ns.astype(np.int64), np.column_stack([p.xyz, p.quat_xyzw]).astype(np.float64)

    def tf() -> Rows:
        p = read_tf(path, TF_PARENT, TF_CHILD)
        return p.t_ns.astype(np.int64), np.column_stack([p.xyz, p.quat_xyzw]).astype(np.float64)

    out: dict[str, Outcome | str] = {}
    parts: dict[str, Callable[[], Any]] = {"summary": summary, "poses": poses, "tf": tf}
    for name, fn in parts.items():
        try:
            out[name] = Outcome(True, fn())
        except ErtoolsError as err:
            out[name] = Outcome(False, why=str(err))
        except Exception:  # a bug: anything but an ErtoolsError
            out[name] = traceback.format_exc(limit=-6)
    return out


# official -----------------------------------------------------------------------------------


def _pose_row(msg: Any) -> list[float]:
    p, q = msg.pose.position, msg.pose.orientation
    return [p.x, p.y, p.z, q.x, q.y, q.z, q.w]


def _tf_rows(msg: Any, t: list[int], v: list[list[float]], ros1: bool) -> None:
    for tr in msg.transforms:
        if (
            tr.header.frame_id.lstrip("/") == TF_PARENT
            and tr.child_frame_id.lstrip("/") == TF_CHILD
        ):
            s = tr.header.stamp
            # ROS1's time is uint32 seconds; rosbags gives ROS2's int32 (a damaged high bit
            # reads as 1947 instead of 2083)
            sec = int(s.sec) % (1 << 32) if ros1 else int(s.sec)
            t.append(sec * 1_000_000_000 + int(s.nanosec))
            a, q = tr.transform.translation, tr.transform.rotation
            v.append([a.x, a.y, a.z, q.x, q.y, q.z, q.w])


def _decoded(
    msgs: list[tuple[str, str, int, Any]], decode: Callable[[Any, str], Any]
) -> dict[str, Outcome]:
    """poses and tf from (topic, type, record time, raw) with the given deserializer."""
    out: dict[str, Outcome] = {}
    pose = [m for m in msgs if m[0] == POSE_TOPIC]
    try:
        if not any(m[0] == POSE_TOPIC for m in msgs) and not pose:
            raise LookupError("no pose messages")
        types = {m[1] for m in pose}
        if types and types != {"geometry_msgs/PoseStamped"}:
            raise TypeError(f"pose topic of type {types}")
        rows = [(t, _pose_row(decode(raw, ty))) for _, ty, t, raw in pose]
        out["poses"] = Outcome(True, _rows([r[0] for r in rows], [r[1] for r in rows]))
    except Exception as err:
        out["poses"] = Outcome(False, why=f"{type(err).__name__}: {err}")
    try:
        t: list[int] = []
        v: list[list[float]] = []
        for topic, ty, _t, raw in msgs:
            if topic == TF_TOPIC and ty in ("tf2_msgs/TFMessage", "tf/tfMessage"):
                _tf_rows(decode(raw, ty), t, v, _ros1_encoded(raw))
        if not t:
            raise LookupError("no world -> robot transform")
        out["tf"] = Outcome(True, _rows(t, v))
    except Exception as err:
        out["tf"] = Outcome(False, why=f"{type(err).__name__}: {err}")
    return out


def _ros1_encoded(raw: Any) -> bool:
    """Whether a message is in ROS1's serialisation: a ROS1 bag's bytes, or an MCAP item
    (schema, encoding, bytes) of the ``ros1`` encoding."""
    return not isinstance(raw, tuple) or raw[1] == "ros1"


def _read_ros1(path: Path, topic: str | None) -> tuple[Summary, dict[str, Outcome]]:
    from rosbags.highlevel import AnyReader

    with AnyReader([path]) as reader:
        conns = list(reader.connections)
        wanted = [c for c in conns if topic is None or c.topic == topic]
        msgs = [
            (c.topic, _short(c.msgtype), int(t), raw)
            for c, t, raw in reader.messages(connections=wanted)
        ]
        summary = _summary_of([(c.topic, _short(c.msgtype)) for c in conns], msgs)
        decoded = _decoded(
            msgs, lambda raw, ty: reader.deserialize(raw, ty.replace("/", "/msg/", 1))
        )
    return summary, decoded


def _summary_of(conns: list[tuple[str, str]], msgs: list[tuple[str, str, int, Any]]) -> Summary:
    out: Summary = {}
    for topic, ty in conns:
        ts = [t for tp, _ty, t, _raw in msgs if tp == topic]
        out.setdefault(topic, (ty, len(ts), min(ts) if ts else None, max(ts) if ts else None))
    return out


# typestores by schema (name, text), kept across cases: rosbags compiles a deserializer per
# type and typestore, which costs far more than reading these small files
_STORES: dict[str, Any] = {}


def _mcap_decoder(schemas: dict[int, Any]) -> Callable[[Any, str], Any]:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    stores = _STORES
    if len(stores) > 256:
        stores.clear()

    def decode(item: Any, _ty: str) -> Any:
        schema, encoding, raw = item
        key = f"{schema.name}\0{schema.data!r}"
        if key not in stores:
            ts = get_typestore(Stores.EMPTY)
            name = schema.name if "/msg/" in schema.name else schema.name.replace("/", "/msg/", 1)
            ts.register(get_types_from_msg(schema.data.decode(), name))
            stores[key] = (ts, name)
        ts, name = stores[key]
        if encoding == "ros1":
            return ts.deserialize_ros1(raw, name)
        return ts.deserialize_cdr(raw, name)

    return decode


def _read_mcap(path: Path, topic: str | None) -> tuple[Summary, dict[str, Outcome]]:
    from mcap.reader import make_reader
    from mcap.records import Channel
    from mcap.stream_reader import StreamReader

    with path.open("rb") as f:
        reader = make_reader(f)
        items = [
            (
                ch.topic,
                _short(sc.name) if sc else "",
                int(m.log_time),
                (sc, ch.message_encoding, m.data),
            )
            for sc, ch, m in reader.iter_messages(
                topics=None if topic is None else [topic], log_time_order=True
            )
        ]
        summ = reader.get_summary()
        if summ is not None:
            channels = dict(summ.channels)
            schemas = dict(summ.schemas)
        else:  # no summary section: the channels as the stream declares them
            f.seek(0)
            channels, schemas = {}, {}
            for record in StreamReader(f, skip_magic=False, emit_chunks=False).records:
                if isinstance(record, Channel):
                    channels.setdefault(record.id, record)
            for _t, _ty, _lt, (sc, _e, _d) in items:
                if sc is not None:
                    schemas[sc.id] = sc
        conns = []
        for cid in sorted(channels):
            sc = schemas.get(channels[cid].schema_id)
            conns.append((channels[cid].topic, _short(sc.name) if sc else ""))
    return _summary_of(conns, items), _decoded(items, _mcap_decoder({}))


def official_answer(path: Path) -> dict[str, Outcome]:
    """The official readers' answers. The summary reads every message; when that read fails,
    poses and tf are read again with only their topic (as ertools reads them: a damaged
    record of another topic need not stop them)."""
    with path.open("rb") as f:
        head = f.read(8)
    read = _read_ros1 if head.startswith(b"#ROSBAG") else _read_mcap
    try:
        summary, decoded = read(path, None)
    except Exception as err:
        failed = Outcome(False, why=f"{type(err).__name__}: {err}")
        out = {"summary": failed}
        for part, topic in (("poses", POSE_TOPIC), ("tf", TF_TOPIC)):
            try:
                out[part] = read(path, topic)[1][part]
            except Exception as err2:
                out[part] = Outcome(False, why=f"{type(err2).__name__}: {err2}")
        return out
    return {"summary": Outcome(True, summary), **decoded}


def mcap_crc_evidence(path: Path) -> str:
    """Which CRC that the MCAP format defines the file fails ('' when none, or when the file
    is not MCAP): every chunk and the data section as ``mcap``'s own linear reader checks
    them (``validate_crcs=True``), and the summary section's CRC in the footer (the
    specification's definition: from the first summary record through the footer's
    ``summary_offset_start``; ``mcap``'s Python reader never checks it).

    The seeking reader the judge asks (``validate_crcs`` off, its default) reads damaged
    bytes as if they were sound: this is the evidence that its answer is a misreading.
    """
    import struct
    import zlib

    from mcap.stream_reader import CRCValidationError, StreamReader

    data = path.read_bytes()
    if not data.startswith(b"\x89MCAP"):
        return ""
    found = []
    try:
        with path.open("rb") as f:
            for _record in StreamReader(f, validate_crcs=True).records:
                pass
    except CRCValidationError as err:
        found.append(f"mcap's reader with validate_crcs=True: {err}")
    except Exception:  # other damage stops the read first: no CRC verdict from it
        pass
    at = len(data) - 8 - 29
    if at > 0 and data[at] == 0x02:
        _op, _n, start, _offsets, crc = struct.unpack_from("<BQQQI", data, at)
        if crc and 0 < start < at and zlib.crc32(data[start : at + 25]) != crc:
            found.append("the summary section fails the footer's summary CRC")
    return "; ".join(found)


def _ros1_fields(head: bytes) -> dict[str, bytes]:
    import struct

    out, at = {}, 0
    while at + 4 <= len(head):
        (n,) = struct.unpack_from("<I", head, at)
        name, _, value = head[at + 4 : at + 4 + n].partition(b"=")
        out[name.decode("latin-1")] = value
        at += 4 + n
    return out


def ros1_record_summary(path: Path) -> dict[str, tuple[int, int, int]] | None:
    """topic -> (count, first, last record time) from the bag's records read one by one
    (chunks decompressed, connection and message records inside them), the index never
    consulted; None when the walk meets a record it cannot read. The judge's own walker (a
    few lines from the format's description), not ertools' nor rosbags'."""
    import bz2
    import struct

    import lz4.frame

    data = path.read_bytes()
    if not data.startswith(b"#ROSBAG V2.0\n"):
        return None

    def walk(
        buf: bytes, at: int, inner: bool, topics: dict[int, str], times: dict[int, list[int]]
    ) -> None:
        while at < len(buf):
            (hlen,) = struct.unpack_from("<I", buf, at)
            head = buf[at + 4 : at + 4 + hlen]
            (dlen,) = struct.unpack_from("<I", buf, at + 4 + hlen)
            body = buf[at + 8 + hlen : at + 8 + hlen + dlen]
            if len(head) != hlen or len(body) != dlen:
                raise ValueError("record cut off")
            f = _ros1_fields(head)
            op = f["op"][0]
            if op == 0x05 and not inner:
                kind = f["compression"].decode()
                raw = {"none": lambda b: b, "bz2": bz2.decompress, "lz4": lz4.frame.decompress}[
                    kind
                ](body)
                walk(raw, 0, True, topics, times)
            elif op == 0x07:
                (cid,) = struct.unpack("<I", f["conn"])
                topics.setdefault(cid, f["topic"].decode())
            elif op == 0x02 and inner:
                (cid,) = struct.unpack("<I", f["conn"])
                sec, nsec = struct.unpack("<II", f["time"])
                times.setdefault(cid, []).append(sec * 1_000_000_000 + nsec)
            at += 8 + hlen + dlen

    topics: dict[int, str] = {}
    times: dict[int, list[int]] = {}
    try:
        walk(data, 13, False, topics, times)
    except Exception:
        return None
    out: dict[str, list[int]] = {}
    for cid, topic in topics.items():
        out.setdefault(topic, []).extend(times.get(cid, []))
    if set(times) - set(topics):
        return None
    return {t: (len(v), min(v, default=0), max(v, default=0)) for t, v in out.items()}


def ros1_index_evidence(path: Path, truth: Outcome) -> str:
    """'' unless the bag's records, read one by one, hold exactly the undamaged file's
    messages (topics, counts, first and last times): then the damage is in the index only,
    and an answer that differs from the undamaged file's was read from a damaged index."""
    if not truth.ok:
        return ""
    walked = ros1_record_summary(path)
    want = {t: (n, a or 0, b or 0) for t, (_ty, n, a, b) in truth.value.items()}
    if walked is not None and walked == want:
        return "the records, read one by one, are the undamaged file's: only the index is damaged"
    # or the other way round: rosbags' own index counts are the undamaged file's while the
    # records it reads through that index say otherwise (a damaged record header)
    try:
        from rosbags.highlevel import AnyReader

        with AnyReader([path]) as reader:
            indexed: dict[str, int] = {}
            for c in reader.connections:
                indexed[c.topic] = indexed.get(c.topic, 0) + c.msgcount
            read: dict[str, int] = {}
            for c, _t, _raw in reader.messages():
                read[c.topic] = read.get(c.topic, 0) + 1
    except Exception:
        return ""
    counts = {t: n for t, (_ty, n, _a, _b) in truth.value.items()}
    if indexed == counts and {t: read.get(t, 0) for t in counts} != counts:
        return (
            "rosbags' own index counts are the undamaged file's, the records it reads "
            "through them are not: a damaged record header"
        )
    return ""


# judging ------------------------------------------------------------------------------------


def _sorted(rows: Rows) -> Rows:
    t, v = rows
    order = np.lexsort((*v.T[::-1], t)) if len(t) else np.arange(0)
    return t[order], v[order]


def _same_rows(a: Rows, b: Rows) -> bool:
    (ta, va), (tb, vb) = _sorted(a), _sorted(b)
    return (
        ta.shape == tb.shape
        and bool(np.array_equal(ta, tb))
        and bool(np.allclose(va, vb, rtol=0, atol=POSE_TOL, equal_nan=True))
    )


def _rows_within(a: Rows, truth: Rows) -> bool:
    """Every row of ``a`` is a row of ``truth`` (time exact, values to the tolerance)."""
    ta, va = a
    tt, vt = truth
    for t, v in zip(ta.tolist(), va, strict=True):
        hit = np.flatnonzero(tt == t)
        if not any(np.allclose(vt[h], v, rtol=0, atol=POSE_TOL) for h in hit):
            return False
    return True


def _union(rows: list[Rows]) -> Rows:
    if not rows:
        return np.empty(0, np.int64), np.empty((0, 7))
    return np.concatenate([r[0] for r in rows]), np.concatenate([r[1] for r in rows])


def _summary_within(a: Summary, truth: Summary) -> bool:
    for topic, (ty, n, first, last) in a.items():
        if topic not in truth:
            return False
        tty, tn, tfirst, tlast = truth[topic]
        if ty != tty or n > tn:
            return False
        if n and (first is None or last is None or tfirst is None or tlast is None):
            return False
        if n and not (tfirst <= first <= last <= tlast):  # type: ignore[operator]
            return False
    return True


def judge_part(
    part: str, ert: Outcome | str, off: Outcome, truths: list[Outcome]
) -> tuple[str, str]:
    """(verdict, detail) of one part. ``truths``: the official answers on the undamaged file
    and, for a mutant of several changes, on the file with each change alone (one damaged
    byte can break the official reader while another changes a pose it would read)."""
    if isinstance(ert, str):
        return "traceback", ert
    if not ert.ok:
        if "\n" in ert.why or not ert.why.strip():
            return "disagree", f"refusal message not one line: {ert.why!r}"
        return "refused", ert.why
    if off.ok:
        same = ert.value == off.value if part == "summary" else _same_rows(ert.value, off.value)
        if same:
            return "agree", ""
        return "disagree", f"ertools {_show(ert.value)} != official {_show(off.value)}"
    good = [t.value for t in truths if t.ok]
    if part == "summary":
        within = all(any(_summary_within({k: v}, g) for g in good) for k, v in ert.value.items())
    else:
        within = _rows_within(ert.value, _union(good))
    if within:
        return "salvaged", f"official failed ({off.why})"
    return (
        "disagree",
        f"official failed ({off.why}); ertools answered {_show(ert.value)}, "
        "not in the undamaged file",
    )


def misread(
    part: str, verdict: tuple[str, str], ert: Outcome | str, truth: Outcome, evidence: str
) -> tuple[str, str]:
    """A ``disagree`` turned ``misread`` when ``evidence`` (:func:`mcap_crc_evidence`) shows
    the official reader read damaged bytes and ertools' answer is exactly the undamaged
    file's (``truth``); every other verdict as it was."""
    v, detail = verdict
    if v != "disagree" or not evidence or isinstance(ert, str) or not ert.ok or not truth.ok:
        return verdict
    same = ert.value == truth.value if part == "summary" else _same_rows(ert.value, truth.value)
    if not same:
        return verdict
    return "misread", f"official reader read damaged bytes ({evidence}): {detail}"


def misread_but_for(
    part: str,
    verdict: tuple[str, str],
    ert: Outcome | str,
    truth: Outcome,
    alone: Outcome,
    rest: Outcome,
    evidence: str,
    where: int,
) -> tuple[str, str]:
    """A ``disagree`` of a mutant of several changes turned ``misread`` when the change at
    byte ``where`` is damage the official reader misreads: ``evidence`` shows it on the file
    with that change alone, where the official reader answers other than the undamaged file
    (``alone``); and without that change the official reader answers exactly as ertools did
    (``rest``: the other changes, a pose's bytes say, ertools read as they are). ertools then
    read past the damage the official reader misread; every other verdict as it was."""
    v, detail = verdict
    if v != "disagree" or not evidence or isinstance(ert, str) or not ert.ok:
        return verdict
    if not (truth.ok and alone.ok and rest.ok):
        return verdict
    if _same(part, alone.value, truth.value) or not _same(part, ert.value, rest.value):
        return verdict
    return "misread", (
        f"official reader read damaged bytes ({evidence}); without the change at byte "
        f"{where} it reads what ertools read: {detail}"
    )


def _same(part: str, a: Any, b: Any) -> bool:
    return bool(a == b) if part == "summary" else _same_rows(a, b)


def _show(value: Any) -> str:
    if isinstance(value, dict):
        return repr(value)
    t, v = value
    return f"{len(t)} rows t[{t[:3].tolist()}...] v0={v[:1].tolist()}"


def worst(verdicts: list[str]) -> str:
    return max(verdicts, key=ORDER.index)


def cli_check(path: Path) -> str:
    """'' when ``ertools info`` and ``ertools noise`` behave (exit 0, or exit 1 and one line
    ``ertools: error: ...`` on stderr, never 'unexpected'), else what went wrong."""
    from ertools.cli.main import main

    problems = []
    for argv in (
        ["info", "--format", "json", str(path)],
        ["noise", str(path), "--topic", POSE_TOPIC, "--format", "json"],
    ):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
        lines = [x for x in err.getvalue().splitlines() if x.strip()]
        errors = [x for x in lines if x.startswith("ertools: error:")]
        if code == 0:
            continue
        if (
            code != 1
            or len(errors) != 1
            or "unexpected" in errors[0]
            or "Traceback" in err.getvalue()
        ):
            problems.append(f"`ertools {argv[0]}` exit {code}, stderr {err.getvalue()!r}")
    return "; ".join(problems)
