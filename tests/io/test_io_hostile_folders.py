"""Hostile folders: one entry that cannot be read (a folder without permission, one deeper
than the system's path limit, a FIFO named like a bag) is one problem line naming it, and
every other bag is still found and read, by `info`, `timeline` and `rescore --init` alike."""

from __future__ import annotations

import errno
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from ertools.cli.main import main
from ertools.io.formats import find_bags, regular_files

REPO = Path(__file__).resolve().parents[2]
FBM3W = REPO / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
LOCKED = "lost+found"
# The longest line a problem naming a too-deep folder may make: its path shortened to about
# 120 characters (ertools.errors.MAX_SHOWN) leaves room for the words around it.
SHORT_LINE = 200


def _folder(tmp_path: Path) -> Path:
    """A logger's folder: one benchmark log, and a ``lost+found`` holding a bag of its own."""
    if not FBM3W.exists():
        pytest.skip("sample_bags/ not generated (make samples)")
    root = tmp_path / "logs"
    (root / LOCKED).mkdir(parents=True)
    shutil.copy(FBM3W, root / FBM3W.name)
    shutil.copy(FBM3W, root / LOCKED / "hidden.bag")
    (root / LOCKED / "goal.yaml").write_text("x: 1\n")
    return root


def _locked(monkeypatch: pytest.MonkeyPatch, name: str = LOCKED) -> None:
    """Folders called ``name`` behave as a folder of mode 700 owned by someone else does for
    a user who is not root: listing it, or looking at anything inside it, is refused (the
    tests run as root here, where chmod refuses nothing)."""
    real_scandir, real_stat = os.scandir, os.stat

    def denied(path: object) -> PermissionError:
        return PermissionError(errno.EACCES, "Permission denied", os.fsdecode(path))  # type: ignore[call-overload]

    def scandir(path: object = ".") -> object:
        if Path(os.fsdecode(path)).name == name:  # type: ignore[call-overload]
            raise denied(path)
        return real_scandir(path)  # type: ignore[call-overload]

    def stat(path: object, *args: object, **kwargs: object) -> os.stat_result:
        if (
            isinstance(path, (str, bytes, os.PathLike))
            and Path(os.fsdecode(path)).parent.name == name
        ):
            raise denied(path)
        return real_stat(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "scandir", scandir)
    monkeypatch.setattr(os, "stat", stat)


def _lines(err: str, kind: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith(f"ertools: {kind}:")]


def test_find_bags_names_an_unreadable_folder_once_and_finds_the_rest(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    root = _folder(tmp_path)
    _locked(monkeypatch)
    found = find_bags([root])
    assert found.bags == (root / FBM3W.name,)
    assert [(p.path, p.problem) for p in found.problems] == [
        (str(root / LOCKED), "folder skipped: permission denied")
    ]
    files, problems = regular_files([root])
    assert files == [root / FBM3W.name]
    assert [p.path for p in problems] == [str(root / LOCKED)]


def test_a_folder_really_unreadable(tmp_path: Path) -> None:
    """The same with a real mode-000 folder, where the system refuses it."""
    if os.geteuid() == 0:
        pytest.skip("n/a: running as root, which reads any folder (the monkeypatched test runs)")
    root = _folder(tmp_path)
    (root / LOCKED).chmod(0)
    try:
        found = find_bags([root])
    finally:
        (root / LOCKED).chmod(0o700)
    assert found.bags == (root / FBM3W.name,)
    assert [p.problem for p in found.problems] == ["folder skipped: permission denied"]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("argv", "code", "kind"),
    [
        # info: each problem is an error line (exit 1), the readable bags are still described
        (lambda root, tmp: ["info", str(root)], 1, "error"),
        # timeline surveys folders with broken files in them: a warning, and exit 0
        (lambda root, tmp: ["timeline", str(root), "--no-clock-check"], 0, "warning"),
        (lambda root, tmp: ["rescore", str(root), "--init", str(tmp / "c.yaml")], 0, None),
    ],
    ids=["info", "timeline", "rescore-init"],
)
def test_commands_go_on_past_an_unreadable_folder(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    argv: Callable[[Path, Path], list[str]],
    code: int,
    kind: str | None,
) -> None:
    root = _folder(tmp_path)
    _locked(monkeypatch)
    assert main(argv(root, tmp_path)) == code
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "unexpected" not in err
    assert "hidden.bag" not in out + err  # never read
    if kind is not None:
        (line,) = _lines(err, kind)
        assert LOCKED in line and "permission denied" in line
    if argv(root, tmp_path)[0] == "info":
        assert FBM3W.name in out
    if argv(root, tmp_path)[0] == "timeline":
        assert FBM3W.name in out
    if argv(root, tmp_path)[0] == "rescore":
        draft = (tmp_path / "c.yaml").read_text()
        assert FBM3W.name in draft and "fbm3w" in draft
        assert "goal.yaml" not in draft


def _deep(root: Path, levels: int = 90, name: str = "d" * 50) -> int:
    """Folders ``levels`` deep under ``root``, made through directory descriptors (their path
    is longer than the system accepts); a bag at the bottom. Returns that path's length."""
    fd = os.open(root, os.O_RDONLY)
    try:
        for _ in range(levels):
            os.mkdir(name, dir_fd=fd)
            child = os.open(name, os.O_RDONLY, dir_fd=fd)
            os.close(fd)
            fd = child
        bag = os.open("x.bag", os.O_WRONLY | os.O_CREAT, 0o644, dir_fd=fd)
        os.write(bag, FBM3W.read_bytes()[:4096])
        os.close(bag)
    finally:
        os.close(fd)
    return len(str(root)) + levels * (len(name) + 1)


def test_a_folder_deeper_than_the_path_limit_is_one_short_problem(tmp_path: Path) -> None:
    root = _folder(tmp_path)
    length = _deep(root)
    assert length > os.pathconf("/", "PC_PATH_MAX")
    found = find_bags([root])
    assert root / FBM3W.name in found.bags
    (problem,) = found.problems
    assert "path longer than the system allows" in problem.problem
    assert problem.path.startswith(str(root)[:40]) and "characters)" in problem.path
    assert len(f"{problem.path}: {problem.problem}") < 200


@pytest.mark.slow
@pytest.mark.parametrize(
    ("argv", "code", "kind"),
    [
        (lambda root, tmp: ["info", str(root)], 1, "error"),
        (lambda root, tmp: ["timeline", str(root), "--no-clock-check"], 0, "warning"),
        (lambda root, tmp: ["rescore", str(root), "--init", str(tmp / "c.yaml")], 0, None),
    ],
    ids=["info", "timeline", "rescore-init"],
)
def test_commands_go_on_past_a_folder_too_deep(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    argv: Callable[[Path, Path], list[str]],
    code: int,
    kind: str | None,
) -> None:
    root = _folder(tmp_path)
    shutil.rmtree(root / LOCKED)
    _deep(root)
    assert main(argv(root, tmp_path)) == code
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "unexpected" not in err
    said = [ln for ln in err.splitlines() if ln.startswith(("ertools: error", "ertools: warning"))]
    # a path past the system's limit shown by its ends (errors.shown): each line naming it stays
    # short (rescore also warns of the log's other problems, with their ordinary paths)
    deep = [ln for ln in said if "(4" in ln and "characters)" in ln]
    assert deep or kind is None, err
    assert all(len(ln) <= SHORT_LINE for ln in deep), err
    if kind is not None:
        (line,) = _lines(err, kind)
        assert "path longer than the system allows" in line
    assert FBM3W.name in (out if argv(root, tmp_path)[0] != "rescore" else "") or (
        FBM3W.name in (tmp_path / "c.yaml").read_text()
    )


def test_a_fifo_named_like_a_bag_is_skipped_and_named(tmp_path: Path) -> None:
    root = _folder(tmp_path)
    shutil.rmtree(root / LOCKED)
    os.mkfifo(root / "recording.bag")
    os.mkfifo(root / "notes.yaml")
    found = find_bags([root])
    assert found.bags == (root / FBM3W.name,)
    assert [(p.path, p.problem) for p in found.problems] == [
        (str(root / "recording.bag"), "not a regular file (a FIFO); skipped")
    ]
    # the config files rescore --init looks through: only regular files
    files, _problems = regular_files([root])
    assert files == [root / FBM3W.name]
    (explicit,) = find_bags([root / "recording.bag"]).problems
    assert explicit.problem == "not a regular file (a FIFO)"
