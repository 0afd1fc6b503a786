"""Every file ertools writes goes through a temporary of a unique name beside it (issue 36,
finding 8): a name chosen in advance (``.OUT.part``) follows a symlink planted there, and two
runs writing one output at once write into the same temporary and leave an unreadable file
while both say "wrote". The Foxglove file is checked against both faults; the rest of
ertools' writers are held to ertools/atomic.py by a scan of the source."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from mcap.reader import make_reader

from ertools.report.foxglove.mcapout import write_mcap
from ertools.views.foxglove import Channel, Collected

PACKAGE = Path(__file__).resolve().parents[2] / "ertools"
TOPIC = "/ertools/note"


def collected(n: int, text: str) -> Collected:
    out = Collected()
    out.channels[TOPIC] = Channel("ertools.Note", "jsonschema", b'{"type":"object"}', "json")
    out.messages.extend((1_000 + i, TOPIC, f'{{"{text}":{i}}}'.encode()) for i in range(n))
    return out


def read_back(path: Path) -> list[bytes]:
    with path.open("rb") as fh:
        return [msg.data for _, _, msg in make_reader(fh).iter_messages()]


def test_foxglove_output_does_not_follow_a_planted_symlink(tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "scene.mcap"
    (tmp_path / ".scene.mcap.part").symlink_to(victim)
    write_mcap(collected(3, "a"), out)
    assert victim.read_text() == "precious\n"
    assert read_back(out) == [b'{"a":0}', b'{"a":1}', b'{"a":2}']
    assert not out.is_symlink()


class _WriteOnceMore(list[tuple[int, str, bytes]]):
    """Messages whose reading, once the writer has read each to order them and then the first
    to write it, starts a second export to the same file (a second run at the same moment),
    written whole before the first goes on."""

    def __init__(self, items: list[tuple[int, str, bytes]], path: Path) -> None:
        super().__init__(items)
        self.path = path
        self.reads = 0

    def __getitem__(self, index: object) -> object:  # type: ignore[override]
        self.reads += 1
        if self.reads == len(self) + 2:  # the first file is open and being written
            write_mcap(collected(2, "second"), self.path)
        return super().__getitem__(index)  # type: ignore[index]


def test_two_foxglove_exports_to_one_file_leave_a_whole_file(tmp_path: Path) -> None:
    out = tmp_path / "scene.mcap"
    first = collected(5, "first")
    first.messages = _WriteOnceMore(first.messages, out)
    write_mcap(first, out)
    # the last rename wins, with a whole file: the first run's, renamed after the second's
    assert read_back(out) == [f'{{"first":{i}}}'.encode() for i in range(5)]
    assert [p.name for p in tmp_path.iterdir()] == ["scene.mcap"]  # no temporary left


# Writes allowed outside ertools/atomic.py: (module or folder, the line's code) and why.
ALLOWED = {
    ("atomic.py", 'with open(path, "wb") as fh:'): "a pipe or a device (-o /dev/stdout)",
    ("atomic.py", "tmp.write_bytes(data)"): "the unique temporary itself",
    ("live/logfile.py", 'open(path, "xb")'): "a new recording, O_EXCL: never a symlink",
    ("live/recover.py", 'open(target, "wb")'): "the temporary of atomic.replacing",
    ("report/figures.py", "path.write_text(svg.render("): "the temporary of atomic.replacing",
    ("io/rosbag2/metadata.py", ".write_text(text"): "a private tempfile.mkdtemp folder",
    ("io/rosbag2/metadata.py", 'out.open("wb")'): "a private tempfile.mkdtemp folder",
    # a generated folder is built whole in a tempfile.mkdtemp folder, then put in place by
    # atomic.replace_folder; its bags by their writers, with O_EXCL
    ("samples/", ""): "inside a tempfile.mkdtemp folder",
    ("simulator/", ""): "inside a tempfile.mkdtemp folder",
    ("api.py", ">>> _ = manifest.write_text("): "a docstring's example",
}
WRITE = re.compile(
    r"""(?<!atomic)\.write_(text|bytes)\(|\bopen\([^)]*["'][rwax]*[wax][b+]*["']"""
    r"""|\.open\(["'][wax]|\.part\b"""
)


# A benchmark's scenario (benchmarks/<name>/sample.py) writes into the same generated folder.
SAMPLE = re.compile(r"benchmarks/\w+/sample\.py")


def allowed(rel: str, code: str) -> bool:
    if SAMPLE.fullmatch(rel):
        return True
    return any(rel.startswith(where) and line in code for where, line in ALLOWED)


@pytest.mark.slow
def test_every_writer_goes_through_a_unique_temporary() -> None:
    """No module of ertools writes a file in place (``open(..., "w")``, ``write_text``,
    ``write_bytes``) or through a name chosen in advance (``.part``), but through
    ``ertools.atomic`` (a folder built whole: ``tempfile.mkdtemp``, then
    ``atomic.replace_folder``). Each exception is listed with why."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("  #", 1)[0].strip()
            if WRITE.search(code) and not allowed(rel, code):
                found.append(f"{rel}:{number}: {code}")
    assert found == []
